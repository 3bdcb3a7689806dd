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
