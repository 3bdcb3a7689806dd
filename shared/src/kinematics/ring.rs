//! Ring platforms: carriages on a circular guide with rod chains and radial linear-actuator chains
//! (KINEMATICS.md 2.1 trainer, 2.2 rotopod, 3 velocities, 4 workspace, 5 statics).

use nalgebra::{Matrix3, Matrix6, RowVector6, Vector3, Vector6};

use super::geometry::{Branch, ChainKind, RingGeometry};
use super::velocity::hadamard_ratio;
use super::{Actuators, AxisKind, Jacobians, KinematicsError, Mechanism, Pose, Reach, WorkspaceReport};
use crate::real::{wrap_once, wrap_pi};
use crate::Real;

/// A ring platform in scalar type `T`, built from a validated [`RingGeometry`].
#[derive(Debug, Clone, Copy)]
pub struct RingPlatform<T: Real> {
    geometry: RingGeometry,
    rr: T,
    rod: T,
    n: usize,
    points: [Vector3<T>; 6],
    kinds: [ChainKind; 6],
    /// Actuator index of the length of each radial chain.
    length_axis: [Option<usize>; 6],
    axes: [AxisKind; 6],
    stroke: [T; 2],
    spacing: [T; 2],
    cones: [T; 2],
    min_index: T,
    com: Vector3<T>,
}

/// Static loads on the drives for an external wrench.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorLoads<T> {
    /// Force along each transmitted line, in wrench-matrix row order (N; positive pushes the platform).
    pub line_forces: [T; 6],
    /// Load on each actuator, in actuator order: torque about the ring axis for carriages (N m), force for
    /// linear actuators (N, positive = compression).
    pub drives: [T; 6],
}

/// Carriages per chain, positions of the platform joints and chain directions at one configuration, computed once
/// for all the checks of a pose (each would otherwise redo the rotation and the joints).
struct Configuration<T: Real> {
    /// Platform orientation.
    rotation: Matrix3<T>,
    joints: [Vector3<T>; 6],
    carriages: [Vector3<T>; 6],
    /// Unit vector from carriage to platform joint.
    dirs: [Vector3<T>; 6],
}

impl<T: Real> RingPlatform<T> {
    /// The mechanism of a geometry, in scalar type `T`.
    pub fn new(geometry: &RingGeometry) -> Self {
        let chains = geometry.chains();
        let n = chains.len();
        let mut points = [Vector3::zeros(); 6];
        let mut kinds = [ChainKind::Radial; 6];
        let mut length_axis = [None; 6];
        let mut axes = [AxisKind::Ring; 6];
        let mut next_length = n;
        // The validated geometry has at most six chains and exactly six actuators, so every index is in range.
        for (i, c) in chains.iter().enumerate() {
            points[i] = Vector3::from(c.platform_point.map(T::of));
            kinds[i] = c.kind;
            if c.kind == ChainKind::Radial {
                length_axis[i] = Some(next_length);
                axes[next_length] = AxisKind::Linear;
                next_length += 1;
            }
        }
        let l = &geometry.limits;
        Self {
            geometry: *geometry,
            rr: T::of(geometry.ring_radius),
            rod: T::of(geometry.rod_length),
            n,
            points,
            kinds,
            length_axis,
            axes,
            stroke: l.stroke.map(T::of),
            spacing: l.carriage_spacing.map(T::of),
            cones: [T::of(l.base_cone), T::of(l.platform_cone)],
            min_index: T::of(l.min_singularity_index),
            com: Vector3::from(l.centre_of_mass.map(T::of)),
        }
    }

    /// The geometry this mechanism was built from.
    pub fn geometry(&self) -> &RingGeometry {
        &self.geometry
    }

    /// Platform joints `A_i = R a_i + p` in the base frame.
    pub fn joints(&self, pose: &Pose<T>) -> [Vector3<T>; 6] {
        self.joints_with(&pose.rotation(), pose)
    }

    fn joints_with(&self, r: &Matrix3<T>, pose: &Pose<T>) -> [Vector3<T>; 6] {
        let p = pose.position();
        self.points.map(|a| r * a + p)
    }

    fn carriage(&self, q: T) -> Vector3<T> {
        Vector3::new(self.rr * q.cos_(), self.rr * q.sin_(), T::zero())
    }

    fn configuration(&self, pose: &Pose<T>, q: &Actuators<T>) -> Configuration<T> {
        let rotation = pose.rotation();
        let joints = self.joints_with(&rotation, pose);
        let mut carriages = [Vector3::zeros(); 6];
        let mut dirs = [Vector3::zeros(); 6];
        for i in 0..self.n {
            carriages[i] = self.carriage(q.0[i]);
            dirs[i] = (joints[i] - carriages[i])
                .try_normalize(T::zero())
                .unwrap_or_else(Vector3::z);
        }
        Configuration {
            rotation,
            joints,
            carriages,
            dirs,
        }
    }

