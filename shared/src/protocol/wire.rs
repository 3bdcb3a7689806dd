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

#[cfg(test)]
#[allow(clippy::expect_used, clippy::panic)]
mod tests {
    use super::*;
    use crate::controller::{Controller, ControllerConfig};
    use crate::protocol::{DeviceMessage, Response, RigSource, MAX_PAYLOAD};

    /// The largest message (a rig) and one of many fields (the status), as a device sends them.
    fn responses() -> [Response; 2] {
        let config = ControllerConfig::trainer_model();
        let status = Controller::new(config).map(|c| c.status());
        let status = status.unwrap_or_else(|e| panic!("the trainer model runs: {e:?}"));
        [
            Response {
                id: 7,
                body: DeviceMessage::Rig {
                    rig: config.rig(),
                    source: RigSource::Stored,
                    pending: true,
                },
            },
            Response {
                id: u32::MAX,
                body: DeviceMessage::Status(status),
            },
        ]
    }

    #[test]
    fn writes_the_bytes_postcard_writes_and_refuses_the_buffers_it_refuses() {
        for response in responses() {
            let (mut ours, mut theirs) = ([0u8; MAX_PAYLOAD], [0u8; MAX_PAYLOAD]);
            let len = to_slice(&response, &mut ours).expect("fits");
            let expected = postcard::to_slice(&response, &mut theirs).expect("fits");
            assert_eq!(&ours[..len], &expected[..]);
            for short in 0..len {
                assert!(
                    to_slice(&response, &mut ours[..short]).is_err(),
                    "{short} of {len} bytes"
                );
            }
        }
    }

    #[test]
    fn reads_what_postcard_reads_and_leaves_the_same_remainder() {
        for response in responses() {
            let mut bytes = [0u8; MAX_PAYLOAD + 3];
            let len = to_slice(&response, &mut bytes).expect("fits");
            bytes[len..len + 3].copy_from_slice(&[1, 2, 3]);
            let with_rest = &bytes[..len + 3];
            assert_eq!(take_from_bytes::<Response>(with_rest), Ok((response, &[1u8, 2, 3][..])));
            assert_eq!(
                take_from_bytes::<Response>(with_rest),
                postcard::take_from_bytes::<Response>(with_rest)
            );
            for cut in 0..len {
                assert_eq!(
                    take_from_bytes::<Response>(&bytes[..cut]),
                    postcard::take_from_bytes::<Response>(&bytes[..cut]),
                    "cut at {cut} of {len}"
                );
                assert!(take_from_bytes::<Response>(&bytes[..cut]).is_err());
            }
        }
    }
}
