//! The rotopod and the trainer in paper 002's terms against the ring platform's own inverse dynamics (Newton-Euler
//! of the payload, the drives from the wrench matrix's statics): along the same smooth motion, the platform's frame,
//! and the drive torques and forces within 1e-6 of the largest.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::super::mechanism::MAX_VARIABLES;
use super::super::ring::{ring_model, RingModel};
use super::super::*;
use crate::kinematics::presets::{ROTOPOD_CH4, TRAINER_CH5};
use crate::kinematics::{Mechanism as _, MotionState, Payload, Pose, RingGeometry, RingPlatform};
use crate::screws::twist_of;

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

/// The drives' rates and accelerations that give the platform the motion's twist and its rate: `K u' = xi`,
/// `K u'' = xi' - (the platform twist's rate at u'' = 0)`, `K` the platform twist per unit drive rate.
fn drive_motion(rm: &RingModel, f: &Frames, ring: &RingPlatform<f64>, s: &MotionState<f64>) -> ([f64; 6], [f64; 6]) {
    let m = &rm.model.mechanism;
    let sens = rm.model.sensitivities(f).unwrap();
    let k = Matrix6::from_fn(|r, c| twist_of(&m.link_twist(f, &sens[c], rm.platform))[r]);
    let body = ring.body_motion(s);
    let (p, pd, pdd) = (
        s.pose.position(),
        Vector3::new(s.rates[0], s.rates[1], s.rates[2]),
        Vector3::new(s.accelerations[0], s.accelerations[1], s.accelerations[2]),
    );
    let join = |a: Vector3<f64>, b: Vector3<f64>| Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z);
    // The twist about the base origin: the velocity of the platform point at the origin is p' - w x p.
    let xi = join(body.omega, pd - body.omega.cross(&p));
    let xi_rate = join(body.omega_dot, pdd - body.omega_dot.cross(&p) - body.omega.cross(&pd));
    let lu = k.lu();
    let ud = lu.solve(&xi).unwrap();
    let qd = m.rates(f, ud.as_slice()).unwrap();
    let qdd = m.accelerations(f, &qd, &[0.0; 6]).unwrap();
    let bias = twist_of(&m.link_twist_rate(f, &qd, &qdd, rm.platform));
    let udd = lu.solve(&(xi_rate - bias)).unwrap();
    (core::array::from_fn(|i| ud[i]), core::array::from_fn(|i| udd[i]))
}

/// Runs the motion on `geometry`; returns the worst drive error relative to the largest drive seen, and that.
fn compare(geometry: &RingGeometry, home: [f64; 6], scale: f64) -> (f64, f64) {
    let ring = RingPlatform::<f64>::new(geometry);
    let s0 = motion(&home, scale, 0.0);
    let rm = ring_model(geometry, &s0.pose, MASS, &inertia()).unwrap();
    let payload = Payload {
        mass: MASS,
        inertia: inertia(),
    };
    let mut guess: [f64; MAX_VARIABLES] = rm.q;
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for step in 0..=40 {
        let s = motion(&home, scale, step as f64 * 0.05);
        let q = ring.inverse(&s.pose).unwrap();
        let expected = ring.drive_demand(&s, &q, &payload).unwrap().drives;
        let closed = rm.model.closed(&guess, &q.0).unwrap();
        let f = rm.model.mechanism.frames(&closed).unwrap();
        // The platform's frame closes on the pose.
        let platform = f.links[rm.platform] * rm.platform_offset;
        let pose = ring_frame(&s.pose);
        assert!((platform - pose).amax() < 1e-10, "step {step}");
        let (ud, udd) = drive_motion(&rm, &f, &ring, &s);
        let solved = rm.model.solve_point(&closed, &q.0, &ud, &udd).unwrap();
        for (got, want) in solved.forces.iter().zip(&expected) {
            worst = worst.max((got - want).abs());
            largest = largest.max(want.abs());
        }
        guess = closed;
    }
    (worst / largest, largest)
}

fn ring_frame(pose: &Pose<f64>) -> nalgebra::Matrix4<f64> {
    super::super::ring::frame_of(&pose.position(), &pose.rotation())
}

#[test]
fn rotopod_drive_torques_equal_the_ring_platforms_inverse_dynamics() {
    let (relative, largest) = compare(&ROTOPOD_CH4, [0.0, 0.0, 0.7, 0.0, 0.0, 0.0], 1.0);
    assert!(largest > 1.0, "{largest}");
    assert!(relative < 1e-6, "{relative:e}");
}

#[test]
fn trainer_drive_torques_and_forces_equal_the_ring_platforms_inverse_dynamics() {
    let (relative, largest) = compare(&TRAINER_CH5, [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], 0.25);
    assert!(largest > 1.0, "{largest}");
    assert!(relative < 1e-6, "{relative:e}");
}