    /// Rows of the wrench matrix: each chain's line `(u, B x u)`, then for each radial chain the tangent force
    /// through its platform joint `(v, A x v)` (KINEMATICS.md 4.5), in SI units about the ring centre.
    pub fn wrench_matrix(&self, pose: &Pose<T>, q: &Actuators<T>) -> Matrix6<T> {
        self.wrench_of(&self.configuration(pose, q), q)
    }

    fn wrench_of(&self, c: &Configuration<T>, q: &Actuators<T>) -> Matrix6<T> {
        let mut w = Matrix6::zeros();
        let mut extra = self.n;
        for i in 0..self.n {
            let (b, u, a) = (c.carriages[i], c.dirs[i], c.joints[i]);
            w.set_row(i, &plucker(&u, &b));
            if self.kinds[i] == ChainKind::Radial {
                let qi = q.0[i];
                let v = Vector3::new(-qi.sin_(), qi.cos_(), T::zero());
                if extra < 6 {
                    w.set_row(extra, &plucker(&v, &a));
                }
                extra += 1;
            }
        }
        w
    }

    /// Scale-free singularity index of the wrench matrix: moments divided by the ring radius, then
    /// [`hadamard_ratio`]. 1 for six orthogonal lines, 0 at a singularity.
    pub fn singularity_index(&self, pose: &Pose<T>, q: &Actuators<T>) -> T {
        self.singularity_of(&self.configuration(pose, q), q)
    }

    fn singularity_of(&self, c: &Configuration<T>, q: &Actuators<T>) -> T {
        let mut w = self.wrench_of(c, q);
        let inv = T::one() / self.rr;
        for c in 3..6 {
            w.column_mut(c).scale_mut(inv);
        }
        hadamard_ratio(&w)
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
        let w = self.wrench_matrix(&pose, &q);
        let f = w
            .transpose()
            .lu()
            .solve(&(-external))
            .filter(|f| f.iter().all(|c| c.finite()))
            .ok_or(KinematicsError::Singular)?;
        let mut drives = [T::zero(); 6];
        let mut extra = self.n;
        for i in 0..self.n {
            // A line's moment about the ring axis is the z part of its moment about the centre.
            drives[i] = f[i] * w[(i, 5)];
            if let Some(axis) = self.length_axis[i] {
                drives[axis] = f[i];
                if extra < 6 {
                    drives[i] += f[extra] * w[(extra, 5)];
                }
                extra += 1;
            }
        }
        Ok(ActuatorLoads {
            line_forces: f.into(),
            drives,
        })
    }

    /// Reach margin of a pose (m), defined whether or not the pose is reachable: the smallest slack of the rod
    /// conditions `|Az| < L` and `|Rr - rho| <= h <= Rr + rho`, and of the radial strokes `s_min <= s <= s_max`.
    /// Negative outside, by how far.
    pub fn reach_margin(&self, pose: &Pose<T>) -> T {
        self.reach_of(&self.joints(pose))
    }

    fn reach_of(&self, joints: &[Vector3<T>; 6]) -> T {
        let mut margin = T::max_value().unwrap_or(T::one());
        for (a, kind) in joints.iter().zip(&self.kinds).take(self.n) {
            let rho = (a.x * a.x + a.y * a.y).sqrt_();
            let m = match kind {
                ChainKind::Rod(_) => {
                    let h = (self.rod * self.rod - a.z * a.z).max(T::zero()).sqrt_();
                    (self.rod - a.z.abs())
                        .min(h - (self.rr - rho).abs())
                        .min(self.rr + rho - h)
                }
                ChainKind::Radial => {
                    let s = ((self.rr - rho) * (self.rr - rho) + a.z * a.z).sqrt_();
                    (s - self.stroke[0]).min(self.stroke[1] - s)
                }
            };
            margin = margin.min(m);
        }
        margin
    }

