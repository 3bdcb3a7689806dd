//! Ring platforms: carriages on a circular guide with rod chains, radial linear-actuator chains and elbow chains
//! (KINEMATICS.md 2.1 trainer, 2.2 rotopod, 3 velocities; the elbow chain's arm in `arm`; the checks of 4 in
//! `checks`, the statics of 5 in `statics`, the inverse dynamics in `dynamics`, tip-over under a lateral
//! acceleration in `tipping`).

mod arm;
mod checks;
mod dynamics;
mod guard;
mod statics;
mod tipping;

use nalgebra::{Matrix6, Vector3, Vector6};

use self::arm::Arm;
use self::checks::{direction, Configuration};
pub use self::dynamics::{BodyMotion, MotionState, Payload};
pub use self::guard::SlowCheckGuard;
pub use self::statics::ActuatorLoads;
pub use self::tipping::{Loaded, TipOver, TipOverError, GRAVITY};
use super::geometry::{Branch, ChainKind, RingGeometry};
use super::{Actuators, AxisKind, Check, Jacobians, KinematicsError, Mechanism, Pose, Reach, WorkspaceReport};
use crate::Real;

/// A chain's solution besides its actuators: its carriage, the start of its last link and its reach margin.
type ChainSolution<T> = (Vector3<T>, Vector3<T>, T);

/// A chain's kind without an elbow chain's dimensions (those are in the platform's `arms`): what the per-pose code
/// branches on, a byte instead of a whole [`ChainKind`] per chain (the firmware keeps several platforms in RAM).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Shape {
    Rod(Branch),
    Radial,
    Elbow,
}

impl Shape {
    fn of(kind: &ChainKind) -> Self {
        match kind {
            ChainKind::Rod(b) => Self::Rod(*b),
            ChainKind::Radial => Self::Radial,
            ChainKind::Elbow(_) => Self::Elbow,
        }
    }

    /// Radial and elbow chains: a planarity constraint and a tangent wrench.
    pub(super) fn is_planar(self) -> bool {
        matches!(self, Self::Radial | Self::Elbow)
    }
}

/// A ring platform in scalar type `T`, built from a validated [`RingGeometry`].
///
/// Laid out in this order (`repr(C)`): what every pose reads first, the elbow chains' arms next, the geometry (large
/// since chains carry an elbow's `f64` dimensions, and read only by reports) last, so that the hot fields keep small
/// offsets wherever the platform is embedded (on the M4F a load beyond 4 KB of its base takes extra instructions).
#[derive(Debug, Clone, Copy)]
#[repr(C)]
pub struct RingPlatform<T: Real> {
    rr: T,
    rod: T,
    n: usize,
    points: [Vector3<T>; 6],
    kinds: [Shape; 6],
    /// The chain of each wrench-matrix row from `n` on (the tangent force of a radial or elbow chain, in chain
    /// order); `u8::MAX` past the last.
    tangent_rows: [u8; 6],
    /// The wrench rows other than the first planar chain's two (its own and the first tangent row), in order: the
    /// rows that keep a moment about its joint (`checks::through_joint`).
    others: [u8; 4],
    /// Actuator index of the length of each radial chain.
    length_axis: [Option<usize>; 6],
    axes: [AxisKind; 6],
    stroke: [T; 2],
    spacing: [T; 2],
    cones: [T; 2],
    min_index: T,
    com: Vector3<T>,
    /// The arm of each elbow chain (with its shoulder's actuator index).
    arms: [Option<Arm<T>>; 6],
    geometry: RingGeometry,
}

