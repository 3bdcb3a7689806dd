use super::*;
use crate::rig::drives;
use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL, TRAINER_MODEL_HOME_Z};

#[test]
fn a_wrapped_yaw_is_followed_the_short_way() {
    let mut yaw = [6.0, 6.2, 0.1, 0.3, 6.2];
    unwrap(&mut yaw);
    let tau = std::f64::consts::TAU;
    let want = [6.0, 6.2, 0.1 + tau, 0.3 + tau, 6.2];
    assert!(yaw.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12), "{yaw:?}");
}

#[test]
fn three_point_derivatives_are_exact_for_a_parabola_on_uneven_steps() {
    let t = [0.0, 0.1, 0.25, 0.3, 0.5];
    let v: Vec<f64> = t.iter().map(|t| 3.0 * t * t - t + 2.0).collect();
    for i in 1..4 {
        let (rate, accel) = derivatives(&t, &v, i);
        assert!((rate - (6.0 * t[i] - 1.0)).abs() < 1e-12, "{i}");
        assert!((accel - 6.0).abs() < 1e-9, "{i}");
    }
}

/// The spec table's motions at its top speed, 0.05 m/s (a heave of +-40 mm, a surge of +-50 mm), and a turn at
/// the 1.9 rad/s of fig. 5.11, sampled every 5 ms over 6 s.
fn spec_motions() -> Vec<Vec<(usize, f64, Pose<f64>)>> {
    let sample = |f: &dyn Fn(f64) -> Pose<f64>| -> Vec<(usize, f64, Pose<f64>)> {
        (0..=1200)
            .map(|i| (i + 1, i as f64 * 0.005, f(i as f64 * 0.005)))
            .collect()
    };
    let z0 = TRAINER_MODEL_HOME_Z;
    vec![
        sample(&|t| Pose::new(0.0, 0.0, z0 + 0.04 * (1.25 * t).sin(), 0.0, 0.0, 0.0)),
        sample(&|t| Pose::new(0.05 * t.sin(), 0.0, z0, 0.0, 0.0, 0.0)),
        sample(&|t| Pose::new(0.0, 0.0, z0, 0.0, 0.0, 1.9 * t)),
    ]
}

/// The spec table's "power consumed (maximum)" (ch. 5.2), W.
const SPEC_POWER: f64 = 40.0;

/// The mechanical power the drives deliver at the axes, summed over the six, at its peak along a profile (W).
fn peak_power(p: &Profile) -> f64 {
    p.demand
        .iter()
        .zip(&p.speed)
        .map(|(d, v)| d.iter().zip(v).map(|(d, v)| (d * v).abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// The spec table's 40 W against the drive-demand analysis: the heaviest payload the model's six FL20s carry
/// through the spec's motions at 0.05 m/s asks a peak of about 0.5 W of mechanical power at the axes, and the
/// drives could give at most 4.86 W on their curves (six motors at the best torque x speed of the assumed
/// pull-out curve, 1.13 W each, times the transmissions' efficiencies): the 40 W is the electrical input (the
/// windings held at their current, the drivers and the logic: source 5.3.2 feeds the power stages from two
/// 15.6 W supplies), not what reaches the platform.
#[test]
fn the_spec_tables_40_w_is_far_above_what_the_drives_deliver() {
    let ring = RingPlatform::<f64>::new(&TRAINER_MODEL);
    let drives = drives::check(&drives::of_preset(Preset::TrainerModel), &ring.axes()).unwrap();
    let motions = spec_motions();
    let payload = |mass: f64| Payload {
        mass,
        inertia: Matrix3::from_diagonal_element(mass * 0.05 * 0.05),
    };
    let keeps_up = |mass: f64| {
        motions.iter().all(|rows| {
            let p = profile_of(&ring, rows, &payload(mass)).unwrap();
            assert!(p.errors.is_empty());
            (0..6).all(|k| drives[k].as_ref().is_none_or(|d| margin(d, &p, k).rows_over == 0))
        })
    };
    // The heaviest payload kept up with, to 10 g.
    let (mut lo, mut hi) = (0.0, 10.0);
    assert!(keeps_up(lo) && !keeps_up(hi));
    while hi - lo > 0.01 {
        let mid = 0.5 * (lo + hi);
        if keeps_up(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let power = motions
        .iter()
        .map(|rows| peak_power(&profile_of(&ring, rows, &payload(lo)).unwrap()))
        .fold(0.0, f64::max);
    // The most a drive gives at its axis: the best torque x speed on its curve, times its efficiency.
    let ceiling: f64 = drives
        .iter()
        .flatten()
        .map(|d| {
            d.pull_out
                .iter()
                .map(|&(rpm, torque)| torque * rpm * std::f64::consts::TAU / 60.0 * d.efficiency)
                .fold(0.0, f64::max)
        })
        .sum();
    // By hand: the curve's best torque x speed is 0.009 N m x 1200 rpm = 0.006 x 1800 = 1.131 W; four ring drives
    // at 90 % and two screws at 35 %.
    let best = 0.009 * 1200.0 * std::f64::consts::TAU / 60.0;
    assert!((ceiling - best * (4.0 * 0.9 + 2.0 * 0.35)).abs() < 1e-9, "{ceiling}");
    assert!((ceiling - 4.863).abs() < 1e-3, "{ceiling}");
    // The FL20s on their gears carry a payload of 60 to 80 g through these motions (the statics alone take most of
    // their torque), and it asks about half a watt at the peak.
    assert!((0.06..0.08).contains(&lo), "{lo} kg");
    assert!(power > 0.3 && power < 1.0, "{power} W");
    assert!(ceiling < SPEC_POWER / 8.0);
}
