//! Assetto Corsa and Assetto Corsa Competizione: the physics page of their shared memory.
//!
//! Sources: Kunos Simulazioni's shared-memory header for Assetto Corsa (`SharedFileOut.h`: `SPageFilePhysics`,
//! `SPageFileGraphic`, `SPageFileStatic`, `#pragma pack(4)`), read in a copy kept in public code (Kunos publish it
//! in a forum post, not read here), and Kunos' "ACC Shared Memory Documentation" v1.8.12 as a public C++ header
//! transcribes it (ACC's `SPageFilePhysics`, which keeps AC's fields and appends `localVelocity`,
//! `P2PActivations` .. `waterTemp`; the transcription checks `abs` at 252, `slipRatio` at 640 and `absInAction`
//! at 676 with `static_assert`s). Both games write the page to the named mapping `Local\acpmf_physics`,
//! little-endian, 4-byte packed:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0-3 | `packetId` | i32, "current step index": the counter of a new sample |
//! | 4-43 | `gas` .. `velocity[3]` | not read |
//! | 44-55 | `accG[3]` | f32, g, "car acceleration" in the car's axes (x, y, z) |
//! | 56-207 | wheels, tyres, `drs`, `tc` | not read |
//! | 208, 212, 216 | `heading`, `pitch`, `roll` | f32, rad |
//! | 220-295 | `cgHeight` .. `roadTemp` | not read |
//! | 296-307 | `localAngularVel[3]` | f32, rad/s, "car angular velocity in local coordinates" |
//! | 308-567 | `finalFF` .. `brakeBias` | not read; AC's page is 568 bytes |
//! | 568-715 | `localVelocity` .. `waterTemp` | ACC only; ACC's page is 716 bytes |
//!
//! The offsets of the fields read are the same in both games; what differs is the page's size (the snapshot must
//! hold the game's whole page). The documentation gives no publish rate: ringpod assumes the physics step of both
//! games, 333 Hz (a sample is new only when `packetId` moves, whatever the rate).
//!
//! ## Conversion
//!
//! Neither document states the axes' senses, nor whether `accG` includes gravity, nor the senses of `pitch`,
//! `roll` and `localAngularVel`: **all assumed** here, from the games' y-up world: the car's axes x to its left,
//! y up, z forward (right-handed), `accG` the car's acceleration without gravity (so its y reads 0 at rest),
//! `pitch` positive nose up, `roll` positive right side down, the angular velocity right-handed about the car's
//! axes:
//!
//! | ringpod | from | |
//! |---|---|---|
//! | force x | `g accG[2] + g sin(pitch)` | AC: a real recording (below); ACC: assumed |
//! | force y | `g accG[0] + g cos(pitch) sin(roll)` | AC: a real recording; ACC: assumed |
//! | force z | `g accG[1] + g cos(pitch) cos(roll)` | AC: a real recording (no gravity); ACC: a snapshot at rest |
//! | rate roll | `localAngularVel[2]` | assumed (about forward) |
//! | rate pitch | `localAngularVel[0]` | assumed (about left) |
//! | rate yaw | `localAngularVel[1]` | assumed (about up) |
//! | time | none: the arrival time is used | the page has no time |
//! | lap | `normalizedCarPosition` of the graphics page | a fraction of the lap, "Car position on the track's spline" |
//!
//! ## Lap position
//!
//! The graphics page (`SPageFileGraphic`, mapping `Local\acpmf_graphics`, the same header and pack) carries where
//! the car is on the lap; its start is the same in both games (ACC's document lists the same members up to
//! `normalizedCarPosition`): `packetId`, `status`, `session` (i32 at 0, 4, 8), `currentTime`, `lastTime`,
//! `bestTime`, `split` (`wchar_t[15]` each, 12 to 131), `completedLaps` .. `iBestTime` (i32, 132 to 151),
//! `sessionTimeLeft`, `distanceTraveled` (f32, 152, 156), `isInPit`, `currentSectorIndex`, `lastSectorTime`,
//! `numberOfLaps` (i32, 160 to 175), `tyreCompound` (`wchar_t[33]`, 176 to 241, padded to 244),
//! `replayTimeMultiplier` (f32, 244), `normalizedCarPosition` (f32 at 248). The page is read when it is there;
//! without it the sample has no lap position (the preview stays off), never an error.
//!
//! A real lap of AC settles `accG`'s senses: AC's UDP remote telemetry sends the same vector in the same order
//! (its document names the three floats vertical, horizontal and frontal, but they are x, y, z), and a recording
//! of it at Monza (Python_UDP_Receiver, CC0, 8,641 datagrams) has `accG[0]` follow the path's centripetal
//! acceleration towards the car's left (correlation 0.997, slope 1.00; the outer wheels turn faster), `accG[1]`
//! average 0.006 g (no gravity) and `accG[2]` follow the speed's derivative (0.991). Two corners are kept as a test
//! (`ac/recording.rs`). The angles' and rates' senses stay assumed (the datagram has neither). ACC runs another
//! engine: of its page only a snapshot at rest (0.0012 km/h) is published, showing `accG` (0, 0, 0), no gravity
//! (acc-manager-server's README, `github.com/madmak2005/acc-manager-server`). A drive captured in each game is the
//! check: accelerating must give force x > 0, a left turn force y > 0 and a positive yaw rate.

