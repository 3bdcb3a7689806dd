//! Statics of a ring platform (KINEMATICS.md 5): the wrench matrix of the transmitted lines, the gravity wrench of
//! the payload, and the loads on the drives that hold it.

use nalgebra::{Matrix6, Vector3, Vector6};

use super::checks::Configuration;
use super::RingPlatform;
use crate::kinematics::velocity::Lu6;
use crate::kinematics::{Actuators, KinematicsError, Pose};
use crate::Real;

/// Static loads on the drives for an external wrench.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorLoads<T> {
    /// Force along each transmitted line, in wrench-matrix row order (N; positive pushes the platform).
    pub line_forces: [T; 6],
    /// Load on each actuator, in actuator order: torque about the ring axis for carriages (N m), force for
    /// linear actuators (N, positive = compression), torque about the shoulder axis for elbow chains' shoulders
    /// (N m, positive toward increasing shoulder angle).
    pub drives: [T; 6],
}

impl<T: Real> RingPlatform<T> {
    /// Rows of the wrench matrix: each chain's line `(u, B x u)` (an elbow chain's along its forearm, `B` its
    /// elbow), then for each radial or elbow chain in chain order the tangent force through its platform joint
    /// `(v, A x v)` (KINEMATICS.md 4.5; for an elbow chain the second wrench of dissertation ch. 5.1, parallel to
    /// the elbow axis), in SI units about the ring centre.
    pub fn wrench_matrix(&self, pose: &Pose<T>, q: &Actuators<T>) -> Matrix6<T> {
        let rows = self.wrench_rows(&self.configuration(pose, q));
        Matrix6::from_fn(|r, c| rows[r][c])
    }

    /// [`RingPlatform::wrench_matrix`] of a configuration, by rows.
    pub(super) fn wrench_rows(&self, c: &Configuration<T>) -> [[T; 6]; 6] {
        let mut w = [[T::zero(); 6]; 6];
        let mut extra = self.n;
        let inv = T::one() / self.rr;
        for i in 0..self.n {
            let (b, u, a) = (c.carriages[i], c.dirs[i], c.joints[i]);
            w[i] = plucker(&u, &c.bases[i]);
            if self.kinds[i].is_planar() {
                // The ring's tangent at the carriage: (-sin q, cos q, 0).
                let v = Vector3::new(-b.y * inv, b.x * inv, T::zero());
                if extra < 6 {
                    w[extra] = plucker(&v, &a);
                }
                extra += 1;
            }
        }
        w
    }

    /// External wrench of a mass at the centre of mass under gravity: `[F; M about the ring centre]` (N, N m).
    pub fn gravity_wrench(&self, pose: &Pose<T>, mass: T) -> Vector6<T> {
        let force = Vector3::new(T::zero(), T::zero(), -mass * T::of(9.80665));
        let at = pose.rotation() * self.com + pose.position();
        let moment = at.cross(&force);
        Vector6::new(force.x, force.y, force.z, moment.x, moment.y, moment.z)
    }

    /// Static loads on the drives that hold the platform against an external wrench `[F; M about the ring centre]`:
    /// solves `W^T f = -w` for the line forces, then takes each carriage's moment about the ring axis.
    pub fn loads(
        &self,
        pose: &Pose<T>,
        q: &Actuators<T>,
        external: &Vector6<T>,
    ) -> Result<ActuatorLoads<T>, KinematicsError> {
        let pose = pose.validated()?;
        let q = q.validated()?;
        if !external.iter().all(|c| c.finite()) {
            return Err(KinematicsError::NonFinite);
        }
        let c = self.configuration(&pose, &q);
        let w = self.wrench_rows(&c);
        let mut transposed = core::array::from_fn(|r| core::array::from_fn(|c| w[c][r]));
        let f = Lu6::in_place(&mut transposed)
            .solve(&(-external).into())
            .ok_or(KinematicsError::Singular)?;
        let mut drives = [T::zero(); 6];
        let mut extra = self.n;
        for i in 0..self.n {
            // A line's moment about the ring axis is the z part of its moment about the centre.
            drives[i] = f[i] * w[i][5];
            if let Some(axis) = self.length_axis[i] {
                drives[axis] = f[i];
            }
            if let Some(arm) = &self.arms[i] {
                // The forearm's force about the shoulder axis `t` (tangent, the direction of increasing s): by
                // virtual work the shoulder's torque is `f t . ((E - S) x u)`; the tangent force is parallel to the
                // axis and has no moment about it.
                let b = c.carriages[i];
                let (cq, sq) = (b.x / self.rr, b.y / self.rr);
                let t = Vector3::new(-sq, cq, T::zero());
                let arm_vector = c.bases[i] - arm.shoulder_point(cq, sq);
                drives[arm.axis] = f[i] * t.dot(&arm_vector.cross(&c.dirs[i]));
            }
            if self.kinds[i].is_planar() {
                if extra < 6 {
                    drives[i] += f[extra] * w[extra][5];
                }
                extra += 1;
            }
        }
        Ok(ActuatorLoads { line_forces: f, drives })
    }
}

/// Plücker coordinates `(u, p x u)` of the line through `p` along `u`.
fn plucker<T: Real>(u: &Vector3<T>, p: &Vector3<T>) -> [T; 6] {
    let m = p.cross(u);
    [u.x, u.y, u.z, m.x, m.y, m.z]
}
