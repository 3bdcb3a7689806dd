//! Euro Truck Simulator 2 and American Truck Simulator: the scs-sdk-plugin's shared memory.
//!
//! Sources: RenCloud/scs-sdk-plugin, `scs-telemetry/inc/scs-telemetry-common.hpp` (`PLUGIN_REVID` 10, commit
//! 2be7683 of 2020-12-23: `scsTelemetryMap_t`, laid out in zones at fixed offsets, in the mapping
//! `Local\SCSTelemetry` of 32 KiB) and `scs-telemetry/src/scs_telemetry.cpp` (which SDK channel fills which
//! field); SCS Software's telemetry SDK 1.12 (`scssdk_value.h`, `scssdk_telemetry_truck_common_channels.h` in the
//! same repository) for the channels' units and axes. Little-endian:
//!
//! | bytes | field | |
//! |---|---|---|
//! | 0 | `sdkActive` | bool: the plugin is loaded and the game running |
//! | 4 | `paused` | bool |
//! | 8 | `time` | u64, µs: the SDK's `paused_simulation_time` made continuous; the counter of a new sample |
//! | 40 | `scs_values.telemetry_plugin_revision` | u32 |
//! | 1880-1891 | `truck_fv.av_accelerationX/Y/Z` | f32: channel `truck.local.velocity.angular`, "vehicle space angular velocity of the truck measured in rotations per second" |
//! | 1892-1903 | `truck_fv.accelerationX/Y/Z` | f32: channel `truck.local.acceleration.linear`, "vehicle space linear acceleration of the truck measured in meters per second^2" |
//! | 2232, 2240 | `truck_dp.rotationY`, `rotationZ` | f64: channel `truck.world.placement`'s `pitch` and `roll` |
//!
//! The plugin writes `time` at the start of each of the game's frames and the channels as the game hands them
//! over in that frame; it has no version or sequence, so a copy is checked only by `time` being the same before and
//! after it; a new `time` is left to stand for one poll before it is copied ([`super::poll`]), so that the frame's
//! channels are written by then.
//! The game calls its plugins every rendered frame: ringpod assumes 60 Hz.
//!
//! ## Conversion
//!
//! `scssdk_value.h`: "In local space the X points to right, Y up and Z backwards"; pitch "stored in unit range
//! where <-0.25,0.25> corresponds to <-90,90> ... positive values pointing up"; roll "stored in unit range where
//! <-0.5,0.5> corresponds to <-180,180>. The angle is measured in counterclockwise when looking in direction of the
//! roll axis". Whether the acceleration includes gravity is not stated; a real snapshot of a truck at rest shows it
//! does not (0.16 m/s^2 up where gravity would be 9.8: TruckSim-Telemetry's buffer, the test in `ets2/tests.rs`), so
//! gravity's reaction is added from pitch and roll; the rotations' senses assumed right-handed about the published
//! axes; the roll axis taken as pointing forward (so a positive roll lifts the right side).
//!
//! | ringpod | from | |
//! |---|---|---|
//! | force x | `-accelerationZ + g sin(2 pi pitch)` | published axes; no gravity in it (a real snapshot at rest) |
//! | force y | `-accelerationX + g cos(2 pi pitch) sin(-2 pi roll)` | as x; roll axis assumed forward |
//! | force z | `accelerationY + g cos(2 pi pitch) cos(2 pi roll)` | as x |
//! | rate roll | `-2 pi av_accelerationZ` | published unit (rotations/s); sense assumed right-handed |
//! | rate pitch | `-2 pi av_accelerationX` | as roll |
//! | rate yaw | `2 pi av_accelerationY` | as roll |
//! | time | `time / 10^6` s | published (µs) |

use std::f64::consts::TAU;

use super::{Bytes, Game, Guard, Read, Sample, Unreadable};
use crate::games::{add, gravity_from_attitude, Telemetry};

/// The plugin's mapping.
pub const MAPPING: &str = r"Local\SCSTelemetry";
/// Assumed: a rendered frame at 60 Hz.
pub const RATE_HZ: f64 = 60.0;
/// The bytes read: through `truck_dp.rotationZ`.
pub const SIZE: usize = at::ROLL + 8;

/// Byte offsets of the fields read.
pub mod at {
    /// `sdkActive`.
    pub const SDK_ACTIVE: usize = 0;
    /// `time`.
    pub const TIME: usize = 8;
    /// `telemetry_plugin_revision`.
    pub const REVISION: usize = 40;
    /// `av_accelerationX`: the angular velocity.
    pub const ANGULAR_VELOCITY: usize = 1880;
    /// `accelerationX`: the linear acceleration.
    pub const ACCELERATION: usize = 1892;
    /// `truck_dp.rotationY`: the pitch.
    pub const PITCH: usize = 2232;
    /// `truck_dp.rotationZ`: the roll.
    pub const ROLL: usize = 2240;
}

/// Reads one snapshot of `Local\SCSTelemetry` (at least its first [`SIZE`] bytes).
pub fn decode(page: &[u8]) -> Result<Read, Unreadable> {
    let b = Bytes(page);
    let (Some(active), Some(time), Some(revision)) = (b.u8(at::SDK_ACTIVE), b.u64(at::TIME), b.u32(at::REVISION))
    else {
        return Err(Unreadable::size(
            Game::Ets2,
            MAPPING,
            page.len(),
            format!("{SIZE} bytes"),
        ));
    };
    if page.len() < SIZE {
        return Err(Unreadable::size(
            Game::Ets2,
            MAPPING,
            page.len(),
            format!("{SIZE} bytes"),
        ));
    }
    if active == 0 || revision == 0 {
        return Err(Unreadable::NoMotion {
            game: Game::Ets2,
            why: format!("the plugin is not active (sdkActive {active}, revision {revision})"),
        });
    }
    let [wx, wy, wz] = b.vec3(at::ANGULAR_VELOCITY).map(|w| TAU * w);
    let [ax, ay, az] = b.vec3(at::ACCELERATION);
    let (pitch, roll) = (TAU * b.f64(at::PITCH), TAU * b.f64(at::ROLL));
    Ok(Read {
        tick: time,
        guard: Guard::of(page, 0, at::TIME, 8),
        sample: Sample {
            time: Some(time as f64 / 1e6),
            telemetry: Telemetry {
                force: add([-az, -ax, ay], gravity_from_attitude(pitch, -roll)),
                rate: [-wz, -wx, wy],
            },
            lap: None,
        },
    })
}

#[cfg(test)]
mod tests;
