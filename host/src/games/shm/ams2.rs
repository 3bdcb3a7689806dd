//! Automobilista 2 and Project CARS 2: their shared memory (`Shared Memory: Project CARS 2` in the game's options).
//!
//! Source: `SharedMemory.h` of Project CARS 2 as Reiza ships it with AMS2 ("Storage structure for storing and
//! updating shared memory", `SHARED_MEMORY_VERSION` 13 in the copy read, kept in public code; AMS2's later
//! releases, version 14, append fields at the end, as the "AMS2 Additions (v10...)" before them did), in the
//! mapping `$pcars2$`. Every member is at most 4 bytes, so the natural alignment is 4-byte
//! packing; little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0 | `mVersion` | u32, `SHARED_MEMORY_VERSION`: 8 or above has `mSequenceNumber` |
//! | 8 | `mGameState` | u32: not used (AMS2 is reported to write 3, paused, while driving) |
//! | 20 | `mViewedParticipantIndex` | i32: the participant viewed (the player's car while driving) |
//! | 28-6427 | `mParticipantInfo[64]` | 100 bytes each: `mIsActive` (bool), `mName` (char[64]), `mWorldPosition` (3 f32 at 68), `mCurrentLapDistance` (f32 at 80, "Metres"), then race position, laps, lap, sector |
//! | 6704 | `mTrackLength` | f32, m, after the unfiltered inputs, car and class names, `mLapsInEvent`, track location and variation |
//! | 6908-6919 | `mOrientation[3]` | f32, "Euler Angles" |
//! | 6944-6955 | `mAngularVelocity[3]` | f32, "Radians per-second" |
//! | 6956-6967 | `mLocalAcceleration[3]` | f32, "Metres per-second" (per second squared: an acceleration) |
//! | 7320 | `mSequenceNumber` | u32, "incremented at start and end of writing, so odd when Shared Memory is being filled, even when the memory is not being touched" |
//!
//! The offsets follow from the header's members in order (`mOrientation` after `mBoostAmount` at 6904;
//! `mSequenceNumber` after `mCloudBrightness` at 7316). The header says the memory "will be updated once per
//! graphics frame": ringpod assumes 60 Hz for its stall count. A sample is new when `mSequenceNumber` is even and
//! has moved; an odd one, or one that moved during the copy, is a torn read.
//!
//! ## Conversion
//!
//! `SharedMemory.h` gives units, not axes, nor the order of the Euler angles, nor whether the angular velocity is
//! in the car's axes. Project CARS, whose engine and whose structure AMS2 and Project CARS 2 keep, sends the same
//! fields in its UDP telemetry, and a real recording of it settles them (Python_UDP_Receiver's `pcars.bin`, CC0,
//! 2,880 packets of a lap of Dubai Autodrome; two corners are kept as a test, `ams2/recording.rs`):
//!
//! - `mLocalAcceleration` is `mWorldAcceleration` turned into the car's axes (correlation 1.00), the world's own
//!   acceleration (it follows the world velocity's derivative, 0.92) without gravity (0 at rest).
//! - The car's axes are x to its **left**, y up, z back: the local velocity is (0, 0, -speed), and where the car
//!   coasts through a turn the right wheels (the published tyre order is FL, FR, RL, RR) turn faster when
//!   `mLocalAcceleration[0]` is positive, in 95 % of the packets: the front wheels' relative speed difference
//!   follows the path's curvature (yaw rate over speed) with correlation 0.95 and slope 1.57 m, the car's track;
//!   the steering is negative in those turns.
//! - `mAngularVelocity` is the car's angular velocity on those axes, by the right-hand rule: `[1]` positive turns
//!   left (it is minus the heading's derivative, -0.99), `[0]` positive dips the nose (minus the pitch's
//!   derivative, -0.88), `[2]` positive lifts the right side (minus the roll's derivative, -0.89).
//! - `mOrientation` is (pitch, heading, roll) in radians: pitch positive nose up (it follows the climb of the
//!   world velocity, 0.87, slope 1.08), roll positive right side down (as the roll rate says).
//!
//! | ringpod | from | |
//! |---|---|---|
//! | force x | `-mLocalAcceleration[2] + g sin(pitch)` | a real recording |
//! | force y | `mLocalAcceleration[0] + g cos(pitch) sin(roll)` | a real recording |
//! | force z | `mLocalAcceleration[1] + g cos(pitch) cos(roll)` | a real recording |
//! | rate roll | `-mAngularVelocity[2]` | a real recording |
//! | rate pitch | `mAngularVelocity[0]` | a real recording |
//! | rate yaw | `mAngularVelocity[1]` | a real recording |
//! | time | none: the arrival time is used | the structure has no simulation clock |
//! | lap | the viewed participant's `mCurrentLapDistance` over `mTrackLength` | a fraction of the lap; none without a positive length or a participant in range |
//!
//! Two real snapshots of AMS2 itself with cars at rest (sim-to-motec's `stm/ams2/test/ams2_inrace.bin` and
//! `ams2_mp4_inpits.bin`, versions 13 and 14, `github.com/GeekyDeaks/sim-to-motec`) read `mLocalAcceleration` below
//! 0.002 m/s^2 on every axis: no gravity in it there either. That AMS2's axes are Project CARS's is inferred from
//! the shared engine and structure, not seen in an AMS2 drive: a capture of one (a left corner must give force
//! y > 0 and a positive yaw rate) is the last check.