    /// Spacing and crossing margins from the counter-clockwise central angles between neighbouring carriages.
    ///
    /// Each gap is measured counter-clockwise in `[0, 2pi)`. The carriages keep their order exactly when the gaps
    /// add up to one turn; two turns or more means some carriage passed a neighbour, and the crossing margin is
    /// then minus the smallest angle by which the order is broken.
    fn ring_order_margins(&self, q: &Actuators<T>) -> (T, T) {
        let two_pi = T::two_pi();
        let mut spacing = T::max_value().unwrap_or(T::one());
        let mut smallest = two_pi;
        let mut largest = T::zero();
        let mut total = T::zero();
        for i in 0..self.n {
            let diff = q.0[(i + 1) % self.n] - q.0[i];
            // IK's angles are within (-pi, pi], so one exact addition wraps their difference; other inputs (a
            // multi-turn angle) take the general wrap.
            let mut gap = if diff.abs() <= T::two_pi() {
                wrap_once(diff)
            } else {
                wrap_pi(diff)
            };
            if gap < T::zero() {
                gap += two_pi;
            }
            total += gap;
            spacing = spacing.min(gap - self.spacing[0]).min(self.spacing[1] - gap);
            smallest = smallest.min(gap);
            largest = largest.max(gap);
        }
        // A carriage that passed its neighbour by d leaves a gap of 2pi - d behind it.
        let order = if total < two_pi + T::pi() {
            smallest
        } else {
            -(two_pi - largest)
        };
        (spacing, order)
    }

    fn cone_margin(&self, c: &Configuration<T>) -> T {
        let normal = c.rotation.column(2).into_owned();
        let mut margin = T::max_value().unwrap_or(T::one());
        for u in c.dirs.iter().take(self.n) {
            let base = u.z.clamp(-T::one(), T::one()).asin_() - self.cones[0];
            let platform = u.dot(&normal).clamp(-T::one(), T::one()).asin_() - self.cones[1];
            margin = margin.min(base).min(platform);
        }
        margin
    }

    fn stability_margin(&self, pose: &Pose<T>, c: &Configuration<T>) -> T {
        let com = c.rotation * self.com + pose.position();
        let mut margin = T::max_value().unwrap_or(T::one());
        for i in 0..self.n {
            let (p0, p1) = (c.carriages[i], c.carriages[(i + 1) % self.n]);
            let edge = p1 - p0;
            let len = (edge.x * edge.x + edge.y * edge.y).sqrt_();
            if len == T::zero() {
                return T::zero();
            }
            // Counter-clockwise polygon: the inside is on the left of each edge.
            let cross = edge.x * (com.y - p0.y) - edge.y * (com.x - p0.x);
            margin = margin.min(cross / len);
        }
        margin
    }
}

/// Plücker row `(u, p x u)` of the line through `p` along `u`.
fn plucker<T: Real>(u: &Vector3<T>, p: &Vector3<T>) -> RowVector6<T> {
    let m = p.cross(u);
    RowVector6::new(u.x, u.y, u.z, m.x, m.y, m.z)
}

/// `dR/dalpha`, `dR/dbeta`, `dR/dgamma` of `R = Rz(gamma) Ry(beta) Rx(alpha)`.
pub(crate) fn rotation_partials<T: Real>(alpha: T, beta: T, gamma: T) -> [Matrix3<T>; 3] {
    let (sa, ca) = (alpha.sin_(), alpha.cos_());
    let (sb, cb) = (beta.sin_(), beta.cos_());
    let (sg, cg) = (gamma.sin_(), gamma.cos_());
    let (o, z) = (T::one(), T::zero());
    let rx = Matrix3::new(o, z, z, z, ca, -sa, z, sa, ca);
    let ry = Matrix3::new(cb, z, sb, z, o, z, -sb, z, cb);
    let rz = Matrix3::new(cg, -sg, z, sg, cg, z, z, z, o);
    let drx = Matrix3::new(z, z, z, z, -sa, -ca, z, ca, -sa);
    let dry = Matrix3::new(-sb, z, cb, z, z, z, -cb, z, -sb);
    let drz = Matrix3::new(-sg, -cg, z, cg, -sg, z, z, z, z);
    [rz * ry * drx, rz * dry * rx, drz * ry * rx]
}

/// Columns `dA/dp_k` of a platform joint with platform coordinates `a`.
pub(crate) fn joint_partials<T: Real>(pose: &Pose<T>, a: &Vector3<T>) -> [Vector3<T>; 6] {
    let [da, db, dg] = rotation_partials(pose.alpha, pose.beta, pose.gamma);
    [Vector3::x(), Vector3::y(), Vector3::z(), da * a, db * a, dg * a]
}

impl<T: Real> Mechanism<T> for RingPlatform<T> {
    fn dof(&self) -> usize {
        6
    }

    fn axes(&self) -> [AxisKind; 6] {
        self.axes
    }

    fn characteristic_length(&self) -> T {
        self.rr
    }

