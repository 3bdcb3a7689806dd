//! A per-axis key that also takes one value for every axis: `translation_high_pass = { omega = 4, zeta = 1 }`
//! (the files written before the axes were separate) or `translation_high_pass = [{ ... }, { ... }, { ... }]`;
//! `tilt_limit_deg = 15` or `[15, 10]`. Read without allocating (the core has no allocator).

use core::marker::PhantomData;

use serde::de::value::MapAccessDeserializer;
use serde::de::{self, IntoDeserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;

/// Deserializes `[V; N]` from one `V` (a number or a table) repeated, or from a list of exactly `N`.
pub fn one_or_each<'de, D, V, const N: usize>(d: D) -> Result<[V; N], D::Error>
where
    D: serde::Deserializer<'de>,
    V: Deserialize<'de> + Copy,
{
    struct OneOrEach<V, const N: usize>(PhantomData<V>);
    impl<'de, V: Deserialize<'de> + Copy, const N: usize> Visitor<'de> for OneOrEach<V, N> {
        type Value = [V; N];
        fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
            write!(f, "one value for every axis, or a list of {N}")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[V; N], A::Error> {
            let first: V = match seq.next_element()? {
                Some(v) => v,
                None => return Err(de::Error::invalid_length(0, &self)),
            };
            let mut out = [first; N];
            for (i, slot) in out.iter_mut().enumerate().skip(1) {
                *slot = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
            }
            if seq.next_element::<de::IgnoredAny>()?.is_some() {
                return Err(de::Error::invalid_length(N + 1, &self));
            }
            Ok(out)
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<[V; N], A::Error> {
            Ok([V::deserialize(MapAccessDeserializer::new(map))?; N])
        }
        fn visit_f64<E: de::Error>(self, v: f64) -> Result<[V; N], E> {
            Ok([V::deserialize(v.into_deserializer())?; N])
        }
        fn visit_i64<E: de::Error>(self, v: i64) -> Result<[V; N], E> {
            Ok([V::deserialize(v.into_deserializer())?; N])
        }
        fn visit_u64<E: de::Error>(self, v: u64) -> Result<[V; N], E> {
            Ok([V::deserialize(v.into_deserializer())?; N])
        }
    }

    d.deserialize_any(OneOrEach::<V, N>(PhantomData))
}