impl<T: Real> RingPlatform<T> {
    /// The mechanism of a geometry, in scalar type `T`.
    pub fn new(geometry: &RingGeometry) -> Self {
        let chains = geometry.chains();
        let n = chains.len();
        let mut points = [Vector3::zeros(); 6];
        let mut kinds = [Shape::Radial; 6];
        let mut length_axis = [None; 6];
        let mut arms = [None; 6];
        let mut next_length = n;
        // The validated geometry has at most six chains and exactly six actuators, so every index is in range.
        for (i, c) in chains.iter().enumerate() {
            points[i] = Vector3::from(c.platform_point.map(T::of));
            kinds[i] = Shape::of(&c.kind);
            if c.kind == ChainKind::Radial {
                length_axis[i] = Some(next_length);
                next_length += 1;
            }
        }
        // Shoulder angles follow every radial length.
        for (i, c) in chains.iter().enumerate() {
            if let ChainKind::Elbow(e) = &c.kind {
                arms[i] = Some(Arm::new(e, next_length));
                next_length += 1;
            }
        }
        let mut tangent_rows = [u8::MAX; 6];
        let planar = chains
            .iter()
            .enumerate()
            .filter(|(_, c)| Shape::of(&c.kind).is_planar());
        for (slot, (i, _)) in tangent_rows.iter_mut().zip(planar) {
            *slot = i as u8;
        }
        let mut others = [u8::MAX; 4];
        let first = tangent_rows[0];
        let mut slot = 0;
        for r in 0..6u8 {
            if r != first && usize::from(r) != n && slot < 4 {
                others[slot] = r;
                slot += 1;
            }
        }
        let l = &geometry.limits;
        Self {
            tangent_rows,
            others,
            geometry: *geometry,
            rr: T::of(geometry.ring_radius),
            rod: T::of(geometry.rod_length),
            n,
            points,
            kinds,
            length_axis,
            arms,
            axes: geometry.axes(),
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
        let (r, p) = (pose.rotation(), pose.position());
        self.points.map(|a| r * a + p)
    }

    /// The platform joints of a pose into a configuration whose rotation is the pose's.
    fn place_joints(&self, pose: &Pose<T>, c: &mut Configuration<T>) {
        let p = pose.position();
        for (joint, a) in c.joints.iter_mut().zip(&self.points).take(self.n) {
            *joint = c.rotation * a + p;
        }
    }

    fn carriage(&self, q: T) -> Vector3<T> {
        let (s, c) = q.sin_cos_();
        Vector3::new(self.rr * c, self.rr * s, T::zero())
    }

    /// An elbow chain's elbow for its carriage angle `q` and shoulder angle `shoulder`.
    fn elbow(&self, arm: &Arm<T>, q: T, shoulder: T) -> Vector3<T> {
        let (sq, cq) = q.sin_cos_();
        let (ss, cs) = shoulder.sin_cos_();
        arm.elbow(cq, sq, cs, ss)
    }

    /// Reach margin of a pose (m), defined whether or not the pose is reachable: the smallest slack of the rod
    /// conditions `|Az| < L` and `|Rr - rho| <= h <= Rr + rho`, of the radial strokes `s_min <= s <= s_max`, and of
    /// the elbow chains' arms (the shoulder-to-joint distance within what the elbow angle limits allow, the elbow's
    /// arc within the shoulder's travel). Negative outside, by how far.
    pub fn reach_margin(&self, pose: &Pose<T>) -> T {
        self.reach_of(&self.joints(pose))
    }

    /// Scale-free singularity index of the wrench matrix: moments divided by the ring radius, then
    /// [`super::velocity::hadamard_ratio`]. 1 for six orthogonal lines, 0 at a singularity.
    pub fn singularity_index(&self, pose: &Pose<T>, q: &Actuators<T>) -> T {
        self.singularity_of(&self.configuration(pose, q))
    }

    /// Inverse kinematics that leaves the rotation, the platform joints and the carriages it found in `c`: the
    /// actuators, or why the pose has no solution.
    ///
    /// Each carriage comes from the triangle of ring radius, rod and the joint's distance from the axis, without
    /// an angle: with `theta` the joint's azimuth and `phi` the angle at the centre, `2 Rr rho (cos phi, sin phi)`
    /// is `(C, S)` with `C = Rr^2 + rho^2 - h^2` and `S = sqrt(inner * outer)`, so the carriage direction
    /// `(cos(theta +- phi), sin(theta +- phi))` is `(x C -+ y S, y C +- x S)` over `2 Rr rho^2`. One `atan2` of it
    /// gives the angle (instead of one for `theta` and one for `phi`), already within `(-pi, pi]`, and the checks
    /// take the carriages as they are instead of a sine and a cosine of each angle.
    ///
    /// The actuators go into `c` as well: returned in a `Result`, the compiler moved them through a copy at an odd
    /// offset, a `memcpy` call on the M4F (measured).
    fn solve(&self, pose: &Pose<T>, c: &mut Configuration<T>) -> Result<(), KinematicsError> {
        self.place(pose, c)?;
        self.solve_chains(c)
    }

    /// The first half of [`RingPlatform::solve`]: the rotation and the platform joints of a valid pose into `c`.
    #[inline(always)]
    fn place(&self, pose: &Pose<T>, c: &mut Configuration<T>) -> Result<(), KinematicsError> {
        let pose = pose.validated()?;
        c.rotation = pose.rotation();
        self.place_joints(&pose, c);
        Ok(())
    }

    /// The second half of [`RingPlatform::solve`]: each chain's actuators, carriage, base and direction from its
    /// joint in `c`, and the reach margin. The direction is taken here, while the chain's joint and base are still
    /// in registers, rather than in a loop of its own that loads them again.
    ///
    /// Never inlined: the envelope search's checks call it after their reach check, and a copy of the per-chain
    /// code there took 1 KB of flash.
    #[inline(never)]
    fn solve_chains(&self, c: &mut Configuration<T>) -> Result<(), KinematicsError> {
        let mut reach = T::max_value().unwrap_or(T::one());
        for i in 0..self.n {
            let joint = c.joints[i];
            let (carriage, base, margin) = self.chain(i, &joint, &mut c.q.0)?;
            c.carriages[i] = carriage;
            c.bases[i] = base;
            c.dirs[i] = direction(&joint, &base);
            reach = reach.min_(margin);
        }
        c.reach = reach;
        Ok(())
    }

    /// Chain `i`'s actuators for its platform joint `a` into `q`, its carriage, the start of its last link (the
    /// carriage, or an elbow chain's elbow) and its reach margin, from the joint's distance from the axis and the
    /// rod's or actuator's length that IK computes anyway (as [`RingPlatform::reach_of`] gives it).
    ///
    /// Always inlined: IK alone keeps only the actuators, and the compiler drops the rest where it sees it unused.
    #[inline(always)]
    fn chain(&self, i: usize, a: &Vector3<T>, q: &mut [T; 6]) -> Result<ChainSolution<T>, KinematicsError> {
        let chain = i as u8;
        let tiny = self.rr * T::of(T::EPS * 16.0);
        let rho2 = a.x * a.x + a.y * a.y;
        let rho = rho2.sqrt_();
        if rho <= tiny {
            return Err(KinematicsError::Unreachable {
                chain,
                reason: Reach::Centre,
            });
        }
        match self.kinds[i] {
            Shape::Rod(branch) => {
                let h2 = self.rod * self.rod - a.z * a.z;
                if h2 <= T::zero() {
                    return Err(KinematicsError::Unreachable {
                        chain,
                        reason: Reach::Height,
                    });
                }
                // (2 Rr rho sin phi)^2 factors into (h^2 - (Rr - rho)^2) ((Rr + rho)^2 - h^2): both factors
                // non-negative is the reach condition, and the factored form keeps sin phi accurate near 0 and
                // pi, where the cosine rule alone would lose half the digits.
                let inner = h2 - (self.rr - rho) * (self.rr - rho);
                let outer = (self.rr + rho) * (self.rr + rho) - h2;
                if inner < T::zero() || outer < T::zero() {
                    return Err(KinematicsError::Unreachable {
                        chain,
                        reason: Reach::Ring,
                    });
                }
                let sine = (inner * outer).sqrt_();
                let cosine = self.rr * self.rr + rho2 - h2;
                let sine = match branch {
                    Branch::Plus => sine,
                    Branch::Minus => -sine,
                };
                let (cx, cy) = (a.x * cosine - a.y * sine, a.y * cosine + a.x * sine);
                q[i] = cy.atan2_(cx);
                let scale = T::one() / (rho2 + rho2);
                let carriage = Vector3::new(cx * scale, cy * scale, T::zero());
                Ok((carriage, carriage, self.rod_reach(rho, a.z, h2)))
            }
            Shape::Radial => {
                q[i] = a.y.atan2_(a.x);
                let scale = self.rr / rho;
                let carriage = Vector3::new(a.x * scale, a.y * scale, T::zero());
                let length = self.radial_length(rho, a.z);
                if let Some(k) = self.length_axis[i] {
                    q[k] = length;
                }
                Ok((carriage, carriage, self.stroke_reach(length)))
            }
            Shape::Elbow => {
                // The carriage is on the joint's radius, as a radial chain's; the arm is a planar dyad there.
                q[i] = a.y.atan2_(a.x);
                let (cq, sq) = (a.x / rho, a.y / rho);
                let carriage = Vector3::new(self.rr * cq, self.rr * sq, T::zero());
                let Some(arm) = &self.arms[i] else {
                    return Ok((carriage, carriage, T::zero()));
                };
                let s = arm.shoulder(rho, a.z).ok_or(KinematicsError::Unreachable {
                    chain,
                    reason: Reach::Dyad,
                })?;
                q[arm.axis] = s.angle;
                Ok((carriage, arm.elbow(cq, sq, s.cos, s.sin), arm.reach(rho, a.z)))
            }
        }
    }
}

/// A pose `offset` from `home` in the tests: translations in ring radii `rr`, rotations in radians.
#[cfg(test)]
fn away_from(home: &[f64; 6], offset: &[f64; 6], rr: f64) -> [f64; 6] {
    core::array::from_fn(|i| home[i] + offset[i] * if i < 3 { rr } else { 1.0 })
}

impl<T: Real> Mechanism<T> for RingPlatform<T> {
    type Guard = SlowCheckGuard<T>;

