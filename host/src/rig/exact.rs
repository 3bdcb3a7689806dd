//! Fixed-length lists of a rig file read exactly. serde reads the first N elements of a longer list into `[T; N]`
//! and drops the rest, so a `home` of seven numbers or a `platform_point` of a hundred thousand would be taken cut
//! short: a mistake to refuse at its key, reading no further than one element past the length.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{Deserialize, Deserializer, Error, IgnoredAny, SeqAccess, Visitor};

struct Exact<T, const N: usize>(PhantomData<T>);

impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for Exact<T, N> {
    type Value = [T; N];

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a list of exactly {N} numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[T; N], A::Error> {
        let mut out = [T::default(); N];
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(i, &self))?;
        }
        if seq.next_element::<IgnoredAny>()?.is_some() {
            return Err(A::Error::custom(format!(
                "more than {N} numbers: a list of exactly {N} numbers"
            )));
        }
        Ok(out)
    }
}

/// `[T; N]` from a list of exactly N elements.
pub fn array<'de, D: Deserializer<'de>, T: Deserialize<'de> + Copy + Default, const N: usize>(
    d: D,
) -> Result<[T; N], D::Error> {
    d.deserialize_seq(Exact::<T, N>(PhantomData))
}

struct Maybe<T, const N: usize>(PhantomData<T>);

impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for Maybe<T, N> {
    type Value = Option<[T; N]>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a list of exactly {N} numbers")
    }

    fn visit_none<E: Error>(self) -> Result<Self::Value, E> {
        Ok(None)
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        array(d).map(Some)
    }
}

/// An optional `[T; N]` from a list of exactly N elements.
pub fn option<'de, D: Deserializer<'de>, T: Deserialize<'de> + Copy + Default, const N: usize>(
    d: D,
) -> Result<Option<[T; N]>, D::Error> {
    d.deserialize_option(Maybe::<T, N>(PhantomData))
}
