//! iRacing: the telemetry of its SDK's memory-mapped file, read through its variable headers.
//!
//! Source: iRacing.com Motorsport Simulations' iRacing SDK, `irsdk_defines.h` (© 2013; the copy read is the SDK's
//! header as ECU-IR/irsdk keeps it, commit 69fdf8d, whose `irsdk_header` and `irsdk_varHeader` later SDK releases
//! keep, the variable header's padding int becoming `bool countAsTime` and padding), with the variable names,
//! units and descriptions as the sim publishes them in its variable headers. The mapping
//! `Local\IRSDKMemMapFileName` is self-describing, little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0, 4, 8 | `ver`, `status`, `tickRate` | i32; `status` bit 0 `irsdk_stConnected`; `tickRate` "60 or 360 etc" |
//! | 12-23 | `sessionInfoUpdate`, `sessionInfoLen`, `sessionInfoOffset` | the YAML session string: not read |
//! | 24, 28 | `numVars`, `varHeaderOffset` | i32: `irsdk_varHeader[numVars]` at `varHeaderOffset` |
//! | 32, 36 | `numBuf`, `bufLen` | i32: at most `IRSDK_MAX_BUFS` (4) buffers of `bufLen` bytes |
//! | 48 + 16 i | `varBuf[i]`: `tickCount`, `bufOffset` | i32, i32 (and 8 bytes of padding) |
//!
//! `irsdk_varHeader` (144 bytes): `type` (i32 at 0: 0 char, 1 bool, 2 int, 3 bitField, 4 float, 5 double),
//! `offset` (i32 at 4, into a buffer), `count` (i32 at 8), `countAsTime` (bool at 12), `name` (32 bytes at 16,
//! NUL-terminated), `desc` (64 at 48), `unit` (32 at 112). The sim writes its buffers in turn, each stamped with
//! the tick it holds; a reader takes the buffer with the highest `tickCount`, copies it, and reads that
//! `tickCount` again: unchanged, the copy is whole (the SDK's `irsdk_getNewData` does the same). The header's
//! comment: "Variables ... are output at a rate of 60 times a second ... The sim writes a new line of variables
//! every 16 ms ... we triple buffer it".
//!
//! No offset is hard-coded: each variable is found by its name in the headers, and its type checked.
//!
//! ## Conversion
//!
//! | ringpod | variable (type, unit, description as published) | sign |
//! |---|---|---|
//! | force x | `LongAccel` (float, m/s^2, "Longitudinal acceleration (including gravity)") | assumed forward |
//! | force y | `LatAccel` (float, m/s^2, "Lateral acceleration (including gravity)") | assumed left |
//! | force z | `VertAccel` (float, m/s^2, "Vertical acceleration (including gravity)") | assumed up, +9.81 at rest |
//! | rate roll | `RollRate` (float, rad/s) | assumed about forward, right side down |
//! | rate pitch | `PitchRate` (float, rad/s) | assumed about left, nose down |
//! | rate yaw | `YawRate` (float, rad/s) | assumed about up, turning left |
//! | time | `SessionTime` (double, s, "Seconds since session start") | published |
//! | lap | `LapDistPct` (float, %, "Percentage distance around lap"; a fraction 0 to 1 as the sim writes it) | read when there, else none |
//!
//! "Including gravity" makes the three accelerations the specific force ringpod wants, with nothing added. The
//! descriptions do not give the senses: ringpod assumes iRacing's car axes are x forward, y left, z up
//! (right-handed), as ringpod's own; a capture settles it. The sim publishes at `tickRate`, 60 Hz.

use super::{Bytes, Game, Guard, Read, Sample, Unreadable};
use crate::games::{LapPosition, Telemetry};

/// The SDK's mapping.
pub const MAPPING: &str = r"Local\IRSDKMemMapFileName";
/// Published: the telemetry's `tickRate` (60 Hz; the header carries it).
pub const RATE_HZ: f64 = 60.0;
/// `irsdk_header` with its four `irsdk_varBuf`.
pub const HEADER: usize = 112;
/// One `irsdk_varHeader`.
pub const VAR_HEADER: usize = 144;
/// `IRSDK_MAX_BUFS`.
pub const MAX_BUFS: usize = 4;
/// The most variables a header may announce (the sim has a few hundred), so that garbage cannot ask for more.
pub const MAX_VARS: usize = 10_000;
/// The longest buffer a header may announce.
pub const MAX_BUF_LEN: usize = 1 << 20;

/// `irsdk_float`.
const FLOAT: i32 = 4;
/// `irsdk_double`.
const DOUBLE: i32 = 5;

/// The float variables read, in ringpod's order: forces x, y, z, then rates about x, y, z.
pub const FLOATS: [&str; 6] = ["LongAccel", "LatAccel", "VertAccel", "RollRate", "PitchRate", "YawRate"];
/// The double variable of the time.
pub const TIME: &str = "SessionTime";
/// The float variable of the lap position.
pub const LAP: &str = "LapDistPct";

/// Where the header says things are: variable headers and the latest buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Places {
    /// `numVars`.
    pub vars: usize,
    /// `varHeaderOffset`.
    pub var_headers: usize,
    /// The index of the buffer with the highest `tickCount`.
    pub buf: usize,
    /// Its `tickCount`.
    pub tick: u32,
    /// Its `bufOffset`.
    pub buf_offset: usize,
    /// `bufLen`.
    pub buf_len: usize,
    /// `status` has `irsdk_stConnected`.
    pub connected: bool,
}