    fn dof(&self) -> usize {
        6
    }

    fn axes(&self) -> [AxisKind; 6] {
        self.axes
    }

    fn characteristic_length(&self) -> T {
        self.rr
    }

    /// IK alone keeps no configuration: only the rotation and the actuators, so nothing of the 348 bytes that
    /// the checks need is cleared or stored.
    fn inverse(&self, pose: &Pose<T>) -> Result<Actuators<T>, KinematicsError> {
        let pose = pose.validated()?;
        let (r, p) = (pose.rotation(), pose.position());
        let mut q = [T::zero(); 6];
        for i in 0..self.n {
            self.chain(i, &(r * self.points[i] + p), &mut q)?;
        }
        Ok(Actuators(q))
    }

    /// IK and the checks on what it found (the rotation, joints and carriages are not computed twice).
    fn inverse_checked(&self, pose: &Pose<T>) -> Result<(Actuators<T>, WorkspaceReport<T>), KinematicsError> {
        // `solve` with its `place` opened up: the rotation goes into the configuration as it is made, so the
        // `memclr` clearing the rest is 36 bytes shorter (38 instructions of IK with the checks, measured).
        let pose = pose.validated()?;
        let mut c = Configuration {
            rotation: pose.rotation(),
            ..Configuration::zeroed()
        };
        self.place_joints(&pose, &mut c);
        self.solve_chains(&mut c)?;
        Ok((c.q, self.report(&pose, &c)))
    }

