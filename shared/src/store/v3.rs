//! The stream section as records of versions 2 and 3 (protocol 9 and before) stored it, read once to carry a
//! builder's stored sections across the firmware update that added `host_gone_ms`; the time such a section gets is
//! the default, [`HOST_GONE_MS`], which those devices had no setting for. The rest of a version-3 record is laid out
//! as today's.
//!
//! Read by hand from postcard's layout (a struct is its fields in order; a `u16` a varint; an enum its variant's
//! index as a varint; an `f32` four little-endian bytes) rather than through a second derived deserializer, for which
//! the firmware's flash has no room; the migration tests write the old layout with postcard itself.

use crate::motion::FollowMode;
use crate::protocol::{wire, StreamSettings};
use crate::safety::HOST_GONE_MS;

/// The old stream section at the start of `bytes` (`timeout_ms`, `gross_jump_ms`, `follow`, `margins`,
/// `telemetry_hz`) as today's with the default time for a host gone, and the bytes after it.
pub(super) fn stream(bytes: &[u8]) -> Option<(StreamSettings, &[u8])> {
    let (timeout_ms, rest) = wire::take_from_bytes::<u16>(bytes).ok()?;
    let (gross_jump_ms, rest) = wire::take_from_bytes::<u16>(rest).ok()?;
    // a variant index is a `u32` varint: 0 and 1 are the same single byte as a `u16`'s
    let (follow, rest) = wire::take_from_bytes::<u16>(rest).ok()?;
    let follow = match follow {
        0 => FollowMode::Interpolate,
        1 => FollowMode::Direct,
        _ => return None,
    };
    let (raw, rest) = rest.split_first_chunk::<24>()?;
    let margins = core::array::from_fn(|i| {
        let b = [raw[4 * i], raw[4 * i + 1], raw[4 * i + 2], raw[4 * i + 3]];
        f32::from_le_bytes(b)
    });
    let (telemetry_hz, rest) = wire::take_from_bytes::<u16>(rest).ok()?;
    let section = StreamSettings {
        timeout_ms,
        gross_jump_ms,
        follow,
        margins,
        telemetry_hz,
        host_gone_ms: HOST_GONE_MS,
    };
    Some((section, rest))
}
