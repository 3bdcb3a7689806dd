//! The five-DOF parallel-serial tool carrier (KINEMATICS.md 2.3).
//!
//! A frame (rotation `Rx(alpha) Ry(beta)`, no yaw) carries a tool `L1` below its centre. A linear carriage along X
//! sets `q1 = x + L1 sin(beta)`, a drive sets `q5 = beta`, and two planar dyads in planes parallel to O-YZ hold the
//! frame pivots `A2` (base pivot `B`) and `A3` (base pivot `D`). Actuators `[q1, q2, q3, q4, q5, q6]`: `q2`, `q4` are
//! the angles of the `L2` links at `B` and `D` to the plane OXY; `q3`, `q6` the angles of the `L3` links, measured
//! the same way. Five drives (`q1..q5`) fix the five DOF: with `q1, q2, q4, q5` alone the frame and the `D` dyad
//! form a four-bar with one free motion, which the `q3` drive removes. `q6` is the auxiliary sixth drive: it
//! follows the pose and is not an input of the forward kinematics.
//!
//! Where the source writes `theta = acos((A2y - yb) / d)`, this uses `atan2(A2z - zb, A2y - yb)`: the same angle
//! when the pivot is above `B`, and still right when it is below.

use nalgebra::{Matrix6, Vector3, Vector6};

use super::geometry::{Branch, ToolGeometry};
use super::{Actuators, AxisKind, Jacobians, KinematicsError, Mechanism, Pose, Reach, WorkspaceReport};
use crate::Real;

const AXES: [AxisKind; 6] = [
    AxisKind::Linear,
    AxisKind::Angle,
    AxisKind::Angle,
    AxisKind::Angle,
    AxisKind::Angle,
    AxisKind::Angle,
];

/// The tool carrier in scalar type `T`.
#[derive(Debug, Clone, Copy)]
pub struct ToolCarrier<T: Real> {
    geometry: ToolGeometry,
    l1: T,
    l2: T,
    l3: T,
    half_b: T,
    /// `(y, z)` of the base pivots `B`, `D`.
    pivots: [(T, T); 2],
    branches: [Branch; 2],
    /// `q1`'s travel `[min, max]` (m).
    stroke: [T; 2],
    min_index: T,
}

/// The frame pivots and their partial derivatives with respect to `(x, y, z, alpha, beta)`.
struct FramePivot<T: Real> {
    at: Vector3<T>,
    d_alpha: Vector3<T>,
    d_beta: Vector3<T>,
}

impl<T: Real> ToolCarrier<T> {
    /// The mechanism of a geometry, in scalar type `T`.
    pub fn new(geometry: &ToolGeometry) -> Self {
        let g = geometry;
        Self {
            geometry: *g,
            l1: T::of(g.l1),
            l2: T::of(g.l2),
            l3: T::of(g.l3),
            half_b: T::of(g.b / 2.0),
            pivots: [
                (T::of(g.pivot_b[1]), T::of(g.pivot_b[2])),
                (T::of(g.pivot_d[1]), T::of(g.pivot_d[2])),
            ],
            branches: [g.branch_b, g.branch_d],
            stroke: [T::of(g.stroke[0]), T::of(g.stroke[1])],
            min_index: T::of(g.min_singularity_index),
        }
    }

    /// The same mechanism assembled on other dyad branches (`[B side, D side]`): the closed form's `theta - kappa`
    /// or `theta + kappa` for `q2` and `q4`. Both assemblies close the same pose; which one the machine is in is
    /// fixed when it is built, so IK must be told.
    pub fn with_branches(&self, branches: [Branch; 2]) -> Self {
        Self::new(&self.geometry.with_branches(branches[0], branches[1]))
    }

    /// The dyad assemblies `[B side, D side]` this mechanism's IK takes.
    pub fn branches(&self) -> [Branch; 2] {
        self.branches
    }

