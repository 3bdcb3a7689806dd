//! Continuous yaw: carriages are multi-turn and keep step precision over 10,000 turns (KINEMATICS.md 3).

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use ringpod_core::kinematics::{presets, Mechanism, MultiTurn, Pose, RingPlatform};

/// 200 full steps x 16 microsteps x 8:1 ring gear (assumed: the source gives no gearing) = 25,600 steps per carriage
/// revolution (about 4,074 steps/rad).
const STEPS_PER_TURN: i64 = 25_600;

/// The commanded pose at tick k: yaw advances by `dyaw` a tick while heave and tilt wobble inside the spec ranges.
/// Yaw goes over the wire within one turn (the host keeps whole turns apart, as the core does), so it is
/// computed in f64 from the tick count and wrapped before it becomes f32.
fn pose_at(k: i64, dyaw: f64) -> Pose<f32> {
    let t = k as f64 * 1e-3;
    let yaw = (k as f64 * dyaw).rem_euclid(std::f64::consts::TAU);
    Pose::new(
        (0.01 * (1.3 * t).sin()) as f32,
        (0.01 * (0.7 * t).cos() - 0.01) as f32,
        (presets::TRAINER_MODEL_HOME_Z + 0.02 * (0.9 * t).sin()) as f32,
        (0.1 * (0.5 * t).sin()) as f32,
        (0.1 * (0.3 * t).sin()) as f32,
        yaw as f32,
    )
}

#[test]
fn ten_thousand_turns_out_and_back_within_one_step() {
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let dyaw = 0.05; // rad a tick: far more than 1.9 rad/s at 1 kHz, to keep the test short.
    let ticks = (10_000.0 * std::f64::consts::TAU / dyaw).round() as i64;
    let start_pose = pose_at(0, dyaw);
    let mut pos = MultiTurn::new(m.inverse(&start_pose).unwrap());
    let start: Vec<i64> = (0..4).map(|i| pos.ring_steps(i, STEPS_PER_TURN)).collect();

    for k in 1..=ticks {
        pos.inverse_near(&m, &pose_at(k, dyaw)).unwrap();
    }
    // Far out: every carriage went 10,000 turns round, and its step count matches an f64 reference.
    let far = pose_at(ticks, dyaw).cast::<f64>();
    let q64 = RingPlatform::<f64>::new(&presets::TRAINER_MODEL).inverse(&far).unwrap();
    for i in 0..4 {
        assert_eq!(pos.turns[i], 10_000, "axis {i} turns");
        let exact = 10_000 * STEPS_PER_TURN + (q64.0[i] * STEPS_PER_TURN as f64 / std::f64::consts::TAU).round() as i64;
        assert!(
            (pos.ring_steps(i, STEPS_PER_TURN) - exact).abs() <= 1,
            "axis {i} far out"
        );
    }
    for k in (0..ticks).rev() {
        pos.inverse_near(&m, &pose_at(k, dyaw)).unwrap();
    }
    for i in 0..4 {
        assert_eq!(pos.turns[i], 0);
        assert!(
            (pos.ring_steps(i, STEPS_PER_TURN) - start[i]).abs() <= 1,
            "axis {i} back home"
        );
    }
}

#[test]
fn one_float_angle_would_drift_by_steps() {
    // Why turns are kept apart: an f32 angle of 10,000 turns cannot hold a step.
    let angle = (10_000.0 * std::f64::consts::TAU) as f32;
    let ulp = f32::from_bits(angle.to_bits() + 1) - angle;
    let steps_per_rad = STEPS_PER_TURN as f32 / std::f32::consts::TAU;
    assert!(
        ulp * steps_per_rad > 10.0,
        "ulp {ulp} rad = {} steps",
        ulp * steps_per_rad
    );
}

#[test]
fn never_jumps_a_turn() {
    // Yaw rate 1.9 rad/s at 1 kHz, a full turn each way: no carriage ever moves more than 0.05 rad in a tick.
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let pose = |k: i64| Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, k as f64 * 1.9e-3);
    let mut pos = MultiTurn::new(m.inverse(&pose(0)).unwrap());
    let mut last: Vec<f64> = (0..4).map(|i| pos.total(i)).collect();
    for k in (1..3400).chain((-3400..3400).rev()) {
        pos.inverse_near(&m, &pose(k)).unwrap();
        for i in 0..4 {
            assert!((pos.total(i) - last[i]).abs() < 0.05, "tick {k} axis {i}");
            last[i] = pos.total(i);
        }
    }
}
