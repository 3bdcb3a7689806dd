//! Pose-to-motion latency of both follow modes (the control core chapter's table, measured by `examples/latency.rs`).

use crate::latency_example as latency;

use ringpod_core::motion::FollowMode;

#[test]
fn motion_starts_on_the_next_tick_and_lags_by_what_braking_needs() {
    for follow in [FollowMode::Interpolate, FollowMode::Direct] {
        for rate in [60, 250, 1000] {
            let l = latency::measure(follow, rate);
            // The first step toward a new setpoint is in the tick after it arrives, in both modes.
            assert_eq!(l.first_step, 1, "{follow:?} {rate} Hz");
            // A 1 mm step at 1 m/s^2 takes 2 sqrt(d / a) = 63 ms at best.
            assert!((63..=70).contains(&l.arrival), "{follow:?} {rate} Hz: {l:?}");
            // Behind a ramp by the setpoints' age (half an interval on average) plus the distance it needs to
            // stop on the newest one (v^2 / 2a = 0.2 mm = 10 ms at 20 mm/s), never more than one interval more.
            let interval_ms = 1000.0 / rate as f32;
            assert!(
                l.ramp_lag_ms >= 9.0 && l.ramp_lag_ms <= 10.0 + 1.5 * interval_ms + 2.0,
                "{follow:?} {rate} Hz: {l:?}"
            );
        }
    }
}
