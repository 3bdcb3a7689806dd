//! rFactor 2 and Le Mans Ultimate: the telemetry of the rF2SharedMemoryMapPlugin (The Iron Wolf).
//!
//! Sources: TheIronWolfModding/rF2SharedMemoryMapPlugin, `Include/rF2State.h` and `Include/MappedBuffer.h`
//! (plugin 3.7.15.1, commit 102b667 of 2024-03-21), mirroring ISI's `InternalsPlugin.hpp` (`TelemInfoV01`,
//! `VehicleScoringInfoV01`), `#pragma pack(4)`, little-endian. Each buffer is preceded in its mapping by
//! `rF2MappedBufferVersionBlock`: the plugin increments `mVersionUpdateBegin` before writing and
//! `mVersionUpdateEnd` after, so a copy in which they differ, or whose `mVersionUpdateBegin` moved during the copy,
//! is torn.
//!
//! `$rFactor2SMMP_Telemetry$` (every vehicle, written at 50 FPS as the plugin's readme states):
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0, 4 | `mVersionUpdateBegin`, `mVersionUpdateEnd` | u32: the counter of a new sample |
//! | 8, 12 | `mBytesUpdatedHint`, `mNumVehicles` | i32 |
//! | 16 + 1888 i | `rF2VehicleTelemetry mVehicles[i]` (128 at most) | |
//!
//! In `rF2VehicleTelemetry`: `mID` (i32 at 0), `mElapsedTime` (f64 at 12, s, "game session time"), `mLocalAccel`
//! (3 f64 at 208, m/s^2, "acceleration in local vehicle coordinates"), `mOri[3]` (3 x 3 f64 at 232, "rows of
//! orientation matrix ... converts local vehicle vectors into world X, Y, or Z using dot product of rows 0, 1,
//! or 2"), `mLocalRot` (3 f64 at 304, rad/s). The player's vehicle is the one whose `mID` is that of the vehicle
//! with `mIsPlayer` in `$rFactor2SMMP_Scoring$`: its version block, `mBytesUpdatedHint` (8), `rF2ScoringInfo`
//! (548 bytes at 12, `mNumVehicles` at its 104), and `rF2VehicleScoring mVehicles[i]` at 560 + 584 i (`mID` at
//! 0, `mIsPlayer` at 196).
//!
//! Le Mans Ultimate runs the same plugin and is read in this layout. LMU also has shared memory of its own
//! (`LMU_Data`, described by the `SharedMemoryInterface.hpp` the game ships), without a version block; that header
//! was not available to check, so ringpod does not read it.
//!
//! ## Conversion
//!
//! `InternalsPlugin.hpp` publishes the axes: "+x points out the left side of the car, +y points out the roof, +z
//! points out the back of the car", and the rotations: "+x pitches up, +y yaws to the right, +z rolls to the right".
//! Whether `mLocalAccel` includes gravity is not stated: ringpod assumes it does not (a kinematic acceleration) and
//! adds gravity's reaction from the orientation's up row. That row is read as ISI's example internals plugin
//! (`Example.cpp`, kept in the public plugins built on it: "Orientation matrix is left-handed") reads it: pitch from
//! the forward vector's world-up share, `-mOri[1].z`, and roll from the left vector's, `mOri[1].x`.
//!
//! | ringpod | from | sign |
//! |---|---|---|
//! | force x | `-mLocalAccel.z + g (-mOri[1].z)` | published axes; gravity assumed absent |
//! | force y | `mLocalAccel.x + g mOri[1].x` | as x |
//! | force z | `mLocalAccel.y + g mOri[1].y` | as x |
//! | rate roll | `mLocalRot.z` | published: +z rolls right (right side down) |
//! | rate pitch | `-mLocalRot.x` | published: +x pitches up (ringpod's positive pitch rate is nose down) |
//! | rate yaw | `-mLocalRot.y` | published: +y yaws right |
//! | time | `mElapsedTime` | published |
//! | lap | the player's `mLapDist` over `mScoringInfo.mLapDist` (a fraction of the lap) | none while the length is not positive |

use super::{Bytes, Game, Guard, Read, Sample, Unreadable};
use crate::games::{add, gravity_from_axes, LapPosition, Telemetry};

/// The telemetry buffer's mapping.
pub const TELEMETRY: &str = "$rFactor2SMMP_Telemetry$";
/// The scoring buffer's mapping.
pub const SCORING: &str = "$rFactor2SMMP_Scoring$";
/// Published (the plugin's readme): telemetry at 50 FPS.
pub const RATE_HZ: f64 = 50.0;
/// `MAX_MAPPED_VEHICLES`.
pub const MAX_VEHICLES: usize = 128;

/// Offsets in the telemetry mapping.
pub mod telemetry {
    /// `mNumVehicles`.
    pub const NUM_VEHICLES: usize = 12;
    /// `mVehicles[0]`.
    pub const VEHICLES: usize = 16;
    /// `sizeof(rF2VehicleTelemetry)`.
    pub const VEHICLE: usize = 1888;
    /// In a vehicle: `mID`.
    pub const ID: usize = 0;
    /// `mElapsedTime`.
    pub const ELAPSED_TIME: usize = 12;
    /// `mLocalAccel`.
    pub const LOCAL_ACCEL: usize = 208;
    /// `mOri[1]`, the row giving world Y (up).
    pub const ORI_ROW_UP: usize = 232 + 24;
    /// `mLocalRot`.
    pub const LOCAL_ROT: usize = 304;
}

