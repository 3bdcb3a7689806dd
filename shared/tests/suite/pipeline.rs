//! The motion pipeline: interpolation without overshoot, limits held on every tick, stream loss braking without a
//! jump, rejected setpoints that never move anything.

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use proptest::prelude::*;
use ringpod_core::kinematics::{presets, AxisKind, Check, Mechanism, Pose, RingPlatform};
use ringpod_core::motion::{
    Accepted, AxisScale, FollowMode, MotionLimits, Pipeline, PipelineConfig, PipelineEvent, RejectReason, Setpoint,
    StepConverter,
};

const HOME: [f32; 6] = [0.0, 0.0, presets::TRAINER_MODEL_HOME_Z as f32, 0.0, 0.0, 0.0];

fn pipeline() -> Pipeline<RingPlatform<f32>> {
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let c = AxisScale::MODEL_CARRIAGE;
    let l = AxisScale::MODEL_LINEAR;
    let converter = StepConverter::new([c, c, c, c, l, l], m.axes());
    let mut p = Pipeline::new(m, PipelineConfig::default(), converter, Pose::from_array(HOME)).unwrap();
    p.start();
    p
}

fn pose_with(axis: usize, v: f32) -> Pose<f32> {
    let mut a = HOME;
    a[axis] += v;
    Pose::from_array(a)
}

/// Per-tick history: checks the pose velocity and acceleration limits and the actuator speed limits on every tick.
struct Trace {
    last: Option<[f32; 6]>,
    velocity: [f32; 6],
    actuators: Option<[f64; 6]>,
}

impl Trace {
    fn new() -> Self {
        Self {
            last: None,
            velocity: [0.0; 6],
            actuators: None,
        }
    }

    fn record(&mut self, p: &Pipeline<RingPlatform<f32>>, limits: &MotionLimits, dt: f32) -> Result<(), TestCaseError> {
        self.record_bound(p, limits, dt, false)
    }

