use std::f64::consts::TAU;

use super::super::testing::{close, Page, DRIVE};
use super::super::{decode as decode_game, Game, Unreadable};
use super::*;

/// The zones of `scsTelemetryMap_t` the decoder reads, from the header's declarations: zone 1 (`sdkActive`, 3
/// bytes, `paused`, 3 bytes, `time`), zone 2 at 40 (`scs_values` first), zone 6 at 1640 (`config_fv`: 9 floats and
/// 3 x 16, then `truck_fv`: linear velocity, angular velocity, linear acceleration, ...), zone 8 at 2200
/// (`truck_dp`: three coordinates, then heading, pitch, roll, all `double`).
mod zones {
    pub const TIME: usize = 1 + 3 + 1 + 3;
    pub const REVISION: usize = 40;
    pub const TRUCK_FV: usize = 1640 + 4 * (9 + 3 * 16);
    pub const ANGULAR_VELOCITY: usize = TRUCK_FV + 12;
    pub const ACCELERATION: usize = TRUCK_FV + 24;
    pub const PITCH: usize = 2200 + 8 * 4;
    pub const ROLL: usize = 2200 + 8 * 5;
}

fn page(time_us: u64, m: &super::super::testing::Moment) -> Vec<u8> {
    let mut p = Page::zeros(32 * 1024);
    // Published axes: x right, y up, z back; angular velocity in turns per second; pitch and roll in turns, a
    // positive roll lifting the right side.
    p.put(0, &[1])
        .u64(zones::TIME, time_us)
        .u32(zones::REVISION, 10)
        .f32s(
            zones::ANGULAR_VELOCITY,
            &[-m.rate[1] / TAU, m.rate[2] / TAU, -m.rate[0] / TAU],
        )
        .f32s(zones::ACCELERATION, &[-m.accel[1], m.accel[2], -m.accel[0]])
        .f64s(zones::PITCH, &[m.pitch / TAU, -m.roll / TAU]);
    p.0
}

#[test]
fn the_zones_offsets_are_the_declared_ones() {
    assert_eq!(
        (
            zones::TIME,
            zones::REVISION,
            zones::ANGULAR_VELOCITY,
            zones::ACCELERATION,
            zones::PITCH,
            zones::ROLL
        ),
        (
            at::TIME,
            at::REVISION,
            at::ANGULAR_VELOCITY,
            at::ACCELERATION,
            at::PITCH,
            at::ROLL
        )
    );
}

#[test]
fn a_drive_decodes_with_the_plugins_time() {
    for (i, m) in DRIVE.iter().enumerate() {
        let t = 5_000_000 + 16_667 * i as u64;
        let read = decode_game(Game::Ets2, &[page(t, m)]).unwrap();
        assert_eq!((read.tick, read.sample.time), (t, Some(t as f64 / 1e6)));
        assert!(close(read.sample.telemetry.force, m.force()), "{}: {read:?}", m.name);
        assert!(close(read.sample.telemetry.rate, m.rate), "{}: {read:?}", m.name);
    }
}

#[test]
fn an_inactive_plugin_or_a_short_map_is_refused() {
    let mut off = page(1, &DRIVE[0]);
    off[0] = 0;
    assert!(matches!(decode(&off), Err(Unreadable::NoMotion { .. })));
    assert!(matches!(
        decode(&page(1, &DRIVE[0])[..SIZE - 1]),
        Err(Unreadable::Size { .. })
    ));
}

/// A real snapshot of the plugin's memory, a Scania S standing still (speed -0.0008 m/s, engine off) on a level
/// road: TruckSim-Telemetry's `dev/buffers/sdk_data_1_10` (Kniffen, MIT licence,
/// `github.com/kniffen/TruckSim-Telemetry`, removed in commit 559246b; its decoded form is the same repository's
/// `docs/data/truck.md`), the fields ringpod reads at their offsets, as the game wrote them. The linear acceleration's up component is 0.16 m/s^2, not
/// 9.8: gravity is not in `truck.local.acceleration.linear`, and ringpod's vertical force at rest is gravity's
/// reaction alone (counted twice it would be 19.8, left out 0.16).
#[test]
fn a_real_truck_at_rest_has_no_gravity_in_its_acceleration() {
    let mut p = Page::zeros(16 * 1024);
    p.put(0, &[1])
        .u64(zones::TIME, 1)
        .u32(zones::REVISION, 10)
        .f32s(
            zones::ANGULAR_VELOCITY,
            &[-0.000_189_367_04, -0.000_012_564_577, 0.000_434_524],
        )
        .f32s(zones::ACCELERATION, &[0.001_310_421_9, 0.162_592_01, 0.008_456_057])
        .f64s(
            zones::PITCH,
            &[-0.002_085_370_477_288_961_4, 0.001_831_818_721_257_150_2],
        );
    let read = decode(&p.0).unwrap();
    let [x, y, z] = read.sample.telemetry.force;
    assert!((z - 9.97).abs() < 0.05, "{read:?}");
    // The placement's pitch (0.75 degrees nose down) and roll (0.66 degrees) give gravity's small x and y shares.
    assert!((x + 0.13).abs() < 0.02 && (y + 0.11).abs() < 0.02, "{read:?}");
}
