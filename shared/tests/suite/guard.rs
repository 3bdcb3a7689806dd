//! The slow-check guard against full evaluation: on random walks through the workspace, with the steps of a control
//! tick and larger, every check passes under the guard exactly when it passes evaluated, and a proved margin is
//! never above the evaluated one.

use ringpod_core::kinematics::{presets, Check, Mechanism, Pose, RingPlatform, SlowCheckGuard};
use ringpod_core::Real;

use crate::common::Lcg;

#[derive(Default, Debug)]
struct Tally {
    steps: u32,
    proved: u32,
    near_edge: u32,
}

/// A walk from `home` with steps of up to `step` metres and `turn` radians per axis; a pose that fails a check or
/// IK is compared, then the walk steps back. `tolerance`: how far a proved margin may exceed the evaluated one
/// (rounding of the evaluated margins themselves).
fn walk<T: Real>(
    m: &RingPlatform<T>,
    home: Pose<f64>,
    step: f64,
    turn: f64,
    seed: u64,
    n: u32,
    tolerance: f64,
) -> Tally {
    let mut rng = Lcg(seed);
    let mut guard = SlowCheckGuard::<T>::default();
    let mut at = home;
    let mut tally = Tally::default();
    // A drift that takes the walk to the edges, where it turns when a pose fails.
    let mut drift = [0.0f64; 6];
    for k in 0..n {
        if k % 500 == 0 {
            drift = core::array::from_fn(|_| rng.uniform() * 0.8);
        }
        let scale = if rng.uniform() > 0.98 { 40.0 } else { 1.0 };
        let d: [f64; 6] =
            core::array::from_fn(|i| (rng.uniform() * scale + drift[i]) * if i < 3 { step } else { turn });
        let a = at.to_array();
        let next = Pose::from_array(core::array::from_fn(|i| a[i] + d[i]));
        let p = next.cast::<T>();
        let full = m.inverse_checked(&p);
        let guarded = m.inverse_guarded(&p, &mut guard);
        match (full, guarded) {
            (Ok((q_full, full)), Ok((q_guarded, guarded))) => {
                assert_eq!(q_full, q_guarded);
                tally.steps += 1;
                let proved = full.singularity_index != guarded.singularity_index;
                tally.proved += u32::from(proved);
                for check in Check::ALL {
                    assert_eq!(full.passes(check), guarded.passes(check), "{check} at {next:?}");
                    let (f, g) = (
                        full.margin(check).map(Real::to_f64),
                        guarded.margin(check).map(Real::to_f64),
                    );
                    if let (Some(f), Some(g)) = (f, g) {
                        assert!(
                            g <= f + tolerance,
                            "{check}: proved {g} above evaluated {f} at {next:?}"
                        );
                    }
                }
                let slow = [Check::JointCones, Check::Singularity];
                if slow.iter().any(|c| full.margin(*c).is_some_and(|v| v.to_f64() < 0.02)) {
                    tally.near_edge += 1;
                }
                if full.all_pass() {
                    at = next;
                } else {
                    drift = core::array::from_fn(|_| rng.uniform() * 0.8);
                }
            }
            (Err(e), Err(g)) => assert_eq!(e, g),
            (full, guarded) => panic!("IK differs: {full:?} vs {guarded:?}"),
        }
    }
    tally
}

fn trainer_home() -> Pose<f64> {
    Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, 0.0)
}

#[test]
fn proved_checks_pass_exactly_when_evaluated_ones_do() {
    let trainer = presets::TRAINER_MODEL;
    // A tick at the model's top speeds (50 mm/s, about 1 rad/s) moves 50 um and 1 mrad.
    for (seed, step, turn) in [(1, 5e-5, 1e-3), (2, 2e-4, 4e-3), (3, 1e-3, 2e-2)] {
        let t64 = walk(
            &RingPlatform::<f64>::new(&trainer),
            trainer_home(),
            step,
            turn,
            seed,
            100_000,
            1e-9,
        );
        let t32 = walk(
            &RingPlatform::<f32>::new(&trainer),
            trainer_home(),
            step,
            turn,
            seed,
            100_000,
            2e-5,
        );
        for t in [&t64, &t32] {
            assert!(t.steps > 50_000, "{t:?}");
            assert!(
                t.near_edge > 100,
                "the walk reached the edges of the slow checks: {t:?}"
            );
        }
        if step <= 5e-5 {
            // Not vacuous: at tick-sized steps most checks are proved.
            assert!(t32.proved * 2 > t32.steps, "{t32:?}");
        }
    }
    // The elbow chains' bounds (forearm row through the elbow, tangent row through the joint).
    let elbow = presets::TRAINER_ELBOW;
    for (seed, step, turn) in [(5, 5e-5, 1e-3), (6, 1e-3, 2e-2)] {
        let t64 = walk(
            &RingPlatform::<f64>::new(&elbow),
            trainer_home(),
            step,
            turn,
            seed,
            50_000,
            1e-9,
        );
        let t32 = walk(
            &RingPlatform::<f32>::new(&elbow),
            trainer_home(),
            step,
            turn,
            seed,
            50_000,
            2e-5,
        );
        for t in [&t64, &t32] {
            assert!(t.steps > 25_000 && t.near_edge > 100, "{t:?}");
        }
        if step <= 5e-5 {
            assert!(t32.proved * 2 > t32.steps, "{t32:?}");
        }
    }
    let rotopod = RingPlatform::<f32>::new(&presets::ROTOPOD_CH4);
    let t = walk(
        &rotopod,
        Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0),
        1e-4,
        1e-3,
        4,
        100_000,
        2e-5,
    );
    assert!(t.steps > 80_000 && t.proved * 2 > t.steps, "{t:?}");
}
