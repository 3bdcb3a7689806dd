//! Games' shared memory (Windows named file mappings), decoded natively into ringpod's [`Telemetry`]: the same
//! axes, units and conventions as the UDP formats of [`crate::games`] (specific force in m/s^2 with x forward, y
//! left, z up and `+9.81` on z at rest; angular rates in rad/s about those axes, right-handed).
//!
//! One module per publisher's layout, each citing its source and tabulating its conversion:
//!
//! | game | module | mappings read |
//! |---|---|---|
//! | `ac` | [`ac`] | Assetto Corsa: `Local\acpmf_physics` (`SPageFilePhysics`), `Local\acpmf_graphics` (its start) |
//! | `acc` | [`ac`] | Assetto Corsa Competizione: the same two, ACC's layouts |
//! | `iracing` | [`iracing`] | iRacing: `Local\IRSDKMemMapFileName` (`irsdk_header`, variable headers, buffers) |
//! | `rf2`, `lmu` | [`rf2`] | rFactor 2, Le Mans Ultimate: `$rFactor2SMMP_Telemetry$` and `$rFactor2SMMP_Scoring$` |
//! | `ams2` | [`ams2`] | Automobilista 2, Project CARS 2: `$pcars2$` (`SharedMemory`) |
//! | `ets2` | [`ets2`] | Euro Truck Simulator 2, American Truck Simulator: `Local\SCSTelemetry` |
//!
//! Each decoder reads a byte snapshot of the mapping(s) ([`Snapshot`]) and returns the game's own counter of the
//! sample (its packet id, tick, version or timestamp) with the sample, or refuses it whole ([`Unreadable`]), never
//! half-used and never a panic. How the bytes are taken from the live memory (a sample is new only when the
//! counter moves; a copy the game wrote into while it was taken is torn, retried and counted) is [`poll`]'s; the
//! Windows mapping itself is [`windows`]'s.

pub mod ac;
pub mod ams2;
pub mod ets2;
pub mod iracing;
pub mod poll;
pub mod rf2;
pub mod take;
#[cfg(windows)]
pub mod windows;

#[cfg(test)]
pub(crate) mod testing;

use super::{checked_values, LapPosition, Sample};

/// The games whose shared memory ringpod reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Game {
    /// Assetto Corsa: `Local\acpmf_physics`.
    Ac,
    /// Assetto Corsa Competizione: `Local\acpmf_physics`, ACC's layout.
    Acc,
    /// iRacing: `Local\IRSDKMemMapFileName`.
    Iracing,
    /// rFactor 2 with the rF2SharedMemoryMapPlugin: `$rFactor2SMMP_Telemetry$`.
    Rf2,
    /// Le Mans Ultimate with the rF2SharedMemoryMapPlugin (its layout, not LMU's own `LMU_Data`).
    Lmu,
    /// Automobilista 2 or Project CARS 2 (`Shared Memory: Project CARS 2`): `$pcars2$`.
    Ams2,
    /// Euro Truck Simulator 2 or American Truck Simulator with the scs-sdk-plugin: `Local\SCSTelemetry`.
    Ets2,
}

impl Game {
    /// Every game.
    #[cfg(test)]
    pub const ALL: [Game; 7] = [
        Game::Ac,
        Game::Acc,
        Game::Iracing,
        Game::Rf2,
        Game::Lmu,
        Game::Ams2,
        Game::Ets2,
    ];