fn header(why: impl Into<String>) -> Unreadable {
    Unreadable::Header {
        game: Game::Iracing,
        why: why.into(),
    }
}

/// Reads the header (its first [`HEADER`] bytes): where the variables and the latest buffer are.
pub fn places(head: &[u8]) -> Result<Places, Unreadable> {
    let b = Bytes(head);
    let int = |at| {
        b.i32(at)
            .ok_or_else(|| Unreadable::size(Game::Iracing, MAPPING, head.len(), "112 bytes"))
    };
    let count = |at, max: usize, what: &str| {
        let v = int(at)?;
        usize::try_from(v)
            .ok()
            .filter(|n| *n <= max)
            .ok_or_else(|| header(format!("{what} is {v}, not 0 to {max}")))
    };
    let status = int(4)?;
    let vars = count(24, MAX_VARS, "numVars")?;
    let var_headers = count(28, usize::MAX, "varHeaderOffset")?;
    let bufs = count(32, MAX_BUFS, "numBuf")?;
    let buf_len = count(36, MAX_BUF_LEN, "bufLen")?;
    let mut latest: Option<(usize, u32, usize)> = None;
    for i in 0..bufs {
        let tick = int(48 + 16 * i)? as u32;
        let offset = count(52 + 16 * i, usize::MAX, "a bufOffset")?;
        if latest.is_none_or(|(_, t, _)| (tick as i32) > (t as i32)) {
            latest = Some((i, tick, offset));
        }
    }
    let (buf, tick, buf_offset) = latest.ok_or_else(|| header("numBuf is 0: no buffer"))?;
    Ok(Places {
        vars,
        var_headers,
        buf,
        tick,
        buf_offset,
        buf_len,
        connected: status & 1 == 1,
    })
}

/// A variable's type and offset in a buffer, found by its name among the headers.
fn lookup(map: &[u8], at: &Places, name: &'static str) -> Result<(i32, usize, usize), Unreadable> {
    let b = Bytes(map);
    for i in 0..at.vars {
        let h = at.var_headers + i * VAR_HEADER;
        let Some(field) = map.get(h + 16..h + 48) else {
            break;
        };
        let end = field.iter().position(|c| *c == 0).unwrap_or(field.len());
        if &field[..end] == name.as_bytes() {
            let (ty, offset, count) = (b.i32(h), b.i32(h + 4), b.i32(h + 8));
            let (Some(ty), Some(offset), Some(count)) = (ty, offset, count) else {
                break;
            };
            let offset = usize::try_from(offset).map_err(|_| variable(name, format!("has offset {offset}")))?;
            return Ok((ty, offset, usize::try_from(count).unwrap_or(0)));
        }
    }
    Err(variable(name, "is not among the variable headers".into()))
}

fn variable(name: &'static str, why: String) -> Unreadable {
    Unreadable::Variable {
        game: Game::Iracing,
        name,
        why,
    }
}

/// A variable of `ty` (4 or 8 bytes) in the latest buffer.
fn value(map: &[u8], at: &Places, name: &'static str, ty: i32) -> Result<f64, Unreadable> {
    let (found, offset, count) = lookup(map, at, name)?;
    if found != ty {
        return Err(variable(name, format!("has type {found}, where ringpod reads {ty}")));
    }
    let width = if ty == DOUBLE { 8 } else { 4 };
    if count < 1 || offset + width > at.buf_len {
        return Err(variable(
            name,
            format!("lies at {offset} (count {count}), outside the buffer"),
        ));
    }
    let b = Bytes(map);
    let at = at.buf_offset + offset;
    Ok(if ty == DOUBLE { b.f64(at) } else { b.f32(at) })
}

/// Reads a snapshot of the mapping: the header, the variable headers and (at least) the latest buffer, at their
/// offsets in the mapping.
pub fn decode(map: &[u8]) -> Result<Read, Unreadable> {
    if map.len() < HEADER {
        return Err(Unreadable::size(
            Game::Iracing,
            MAPPING,
            map.len(),
            "at least 112 bytes",
        ));
    }
    let at = places(map)?;
    if !at.connected {
        return Err(Unreadable::NoMotion {
            game: Game::Iracing,
            why: "the sim is not connected (status bit irsdk_stConnected is clear)".into(),
        });
    }
    let headers_end = at.var_headers.saturating_add(at.vars * VAR_HEADER);
    let buf_end = at.buf_offset.saturating_add(at.buf_len);
    let need = headers_end.max(buf_end);
    if map.len() < need {
        return Err(Unreadable::size(
            Game::Iracing,
            MAPPING,
            map.len(),
            format!("{need} bytes (its header says)"),
        ));
    }
    let mut v = [0.0; 6];
    for (slot, name) in v.iter_mut().zip(FLOATS) {
        *slot = value(map, &at, name, FLOAT)?;
    }
    let time = value(map, &at, TIME, DOUBLE)?;
    // The lap position is for the preview alone: without it the motion is whole.
    let lap = value(map, &at, LAP, FLOAT).ok().map(LapPosition::Along);
    Ok(Read {
        tick: u64::from(at.tick),
        guard: Guard::of(map, 0, 48 + 16 * at.buf, 4),
        sample: Sample {
            time: Some(time),
            telemetry: Telemetry {
                force: [v[0], v[1], v[2]],
                rate: [v[3], v[4], v[5]],
            },
            lap,
        },
    })
}

#[cfg(test)]
mod tests;
