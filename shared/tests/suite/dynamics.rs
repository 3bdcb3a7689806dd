//! Inverse dynamics of the ring platforms, checked by energy: over random smooth motions the drives' power equals the
//! rate of change of the payload's kinetic and potential energy; at rest the demand is the statics.

use crate::common::Lcg;
use nalgebra::Matrix3;
use ringpod_core::kinematics::{presets, AxisKind, Mechanism, MotionState, Payload, Pose, RingPlatform};

/// A smooth motion: every axis a sine around the trainer model's home, amplitudes within its spec ranges.
struct Motion {
    amplitude: [f64; 6],
    frequency: [f64; 6],
    phase: [f64; 6],
}

impl Motion {
    fn random(rng: &mut Lcg) -> Self {
        let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES;
        let scale = [t, t, h, r, r, 1.5];
        Self {
            amplitude: core::array::from_fn(|i| scale[i] * 0.8 * rng.uniform()),
            frequency: core::array::from_fn(|_| 0.5 + 2.0 * (rng.uniform() + 1.0)),
            phase: core::array::from_fn(|_| 3.0 * rng.uniform()),
        }
    }

    fn at(&self, t: f64) -> MotionState<f64> {
        let home = [0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, 0.0];
        let w: [f64; 6] = core::array::from_fn(|i| std::f64::consts::TAU * self.frequency[i]);
        let arg = |i: usize| w[i] * t + self.phase[i];
        MotionState {
            pose: Pose::from_array(core::array::from_fn(|i| home[i] + self.amplitude[i] * arg(i).sin())),
            rates: core::array::from_fn(|i| self.amplitude[i] * w[i] * arg(i).cos()),
            accelerations: core::array::from_fn(|i| -self.amplitude[i] * w[i] * w[i] * arg(i).sin()),
        }
    }
}

fn payload(rng: &mut Lcg) -> Payload<f64> {
    let mass = 1.0 + 2.0 * (rng.uniform() + 1.0);
    let d = |rng: &mut Lcg| 0.01 + 0.01 * (rng.uniform() + 1.0);
    Payload {
        mass,
        inertia: Matrix3::from_diagonal(&nalgebra::Vector3::new(d(rng), d(rng), 2.0 * d(rng))),
    }
}

#[test]
fn the_drives_power_is_the_rate_of_change_of_energy() {
    power_is_the_rate_of_change_of_energy(&presets::TRAINER_MODEL);
}

/// The elbow chains' shoulder torques by the same energy balance (and their carriages', which the tangent force
/// and the forearm's line share).
#[test]
fn the_elbow_trainers_drives_power_is_the_rate_of_change_of_energy() {
    power_is_the_rate_of_change_of_energy(&presets::TRAINER_ELBOW);
}

fn power_is_the_rate_of_change_of_energy(geometry: &ringpod_core::kinematics::RingGeometry) {
    let m = RingPlatform::<f64>::new(geometry);
    let mut rng = Lcg(21);
    let mut checked = 0;
    for _ in 0..300 {
        let motion = Motion::random(&mut rng);
        let load = payload(&mut rng);
        let t = 3.0 * (rng.uniform() + 1.0);
        let s = motion.at(t);
        let Ok((q, report)) = m.inverse_checked(&s.pose) else {
            continue;
        };
        if !(report.all_pass() && report.singularity_index > 0.05) {
            continue;
        }
        let demand = m.drive_demand(&s, &q, &load).unwrap();
        // Actuator rates by central differences of IK along the motion, energy rate likewise.
        let h = 1e-6;
        let (q1, q0) = (
            m.inverse(&motion.at(t + h).pose).unwrap(),
            m.inverse(&motion.at(t - h).pose).unwrap(),
        );
        let axes = m.axes();
        let (mut power, mut magnitude) = (0.0, 0.0);
        for (i, axis) in axes.iter().enumerate() {
            let mut d = q1.0[i] - q0.0[i];
            if *axis == AxisKind::Ring {
                d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            }
            let rate = d / (2.0 * h);
            power += demand.drives[i] * rate;
            magnitude += (demand.drives[i] * rate).abs();
        }
        let energy_rate =
            (m.payload_energy(&motion.at(t + h), &load) - m.payload_energy(&motion.at(t - h), &load)) / (2.0 * h);
        assert!(
            (power - energy_rate).abs() <= 1e-5 * magnitude.max(1e-3),
            "power {power} vs dE/dt {energy_rate} (terms {magnitude})"
        );
        checked += 1;
    }
    assert!(checked > 100, "only {checked} motions inside the checks");
}

#[test]
fn at_rest_the_demand_is_the_statics_and_inertia_costs_torque() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let load = Payload {
        mass: 2.0,
        inertia: Matrix3::from_diagonal(&nalgebra::Vector3::new(0.02, 0.02, 0.04)),
    };
    let pose = Pose::new(0.01, -0.02, 0.23, 0.1, -0.05, 0.7);
    let q = m.inverse(&pose).unwrap();
    let rest = MotionState {
        pose,
        rates: [0.0; 6],
        accelerations: [0.0; 6],
    };
    let dynamic = m.drive_demand(&rest, &q, &load).unwrap();
    let statics = m.loads(&pose, &q, &m.gravity_wrench(&pose, load.mass)).unwrap();
    for (a, b) in dynamic.drives.iter().zip(statics.drives) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
    }
    // Yawing up at 20 rad/s^2 costs carriage torque beyond the statics; a pure yaw rate at the centre of mass of a
    // body symmetric about z costs none.
    let spin_up = MotionState {
        accelerations: [0.0, 0.0, 0.0, 0.0, 0.0, 20.0],
        ..rest
    };
    let d = m.drive_demand(&spin_up, &q, &load).unwrap();
    assert!(
        (0..4).any(|i| (d.drives[i] - statics.drives[i]).abs() > 1e-3),
        "{:?}",
        d.drives
    );
    let level = MotionState {
        pose: Pose::new(0.0, 0.0, 0.23, 0.0, 0.0, 0.7),
        rates: [0.0, 0.0, 0.0, 0.0, 0.0, 1.9],
        accelerations: [0.0; 6],
    };
    let ql = m.inverse(&level.pose).unwrap();
    let centred = Payload {
        mass: 2.0,
        inertia: load.inertia,
    };
    let spinning = m.drive_demand(&level, &ql, &centred).unwrap();
    let still = m
        .drive_demand(
            &MotionState {
                rates: [0.0; 6],
                ..level
            },
            &ql,
            &centred,
        )
        .unwrap();
    for (a, b) in spinning.drives.iter().zip(still.drives) {
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "{a} vs {b}");
    }
    // Non-finite motion is refused.
    let bad = MotionState {
        rates: [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0],
        ..rest
    };
    assert!(m.drive_demand(&bad, &q, &load).is_err());
}