    /// IK and the checks in their order, each evaluated only while every one before it left its room: a point of
    /// the envelope search outside the workspace mostly fails the reach check, and then skips the joint cones,
    /// the singularity index (a 6x6 decomposition) and the stability.
    fn inverse_within(&self, pose: &Pose<T>, room: &[T; 6]) -> Result<Actuators<T>, Check> {
        self.within(pose, room, &mut Configuration::zeroed())
    }

    /// [`Mechanism::inverse_within`] in the guard's configuration of the pose being checked: IK writes every entry
    /// the checks read (`shared/tests` fill it with NaN first and compare), so nothing is cleared (a 348-byte
    /// `memclr`, 155 instructions on the M4F, per evaluation).
    fn inverse_within_in(
        &self,
        pose: &Pose<T>,
        room: &[T; 6],
        guard: &mut SlowCheckGuard<T>,
    ) -> Result<Actuators<T>, Check> {
        self.within(pose, room, guard.checked())
    }

    /// IK and the checks, the joint cones and the singularity index proved by [`SlowCheckGuard`] when they can be.
    fn inverse_guarded(
        &self,
        pose: &Pose<T>,
        guard: &mut SlowCheckGuard<T>,
    ) -> Result<(Actuators<T>, WorkspaceReport<T>), KinematicsError> {
        // The configuration solved into; evaluating the slow checks there makes it the reference, and the next
        // pose goes into the other.
        let current = guard.current & 1;
        let c = &mut guard.configs[current];
        self.solve(pose, c)?;
        let (slow, _) = self.slow_margins(guard);
        let c = &guard.configs[current];
        Ok((c.q, self.report_with(pose, c, &slow)))
    }

