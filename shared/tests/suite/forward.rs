//! Forward kinematics at the edges: it returns the platform's pose or an error that says why, never another
//! solution of the same actuators as a success.

use ringpod_core::kinematics::{
    presets, start_from_home, Actuators, KinematicsError, Mechanism, NewtonOptions, Pose, RingPlatform,
    FROM_HOME_DISTANCE,
};

/// The options for a start from home (it knows only the yaw).
fn from_home() -> NewtonOptions<f64> {
    NewtonOptions {
        max_distance: FROM_HOME_DISTANCE,
        ..NewtonOptions::default()
    }
}

use crate::common::Lcg;

fn trainer() -> RingPlatform<f64> {
    RingPlatform::new(&presets::TRAINER_MODEL)
}

fn trainer_home() -> Pose<f64> {
    Pose::from_array(presets::Preset::TrainerModel.home())
}

/// The largest difference of two poses (yaw modulo a turn).
fn distance(a: &Pose<f64>, b: &Pose<f64>) -> f64 {
    let (a, b) = (a.to_array(), b.to_array());
    (0..6)
        .map(|i| {
            let d = a[i] - b[i];
            if i == 5 {
                (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
            } else {
                d
            }
            .abs()
        })
        .fold(0.0, f64::max)
}

/// Random poses inside every check, any yaw: translations and tilts up to `spread` times the given ranges.
fn inside_poses(
    m: &RingPlatform<f64>,
    home: Pose<f64>,
    ranges: [f64; 3],
    n: usize,
    seed: u64,
) -> Vec<(Pose<f64>, Actuators<f64>)> {
    let mut rng = Lcg(seed);
    let mut out = Vec::new();
    while out.len() < n {
        let p = Pose::new(
            rng.uniform() * ranges[0],
            rng.uniform() * ranges[0],
            home.z + rng.uniform() * ranges[1],
            rng.uniform() * ranges[2],
            rng.uniform() * ranges[2],
            rng.uniform() * std::f64::consts::PI,
        );
        if let Ok((q, report)) = m.inverse_checked(&p) {
            if report.all_pass() {
                out.push((p, q));
            }
        }
    }
    out
}

#[test]
fn without_a_guess_the_carriages_give_the_yaw_and_fk_finds_every_pose() {
    let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES;
    let m = trainer();
    let home = trainer_home();
    // Half again beyond the spec ranges: whatever of that is inside the checks.
    for (p, q) in inside_poses(&m, home, [1.5 * t, 1.5 * h, 1.5 * r], 3_000, 1) {
        let start = start_from_home(&m, &q, &home);
        let fk = m
            .forward(&q, &start, &from_home())
            .unwrap_or_else(|e| panic!("{p:?}: {e}"));
        assert!(distance(&fk.pose, &p) < 1e-9, "{p:?} -> {:?}", fk.pose);
    }
    let rotopod = RingPlatform::<f64>::new(&presets::ROTOPOD_CH4);
    let home = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
    for (p, q) in inside_poses(&rotopod, home, [0.15, 0.2, 0.2], 3_000, 2) {
        let start = start_from_home(&rotopod, &q, &home);
        let fk = rotopod
            .forward(&q, &start, &from_home())
            .unwrap_or_else(|e| panic!("{p:?}: {e}"));
        assert!(distance(&fk.pose, &p) < 1e-9, "{p:?} -> {:?}", fk.pose);
    }
}

#[test]
fn fk_returns_the_platforms_pose_or_an_error_never_another_solution() {
    // Guesses up to 30 mm and 0.3 rad off, poses anywhere inside the checks (near type-2 singularities too): the
    // answer is the pose the actuators came from, or an error.
    let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES;
    let m = trainer();
    let mut rng = Lcg(3);
    let (mut right, mut refused) = (0, 0);
    for (p, q) in inside_poses(&m, trainer_home(), [1.5 * t, 1.5 * h, 1.5 * r], 4_000, 4) {
        let a = p.to_array();
        let guess = Pose::from_array(core::array::from_fn(|i| {
            a[i] + rng.uniform() * if i < 3 { 0.03 } else { 0.3 }
        }));
        match m.forward(&q, &guess, &NewtonOptions::default()) {
            Ok(fk) => {
                assert!(distance(&fk.pose, &p) < 1e-9, "{p:?} from {guess:?} -> {:?}", fk.pose);
                right += 1;
            }
            Err(_) => refused += 1,
        }
    }
    assert!(right > 3_600, "{right} right, {refused} refused");
}

#[test]
fn two_hard_sets_of_actuators_get_a_right_answer_or_an_error() {
    let m = trainer();
    let options = NewtonOptions::default();
    // From the default guess (home, yaw 0) Newton reaches z = 0.114, alpha = -27.42 rad: not the platform's pose.
    let q = Actuators([-0.126419, 1.431662, 3.136982, -1.769915, 0.236447, 0.234549]);
    let home = trainer_home();
    if let Ok(fk) = m.forward(&q, &home, &options) {
        panic!("a pose {:?} from a guess two radians of yaw off", fk.pose);
    }
    let fk = m
        .forward(&q, &start_from_home(&m, &q, &home), &from_home())
        .expect("the carriages give the yaw");
    assert!((fk.pose.gamma - 2.217).abs() < 1e-3, "{:?}", fk.pose);
    let back = m.inverse(&fk.pose).expect("the pose has IK");
    assert!(back.0.iter().zip(q.0).all(|(a, b)| (a - b).abs() < 1e-5), "{back:?}");
    assert!(fk.pose.alpha.abs() <= std::f64::consts::PI && fk.pose.beta.abs() <= std::f64::consts::PI);
    // From this guess Newton can reach a pose 7 mm and 0.02 rad from the one the actuators came from: the answer
    // must be the right one or an error.
    let q = Actuators([-0.227380, 0.848999, 2.658173, -2.129843, 0.222059, 0.253623]);
    let guess = Pose::new(-0.0536, 0.0008, 0.1658, 0.4937, 0.0425, 1.8801);
    match m.forward(&q, &guess, &options) {
        Ok(fk) => {
            let back = m.inverse(&fk.pose).expect("the pose has IK");
            assert!(back.0.iter().zip(q.0).all(|(a, b)| (a - b).abs() < 1e-5), "{back:?}");
            let (_, report) = m.inverse_checked(&fk.pose).expect("IK");
            assert!(report.all_pass());
            assert!(m.jacobians(&fk.pose, &q).index_a() >= 0.01);
        }
        Err(e) => assert!(matches!(
            e,
            KinematicsError::NearSingularity | KinematicsError::FarFromGuess | KinematicsError::Outside(_)
        )),
    }
}

#[test]
fn a_guess_below_the_ring_or_off_by_turns_is_answered_rightly() {
    let m = trainer();
    let options = NewtonOptions::default();
    let pose = Pose::new(0.01, -0.005, 0.22, 0.05, -0.03, 0.4);
    let q = m.inverse(&pose).expect("IK");
    // The mirror image below the ring solves the same equations; it is not a pose the platform can take.
    let below = Pose { z: -pose.z, ..pose };
    let err = m.forward(&q, &below, &options).expect_err("the mirror pose is refused");
    assert!(
        matches!(
            err,
            KinematicsError::Outside(_) | KinematicsError::FarFromGuess | KinematicsError::OtherBranch
        ),
        "{err}"
    );
    // Roll and pitch come back within a half turn, yaw within a half turn of the guess's.
    let turned = Pose {
        alpha: pose.alpha + std::f64::consts::TAU,
        gamma: pose.gamma + 4.0 * std::f64::consts::TAU,
        ..pose
    };
    let fk = m.forward(&q, &turned, &options).expect("converges");
    assert!((fk.pose.alpha - pose.alpha).abs() < 1e-9, "{:?}", fk.pose);
    assert!((fk.pose.gamma - turned.gamma).abs() < 1e-9, "{:?}", fk.pose);
    // Near a type-2 singularity (the platform nearly in the ring plane) FK refuses, as `check` classifies.
    let flat = Pose::new(0.0, 0.0, 0.004, 0.0, 0.0, 0.0);
    let q = m.inverse(&flat).expect("IK");
    let relaxed = NewtonOptions {
        inside: false,
        ..options
    };
    assert_eq!(
        m.forward(&q, &flat, &relaxed).map(|_| ()),
        Err(KinematicsError::NearSingularity)
    );
}

/// Without the workspace acceptance FK gives what it gives with it, but for a solution outside a check, which it
/// returns: the other acceptance tests (distance, branches, singularity) are the same. Poses from home to beyond
/// the workspace, guesses from near to far (so that every error class comes up), `f32` and `f64`.
#[test]
fn fk_without_the_workspace_acceptance_differs_only_outside() {
    let m = trainer();
    let m32 = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let home = trainer_home().to_array();
    let mut rng = Lcg(0x5eed_f0f0);
    let mut tally = [0u32; 3];
    for k in 0..4_000 {
        let reach = if k % 2 == 0 { 0.1 } else { 0.25 };
        let pose = Pose::from_array(std::array::from_fn(|i| {
            home[i] + rng.uniform() * if i < 3 { reach * 0.6 } else { reach * 4.0 }
        }));
        let Ok(q) = m.inverse(&pose) else { continue };
        let off = if k % 3 == 0 { 0.2 } else { 0.01 };
        let p = pose.to_array();
        let guess = Pose::from_array(std::array::from_fn(|i| p[i] + rng.uniform() * off));
        let inside = NewtonOptions::default();
        let relaxed = NewtonOptions {
            inside: false,
            ..inside
        };
        let (checked, unchecked) = (m.forward(&q, &guess, &inside), m.forward(&q, &guess, &relaxed));
        match checked {
            Err(KinematicsError::Outside(_)) => {
                assert!(unchecked.is_ok(), "{pose:?}: {unchecked:?}");
                tally[0] += 1;
            }
            other => {
                tally[usize::from(other.is_ok()) + 1] += 1;
                assert_eq!(unchecked, other, "{pose:?}");
            }
        }
        let (q32, guess32) = (Actuators(q.0.map(|v| v as f32)), guess.cast::<f32>());
        let inside32 = NewtonOptions::<f32>::default();
        let relaxed32 = NewtonOptions {
            inside: false,
            ..inside32
        };
        match m32.forward(&q32, &guess32, &inside32) {
            Err(KinematicsError::Outside(_)) => assert!(m32.forward(&q32, &guess32, &relaxed32).is_ok()),
            other => assert_eq!(m32.forward(&q32, &guess32, &relaxed32), other, "{pose:?}"),
        }
    }
    // Every class came up: outside, other errors, inside.
    assert!(tally.iter().all(|&n| n > 20), "{tally:?}");
}
