//! Homing: the plan refuses orders that could bring carriages too close, and the sequence finds switches, backs
//! off them, and fails on a missing or stuck switch.

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::geometry::DEG;
use ringpod_core::safety::homing::{AxisHoming, HomingConfig, HomingError, HomingPlan, RingHoming};
use ringpod_core::safety::{HomingSequencer, HomingStep};

fn ring() -> RingHoming {
    // Four carriages 90 degrees apart, 12 degrees minimum spacing, 25,600 steps per turn.
    RingHoming {
        carriages: 4,
        home_angles: [0.0, 90.0 * DEG, 180.0 * DEG, 270.0 * DEG, 0.0, 0.0],
        min_spacing: 12.0 * DEG,
        steps_per_rad: 25_600.0 / std::f64::consts::TAU,
    }
}

fn axis(search_deg: f64) -> AxisHoming {
    let steps = (search_deg * DEG * 25_600.0 / std::f64::consts::TAU) as u32;
    AxisHoming {
        toward: 1,
        search_steps: steps,
        backoff_steps: steps / 10,
        fast_rate: 4_000,
        slow_rate: 500,
        home_position: 0,
    }
}

#[test]
fn plan_checks_spacing_and_order() {
    let ok = HomingConfig {
        axes: [axis(30.0); 6],
        order: [4, 5, 0, 2, 1, 3],
    };
    assert!(HomingPlan::new(ok, &ring()).is_ok());
    // 40 degrees of travel each: carriages 1 and 3 first (their neighbours may still be anywhere within their own
    // travel: 90 - 40 - 40 = 10 < 12 degrees).
    let wide = HomingConfig {
        axes: [axis(40.0); 6],
        order: [4, 5, 0, 2, 1, 3],
    };
    assert_eq!(HomingPlan::new(wide, &ring()), Err(HomingError::Spacing(0)));
    // With 37 degrees, non-neighbours first works (90 - 37 - 37 = 16) ...
    let nonadjacent = HomingConfig {
        axes: [axis(37.0); 6],
        order: [4, 5, 0, 2, 1, 3],
    };
    assert!(HomingPlan::new(nonadjacent, &ring()).is_ok());
    // ... and the home angles decide: squeeze carriage 2 to 50 degrees from carriage 1 and the same plan fails.
    let mut tight = ring();
    tight.home_angles[1] = 50.0 * DEG;
    assert_eq!(HomingPlan::new(nonadjacent, &tight), Err(HomingError::Spacing(0)));
    assert_eq!(
        HomingPlan::new(
            HomingConfig {
                order: [0, 0, 1, 2, 3, 4],
                ..ok
            },
            &ring()
        ),
        Err(HomingError::BadOrder)
    );
    assert_eq!(
        HomingPlan::new(
            HomingConfig {
                order: [0, 1, 2, 3, 4, 9],
                ..ok
            },
            &ring()
        ),
        Err(HomingError::BadOrder)
    );
    let mut zero = ok;
    zero.axes[3].toward = 0;
    assert_eq!(HomingPlan::new(zero, &ring()), Err(HomingError::BadAxis(3)));
    let mut slow = ok;
    slow.axes[2].slow_rate = 0;
    assert_eq!(HomingPlan::new(slow, &ring()), Err(HomingError::BadAxis(2)));
}

#[test]
fn the_model_configuration_is_safe() {
    assert!(ringpod_core::controller::Controller::new(ControllerConfig::trainer_model()).is_ok());
}

/// Drives a sequencer against one simulated axis whose switch is active where `switch(pos)` says.
fn run(mut s: HomingSequencer, start: [i64; 6], switch: impl Fn(usize, i64) -> bool) -> (Vec<HomingStep>, [i64; 6]) {
    let mut pos = start;
    let mut events = Vec::new();
    for _ in 0..200_000 {
        let bits = (0..6).filter(|&a| switch(a, pos[a])).fold(0u16, |b, a| b | 1 << a);
        let step = s.update(&pos, bits);
        match step {
            HomingStep::Move { axis, rate } => pos[usize::from(axis)] += i64::from(rate.signum()),
            HomingStep::Homed { axis, .. } => {
                events.push(step);
                pos[usize::from(axis)] = 0; // the controller redefines the origin at the switch
            }
            HomingStep::Done | HomingStep::Failed(_) => {
                events.push(step);
                break;
            }
        }
    }
    (events, pos)
}

#[test]
fn sequence_finds_backs_off_and_clears() {
    let cfg = HomingConfig {
        axes: [axis(30.0); 6],
        order: [4, 5, 0, 2, 1, 3],
    };
    let plan = HomingPlan::new(cfg, &ring()).unwrap();
    let start = [-500, -400, -300, -200, -100, -50];
    // A flag 60 steps wide at 0 for every axis.
    let (events, end) = run(HomingSequencer::new(plan, &start), start, |_, p| (0..60).contains(&p));
    let homed: Vec<u8> = events
        .iter()
        .filter_map(|e| {
            if let HomingStep::Homed { axis, .. } = e {
                Some(*axis)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(homed, [4, 5, 0, 2, 1, 3]);
    assert_eq!(events.last(), Some(&HomingStep::Done));
    // Every axis ends backed off its switch by the back-off distance (moving away from +1 means negative).
    for a in 0..6 {
        assert_eq!(end[a], -i64::from(cfg.axes[a].backoff_steps), "axis {a}");
    }
}

#[test]
fn missing_or_stuck_switch_fails() {
    let cfg = HomingConfig {
        axes: [axis(10.0); 6],
        order: [0, 1, 2, 3, 4, 5],
    };
    let plan = HomingPlan::new(cfg, &ring()).unwrap();
    let (events, _) = run(HomingSequencer::new(plan, &[0; 6]), [0; 6], |_, _| false);
    assert_eq!(events.last(), Some(&HomingStep::Failed(0)));
    let (events, _) = run(HomingSequencer::new(plan, &[0; 6]), [0; 6], |a, _| a == 0);
    assert_eq!(
        events.last(),
        Some(&HomingStep::Failed(0)),
        "a switch that never releases"
    );
}