    /// As [`Trace::record`]; `actuator_bound`: the actuator limits slowed this tick's step, which they may do
    /// faster than the pose acceleration limit (they take precedence): then only speed gained is limited.
    fn record_bound(
        &mut self,
        p: &Pipeline<RingPlatform<f32>>,
        limits: &MotionLimits,
        dt: f32,
        actuator_bound: bool,
    ) -> Result<(), TestCaseError> {
        let q: [f64; 6] = std::array::from_fn(|i| p.actuators().total(i));
        if let Some(last) = self.actuators {
            for i in 0..6 {
                let v = ((q[i] - last[i]) / f64::from(dt)) as f32;
                // The scaling is linear in the step; the curvature of a long step along the workspace's edge
                // leaves up to 0.1 % more after it.
                prop_assert!(
                    v.abs() <= limits.actuator_velocity[i] * 1.002 + 1e-4,
                    "actuator {i}: {v}"
                );
            }
        }
        self.actuators = Some(q);
        let pose = p.pose();
        let now = pose.to_array();
        if let Some(last) = self.last {
            for i in 0..6 {
                let mut d = now[i] - last[i];
                // Unwrap only across the +-pi seam: rem_euclid around pi would cost the digits being measured.
                if i == 5 && d > std::f32::consts::PI {
                    d -= std::f32::consts::TAU;
                } else if i == 5 && d < -std::f32::consts::PI {
                    d += std::f32::consts::TAU;
                }
                let v = d / dt;
                // Positions are f32: allow a few ulps of the values differentiated (yaw near 2 pi: 5e-7 rad).
                let slack_v = 4.0 * now[i].abs().max(last[i].abs()).max(1e-3) * f32::EPSILON / dt;
                prop_assert!(
                    v.abs() <= limits.pose_velocity[i] * (1.0 + 1e-4) + slack_v,
                    "axis {i}: {v} > {}",
                    limits.pose_velocity[i]
                );
                let a = (v - self.velocity[i]) / dt;
                let a_max = limits.pose_acceleration[i] * (1.0 + 1e-3) + slack_v / dt;
                if actuator_bound {
                    // Slowed by the actuators: no axis gains more speed than its acceleration limit allows.
                    prop_assert!(
                        (v.abs() - self.velocity[i].abs()) / dt <= a_max,
                        "axis {i}: accel {a} (bound)"
                    );
                } else {
                    prop_assert!(a.abs() <= a_max, "axis {i}: accel {a}");
                }
                self.velocity[i] = v;
            }
        }
        self.last = Some(now);
        Ok(())
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// A monotone 60 Hz stream on one axis: the commanded position is monotone and never passes the last setpoint.
    #[test]
    fn interpolation_never_overshoots(axis in 0usize..5, steps in prop::collection::vec(0.0f32..1.0, 5..40), sign in prop::bool::ANY) {
        let mut p = pipeline();
        let limits = p.config().limits;
        let dt = 1e-3;
        let per_setpoint_max = limits.pose_velocity[axis] * (1.0 / 60.0);
        let s = if sign { 1.0 } else { -1.0 };
        let mut target = 0.0f32;
        let mut trace = Trace::new();
        trace.record(&p, &limits, dt)?;
        let mut last_pos = 0.0f32;
        let mut t_us = 0u64;
        let mut accepted = 0;
        for (k, frac) in steps.iter().enumerate() {
            // Stay inside the spec range of the axis.
            let next = (target + s * frac * per_setpoint_max).clamp(-presets::TRAINER_MODEL_RANGES[axis] as f32 * 0.9, presets::TRAINER_MODEL_RANGES[axis] as f32 * 0.9);
            t_us += 16_667;
            if p.submit(&Setpoint { seq: k as u32 + 1, time_us: t_us, pose: pose_with(axis, next), aux: [None; 2], spare: [None; 2] }).is_ok() {
                target = next;
                accepted += 1;
            }
            for _ in 0..17 {
                let (_, event) = p.tick();
                prop_assert!(event.is_none(), "{event:?}");
                trace.record(&p, &limits, dt)?;
                let pos = p.pose().to_array()[axis] - HOME[axis];
                prop_assert!((pos - last_pos) * s >= -1e-6, "not monotone: {last_pos} -> {pos}");
                prop_assert!((pos - target) * s <= 1e-6, "overshoot: {pos} beyond {target}");
                last_pos = pos;
            }
        }
        prop_assert!(accepted > 0);
    }

    /// Pull the stream in the middle of a fast motion: braking within the acceleration limits, then at rest.
    #[test]
    fn stream_loss_ramps_to_rest(axis in 0usize..6, cut_ms in 100u32..900) {
        let mut p = pipeline();
        let limits = p.config().limits;
        let mut trace = Trace::new();
        trace.record(&p, &limits, 1e-3)?;
        let rate = limits.pose_velocity[axis] * 0.9;
        let mut events = Vec::new();
        for ms in 1..=3000u32 {
            if ms <= cut_ms && ms % 10 == 0 {
                let v = rate * ms as f32 * 1e-3;
                let v = if axis == 5 { v.rem_euclid(std::f32::consts::TAU) } else { v.min(presets::TRAINER_MODEL_RANGES[axis.min(4)] as f32 * 0.8) };
                p.submit(&Setpoint { seq: ms, time_us: u64::from(ms) * 1000, pose: pose_with(axis, v), aux: [None; 2], spare: [None; 2] }).unwrap();
            }
            let (_, e) = p.tick();
            trace.record(&p, &limits, 1e-3)?;
            if let Some(e) = e {
                events.push((ms, e));
            }
        }
        prop_assert_eq!(events.len(), 2, "{:?}", events);
        prop_assert_eq!(events[0].1, PipelineEvent::StreamLost);
        // The stream timeout is 100 ms after the last setpoint (sent every 10 ms).
        let last = cut_ms - cut_ms % 10;
        prop_assert!(events[0].0 >= last + 100 && events[0].0 <= last + 101, "{:?}", events);
        prop_assert_eq!(events[1].1, PipelineEvent::AtRest);
        prop_assert!(p.at_rest(), "not at rest: {:?} vs {:?}", p.pose(), p.target());
        // After a loss the stream stays closed until started again.
        let next = Setpoint { seq: 5000, time_us: 5_000_000, pose: p.pose(), aux: [None; 2], spare: [None; 2] };
        prop_assert_eq!(p.submit(&next), Err(RejectReason::NotStreaming));
        p.start();
        prop_assert_eq!(p.submit(&next), Ok(Accepted::Applied));
    }

    /// The yaw spins at 1.9 rad/s for many turns: carriages follow, steps stay exact.
    #[test]
    fn continuous_yaw_stream(turns in 1u32..4) {
        let mut p = pipeline();
        let limits = p.config().limits;
        let mut trace = Trace::new();
        trace.record(&p, &limits, 1e-3)?;
        let rate = 1.8f64;
        let total_ms = (f64::from(turns) * std::f64::consts::TAU / rate * 1000.0) as u32;
        for ms in 1..=total_ms {
            if ms % 10 == 0 {
                let yaw = (rate * f64::from(ms) * 1e-3).rem_euclid(std::f64::consts::TAU) as f32;
                p.submit(&Setpoint { seq: ms, time_us: u64::from(ms) * 1000, pose: pose_with(5, yaw), aux: [None; 2], spare: [None; 2] }).unwrap();
            }
            p.tick();
            trace.record(&p, &limits, 1e-3)?;
        }
        prop_assert_eq!(p.rejected().total(), 0);
        prop_assert!(p.actuators().turns[..4].iter().all(|t| t.unsigned_abs() >= turns - 1), "{:?}", p.actuators().turns);
    }
}

#[test]
fn rejected_setpoints_never_move() {
    let mut p = pipeline();
    let start = p.steps();
    let jump = RejectReason::GrossJump {
        outside: Some(Check::Reach),
    };
    let bad = [
        (Pose::new(f32::NAN, 0.0, 0.227, 0.0, 0.0, 0.0), RejectReason::NonFinite),
        // 27 cm up in one setpoint: a broken source, and out of reach as well (both are said).
        (Pose::new(0.0, 0.0, 0.5, 0.0, 0.0, 0.0), jump),
        (Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.0), RejectReason::Stale),
    ];
    for (k, (pose, reason)) in bad.iter().enumerate() {
        // The first two carry new sequence numbers; the last repeats the sequence number of the accepted one.
        let seq = if *reason == RejectReason::Stale {
            10
        } else {
            k as u32 + 1
        };
        if *reason == RejectReason::Stale {
            p.submit(&Setpoint {
                seq: 10,
                time_us: 10_000,
                pose: Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.0),
                aux: [None; 2],
                spare: [None; 2],
            })
            .unwrap();
        }
        assert_eq!(
            p.submit(&Setpoint {
                seq,
                time_us: 20_000 + k as u64,
                pose: *pose,
                aux: [None; 2],
                spare: [None; 2],
            }),
            Err(*reason)
        );
    }
    for _ in 0..100 {
        p.tick();
    }
    assert_eq!(p.steps(), start, "only the accepted home setpoint applied: no motion");
    assert_eq!(p.rejected().total(), 3);
    assert_eq!(p.rejected().gross_jump, 1);
}