    /// The name given on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Game::Ac => "ac",
            Game::Acc => "acc",
            Game::Iracing => "iracing",
            Game::Rf2 => "rf2",
            Game::Lmu => "lmu",
            Game::Ams2 => "ams2",
            Game::Ets2 => "ets2",
        }
    }

    /// The game in words.
    pub fn title(self) -> &'static str {
        match self {
            Game::Ac => "Assetto Corsa",
            Game::Acc => "Assetto Corsa Competizione",
            Game::Iracing => "iRacing",
            Game::Rf2 => "rFactor 2",
            Game::Lmu => "Le Mans Ultimate",
            Game::Ams2 => "Automobilista 2 / Project CARS 2",
            Game::Ets2 => "Euro Truck Simulator 2 / American Truck Simulator",
        }
    }

    /// The named mappings read, the first holding the sample's counter.
    pub fn mappings(self) -> &'static [&'static str] {
        match self {
            Game::Ac | Game::Acc => &[ac::MAPPING, ac::GRAPHICS],
            Game::Iracing => &[iracing::MAPPING],
            Game::Rf2 | Game::Lmu => &[rf2::TELEMETRY, rf2::SCORING],
            Game::Ams2 => &[ams2::MAPPING],
            Game::Ets2 => &[ets2::MAPPING],
        }
    }

    /// Whether the layout guards its writes (rF2's version block, AMS2's sequence, iRacing's rotating buffers): a
    /// layout without (AC, ACC, ETS2) has its counter read again after the copy only, and a new counter is left to
    /// stand for a poll before it is copied.
    pub fn guarded(self) -> bool {
        !matches!(self, Game::Ac | Game::Acc | Game::Ets2)
    }

    /// How often the game writes a new sample (Hz), as published or assumed (each module's table says which):
    /// the pause after which a game is counted as stalled is a number of these periods.
    pub fn rate_hz(self) -> f64 {
        match self {
            Game::Ac | Game::Acc => ac::RATE_HZ,
            Game::Iracing => iracing::RATE_HZ,
            Game::Rf2 | Game::Lmu => rf2::RATE_HZ,
            Game::Ams2 => ams2::RATE_HZ,
            Game::Ets2 => ets2::RATE_HZ,
        }
    }
}

impl std::fmt::Display for Game {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The live memory of a game's mappings, read by bytes: the Windows mappings ([`windows`]), or snapshots held in
/// memory (the tests on every system).
pub trait Memory {
    /// Copies `out.len()` bytes at `at` of the game's mapping `page` (an index into [`Game::mappings`]), or says
    /// it is not there: not open (the game not running) or shorter.
    fn read(&mut self, page: usize, at: usize, out: &mut [u8]) -> Result<(), Absent>;
}

/// A mapping that is not there (or not as long as a read of it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Absent;

/// The bytes of a game's mappings, in the order of [`Game::mappings`], each from its start.
pub type Snapshot = [Vec<u8>];

/// One sample of a game's shared memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Read {
    /// The game's own counter of the sample (packet id, tick, version, timestamp): a sample is new when it moves.
    pub tick: u64,
    /// Where the counter lies (mapping, byte offset, width): read again after the copy, the copy is whole only if
    /// it has not moved.
    pub guard: Guard,
    /// The sample.
    pub sample: Sample,
}

/// A counter's place in the live memory, and its value in the copy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Guard {
    /// Index into [`Game::mappings`].
    pub page: usize,
    /// Byte offset.
    pub at: usize,
    /// Its bytes in the copy (the first `len`).
    pub bytes: [u8; 8],
    /// Its width, 4 or 8.
    pub len: usize,
}

impl Guard {
    /// The `len` bytes at `at` of `page` in `snapshot` (which the caller has checked are there).
    fn of(snapshot: &[u8], page: usize, at: usize, len: usize) -> Self {
        let mut bytes = [0; 8];
        bytes[..len].copy_from_slice(&snapshot[at..at + len]);
        Self { page, at, bytes, len }
    }
}

/// Why a snapshot was not used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unreadable {
    /// Shorter than the layout.
    #[error("{game}: {got} bytes of {mapping}, where the layout has {expected}")]
    Size {
        /// The game.
        game: Game,
        /// The mapping.
        mapping: &'static str,
        /// The snapshot's size.
        got: usize,
        /// The size the layout needs, in words.
        expected: String,
    },
    /// The right size, but not the layout's header (version, counts, offsets out of the mapping).
    #[error("{game}: {why}")]
    Header {
        /// The game.
        game: Game,
        /// What was found.
        why: String,
    },
    /// iRacing: a variable ringpod reads is not among the variable headers, or not of its type.
    #[error("{game}: the variable {name} {why}")]
    Variable {
        /// The game.
        game: Game,
        /// The variable.
        name: &'static str,
        /// Missing, or of another type.
        why: String,
    },
    /// A value, or the time, is not a finite number.
    #[error("{game}: {what} is not a finite number")]
    NotFinite {
        /// The game.
        game: Game,
        /// Which value.
        what: &'static str,
    },
    /// The game writes no motion of the player's vehicle now (no player's car, in the menus).
    #[error("{game}: {why}")]
    NoMotion {
        /// The game.
        game: Game,
        /// Why.
        why: String,
    },
    /// The copy was taken while the game wrote it (its begin and end versions differ, its sequence is odd).
    #[error("{game}: the copy was taken while the game wrote it")]
    Torn {
        /// The game.
        game: Game,
    },
}

