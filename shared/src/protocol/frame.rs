//! Framing: postcard payload, CRC-32C, COBS, `0x00` delimiter.

use core::fmt;

use serde::{de::DeserializeOwned, Serialize};

use super::wire;

/// Largest postcard payload of any message (bytes): a rig record with six chains (`HostMessage::SetRig`,
/// `DeviceMessage::Rig`) is the largest, about 560 (tested in `tests/suite/rig_record.rs`).
pub const MAX_PAYLOAD: usize = 768;
/// Largest encoded frame including the delimiter (bytes).
pub const MAX_FRAME: usize = cobs::max_encoding_length(MAX_PAYLOAD + 4) + 1;

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// The frames' CRC-32C of `bytes` (also the flashed image's, `firmware::image_crc`: one table in the firmware).
pub(super) fn crc32c(bytes: &[u8]) -> u32 {
    CRC.checksum(bytes)
}

/// Why a frame could not be encoded or decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum FrameError {
    /// The message does not fit in [`MAX_PAYLOAD`] or the output buffer.
    TooLong,
    /// Not valid COBS.
    Cobs,
    /// Shorter than a checksum.
    TooShort,
    /// The checksum does not match: the frame was corrupted.
    Checksum,
    /// The payload is not a message of this protocol (or has trailing bytes).
    Payload,
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::TooLong => "frame too long",
            Self::Cobs => "invalid COBS framing",
            Self::TooShort => "frame shorter than its checksum",
            Self::Checksum => "checksum mismatch",
            Self::Payload => "not a message of this protocol",
        })
    }
}

impl core::error::Error for FrameError {}

/// Most payload bytes an answer to a setpoint takes (ack, limited, nack; 15 at most, tested): such a message is
/// serialized through a buffer of this size, not one of [`MAX_PAYLOAD`], whose zeroing alone would cost the
/// stream's hot path hundreds of instructions (and one of 96 bytes about 30 more than this one).
const SMALL_PAYLOAD: usize = 20;

/// Encodes `message` into `out` as one frame, delimiter included; returns its length.
pub fn encode<M: Serialize>(message: &M, out: &mut [u8]) -> Result<usize, FrameError> {
    let mut small = [0u8; SMALL_PAYLOAD + 4];
    if let Ok(len) = wire::to_slice(message, &mut small[..SMALL_PAYLOAD]) {
        return seal(&mut small, len, out);
    }
    let mut raw = [0u8; MAX_PAYLOAD + 4];
    let len = wire::to_slice(message, &mut raw[..MAX_PAYLOAD]).map_err(|_| FrameError::TooLong)?;
    seal(&mut raw, len, out)
}

/// Appends the CRC to the payload `raw[..len]` and writes it COBS-encoded with its delimiter into `out`.
fn seal(raw: &mut [u8], len: usize, out: &mut [u8]) -> Result<usize, FrameError> {
    let crc = CRC.checksum(&raw[..len]).to_le_bytes();
    raw[len..len + 4].copy_from_slice(&crc);
    let n = cobs::try_encode(&raw[..len + 4], out).map_err(|_| FrameError::TooLong)?;
    let end = out.get_mut(n).ok_or(FrameError::TooLong)?;
    *end = 0;
    Ok(n + 1)
}

/// Decodes one frame (its bytes up to, not including, the delimiter).
pub fn decode<M: DeserializeOwned>(frame: &[u8]) -> Result<M, FrameError> {
    let mut raw = [0u8; MAX_FRAME];
    parse(unframe(frame, &mut raw)?)
}

/// The checked payload of one frame (its bytes up to, not including, the delimiter), COBS-decoded into `scratch`
/// (at least as long as the frame). A frame holding a delimiter is not one.
///
/// Copied, then decoded in place: `cobs::decode` runs its streaming decoder's state machine per byte, about 950
/// instructions for a setpoint frame on the M4F, where the in-place decoder copies each run in a plain loop.
pub fn unframe<'a>(frame: &[u8], scratch: &'a mut [u8]) -> Result<&'a [u8], FrameError> {
    if frame.is_empty() || frame.len() > MAX_FRAME {
        return Err(FrameError::Cobs);
    }
    let raw = scratch.get_mut(..frame.len()).ok_or(FrameError::Cobs)?;
    raw.copy_from_slice(frame);
    let report = cobs::decode_in_place_report(raw).map_err(|_| FrameError::Cobs)?;
    // The decoder stops at a delimiter; bytes after one are not part of the frame.
    if report.parsed_size() != frame.len() {
        return Err(FrameError::Cobs);
    }
    let len = report.frame_size();
    if len < 5 {
        return Err(FrameError::TooShort);
    }
    let (payload, crc) = scratch[..len].split_at(len - 4);
    if CRC.checksum(payload).to_le_bytes() != crc {
        return Err(FrameError::Checksum);
    }
    Ok(payload)
}

/// A message from a whole payload (no bytes left over).
pub fn parse<M: DeserializeOwned>(payload: &[u8]) -> Result<M, FrameError> {
    match wire::take_from_bytes::<M>(payload) {
        Ok((message, [])) => Ok(message),
        _ => Err(FrameError::Payload),
    }
}

/// Splits a byte stream into frames at the `0x00` delimiters, with a fixed buffer. Bytes of a frame that overruns
/// the buffer are dropped up to the next delimiter, and counted.
#[derive(Debug, Clone)]
pub struct FrameReader {
    buf: [u8; MAX_FRAME],
    len: usize,
    overrun: bool,
    overruns: u32,
}

impl Default for FrameReader {
    fn default() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            overrun: false,
            overruns: 0,
        }
    }
}

impl FrameReader {
    /// Feeds one byte; returns a complete frame (without delimiter) when the byte ends one.
    pub fn push(&mut self, byte: u8) -> Option<&[u8]> {
        if byte == 0 {
            let (len, overrun) = (self.len, self.overrun);
            self.len = 0;
            self.overrun = false;
            if overrun {
                self.overruns = self.overruns.saturating_add(1);
                return None;
            }
            return if len == 0 { None } else { self.buf.get(..len) };
        }
        match self.buf.get_mut(self.len) {
            Some(slot) if !self.overrun => {
                *slot = byte;
                self.len += 1;
            }
            _ => self.overrun = true,
        }
        None
    }

    /// Frames dropped because they were longer than [`MAX_FRAME`].
    pub fn overruns(&self) -> u32 {
        self.overruns
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::kinematics::Check;
    use crate::motion::{LimitReport, RejectReason};
    use crate::protocol::{DeviceMessage, NackReason, Response};

    /// Every answer to a setpoint, at its longest, fits the small buffer that [`encode`] tries first.
    #[test]
    fn the_answers_to_a_setpoint_fit_the_small_buffer() {
        let reasons = [
            RejectReason::NonFinite,
            RejectReason::Unreachable,
            RejectReason::GrossJump {
                outside: Some(Check::Stability),
            },
            RejectReason::Stale,
            RejectReason::NotStreaming,
        ];
        let limited = LimitReport {
            check: Check::Stability,
            translation: f32::MAX,
            rotation: f32::MIN,
        };
        let bodies = [DeviceMessage::Ack, DeviceMessage::Limited(limited)]
            .into_iter()
            .chain(reasons.map(|r| DeviceMessage::Nack(NackReason::Rejected(r))));
        for body in bodies {
            let response = Response { id: u32::MAX, body };
            let mut small = [0u8; SMALL_PAYLOAD];
            assert!(wire::to_slice(&response, &mut small).is_ok(), "{response:?}");
        }
    }
}