    /// The geometry this mechanism was built from.
    pub fn geometry(&self) -> &ToolGeometry {
        &self.geometry
    }

    /// Frame pivot `A2` (`side = 0`, `+b/2`) or `A3` (`side = 1`, `-b/2`).
    fn pivot(&self, pose: &Pose<T>, side: usize) -> FramePivot<T> {
        let h = if side == 0 { self.half_b } else { -self.half_b };
        let (sa, ca) = pose.alpha.sin_cos_();
        let (sb, cb) = pose.beta.sin_cos_();
        let l1 = self.l1;
        FramePivot {
            at: Vector3::new(
                pose.x + l1 * sb,
                pose.y + h * ca - l1 * cb * sa,
                pose.z + h * sa + l1 * cb * ca,
            ),
            d_alpha: Vector3::new(T::zero(), -h * sa - l1 * cb * ca, h * ca - l1 * cb * sa),
            d_beta: Vector3::new(l1 * cb, l1 * sb * sa, -l1 * sb * ca),
        }
    }

    /// Elbow `(y, z)` of a dyad whose `L2` link is at angle `q`.
    fn elbow(&self, side: usize, q: T) -> (T, T) {
        let (py, pz) = self.pivots[side];
        (py + self.l2 * q.cos_(), pz + self.l2 * q.sin_())
    }

    /// `(d, theta, kappa)` of a dyad: pivot distance, its direction, and the elbow's offset angle.
    fn dyad(&self, side: usize, at: &Vector3<T>) -> Result<(T, T, T), KinematicsError> {
        let (py, pz) = self.pivots[side];
        let (dy, dz) = (at.y - py, at.z - pz);
        let d = (dy * dy + dz * dz).sqrt_();
        let chain = if side == 0 { 1 } else { 3 };
        let unreachable = KinematicsError::Unreachable {
            chain,
            reason: Reach::Dyad,
        };
        if d == T::zero() {
            return Err(unreachable);
        }
        let cos_kappa = (d * d + self.l2 * self.l2 - self.l3 * self.l3) / (T::of(2.0) * self.l2 * d);
        if !cos_kappa.finite() || cos_kappa.abs() > T::one() {
            return Err(unreachable);
        }
        Ok((d, dz.atan2_(dy), cos_kappa.acos_()))
    }

    fn check_mobility(pose: &Pose<T>) -> Result<(), KinematicsError> {
        if pose.gamma != T::zero() {
            return Err(KinematicsError::OutsideMobility);
        }
        Ok(())
    }
}

impl<T: Real> Mechanism<T> for ToolCarrier<T> {
    type Guard = ();

    fn dof(&self) -> usize {
        5
    }

    fn axes(&self) -> [AxisKind; 6] {
        AXES
    }

    fn characteristic_length(&self) -> T {
        self.l2
    }

    fn inverse(&self, pose: &Pose<T>) -> Result<Actuators<T>, KinematicsError> {
        let pose = pose.validated()?;
        Self::check_mobility(&pose)?;
        let mut q = [T::zero(); 6];
        q[0] = pose.x + self.l1 * pose.beta.sin_();
        q[4] = pose.beta;
        for (side, (drive, link)) in [(1, 2), (3, 5)].into_iter().enumerate() {
            let at = self.pivot(&pose, side).at;
            let (_, theta, kappa) = self.dyad(side, &at)?;
            q[drive] = match self.branches[side] {
                Branch::Minus => theta - kappa,
                Branch::Plus => theta + kappa,
            };
            let (ey, ez) = self.elbow(side, q[drive]);
            q[link] = (at.z - ez).atan2_(at.y - ey);
        }
        Ok(Actuators(q))
    }

