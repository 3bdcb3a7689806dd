//! Inverse dynamics of a ring platform: the drive torques and forces that move a rigid payload along a motion.
//!
//! The moving mass is the platform with its payload, a rigid body with its centre of mass at the geometry's
//! `centre_of_mass` and an inertia about it in the platform frame; the chains (rods, carriages, actuators) are taken
//! as massless. Newton-Euler gives the wrench the chains must apply: `F = m (a_c - g)` at the centre of mass and
//! `M_c = I w' + w x I w`, moved to the ring centre as `M_o = M_c + c x F`. The drives follow from the statics
//! (`loads`) with the opposite of that wrench as the external one, so at rest the dynamics is the statics, and the
//! drives' power equals the rate of change of the payload's kinetic and potential energy (tested).
//!
//! The angular velocity comes from the Euler-angle rates of `R = Rz(gamma) Ry(beta) Rx(alpha)`, not the rates
//! themselves: `w = gamma' z + beta' Rz(gamma) y + alpha' Rz(gamma) Ry(beta) x`.

use nalgebra::{Matrix3, Vector3, Vector6};

use super::{ActuatorLoads, RingPlatform};
use crate::kinematics::{Actuators, KinematicsError, Pose};
use crate::Real;

/// Standard gravity (m/s^2), as the statics use.
const G: f64 = 9.80665;

/// The moving rigid body: platform and payload.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Payload<T: Real> {
    /// Mass (kg), at the geometry's centre of mass.
    pub mass: T,
    /// Inertia about the centre of mass in the platform frame (kg m^2).
    pub inertia: Matrix3<T>,
}

/// A motion at one instant: the pose, and the first and second time derivatives of its six coordinates (the
/// angles' derivatives are Euler-angle rates, rad/s and rad/s^2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionState<T: Real> {
    /// The pose.
    pub pose: Pose<T>,
    /// `d/dt` of `[x, y, z, alpha, beta, gamma]`.
    pub rates: [T; 6],
    /// `d2/dt2` of `[x, y, z, alpha, beta, gamma]`.
    pub accelerations: [T; 6],
}

/// Velocities of the moving body at one instant, in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMotion<T: Real> {
    /// Angular velocity (rad/s).
    pub omega: Vector3<T>,
    /// Angular acceleration (rad/s^2).
    pub omega_dot: Vector3<T>,
    /// Position of the centre of mass (m).
    pub centre: Vector3<T>,
    /// Velocity of the centre of mass (m/s).
    pub velocity: Vector3<T>,
    /// Acceleration of the centre of mass (m/s^2).
    pub acceleration: Vector3<T>,
}

impl<T: Real> RingPlatform<T> {
    /// The angular and centre-of-mass motion of the platform for a motion state.
    pub fn body_motion(&self, s: &MotionState<T>) -> BodyMotion<T> {
        let p = &s.pose;
        let [_, _, _, da, db, dg] = s.rates;
        let [_, _, _, dda, ddb, ddg] = s.accelerations;
        let (sb, cb) = p.beta.sin_cos_();
        let (sg, cg) = p.gamma.sin_cos_();
        let omega = Vector3::new(da * cg * cb - db * sg, da * sg * cb + db * cg, dg - da * sb);
        let omega_dot = Vector3::new(
            dda * cg * cb - da * (sg * cb * dg + cg * sb * db) - ddb * sg - db * cg * dg,
            dda * sg * cb + da * (cg * cb * dg - sg * sb * db) + ddb * cg - db * sg * dg,
            ddg - dda * sb - da * cb * db,
        );
        let r = p.rotation() * self.com;
        let v = |a: &[T; 6]| Vector3::new(a[0], a[1], a[2]);
        BodyMotion {
            omega,
            omega_dot,
            centre: p.position() + r,
            velocity: v(&s.rates) + omega.cross(&r),
            acceleration: v(&s.accelerations) + omega_dot.cross(&r) + omega.cross(&omega.cross(&r)),
        }
    }

    /// The external wrench `[F; M about the ring centre]` equivalent to gravity and the payload's inertia along the
    /// motion: what the chains must balance. At rest it is [`RingPlatform::gravity_wrench`].
    pub fn dynamic_wrench(&self, s: &MotionState<T>, payload: &Payload<T>) -> Vector6<T> {
        let b = self.body_motion(s);
        let gravity = Vector3::new(T::zero(), T::zero(), -T::of(G));
        let force = (b.acceleration - gravity) * payload.mass;
        let rotation = s.pose.rotation();
        let inertia = rotation * payload.inertia * rotation.transpose();
        let moment = inertia * b.omega_dot + b.omega.cross(&(inertia * b.omega)) + b.centre.cross(&force);
        -Vector6::new(force.x, force.y, force.z, moment.x, moment.y, moment.z)
    }

    /// Drive torques (carriages, N m) and forces (linear actuators, N) that move the payload along the motion, in
    /// the sign convention of [`RingPlatform::loads`]: the drives' power `sum(drive_i * q_i')` is the rate of change
    /// of the payload's kinetic and potential energy.
    pub fn drive_demand(
        &self,
        s: &MotionState<T>,
        q: &Actuators<T>,
        payload: &Payload<T>,
    ) -> Result<ActuatorLoads<T>, KinematicsError> {
        let finite = s.rates.iter().chain(&s.accelerations).all(|v| v.finite())
            && payload.mass.finite()
            && payload.inertia.iter().all(|v| v.finite());
        if !finite {
            return Err(KinematicsError::NonFinite);
        }
        self.loads(&s.pose, q, &self.dynamic_wrench(s, payload))
    }

    /// Kinetic plus potential energy of the payload (J; potential from the ring plane).
    pub fn payload_energy(&self, s: &MotionState<T>, payload: &Payload<T>) -> T {
        let b = self.body_motion(s);
        let rotation = s.pose.rotation();
        let inertia = rotation * payload.inertia * rotation.transpose();
        let half = T::of(0.5);
        half * payload.mass * b.velocity.dot(&b.velocity)
            + half * b.omega.dot(&(inertia * b.omega))
            + payload.mass * T::of(G) * b.centre.z
    }
}