    fn inverse(&self, pose: &Pose<T>) -> Result<Actuators<T>, KinematicsError> {
        let pose = pose.validated()?;
        let joints = self.joints(&pose);
        let mut q = [T::zero(); 6];
        let tiny = self.rr * T::of(T::EPS * 16.0);
        for i in 0..self.n {
            let a = joints[i];
            let chain = i as u8;
            let rho2 = a.x * a.x + a.y * a.y;
            let rho = rho2.sqrt_();
            if rho <= tiny {
                return Err(KinematicsError::Unreachable {
                    chain,
                    reason: Reach::Centre,
                });
            }
            let theta = a.y.atan2_(a.x);
            match self.kinds[i] {
                ChainKind::Rod(branch) => {
                    let h2 = self.rod * self.rod - a.z * a.z;
                    if h2 <= T::zero() {
                        return Err(KinematicsError::Unreachable {
                            chain,
                            reason: Reach::Height,
                        });
                    }
                    // (2 Rr rho sin phi)^2 factors into (h^2 - (Rr - rho)^2) ((Rr + rho)^2 - h^2): both factors
                    // non-negative is the reach condition, and atan2 keeps phi accurate near 0 and pi where acos
                    // of the cosine rule would lose half the digits.
                    let inner = h2 - (self.rr - rho) * (self.rr - rho);
                    let outer = (self.rr + rho) * (self.rr + rho) - h2;
                    if inner < T::zero() || outer < T::zero() {
                        return Err(KinematicsError::Unreachable {
                            chain,
                            reason: Reach::Ring,
                        });
                    }
                    let phi = (inner * outer).sqrt_().atan2_(self.rr * self.rr + rho2 - h2);
                    // theta is in [-pi, pi] and phi in [0, pi]: one exact addition wraps the sum.
                    q[i] = wrap_once(match branch {
                        Branch::Plus => theta + phi,
                        Branch::Minus => theta - phi,
                    });
                }
                ChainKind::Radial => {
                    q[i] = theta;
                    if let Some(k) = self.length_axis[i] {
                        q[k] = ((self.rr - rho) * (self.rr - rho) + a.z * a.z).sqrt_();
                    }
                }
            }
        }
        Ok(Actuators(q))
    }

    fn residuals(&self, pose: &Pose<T>, q: &Actuators<T>) -> Vector6<T> {
        let joints = self.joints(pose);
        let mut f = Vector6::zeros();
        let mut extra = self.n;
        for i in 0..self.n {
            let (a, qi) = (joints[i], q.0[i]);
            let d = a - self.carriage(qi);
            let length = match self.length_axis[i] {
                Some(k) => q.0[k],
                None => self.rod,
            };
            f[i] = d.dot(&d) - length * length;
            if self.kinds[i] == ChainKind::Radial && extra < 6 {
                f[extra] = a.x * qi.sin_() - a.y * qi.cos_();
                extra += 1;
            }
        }
        f
    }

    fn jacobians(&self, pose: &Pose<T>, q: &Actuators<T>) -> Jacobians<T> {
        let joints = self.joints(pose);
        let mut a_mat = Matrix6::zeros();
        let mut b_mat = Matrix6::zeros();
        let mut extra = self.n;
        let two = T::of(2.0);
        for i in 0..self.n {
            let (a, qi) = (joints[i], q.0[i]);
            let (s, c) = (qi.sin_(), qi.cos_());
            let d = a - self.carriage(qi);
            let partials = joint_partials(pose, &self.points[i]);
            for (k, da) in partials.iter().enumerate() {
                a_mat[(i, k)] = two * d.dot(da);
            }
            // dF/dq = -2 d . dB/dq with dB/dq = Rr (-sin q, cos q, 0).
            b_mat[(i, i)] = -two * self.rr * (-d.x * s + d.y * c);
            if let Some(k) = self.length_axis[i] {
                b_mat[(i, k)] = -two * q.0[k];
                if extra < 6 {
                    for (col, da) in partials.iter().enumerate() {
                        a_mat[(extra, col)] = s * da.x - c * da.y;
                    }
                    b_mat[(extra, i)] = a.x * c + a.y * s;
                    extra += 1;
                }
            }
        }
        Jacobians {
            a: a_mat,
            b: b_mat,
            dof: 6,
            length: self.rr,
            axes: self.axes,
        }
    }

    fn workspace(&self, pose: &Pose<T>, q: &Actuators<T>) -> WorkspaceReport<T> {
        let c = self.configuration(pose, q);
        let (spacing, order) = self.ring_order_margins(q);
        let index = self.singularity_of(&c, q);
        WorkspaceReport::new(
            [
                Some(self.reach_of(&c.joints)),
                Some(spacing),
                Some(order),
                Some(self.cone_margin(&c)),
                Some(index - self.min_index),
                Some(self.stability_margin(pose, &c)),
            ],
            index,
        )
    }
}