    fn residuals(&self, pose: &Pose<T>, q: &Actuators<T>) -> Vector6<T> {
        let q = &q.0;
        let a2 = self.pivot(pose, 0).at;
        let a3 = self.pivot(pose, 1).at;
        let (by, bz) = self.pivots[0];
        let (cy, cz) = self.elbow(1, q[3]);
        let (ey, ez) = (a3.y - cy, a3.z - cz);
        Vector6::new(
            pose.x + self.l1 * pose.beta.sin_() - q[0],
            a2.y - by - self.l2 * q[1].cos_() - self.l3 * q[2].cos_(),
            a2.z - bz - self.l2 * q[1].sin_() - self.l3 * q[2].sin_(),
            ey * ey + ez * ez - self.l3 * self.l3,
            pose.beta - q[4],
            // Auxiliary: the L3 link at D points along q6.
            ey * q[5].sin_() - ez * q[5].cos_(),
        )
    }

    fn jacobians(&self, pose: &Pose<T>, q: &Actuators<T>) -> Jacobians<T> {
        let q = &q.0;
        let p2 = self.pivot(pose, 0);
        let p3 = self.pivot(pose, 1);
        let (cy, cz) = self.elbow(1, q[3]);
        let (ey, ez) = (p3.at.y - cy, p3.at.z - cz);
        let two = T::of(2.0);
        let (o, z) = (T::one(), T::zero());
        let (s6, c6) = q[5].sin_cos_();
        let (s4, c4) = q[3].sin_cos_();
        #[rustfmt::skip]
        let a = Matrix6::new(
            o, z, z, z, self.l1 * pose.beta.cos_(), z,
            z, o, z, p2.d_alpha.y, p2.d_beta.y, z,
            z, z, o, p2.d_alpha.z, p2.d_beta.z, z,
            z, two * ey, two * ez, two * (ey * p3.d_alpha.y + ez * p3.d_alpha.z),
                two * (ey * p3.d_beta.y + ez * p3.d_beta.z), z,
            z, z, z, z, o, z,
            z, s6, -c6, s6 * p3.d_alpha.y - c6 * p3.d_alpha.z, s6 * p3.d_beta.y - c6 * p3.d_beta.z, z,
        );
        let (l2, l3) = (self.l2, self.l3);
        #[rustfmt::skip]
        let b = Matrix6::new(
            -o, z, z, z, z, z,
            z, l2 * q[1].sin_(), l3 * q[2].sin_(), z, z, z,
            z, -l2 * q[1].cos_(), -l3 * q[2].cos_(), z, z, z,
            z, z, z, two * l2 * (ey * s4 - ez * c4), z, z,
            z, z, z, z, -o, z,
            z, z, z, l2 * (s6 * s4 + c6 * c4), z, ey * c6 + ez * s6,
        );
        Jacobians {
            a,
            b,
            dof: 5,
            length: self.l2,
            axes: AXES,
        }
    }

    /// Reach (the smaller of the dyads' closure slack and the carriage's room to its stroke ends, m) and singularity (the smaller of `|sin|` of the D-dyad's elbow angle, a type-1
    /// boundary, and of the angle between its `L3` link and the frame, the type-2 transmission). The ring checks
    /// (spacing, crossing, cones, stability) do not apply to this mechanism.
    fn workspace(&self, pose: &Pose<T>, q: &Actuators<T>) -> WorkspaceReport<T> {
        let mut reach = T::max_value().unwrap_or(T::one());
        for side in 0..2 {
            let at = self.pivot(pose, side).at;
            let (py, pz) = self.pivots[side];
            let d = ((at.y - py) * (at.y - py) + (at.z - pz) * (at.z - pz)).sqrt_();
            reach = reach.min(self.l2 + self.l3 - d).min(d - (self.l2 - self.l3).abs());
        }
        let q = &q.0;
        reach = reach.min(q[0] - self.stroke[0]).min(self.stroke[1] - q[0]);
        let elbow = (q[5] - q[3]).sin_().abs();
        let transmission = (q[5] - pose.alpha).sin_().abs();
        let index = elbow.min(transmission);
        WorkspaceReport::new(
            [Some(reach), None, None, None, Some(index - self.min_index), None],
            index,
        )
    }
}
