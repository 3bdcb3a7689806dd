//! The rotopod and the trainer in paper 002's terms against the ring platform's own inverse dynamics (Newton-Euler
//! of the payload, the drives from the wrench matrix's statics): along the same smooth motion, the platform's frame,
//! and the drive torques and forces within 1e-6 of the largest.

use nalgebra::Matrix3;

use super::super::mechanism::MAX_VARIABLES;
use super::super::ring::ring_model;
use crate::kinematics::presets::{ROTOPOD_CH4, TRAINER_CH5};
use crate::kinematics::{Mechanism as _, MotionState, Payload, Pose, RingGeometry, RingPlatform};

const MASS: f64 = 3.5;

fn inertia() -> Matrix3<f64> {
    Matrix3::new(0.30, -0.02, 0.01, -0.02, 0.42, 0.03, 0.01, 0.03, 0.55)
}

/// A smooth motion about `home`: each coordinate `scale a_k sin(w_k t + p_k)`, with its exact rates and accelerations.
fn motion(home: &[f64; 6], scale: f64, t: f64) -> MotionState<f64> {
    let a = [0.04, -0.03, 0.05, 0.06, -0.05, 0.08].map(|v| v * scale);
    let w = [2.0, 3.1, 1.7, 2.6, 1.3, 2.2];
    let p = [0.0, 0.4, 1.1, 0.3, 0.9, 0.2];
    let at = |k: usize| home[k] + a[k] * (w[k] * t + p[k]).sin();
    MotionState {
        pose: Pose::new(at(0), at(1), at(2), at(3), at(4), at(5)),
        rates: core::array::from_fn(|k| a[k] * w[k] * (w[k] * t + p[k]).cos()),
        accelerations: core::array::from_fn(|k| -a[k] * w[k] * w[k] * (w[k] * t + p[k]).sin()),
    }
}

/// Runs the motion on `geometry`; returns the worst drive error relative to the largest drive seen, and that.
fn compare(geometry: &RingGeometry, home: [f64; 6], scale: f64) -> Result<(f64, f64), String> {
    let ring = RingPlatform::<f64>::new(geometry);
    let s0 = motion(&home, scale, 0.0);
    let rm = ring_model(geometry, &s0.pose, MASS, &inertia()).map_err(|e| format!("{e:?}"))?;
    let payload = Payload {
        mass: MASS,
        inertia: inertia(),
    };
    let mut guess: [f64; MAX_VARIABLES] = rm.q;
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for step in 0..=40 {
        let s = motion(&home, scale, step as f64 * 0.05);
        let q = ring.inverse(&s.pose).map_err(|e| format!("{e:?}"))?;
        let expected = ring
            .drive_demand(&s, &q, &payload)
            .map_err(|e| format!("{e:?}"))?
            .drives;
        let closed = rm.model.closed(&guess, &q.0).map_err(|e| format!("{e:?}"))?;
        let f = rm.model.mechanism.frames(&closed).map_err(|e| format!("{e:?}"))?;
        // The platform's frame closes on the pose.
        let platform = f.links[rm.platform] * rm.platform_offset;
        let pose = ring_frame(&s.pose);
        assert!((platform - pose).amax() < 1e-10, "step {step}");
        let (ud, udd) = rm.drive_motion(&f, &ring, &s).map_err(|e| format!("{e:?}"))?;
        let solved = rm
            .model
            .solve_point(&closed, &q.0, &ud, &udd)
            .map_err(|e| format!("{e:?}"))?;
        for (got, want) in solved.forces.iter().zip(&expected) {
            worst = worst.max((got - want).abs());
            largest = largest.max(want.abs());
        }
        guess = closed;
    }
    Ok((worst / largest, largest))
}

fn ring_frame(pose: &Pose<f64>) -> nalgebra::Matrix4<f64> {
    super::super::ring::frame_of(&pose.position(), &pose.rotation())
}

#[test]
fn rotopod_drive_torques_equal_the_ring_platforms_inverse_dynamics() -> Result<(), String> {
    let (relative, largest) = compare(&ROTOPOD_CH4, [0.0, 0.0, 0.7, 0.0, 0.0, 0.0], 1.0)?;
    assert!(largest > 1.0, "{largest}");
    assert!(relative < 1e-6, "{relative:e}");
    Ok(())
}

#[test]
fn trainer_drive_torques_and_forces_equal_the_ring_platforms_inverse_dynamics() -> Result<(), String> {
    let (relative, largest) = compare(&TRAINER_CH5, [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], 0.25)?;
    assert!(largest > 1.0, "{largest}");
    assert!(relative < 1e-6, "{relative:e}");
    Ok(())
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]
    /// At any pose near the rotopod's home, with any rates and accelerations, the matrix method's drive torques are
    /// the ring platform's.
    #[test]
    fn any_instant_near_home_gives_the_ring_platforms_drive_torques(
        offset in proptest::array::uniform6(-0.05f64..0.05),
        rates in proptest::array::uniform6(-0.5f64..0.5),
        accelerations in proptest::array::uniform6(-3.0f64..3.0),
    ) {
        let fail = |e: String| proptest::test_runner::TestCaseError::fail(e);
        let home = [0.0, 0.0, 0.7, 0.0, 0.0, 0.0];
        let ring = RingPlatform::<f64>::new(&ROTOPOD_CH4);
        let at = |p: [f64; 6]| Pose::new(p[0], p[1], p[2], p[3], p[4], p[5]);
        let rm = ring_model(&ROTOPOD_CH4, &at(home), MASS, &inertia()).map_err(|e| fail(format!("{e:?}")))?;
        let s = MotionState { pose: at(core::array::from_fn(|k| home[k] + offset[k])), rates, accelerations };
        let payload = Payload { mass: MASS, inertia: inertia() };
        let q = ring.inverse(&s.pose).map_err(|e| fail(format!("{e:?}")))?;
        let expected = ring.drive_demand(&s, &q, &payload).map_err(|e| fail(format!("{e:?}")))?.drives;
        let closed = rm.model.closed(&rm.q, &q.0).map_err(|e| fail(format!("{e:?}")))?;
        let f = rm.model.mechanism.frames(&closed).map_err(|e| fail(format!("{e:?}")))?;
        let (ud, udd) = rm.drive_motion(&f, &ring, &s).map_err(|e| fail(format!("{e:?}")))?;
        let solved = rm.model.solve_point(&closed, &q.0, &ud, &udd).map_err(|e| fail(format!("{e:?}")))?;
        let largest = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (got, want) in solved.forces.iter().zip(&expected) {
            proptest::prop_assert!((got - want).abs() <= 1e-9 * largest, "{:?} vs {:?}", solved.forces, expected);
        }
    }
}