use super::{Bytes, Game, Guard, Read, Sample, Unreadable};
use crate::games::{add, gravity_from_attitude, LapPosition, Telemetry, G};

/// The mapping of both games' physics page.
pub const MAPPING: &str = r"Local\acpmf_physics";
/// AC's `SPageFilePhysics` (through `brakeBias`).
pub const AC_SIZE: usize = 568;
/// ACC's `SPageFilePhysics` (through `waterTemp`, v1.8.12).
pub const ACC_SIZE: usize = 716;
/// The mapping of both games' graphics page.
pub const GRAPHICS: &str = r"Local\acpmf_graphics";
/// The graphics page's bytes read: through `normalizedCarPosition`.
pub const GRAPHICS_SIZE: usize = 252;
/// Assumed: the physics step.
pub const RATE_HZ: f64 = 333.0;

/// Byte offsets of the fields read.
pub mod at {
    /// `packetId`.
    pub const PACKET_ID: usize = 0;
    /// `accG[3]`.
    pub const ACC_G: usize = 44;
    /// `pitch`.
    pub const PITCH: usize = 212;
    /// `roll`.
    pub const ROLL: usize = 216;
    /// `localAngularVel[3]`.
    pub const LOCAL_ANGULAR_VEL: usize = 296;
    /// `normalizedCarPosition`, in the graphics page.
    pub const NORMALIZED_CAR_POSITION: usize = 248;
}

/// The page's size in `game`.
pub fn size(game: Game) -> usize {
    if game == Game::Acc {
        ACC_SIZE
    } else {
        AC_SIZE
    }
}

/// Reads one physics page of `game` (AC or ACC), and the lap position from its graphics page when that is there.
pub fn decode(game: Game, page: &[u8], graphics: &[u8]) -> Result<Read, Unreadable> {
    let size = size(game);
    if page.len() < size {
        return Err(Unreadable::size(game, MAPPING, page.len(), format!("{size} bytes")));
    }
    let b = Bytes(page);
    let [ax, ay, az] = b.vec3(at::ACC_G);
    let (pitch, roll) = (b.f32(at::PITCH), b.f32(at::ROLL));
    let [wx, wy, wz] = b.vec3(at::LOCAL_ANGULAR_VEL);
    let force = add([G * az, G * ax, G * ay], gravity_from_attitude(pitch, roll));
    Ok(Read {
        tick: u64::from(b.u32(at::PACKET_ID).unwrap_or(0)),
        guard: Guard::of(page, 0, at::PACKET_ID, 4),
        sample: Sample {
            time: None,
            telemetry: Telemetry {
                force,
                rate: [wz, wx, wy],
            },
            lap: (graphics.len() >= GRAPHICS_SIZE)
                .then(|| LapPosition::Along(Bytes(graphics).f32(at::NORMALIZED_CAR_POSITION))),
        },
    })
}

#[cfg(test)]
mod recording;
#[cfg(test)]
mod tests;
