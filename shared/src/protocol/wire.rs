//! postcard over a byte slice, with the byte moves out of line: the messages and the stored record are serialized
//! and read through these, not through `postcard::to_slice` and `postcard::take_from_bytes`.
//!
//! postcard's own slice flavors mark writing and reading a byte `#[inline(always)]`, so every field of every
//! message, each array element and each varint byte gets its own copy of the bounds check and the copy: with LTO,
//! 12 KB of the firmware's flash. Here they are one call each; the wire format is postcard's, unchanged. The one
//! path that runs per setpoint (`setpoint_request`) keeps postcard's inline reading.

use postcard::{de_flavors, ser_flavors};
use serde::{Deserialize, Serialize};

/// Writes into a byte slice, a call per write.
struct Writer<'a>(ser_flavors::Slice<'a>);

impl<'a> ser_flavors::Flavor for Writer<'a> {
    type Output = &'a mut [u8];

    #[inline(never)]
    fn try_push(&mut self, byte: u8) -> postcard::Result<()> {
        self.0.try_push(byte)
    }

    #[inline(never)]
    fn try_extend(&mut self, bytes: &[u8]) -> postcard::Result<()> {
        self.0.try_extend(bytes)
    }

    fn finalize(self) -> postcard::Result<Self::Output> {
        self.0.finalize()
    }
}

/// Reads from a byte slice, a call per read.
struct Reader<'de>(de_flavors::Slice<'de>);

impl<'de> de_flavors::Flavor<'de> for Reader<'de> {
    type Remainder = &'de [u8];
    type Source = &'de [u8];

    #[inline(never)]
    fn pop(&mut self) -> postcard::Result<u8> {
        self.0.pop()
    }

    fn size_hint(&self) -> Option<usize> {
        self.0.size_hint()
    }

    #[inline(never)]
    fn try_take_n(&mut self, count: usize) -> postcard::Result<&'de [u8]> {
        self.0.try_take_n(count)
    }

    fn finalize(self) -> postcard::Result<&'de [u8]> {
        self.0.finalize()
    }
}

/// `value` serialized into the start of `buf`: the number of bytes written. One copy per type: the callers that try
/// a small buffer before a large one call the same function twice.
#[inline(never)]
pub(crate) fn to_slice<T: Serialize + ?Sized>(value: &T, buf: &mut [u8]) -> postcard::Result<usize> {
    postcard::serialize_with_flavor(value, Writer(ser_flavors::Slice::new(buf))).map(|written| written.len())
}

/// A `T` from the start of `bytes`, and the bytes after it.
pub(crate) fn take_from_bytes<'de, T: Deserialize<'de>>(bytes: &'de [u8]) -> postcard::Result<(T, &'de [u8])> {
    let mut deserializer = postcard::Deserializer::from_flavor(Reader(de_flavors::Slice::new(bytes)));
    let value = T::deserialize(&mut deserializer)?;
    Ok((value, deserializer.finalize()?))
}