use super::{Bytes, Game, Guard, Read, Sample, Unreadable};
use crate::games::{add, gravity_from_attitude, LapPosition, Telemetry};

/// The mapping.
pub const MAPPING: &str = "$pcars2$";
/// Assumed: a graphics frame at 60 Hz.
pub const RATE_HZ: f64 = 60.0;
/// The first version with `mSequenceNumber`.
pub const MIN_VERSION: u32 = 8;
/// The bytes read: through `mSequenceNumber`.
pub const SIZE: usize = at::SEQUENCE_NUMBER + 4;

/// Byte offsets of the fields read.
pub mod at {
    /// `mVersion`.
    pub const VERSION: usize = 0;
    /// `mOrientation[3]`.
    pub const ORIENTATION: usize = 6908;
    /// `mAngularVelocity[3]`.
    pub const ANGULAR_VELOCITY: usize = 6944;
    /// `mLocalAcceleration[3]`.
    pub const LOCAL_ACCELERATION: usize = 6956;
    /// `mSequenceNumber`.
    pub const SEQUENCE_NUMBER: usize = 7320;
    /// `mViewedParticipantIndex`.
    pub const VIEWED_PARTICIPANT: usize = 20;
    /// `mParticipantInfo[0]`, and one participant's size.
    pub const PARTICIPANTS: usize = 28;
    /// `sizeof(ParticipantInfo)`.
    pub const PARTICIPANT: usize = 100;
    /// In a participant: `mCurrentLapDistance`.
    pub const CURRENT_LAP_DISTANCE: usize = 80;
    /// `mTrackLength`.
    pub const TRACK_LENGTH: usize = 6704;
}

/// `STORED_PARTICIPANTS_MAX`.
pub const PARTICIPANTS_MAX: usize = 64;

/// The viewed participant's lap position: its lap distance over the track's length.
fn lap(b: Bytes<'_>) -> Option<LapPosition> {
    let i = usize::try_from(b.i32(at::VIEWED_PARTICIPANT)?)
        .ok()
        .filter(|i| *i < PARTICIPANTS_MAX)?;
    let length = b.f32(at::TRACK_LENGTH);
    let d = b.f32(at::PARTICIPANTS + i * at::PARTICIPANT + at::CURRENT_LAP_DISTANCE);
    (length.is_finite() && length > 0.0).then(|| LapPosition::Along(d / length))
}

/// Reads one snapshot of `$pcars2$` (at least its first [`SIZE`] bytes).
pub fn decode(page: &[u8]) -> Result<Read, Unreadable> {
    let b = Bytes(page);
    let (Some(version), Some(sequence)) = (b.u32(at::VERSION), b.u32(at::SEQUENCE_NUMBER)) else {
        return Err(Unreadable::size(
            Game::Ams2,
            MAPPING,
            page.len(),
            format!("{SIZE} bytes"),
        ));
    };
    if version < MIN_VERSION {
        return Err(Unreadable::Header {
            game: Game::Ams2,
            why: format!("mVersion is {version}: before {MIN_VERSION} the memory has no mSequenceNumber"),
        });
    }
    if sequence % 2 == 1 {
        return Err(Unreadable::Torn { game: Game::Ams2 });
    }
    let [pitch, _, roll] = b.vec3(at::ORIENTATION);
    let [wx, wy, wz] = b.vec3(at::ANGULAR_VELOCITY);
    let [ax, ay, az] = b.vec3(at::LOCAL_ACCELERATION);
    Ok(Read {
        tick: u64::from(sequence),
        guard: Guard::of(page, 0, at::SEQUENCE_NUMBER, 4),
        sample: Sample {
            time: None,
            telemetry: Telemetry {
                force: add([-az, ax, ay], gravity_from_attitude(pitch, roll)),
                rate: [-wz, wx, wy],
            },
            lap: lap(b),
        },
    })
}

#[cfg(test)]
mod recording;
#[cfg(test)]
mod tests;
