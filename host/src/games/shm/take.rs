//! How each game's live memory is read: its counter alone (a few bytes, every poll), and a snapshot of what its
//! decoder reads (only when the counter moved).

use super::{ac, ams2, ets2, iracing, rf2, Absent, Game, Memory};

/// Where a game's counter is now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Now {
    /// At this value.
    Tick(u64),
    /// The game says it is writing (rF2's versions differ, AMS2's sequence is odd).
    Writing,
    /// The game says nobody is there (iRacing not connected, the SCS plugin inactive).
    Idle,
}

/// The biggest snapshot taken (a header that asks for more is garbage).
pub const MAX_SNAPSHOT: usize = 64 << 20;

/// `len` bytes at `at` of `page`.
fn bytes(mem: &mut dyn Memory, page: usize, at: usize, len: usize) -> Result<Vec<u8>, Absent> {
    let mut v = vec![0; len];
    mem.read(page, at, &mut v)?;
    Ok(v)
}

/// The game's counter, read alone.
pub fn now(game: Game, mem: &mut dyn Memory) -> Result<Now, Absent> {
    Ok(match game {
        Game::Ac | Game::Acc => {
            let b = bytes(mem, 0, ac::at::PACKET_ID, 4)?;
            Now::Tick(u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
        }
        Game::Iracing => match iracing::places(&bytes(mem, 0, 0, iracing::HEADER)?) {
            Ok(p) if p.connected => Now::Tick(u64::from(p.tick)),
            _ => Now::Idle,
        },
        Game::Rf2 | Game::Lmu => {
            let b = bytes(mem, 0, 0, 8)?;
            let (begin, end) = (&b[..4], &b[4..]);
            if begin == end {
                Now::Tick(u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            } else {
                Now::Writing
            }
        }
        Game::Ams2 => {
            let b = bytes(mem, 0, ams2::at::SEQUENCE_NUMBER, 4)?;
            match u32::from_le_bytes([b[0], b[1], b[2], b[3]]) {
                s if s % 2 == 1 => Now::Writing,
                s => Now::Tick(u64::from(s)),
            }
        }
        Game::Ets2 => {
            let b = bytes(mem, 0, 0, 16)?;
            let time = u64::from_le_bytes([b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]]);
            if b[ets2::at::SDK_ACTIVE] == 0 {
                Now::Idle
            } else {
                Now::Tick(time)
            }
        }
    })
}

/// A snapshot of what the game's decoder reads, each mapping from its start.
pub fn copy(game: Game, mem: &mut dyn Memory) -> Result<Vec<Vec<u8>>, Absent> {
    Ok(match game {
        Game::Ac | Game::Acc => vec![
            bytes(mem, 0, 0, ac::size(game))?,
            // The lap position only: without the graphics page the sample has none.
            bytes(mem, 1, 0, ac::GRAPHICS_SIZE).unwrap_or_default(),
        ],
        Game::Iracing => vec![iracing_copy(mem)?],
        Game::Rf2 | Game::Lmu => {
            let t = rf2::telemetry::VEHICLES;
            let s = rf2::scoring::NUM_VEHICLES + 4;
            vec![
                vehicles(mem, 0, t, |head| {
                    rf2::extent(head, rf2::telemetry::NUM_VEHICLES, t, rf2::telemetry::VEHICLE)
                })?,
                vehicles(mem, 1, s, |head| {
                    rf2::extent(
                        head,
                        rf2::scoring::NUM_VEHICLES,
                        rf2::scoring::VEHICLES,
                        rf2::scoring::VEHICLE,
                    )
                })?,
            ]
        }
        Game::Ams2 => vec![bytes(mem, 0, 0, ams2::SIZE)?],
        Game::Ets2 => vec![bytes(mem, 0, 0, ets2::SIZE)?],
    })
}

/// An rF2 buffer: its first `head` bytes, then as many as its vehicles take (the head alone when its count is
/// garbage: the decoder refuses it).
fn vehicles(
    mem: &mut dyn Memory,
    page: usize,
    head: usize,
    extent: impl Fn(&[u8]) -> Option<(usize, usize)>,
) -> Result<Vec<u8>, Absent> {
    let mut v = bytes(mem, page, 0, head)?;
    if let Some((_, len)) = extent(&v) {
        v.resize(len, 0);
        mem.read(page, head, &mut v[head..])?;
    }
    Ok(v)
}

/// iRacing's header, variable headers and latest buffer, at their offsets (the rest zeros); the header alone when
/// it is garbage (the decoder refuses it).
fn iracing_copy(mem: &mut dyn Memory) -> Result<Vec<u8>, Absent> {
    let head = bytes(mem, 0, 0, iracing::HEADER)?;
    let Ok(p) = iracing::places(&head) else {
        return Ok(head);
    };
    let headers = (p.var_headers, p.vars * iracing::VAR_HEADER);
    let buffer = (p.buf_offset, p.buf_len);
    let end = (headers.0.saturating_add(headers.1)).max(buffer.0.saturating_add(buffer.1));
    if end > MAX_SNAPSHOT {
        return Ok(head);
    }
    let mut v = vec![0; end.max(iracing::HEADER)];
    v[..iracing::HEADER].copy_from_slice(&head);
    for (at, len) in [headers, buffer] {
        mem.read(0, at, &mut v[at..at + len])?;
    }
    Ok(v)
}