#[test]
fn a_stream_out_of_the_workspace_is_limited_not_refused() {
    // Heave down 0.8 mm a setpoint at 50 Hz until far below the workspace: every setpoint is taken, those
    // outside are limited to the edge (with the margin), and the platform stays inside every check.
    let mut far = pipeline();
    let margins = far.config().margins;
    let mut z = HOME[2];
    let mut limited = 0;
    for k in 1..200u32 {
        z -= 0.0008;
        let answer = far.submit(&Setpoint {
            seq: k,
            time_us: u64::from(k) * 20_000,
            pose: pose_with(2, z - HOME[2]),
            aux: [None; 2],
            spare: [None; 2],
        });
        match answer {
            Ok(Accepted::Applied) => assert_eq!(limited, 0, "inside again after the edge"),
            Ok(Accepted::Limited(report)) => {
                limited += 1;
                assert!(report.translation > 0.0 && report.translation < 0.2, "{report:?}");
            }
            Err(e) => panic!("setpoint {k} refused: {e:?}"),
        }
        for _ in 0..20 {
            far.tick();
            let (_, report) = far.mechanism().inverse_checked(&far.pose()).unwrap();
            assert!(report.all_pass(), "{:?}", far.pose());
        }
    }
    assert!(limited > 50, "{limited}");
    assert_eq!(far.limited().count, limited);
    assert_eq!(far.applied(), 199);
    assert_eq!(far.held(), 0);
    assert_eq!(far.rejected().total(), 0);
    // The platform rests at the edge, inside the margin of the check that bound it.
    let (_, report) = far.mechanism().inverse_checked(&far.pose()).unwrap();
    assert_eq!(margins.first_short(&report), None, "{report:?}");
    let largest = far.limited().largest_translation;
    let asked = HOME[2] - 0.0008 * 199.0;
    assert!((largest - (far.target().z - asked)).abs() < 1e-5, "{largest}");
}

