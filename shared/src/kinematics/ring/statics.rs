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
        self.wrench_rows_scaled(c, T::one())
    }

    /// [`RingPlatform::wrench_rows`] with the moments multiplied by `scale`.
    ///
    /// Each row is computed where it goes (the row of chain `i` at `i`, the tangent rows from `n` on by
    /// `tangent_rows`): a matrix cleared first and filled in chain order cost a 144-byte `memclr` on the M4F.
    pub(super) fn wrench_rows_scaled(&self, c: &Configuration<T>, scale: T) -> [[T; 6]; 6] {
        core::array::from_fn(|r| {
            let (u, p) = self.line(c, r);
            let m = p.cross(&u);
            [u.x, u.y, u.z, m.x * scale, m.y * scale, m.z * scale]
        })
    }

    /// Wrench row `r`'s line: its direction and a point on it (rows past the last are zero).
    #[inline(always)]
    pub(super) fn line(&self, c: &Configuration<T>, r: usize) -> (Vector3<T>, Vector3<T>) {
        if r < self.n {
            return (c.dirs[r], c.bases[r]);
        }
        let inv = T::one() / self.rr;
        match self
            .tangent_rows
            .get(r - self.n)
            .and_then(|&i| c.carriages.get(usize::from(i)).zip(c.joints.get(usize::from(i))))
        {
            // The ring's tangent at the carriage, (-sin q, cos q, 0), through the platform joint.
            Some((b, a)) => (Vector3::new(-b.y * inv, b.x * inv, T::zero()), *a),
            None => (Vector3::zeros(), Vector3::zeros()),
        }
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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::kinematics::presets::{Preset, PresetGeometry};
    use crate::kinematics::Mechanism;

    /// The rows as a matrix cleared and filled in chain order: each chain's line, then the tangent rows.
    fn filled<T: Real>(m: &RingPlatform<T>, c: &Configuration<T>) -> [[T; 6]; 6] {
        let line = |u: &Vector3<T>, p: &Vector3<T>| {
            let m = p.cross(u);
            [u.x, u.y, u.z, m.x, m.y, m.z]
        };
        let mut w = [[T::zero(); 6]; 6];
        let mut extra = m.n;
        let inv = T::one() / m.rr;
        for i in 0..m.n {
            w[i] = line(&c.dirs[i], &c.bases[i]);
            if m.kinds[i].is_planar() {
                let b = c.carriages[i];
                if extra < 6 {
                    w[extra] = line(&Vector3::new(-b.y * inv, b.x * inv, T::zero()), &c.joints[i]);
                }
                extra += 1;
            }
        }
        w
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]
        /// Every ring preset's wrench rows, bit for bit those of the matrix filled in chain order.
        #[test]
        fn the_rows_are_those_filled_in_chain_order(
            t in prop::array::uniform3(-0.3f64..0.3),
            r in prop::array::uniform3(-0.6f64..0.6),
        ) {
            for preset in Preset::ALL {
                let PresetGeometry::Ring(g) = preset.geometry() else { continue };
                let m = RingPlatform::<f32>::new(g);
                let h = preset.home();
                let o = [t[0], t[1], t[2] * 0.3, r[0], r[1], r[2] * 5.0];
                let scale = [g.ring_radius, g.ring_radius, g.ring_radius, 1.0, 1.0, 1.0];
                let pose = Pose::from_array(core::array::from_fn(|i| (h[i] + o[i] * scale[i]) as f32));
                let Ok(q) = m.inverse(&pose) else { continue };
                let c = m.configuration(&pose, &q);
                let bits = |w: [[f32; 6]; 6]| w.map(|row| row.map(f32::to_bits));
                prop_assert_eq!(bits(m.wrench_rows(&c)), bits(filled(&m, &c)), "{}", preset.name());
            }
        }
    }
}