    fn residuals(&self, pose: &Pose<T>, q: &Actuators<T>) -> Vector6<T> {
        let joints = self.joints(pose);
        let mut f = Vector6::zeros();
        let mut extra = self.n;
        for i in 0..self.n {
            let (a, qi) = (joints[i], q.0[i]);
            let (d, length) = match (&self.arms[i], self.length_axis[i]) {
                (Some(arm), _) => (a - self.elbow(arm, qi, q.0[arm.axis]), arm.l2),
                (None, Some(k)) => (a - self.carriage(qi), q.0[k]),
                (None, None) => (a - self.carriage(qi), self.rod),
            };
            f[i] = d.dot(&d) - length * length;
            if self.kinds[i].is_planar() && extra < 6 {
                let (s, c) = qi.sin_cos_();
                f[extra] = a.x * s - a.y * c;
                extra += 1;
            }
        }
        f
    }

    fn jacobians(&self, pose: &Pose<T>, q: &Actuators<T>) -> Jacobians<T> {
        let joints = self.joints(pose);
        let [da, db, dg] = pose.rotation_partials();
        let mut a_mat = Matrix6::zeros();
        let mut b_mat = Matrix6::zeros();
        let mut extra = self.n;
        let two = T::of(2.0);
        for i in 0..self.n {
            let (a, qi) = (joints[i], q.0[i]);
            let (s, c) = qi.sin_cos_();
            let p = &self.points[i];
            // Columns dA/dp_k of this joint.
            let partials = [Vector3::x(), Vector3::y(), Vector3::z(), da * p, db * p, dg * p];
            let second = match &self.arms[i] {
                Some(arm) => {
                    // dF/dq = -2 d . dE/dq with dE/dq = r_e (-sin q, cos q, 0), r_e the elbow's distance from the
                    // axis; dF/ds = -2 d . dE/ds with dE/ds = l1 (sin s (cos q, sin q, 0) + cos s z).
                    let shoulder = q.0[arm.axis];
                    let (ss, cs) = shoulder.sin_cos_();
                    let d = a - arm.elbow(c, s, cs, ss);
                    for (k, da) in partials.iter().enumerate() {
                        a_mat[(i, k)] = two * d.dot(da);
                    }
                    b_mat[(i, i)] = -two * (arm.rs - arm.l1 * cs) * (-d.x * s + d.y * c);
                    b_mat[(i, arm.axis)] = -two * arm.l1 * (ss * (d.x * c + d.y * s) + cs * d.z);
                    Some(arm.axis)
                }
                None => {
                    let d = a - self.carriage(qi);
                    for (k, da) in partials.iter().enumerate() {
                        a_mat[(i, k)] = two * d.dot(da);
                    }
                    // dF/dq = -2 d . dB/dq with dB/dq = Rr (-sin q, cos q, 0).
                    b_mat[(i, i)] = -two * self.rr * (-d.x * s + d.y * c);
                    if let Some(k) = self.length_axis[i] {
                        b_mat[(i, k)] = -two * q.0[k];
                    }
                    self.length_axis[i]
                }
            };
            // The planarity row of a radial or elbow chain.
            if second.is_some() && extra < 6 {
                for (col, da) in partials.iter().enumerate() {
                    a_mat[(extra, col)] = s * da.x - c * da.y;
                }
                b_mat[(extra, i)] = a.x * c + a.y * s;
                extra += 1;
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
        self.report(pose, &self.configuration(pose, q))
    }
}