#[test]
fn steps_follow_the_actuators() {
    let mut p = pipeline();
    for k in 1..=50u32 {
        p.submit(&Setpoint {
            seq: k,
            time_us: u64::from(k) * 10_000,
            pose: pose_with(2, k as f32 * 4e-4),
            aux: [None; 2],
            spare: [None; 2],
        })
        .unwrap();
        for _ in 0..10 {
            p.tick();
        }
    }
    let q = p.actuators();
    let s = p.steps();
    for i in 0..6 {
        let per = if p.mechanism().axes()[i] == AxisKind::Ring {
            25_600.0 / std::f64::consts::TAU
        } else {
            1.6e6
        };
        let want = (q.total(i) * per).round() as i64;
        assert!((s[i] - want).abs() <= 1, "axis {i}: {} vs {want}", s[i]);
    }
}

/// Ticks on which something other than the pose limits shaped the motion: actuator limits, the workspace's edge.
fn bound(p: &Pipeline<RingPlatform<f32>>) -> u32 {
    p.limited().actuator_ticks + p.limited().edge_ticks + p.held()
}

/// One axis of a random source: a sum of two sines around home.
#[derive(Debug, Clone)]
struct Wave {
    amplitude: [f32; 2],
    omega: [f32; 2],
    phase: [f32; 2],
}

impl Wave {
    fn at(&self, t: f32) -> f32 {
        (0..2)
            .map(|k| self.amplitude[k] * (self.omega[k] * t + self.phase[k]).sin())
            .sum()
    }
}