impl Unreadable {
    fn size(game: Game, mapping: &'static str, got: usize, expected: impl Into<String>) -> Self {
        Unreadable::Size {
            game,
            mapping,
            got,
            expected: expected.into(),
        }
    }
}

/// Decodes a snapshot of `game`'s mappings.
pub fn decode(game: Game, snapshot: &Snapshot) -> Result<Read, Unreadable> {
    let page = |i: usize| snapshot.get(i).map_or(&[][..], Vec::as_slice);
    let read = match game {
        Game::Ac | Game::Acc => ac::decode(game, page(0), page(1)),
        Game::Iracing => iracing::decode(page(0)),
        Game::Rf2 | Game::Lmu => rf2::decode(game, page(0), page(1)),
        Game::Ams2 => ams2::decode(page(0)),
        Game::Ets2 => ets2::decode(page(0)),
    }?;
    checked_values(&read.sample).map_err(|what| Unreadable::NotFinite { game, what })?;
    Ok(read)
}

/// The sample as a line of ringpod's `text` telemetry format, `[t] ax ay az wx wy wz [lap]` (each number as Rust
/// writes an `f64`: read back exactly), which `stream --capture` writes and `cue --input` reads. The lap position
/// goes last where the sample has its time (the format's eighth number follows a time) and it is a distance along
/// the lap, as every shared-memory game's is.
pub fn text_line(sample: &Sample) -> String {
    let t = &sample.telemetry;
    let lap = match (sample.time, sample.lap) {
        (Some(_), Some(LapPosition::Along(d))) => Some(d),
        _ => None,
    };
    let numbers = sample
        .time
        .into_iter()
        .chain(t.force)
        .chain(t.rate)
        .chain(lap)
        .map(|v| v.to_string())
        .collect::<Vec<_>>();
    numbers.join(" ")
}

/// Little-endian fields at byte offsets of a snapshot whose size the decoder has checked: a float past its end
/// reads as NaN (which [`decode`] refuses as not finite), an integer as `None`; nothing panics.
#[derive(Clone, Copy)]
pub(crate) struct Bytes<'a>(pub &'a [u8]);

impl Bytes<'_> {
    fn array<const N: usize>(&self, at: usize) -> Option<[u8; N]> {
        self.0.get(at..at.checked_add(N)?)?.try_into().ok()
    }

    fn f32(&self, at: usize) -> f64 {
        self.array(at).map_or(f64::NAN, |b| f64::from(f32::from_le_bytes(b)))
    }

    fn f64(&self, at: usize) -> f64 {
        self.array(at).map_or(f64::NAN, f64::from_le_bytes)
    }

    fn u32(&self, at: usize) -> Option<u32> {
        self.array(at).map(u32::from_le_bytes)
    }

    fn i32(&self, at: usize) -> Option<i32> {
        self.array(at).map(i32::from_le_bytes)
    }

    fn u64(&self, at: usize) -> Option<u64> {
        self.array(at).map(u64::from_le_bytes)
    }

    fn u8(&self, at: usize) -> Option<u8> {
        self.0.get(at).copied()
    }

    /// Three consecutive `f32`.
    fn vec3(&self, at: usize) -> [f64; 3] {
        [self.f32(at), self.f32(at + 4), self.f32(at + 8)]
    }

    /// Three consecutive `f64`.
    fn dvec3(&self, at: usize) -> [f64; 3] {
        [self.f64(at), self.f64(at + 8), self.f64(at + 16)]
    }
}

#[cfg(test)]
mod tests;