/// Offsets in the scoring mapping.
pub mod scoring {
    /// `mScoringInfo.mNumVehicles`.
    pub const NUM_VEHICLES: usize = 12 + 104;
    /// `mVehicles[0]`.
    pub const VEHICLES: usize = 12 + 548;
    /// `sizeof(rF2VehicleScoring)`.
    pub const VEHICLE: usize = 584;
    /// In a vehicle: `mID`.
    pub const ID: usize = 0;
    /// `mIsPlayer`.
    pub const IS_PLAYER: usize = 196;
    /// `mLapDist` (f64, m, "current distance around track"): after `mID`, `mDriverName[32]`, `mVehicleName[64]`,
    /// `mTotalLaps` (i16), `mSector`, `mFinishStatus` (i8).
    pub const LAP_DIST: usize = 104;
    /// `mScoringInfo.mLapDist` (f64, m, "distance around track": the lap's length), after `mTrackName[64]`,
    /// `mSession` (i32), `mCurrentET`, `mEndET` (f64), `mMaxLaps` (i32).
    pub const TRACK_LENGTH: usize = 12 + 88;
}

/// The vehicles a buffer announces (its `mNumVehicles` at `at`, at most [`MAX_VEHICLES`]), and the bytes that
/// takes from `first` in steps of `size`; `None` when the count is missing or out of range.
pub fn extent(page: &[u8], at: usize, first: usize, size: usize) -> Option<(usize, usize)> {
    let n = usize::try_from(Bytes(page).i32(at)?)
        .ok()
        .filter(|n| *n <= MAX_VEHICLES)?;
    Some((n, first + n * size))
}

/// Refuses a buffer shorter than `need`, or one whose version block says it was being written.
fn whole(game: Game, mapping: &'static str, page: &[u8], need: usize) -> Result<(), Unreadable> {
    let b = Bytes(page);
    match (b.u32(0), b.u32(4)) {
        (Some(begin), Some(end)) if page.len() >= need => {
            if begin == end {
                Ok(())
            } else {
                Err(Unreadable::Torn { game })
            }
        }
        _ => Err(Unreadable::size(game, mapping, page.len(), format!("{need} bytes"))),
    }
}

/// The `mID` of the player's vehicle in a scoring snapshot.
pub fn player(game: Game, page: &[u8]) -> Result<i32, Unreadable> {
    let (n, need) =
        extent(page, scoring::NUM_VEHICLES, scoring::VEHICLES, scoring::VEHICLE).ok_or_else(|| Unreadable::Header {
            game,
            why: format!("{SCORING}: mNumVehicles is not 0 to {MAX_VEHICLES}"),
        })?;
    whole(game, SCORING, page, need)?;
    let b = Bytes(page);
    (0..n)
        .map(|i| scoring::VEHICLES + i * scoring::VEHICLE)
        .find(|v| b.u8(v + scoring::IS_PLAYER).is_some_and(|p| p != 0))
        .and_then(|v| b.i32(v + scoring::ID))
        .ok_or_else(|| Unreadable::NoMotion {
            game,
            why: "no vehicle is the player's (mIsPlayer): in the menus, or watching".into(),
        })
}

/// The player's lap position in a scoring snapshot [`player`] has found whole: `mLapDist` over the track's length
/// (the scoring is written at 5 Hz, so the value moves in steps; the preview takes it as it comes).
fn lap(page: &[u8]) -> Option<LapPosition> {
    let b = Bytes(page);
    let (n, _) = extent(page, scoring::NUM_VEHICLES, scoring::VEHICLES, scoring::VEHICLE)?;
    let v = (0..n)
        .map(|i| scoring::VEHICLES + i * scoring::VEHICLE)
        .find(|v| b.u8(v + scoring::IS_PLAYER).is_some_and(|p| p != 0))?;
    let length = b.f64(scoring::TRACK_LENGTH);
    (length.is_finite() && length > 0.0).then(|| LapPosition::Along(b.f64(v + scoring::LAP_DIST) / length))
}

/// Reads the player's vehicle from snapshots of the telemetry and scoring mappings.
pub fn decode(game: Game, page: &[u8], scoring: &[u8]) -> Result<Read, Unreadable> {
    let (n, need) = extent(page, telemetry::NUM_VEHICLES, telemetry::VEHICLES, telemetry::VEHICLE)
        .ok_or_else(|| Unreadable::size(game, TELEMETRY, page.len(), "a version block and mNumVehicles"))?;
    whole(game, TELEMETRY, page, need)?;
    let id = player(game, scoring)?;
    let b = Bytes(page);
    let v = (0..n)
        .map(|i| telemetry::VEHICLES + i * telemetry::VEHICLE)
        .find(|v| b.i32(v + telemetry::ID) == Some(id))
        .ok_or_else(|| Unreadable::NoMotion {
            game,
            why: format!("the player's vehicle (mID {id}) is not in the telemetry"),
        })?;
    let [ax, ay, az] = b.dvec3(v + telemetry::LOCAL_ACCEL);
    // The up row: the world-up share of the car's left (x) and back (z) axes; the up axis' own share follows
    // from them (taken as upright, as the UDP formats take it).
    let [up_x, _, up_z] = b.dvec3(v + telemetry::ORI_ROW_UP);
    let [rx, ry, rz] = b.dvec3(v + telemetry::LOCAL_ROT);
    let gravity = gravity_from_axes(-up_z, up_x);
    Ok(Read {
        tick: u64::from(b.u32(0).unwrap_or(0)),
        guard: Guard::of(page, 0, 0, 8),
        sample: Sample {
            time: Some(b.f64(v + telemetry::ELAPSED_TIME)),
            telemetry: Telemetry {
                force: add([-az, ax, ay], gravity),
                rate: [rz, -rx, -ry],
            },
            lap: lap(scoring),
        },
    })
}

#[cfg(test)]
mod tests;