/// A wave on pose axis `axis` that wanders up to 1.5 times beyond the spec range and peaks at up to 3 times the
/// velocity limit.
fn wave(axis: usize) -> impl Strategy<Value = Wave> {
    let range = presets::TRAINER_MODEL_RANGES[axis] as f32;
    let vmax = MotionLimits::TRAINER_MODEL.pose_velocity[axis];
    (
        prop::array::uniform2(0.1f32..0.75),
        prop::array::uniform2(0.1f32..1.5),
        prop::array::uniform2(0.0f32..6.3),
    )
        .prop_map(move |(share, speed, phase)| {
            let amplitude = share.map(|s| s * 1.5 * range * 2.0 / 2.0);
            // Peak speed of each sine: amplitude * omega = speed * vmax (two of them add up to 3 vmax).
            let omega = [0, 1].map(|k| speed[k] * vmax / amplitude[k]);
            Wave {
                amplitude,
                omega,
                phase,
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Streams as simulator software sends them: sums of sines wandering up to 1.5x beyond the spec ranges at up to
    /// 3x the speed limits, 30 Hz to 1 kHz, yaw turning, in both follow modes. Nothing is refused, every tick is
    /// inside all checks, the velocity and acceleration limits hold on every tick, the stream never dies, and
    /// the platform ends at the IK of the last (limited) target.
    #[test]
    fn every_stream_flows(
        waves in (wave(0), wave(1), wave(2), wave(3), wave(4)),
        yaw_rate in -1.8f32..1.8,
        rate_hz in 30.0f64..1000.0,
        direct in prop::bool::ANY,
    ) {
        let waves = [waves.0, waves.1, waves.2, waves.3, waves.4];
        let mut p = pipeline();
        let mut config = *p.config();
        config.follow = if direct { FollowMode::Direct } else { FollowMode::Interpolate };
        p.set_config(config);
        let limits = config.limits;
        let dt = 1e-3;
        let mut trace = Trace::new();
        trace.record(&p, &limits, dt)?;
        let seconds = 3.0;
        let mut seq = 0u32;
        let mut next_us = 0.0f64;
        let mut last = Pose::from_array(HOME);
        // The source eases in over its first second from home, as a stream after a lead-in does.
        let source = |t: f32| {
            let ease = (t / 1.0).min(1.0);
            let mut a = HOME;
            for i in 0..5 {
                a[i] += ease * ease * waves[i].at(t);
            }
            a[5] = yaw_rate * ease * t;
            Pose::from_array(a)
        };
        let total_ms = (seconds * 1000.0) as u32 + 5000;
        for ms in 1..=total_ms {
            let now_us = f64::from(ms) * 1000.0;
            while next_us <= now_us {
                let t = (next_us * 1e-6) as f32;
                // After the source ends it holds its last pose (as `ringpod stream` settles).
                if t <= seconds {
                    last = source(t);
                }
                seq += 1;
                let answer = p.submit(&Setpoint { seq, time_us: next_us as u64 + 1, pose: last, aux: [None; 2], spare: [None; 2] });
                prop_assert!(answer.is_ok(), "setpoint {seq} at {t} s: {answer:?}");
                next_us += 1e6 / rate_hz;
            }
            let bound_before = bound(&p);
            let (_, event) = p.tick();
            prop_assert!(event.is_none(), "{ms} ms: {event:?}");
            trace.record_bound(&p, &limits, dt, bound(&p) != bound_before)?;
            let (_, report) = p.mechanism().inverse_checked(&p.pose()).unwrap();
            prop_assert!(report.all_pass(), "{ms} ms: {:?} fails {:?}", p.pose(), report.first_failure());
        }
        prop_assert_eq!(p.rejected().total(), 0);
        // Held ticks (no part of any step stayed inside: the platform stopped where it was) happen only on the edge
        // of the workspace, in streams far beyond the spec ranges: counted, never fatal, never outside.
        if p.held() > 0 {
            prop_assert!(p.limited().edge_ticks > 0, "held {} ticks away from the edge", p.held());
        }
        prop_assert_eq!(p.applied(), seq);
        // The margins keep the trackers' path off the edge nearly always.
        let limited = p.limited();
        // A stream that never met the edge of the workspace ends at rest on its last target, to the step. One that
        // did may not reach it (see the pipeline's `along_edge`: it stays inside, within the limits, and keeps
        // streaming); counted, and then a stop must still bring it to rest inside.
        if limited.edge_ticks + p.held() > 0 {
            p.stop();
            for _ in 0..5000 {
                let bound_before = bound(&p);
                let (_, event) = p.tick();
                trace.record_bound(&p, &limits, dt, bound(&p) != bound_before)?;
                prop_assert!(p.mechanism().inverse_checked(&p.pose()).unwrap().1.all_pass());
                if event == Some(PipelineEvent::AtRest) {
                    return Ok(());
                }
            }
            prop_assert!(false, "no rest after a stop");
        }
        prop_assert!(p.at_rest(), "not at rest: {:?} vs {:?}", p.pose(), p.target());
        let (target, pose) = (p.target().to_array(), p.pose().to_array());
        for i in 0..6 {
            prop_assert!((target[i] - pose[i]).abs() < 2e-6, "axis {i}: {target:?} vs {pose:?}");
        }
        let mut q = *p.actuators();
        q.follow(&p.mechanism().inverse(&p.target()).unwrap(), &p.mechanism().axes());
        let want = p.converter().to_steps(&q);
        for i in 0..6 {
            prop_assert!((want[i] - p.steps()[i]).abs() <= 1, "axis {i}: {want:?} vs {:?}", p.steps());
        }
    }
}
