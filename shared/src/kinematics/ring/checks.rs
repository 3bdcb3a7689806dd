//! The six workspace checks of a ring platform (KINEMATICS.md 4), each with a signed margin, from one
//! [`Configuration`] computed once per pose.
//!
//! The control tick runs these for every commanded pose, so each is written for the Cortex-M4F: no check repeats
//! the rotation, the joints or the carriages, the cone margins take two `asin` instead of twelve (`asin` is
//! increasing, so the smallest angle is the `asin` of the smallest sine), and the singularity index takes its
//! determinant through a planar chain's joint without pivoting (a platform of six rod chains decomposes its 6x6
//! matrix on plain arrays).

use nalgebra::{Matrix3, Vector3};

use super::{RingPlatform, Shape};
use crate::kinematics::velocity::hadamard_ratio_in_place;
use crate::kinematics::workspace::short_of;
use crate::kinematics::{Actuators, Check, Pose, WorkspaceReport};
use crate::real::{length, wrap_pi};
use crate::Real;

/// Where everything of one pose is: computed once for all the checks (and for the statics).
#[derive(Debug, Clone, Copy)]
pub(super) struct Configuration<T: Real> {
    /// The actuators.
    pub q: Actuators<T>,
    /// Platform orientation.
    pub rotation: Matrix3<T>,
    /// Platform joints `A_i` in the base frame.
    pub joints: [Vector3<T>; 6],
    /// Carriage joints `B_i` on the ring.
    pub carriages: [Vector3<T>; 6],
    /// Where each chain's last link starts: the carriage joint, or an elbow chain's elbow.
    pub bases: [Vector3<T>; 6],
    /// Unit vector along each chain's last link, toward the platform joint.
    pub dirs: [Vector3<T>; 6],
    /// The reach margin ([`RingPlatform::reach_of`] the joints), which IK's chains give at little cost.
    pub reach: T,
}

/// The checks that cost the most and change slowly with the pose: the joint-cone margin (rad) and the raw
/// singularity index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SlowMargins<T> {
    pub cones: T,
    pub index: T,
}

impl<T: Real> Configuration<T> {
    /// Everything at zero, to be filled in place (these arrays are too large to move around on the M4F: each move
    /// is a `memcpy` call). One `memclr`: nothing of a chain past the platform's is read, so no entry needs another
    /// value.
    pub fn zeroed() -> Self {
        Self {
            q: Actuators([T::zero(); 6]),
            rotation: Matrix3::zeros(),
            joints: [Vector3::zeros(); 6],
            carriages: [Vector3::zeros(); 6],
            bases: [Vector3::zeros(); 6],
            dirs: [Vector3::zeros(); 6],
            reach: T::zero(),
        }
    }

    /// The directions of the first `n` chains' last links, from their joints and bases.
    pub fn direct(&mut self, n: usize) {
        for i in 0..n.min(6) {
            self.dirs[i] = direction(&self.joints[i], &self.bases[i]);
        }
    }
}

/// The unit vector from a chain's base to its platform joint; a link of no length points up.
#[inline(always)]
pub(super) fn direction<T: Real>(joint: &Vector3<T>, base: &Vector3<T>) -> Vector3<T> {
    let d = joint - base;
    let len = length(&d);
    if len > T::zero() {
        d / len
    } else {
        Vector3::z()
    }
}

impl<T: Real> RingPlatform<T> {
    /// The configuration of a pose with given actuators (carriages from their angles).
    pub(super) fn configuration(&self, pose: &Pose<T>, q: &Actuators<T>) -> Configuration<T> {
        let mut c = Configuration::zeroed();
        c.q = *q;
        c.rotation = pose.rotation();
        self.place_joints(pose, &mut c);
        for i in 0..self.n {
            let qi = q.0[i];
            c.carriages[i] = self.carriage(qi);
            c.bases[i] = match &self.arms[i] {
                Some(arm) => self.elbow(arm, qi, q.0[arm.axis]),
                None => c.carriages[i],
            };
        }
        c.direct(self.n);
        c.reach = self.reach_of(&c.joints);
        c
    }

    /// All six margins, in the order of [`crate::kinematics::Check::ALL`].
    pub(super) fn report(&self, pose: &Pose<T>, c: &Configuration<T>) -> WorkspaceReport<T> {
        let slow = SlowMargins {
            cones: self.cone_margin(c),
            index: self.singularity_of(c),
        };
        self.report_with(pose, c, &slow)
    }

    /// The margins with the slow ones given (evaluated, or proved by [`super::guard`]).
    pub(super) fn report_with(
        &self,
        pose: &Pose<T>,
        c: &Configuration<T>,
        slow: &SlowMargins<T>,
    ) -> WorkspaceReport<T> {
        let (spacing, order, ring_order) = self.spacing_and_order(&c.q);
        WorkspaceReport::new(
            [
                Some(c.reach),
                Some(spacing),
                Some(order),
                Some(slow.cones),
                Some(slow.index - self.min_index),
                Some(self.stability_margin(pose, c, ring_order.as_ref())),
            ],
            slow.index,
        )
    }

    /// IK and the checks in the order of [`Check::ALL`], up to the first short of its `room` (see
    /// [`crate::kinematics::Mechanism::inverse_within`]): the margins are those of [`RingPlatform::report`].
    ///
    /// Never inlined: inlined, it changed how LTO inlined IK with all the checks beside it (measured under QEMU:
    /// +85 instructions there, and FK +83), for 250 fewer instructions of the envelope search's eight calls.
    #[inline(never)]
    pub(super) fn within(
        &self,
        pose: &Pose<T>,
        room: &[T; 6],
        c: &mut Configuration<T>,
    ) -> Result<Actuators<T>, Check> {
        let leaves = |check: Check, margin: T| {
            if short_of(margin, room[check.index()]) {
                Err(check)
            } else {
                Ok(())
            }
        };
        // The reach margin needs only the joints: a point short of it (most of the envelope search's points
        // outside) skips the chains' solves (their atan2). A pose has no IK or is short of its reach room alike
        // as before: either is the reach check's.
        self.place(pose, c).map_err(|_| Check::Reach)?;
        leaves(Check::Reach, self.reach_of(&c.joints))?;
        self.solve_chains(c).map_err(|_| Check::Reach)?;
        let (spacing, order, ring_order) = self.spacing_and_order(&c.q);
        leaves(Check::CarriageSpacing, spacing)?;
        leaves(Check::RodCrossing, order)?;
        leaves(Check::JointCones, self.cone_margin(c))?;
        leaves(Check::Singularity, self.singularity_of(c) - self.min_index)?;
        leaves(Check::Stability, self.stability_margin(pose, c, ring_order.as_ref()))?;
        Ok(c.q)
    }

    /// The spacing and crossing margins, and the chains' order around the ring when the crossing margin says the
    /// chain order is broken: the spacing (and the support polygon) are then measured around the ring instead, so
    /// that they still say how far outside.
    #[inline(always)]
    fn spacing_and_order(&self, q: &Actuators<T>) -> (T, T, Option<[usize; 6]>) {
        let (spacing, order) = self.ring_order_margins(q);
        let ring_order = (order < T::zero()).then(|| self.ring_order(q));
        let spacing = ring_order.as_ref().map_or(spacing, |o| self.spacing_around(q, o));
        (spacing, order, ring_order)
    }

    pub(super) fn reach_of(&self, joints: &[Vector3<T>; 6]) -> T {
        let mut margin = T::max_value().unwrap_or(T::one());
        for (i, (a, kind)) in joints.iter().zip(&self.kinds).enumerate().take(self.n) {
            let rho = (a.x * a.x + a.y * a.y).sqrt_();
            let m = match kind {
                Shape::Rod(_) => self.rod_reach(rho, a.z, self.rod * self.rod - a.z * a.z),
                Shape::Radial => self.stroke_reach(self.radial_length(rho, a.z)),
                Shape::Elbow => match &self.arms[i] {
                    Some(arm) => arm.reach(rho, a.z),
                    None => T::zero(),
                },
            };
            margin = margin.min_(m);
        }
        margin
    }

    /// A rod chain's reach margin from its joint's distance from the axis `rho`, its height `z` and
    /// `h2 = L^2 - z^2`: the slack of `|z| < L` and `|Rr - rho| <= h <= Rr + rho`.
    #[inline(always)]
    pub(super) fn rod_reach(&self, rho: T, z: T, h2: T) -> T {
        let h = h2.max_(T::zero()).sqrt_();
        (self.rod - z.abs())
            .min_(h - (self.rr - rho).abs())
            .min_(self.rr + rho - h)
    }

    /// A radial chain's length, from its joint's distance from the axis and its height.
    #[inline(always)]
    pub(super) fn radial_length(&self, rho: T, z: T) -> T {
        ((self.rr - rho) * (self.rr - rho) + z * z).sqrt_()
    }

    /// A radial chain's reach margin: the slack of its length within the stroke.
    #[inline(always)]
    pub(super) fn stroke_reach(&self, length: T) -> T {
        (length - self.stroke[0]).min_(self.stroke[1] - length)
    }

    /// Spacing and crossing margins from the counter-clockwise central angles between neighbouring carriages.
    ///
    /// Each gap is measured counter-clockwise in `[0, 2pi)`. The carriages keep their order exactly when the gaps
    /// add up to one turn; two turns or more means some carriage passed a neighbour, and the crossing margin is
    /// then minus the smallest angle by which the order is broken.
    pub(super) fn ring_order_margins(&self, q: &Actuators<T>) -> (T, T) {
        let two_pi = T::two_pi();
        let mut smallest = two_pi;
        let mut largest = T::zero();
        let mut total = T::zero();
        for i in 0..self.n {
            let diff = q.0[(i + 1) % self.n] - q.0[i];
            // IK's angles are within (-pi, pi], so one exact addition wraps their difference into [0, 2pi) (a
            // difference down to -pi, or wrapped below 0 from above pi, takes a turn); other inputs (a multi-turn
            // angle) take the general wrap. Two comparisons, one fewer than wrapping into (-pi, pi] and then into
            // [0, 2pi), for the same gaps.
            let gap = if diff.abs() <= T::two_pi() {
                let gap = if diff > T::pi() { diff - two_pi } else { diff };
                if gap < T::zero() {
                    gap + two_pi
                } else {
                    gap
                }
            } else {
                let gap = wrap_pi(diff);
                if gap < T::zero() {
                    gap + two_pi
                } else {
                    gap
                }
            };
            total += gap;
            smallest = smallest.min_(gap);
            largest = largest.max_(gap);
        }
        // The least `gap - spacing[0]` is the smallest gap's and the least `spacing[1] - gap` the largest's (a
        // subtraction rounds monotonically), so the spacing margin takes two comparisons in all rather than two a
        // chain (four instructions each on the M4F). A NaN gap is left out of both, as `min_` leaves it out of a
        // margin taken gap by gap; with no gap the margin is the largest value.
        let spacing = if smallest <= largest {
            (smallest - self.spacing[0]).min_(self.spacing[1] - largest)
        } else {
            T::max_value().unwrap_or(T::one())
        };
        // A carriage that passed its neighbour by d leaves a gap of 2pi - d behind it.
        let order = if total < two_pi + T::pi() {
            smallest
        } else {
            -(two_pi - largest)
        };
        (spacing, order)
    }

    /// The smallest angle of a chain to the base plane and to the platform plane, each above its cone limit. An
    /// elbow chain has no ball joint at the base (its shoulder is a revolute, limited by its travel): only its
    /// forearm's angle to the platform plane counts.
    pub(super) fn cone_margin(&self, c: &Configuration<T>) -> T {
        let normal = c.rotation.column(2).into_owned();
        let (mut base, mut platform) = (T::one(), T::one());
        for (u, arm) in c.dirs.iter().zip(&self.arms).take(self.n) {
            if arm.is_none() {
                base = base.min_(u.z);
            }
            platform = platform.min_(u.dot(&normal));
        }
        let angle = |sine: T| sine.clamp(-T::one(), T::one()).asin_();
        (angle(base) - self.cones[0]).min_(angle(platform) - self.cones[1])
    }

    /// The scale-free singularity index of the wrench matrix (moments divided by the ring radius): Hadamard's ratio
    /// `|det W| / prod_i |w_i|`, the determinant through a planar chain's joint when there is one (see
    /// [`RingPlatform::through_joint`]), else by LU.
    pub(super) fn singularity_of(&self, c: &Configuration<T>) -> T {
        let Some((det, squares)) = self.through_joint(c) else {
            return hadamard_ratio_in_place(&mut self.wrench_rows_scaled(c, T::one() / self.rr)).0;
        };
        // The product of the squared norms under one root, where six roots each cost five instructions on the M4F.
        let norms = squares.sqrt_();
        if norms == T::zero() || !norms.finite() || !det.finite() {
            return T::zero();
        }
        (det / norms).abs()
    }

    /// `det W` of the wrench rows (moments divided by the ring radius) and the product of their squared norms, by
    /// the lines through the joint `A` of the first planar chain `k`, whose tangent row is row `n`; `None` for a
    /// platform without one.
    ///
    /// Both of chain `k`'s lines pass through `A`: its last link ends there and its tangent force acts there.
    /// Taking every moment about `A` instead of the ring centre subtracts `A x f` from each row's moment, a
    /// multiple of its force columns, which leaves the determinant as it is; those two rows then have no moment,
    /// and Laplace's expansion along them leaves one 4x4 determinant per force column. With the other four rows'
    /// forces `f_i` and moments about `A` `m_i`, and `g_i = (-1)^i det` of the moments without row `i` (the
    /// cofactors of a 4x3 matrix), those are the components of `D = sum_i g_i f_i`, and
    /// `det W = +-(u x v) . D / Rr^3` for the chain's direction `u` and tangent `v` (the sign of the row order
    /// `k`, `n`, then the rest; a moment column divided by `Rr` divides the determinant by it). About 260
    /// arithmetic operations with the rows' norms, and no pivot's branch, where the wrench matrix, its norms and its
    /// LU with partial pivoting took about 780 instructions on the M4F. Without pivoting, its error is bounded by the rounding of each
    /// product (the minors of unit rows are at most 1, by Hadamard's inequality); tested against the LU over the
    /// workspace of every ring preset.
    pub(super) fn through_joint(&self, c: &Configuration<T>) -> Option<(T, T)> {
        let (k, t) = (usize::from(self.tangent_rows[0]), self.n);
        if k >= t || t >= 6 {
            return None;
        }
        let inv = T::one() / self.rr;
        let inv2 = inv * inv;
        let square = |f: &Vector3<T>, m: &Vector3<T>| f.dot(f) + m.dot(m) * inv2;
        let a = c.joints[k];
        let (u, b) = self.line(c, k);
        let (v, _) = self.line(c, t);
        let mut squares = square(&u, &b.cross(&u)) * square(&v, &a.cross(&v));
        let mut f = [Vector3::zeros(); 4];
        let mut m = [Vector3::zeros(); 4];
        for (j, &r) in self.others.iter().enumerate() {
            let (fj, p) = self.line(c, usize::from(r));
            squares *= square(&fj, &p.cross(&fj));
            f[j] = fj;
            m[j] = (p - a).cross(&fj);
        }
        let (m01, m23) = (m[0].cross(&m[1]), m[2].cross(&m[3]));
        let g = [m[1].dot(&m23), -m[0].dot(&m23), m[3].dot(&m01), -m[2].dot(&m01)];
        let d = f[0] * g[0] + f[1] * g[1] + f[2] * g[2] + f[3] * g[3];
        let det = u.cross(&v).dot(&d) * (inv2 * inv);
        // Row k to the front passes k rows, row t to second place t - 1 more.
        Some((if (k + t) % 2 == 0 { -det } else { det }, squares))
    }

    /// The chains in the order their carriages come around the ring (counter-clockwise from angle 0).
    pub(super) fn ring_order(&self, q: &Actuators<T>) -> [usize; 6] {
        let angle = |i: usize| {
            let a = wrap_pi(q.0[i]);
            if a < T::zero() {
                a + T::two_pi()
            } else {
                a
            }
        };
        let mut order = [0, 1, 2, 3, 4, 5];
        // Insertion sort of at most six.
        for k in 1..self.n {
            let mut j = k;
            while j > 0 && angle(order[j]) < angle(order[j - 1]) {
                order.swap(j, j - 1);
                j -= 1;
            }
        }
        order
    }

    /// The spacing margin over the gaps between carriages that are neighbours around the ring.
    fn spacing_around(&self, q: &Actuators<T>, order: &[usize; 6]) -> T {
        let mut spacing = T::max_value().unwrap_or(T::one());
        for k in 0..self.n {
            let (i, j) = (order[k], order[(k + 1) % self.n]);
            let mut gap = wrap_pi(q.0[j] - q.0[i]);
            if gap < T::zero() {
                gap += T::two_pi();
            }
            spacing = spacing.min_(gap - self.spacing[0]).min_(self.spacing[1] - gap);
        }
        spacing
    }

    /// Distance of the centre of mass inside the polygon of the carriages, taken in chain order, or around the ring
    /// when the order is broken.
    fn stability_margin(&self, pose: &Pose<T>, c: &Configuration<T>, order: Option<&[usize; 6]>) -> T {
        let com = c.rotation * self.com + pose.position();
        let mut margin = T::max_value().unwrap_or(T::one());
        let at = |k: usize| order.map_or(k, |o| o[k]);
        if self.n == 0 {
            return margin;
        }
        // The closing edge first, then each from the corner before: the same edges as (k, k + 1 mod n) without a
        // division a corner (their minimum does not depend on the order; any edge of no length gives 0).
        let mut p0 = c.carriages[at(self.n - 1)];
        for k in 0..self.n {
            let p1 = c.carriages[at(k)];
            let edge = p1 - p0;
            let len = (edge.x * edge.x + edge.y * edge.y).sqrt_();
            if len == T::zero() {
                return T::zero();
            }
            // Counter-clockwise polygon: the inside is on the left of each edge.
            let cross = edge.x * (com.y - p0.y) - edge.y * (com.x - p0.x);
            margin = margin.min_(cross / len);
            p0 = p1;
        }
        margin
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::kinematics::geometry::{Branch, Chain, ChainKind, RingGeometry};
    use crate::kinematics::presets::{Preset, PresetGeometry};
    use crate::kinematics::Mechanism;
    use crate::real::wrap_once;

    /// The spacing and crossing margins taken gap by gap, the spacing of every gap: what
    /// [`RingPlatform::ring_order_margins`] must give.
    fn every_gap<T: Real>(m: &RingPlatform<T>, q: &Actuators<T>) -> (T, T) {
        let two_pi = T::two_pi();
        let mut spacing = T::max_value().unwrap_or(T::one());
        let (mut smallest, mut largest, mut total) = (two_pi, T::zero(), T::zero());
        for i in 0..m.n {
            let diff = q.0[(i + 1) % m.n] - q.0[i];
            let mut gap = if diff.abs() <= T::two_pi() {
                wrap_once(diff)
            } else {
                wrap_pi(diff)
            };
            if gap < T::zero() {
                gap += two_pi;
            }
            total += gap;
            spacing = spacing.min_(gap - m.spacing[0]).min_(m.spacing[1] - gap);
            smallest = smallest.min_(gap);
            largest = largest.max_(gap);
        }
        let order = if total < two_pi + T::pi() {
            smallest
        } else {
            -(two_pi - largest)
        };
        (spacing, order)
    }

    /// The stability margin edge (k, k + 1 mod n) after edge: what
    /// [`RingPlatform::stability_margin`] must give.
    fn edge_by_edge<T: Real>(
        m: &RingPlatform<T>,
        pose: &Pose<T>,
        c: &Configuration<T>,
        order: Option<&[usize; 6]>,
    ) -> T {
        let com = c.rotation * m.com + pose.position();
        let mut margin = T::max_value().unwrap_or(T::one());
        let at = |k: usize| order.map_or(k, |o| o[k]);
        for k in 0..m.n {
            let (p0, p1) = (c.carriages[at(k)], c.carriages[at((k + 1) % m.n)]);
            let edge = p1 - p0;
            let len = (edge.x * edge.x + edge.y * edge.y).sqrt_();
            if len == T::zero() {
                return T::zero();
            }
            let cross = edge.x * (com.y - p0.y) - edge.y * (com.x - p0.x);
            margin = margin.min_(cross / len);
        }
        margin
    }

    fn compare_stability<T: Real>(offset: &[f64; 6], angles: &[f64; 6]) {
        for preset in Preset::ALL {
            let PresetGeometry::Ring(g) = preset.geometry() else {
                continue;
            };
            let m = RingPlatform::<T>::new(g);
            let rr = g.ring_radius;
            let home = preset.home();
            let pose = Pose::from_array(super::super::away_from(&home, offset, rr).map(T::of));
            // Carriages where IK puts them, and at any angles (in and out of order, on top of each other).
            let mut c = Configuration::zeroed();
            let solved = m.solve(&pose, &mut c).is_ok();
            let q = Actuators(angles.map(T::of));
            let mut wild = m.configuration(&pose, &q);
            wild.carriages[1] = wild.carriages[0];
            for c in [&c, &m.configuration(&pose, &q), &wild]
                .into_iter()
                .skip(usize::from(!solved))
            {
                let ring = m.ring_order(&c.q);
                for order in [None, Some(&ring)] {
                    let (new, old) = (m.stability_margin(&pose, c, order), edge_by_edge(&m, &pose, c, order));
                    assert!(same((new, new), (old, old)), "{}: {new:?} != {old:?}", preset.name());
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        #[test]
        fn the_stability_margin_from_the_closing_edge_first_is_that_edge_by_edge(
            t in prop::array::uniform3(-0.5f64..0.5),
            r in prop::array::uniform3(-0.8f64..0.8),
            angles in prop::array::uniform6(-4.0f64..4.0),
        ) {
            let offset = [t[0], t[1], t[2], r[0], r[1], r[2]];
            compare_stability::<f32>(&offset, &angles);
            compare_stability::<f64>(&offset, &angles);
        }
    }

    /// Equal as values, or both NaN.
    fn same<T: Real>(a: (T, T), b: (T, T)) -> bool {
        let eq = |x: T, y: T| x == y || (x.partial_cmp(&x).is_none() && y.partial_cmp(&y).is_none());
        eq(a.0, b.0) && eq(a.1, b.1)
    }

    fn compare<T: Real>(angles: &[f64; 6]) {
        for preset in Preset::ALL {
            let PresetGeometry::Ring(g) = preset.geometry() else {
                continue;
            };
            let m = RingPlatform::<T>::new(g);
            let q = Actuators(angles.map(T::of));
            let (new, old) = (m.ring_order_margins(&q), every_gap(&m, &q));
            assert!(same(new, old), "{}: {new:?} != {old:?} at {q:?}", preset.name());
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(5_000))]

        /// Angles of IK (within a half turn), of a wound-up carriage, and any bits at all (NaN and infinities).
        #[test]
        fn the_spacing_margin_from_the_extreme_gaps_is_that_of_every_gap(
            within in prop::array::uniform6(-core::f64::consts::PI..=core::f64::consts::PI),
            wound in prop::array::uniform6(-40.0f64..40.0),
            bits in prop::array::uniform6(any::<u64>()),
        ) {
            for angles in [within, wound, bits.map(f64::from_bits)] {
                compare::<f32>(&angles);
                compare::<f64>(&angles);
            }
        }
    }

    /// The determinant through a planar chain's joint against the LU's of the same rows, in `f64` (signed, so a
    /// wrong row-order sign fails), and the index in `T` against the LU's index in `f64` of the same inputs, at IK's
    /// actuators when the pose has them and at `any` others; false for a platform without a planar chain.
    fn compare_index_on<T: Real>(g: &RingGeometry, home: &[f64; 6], offset: &[f64; 6], any: &[f64; 6]) -> bool {
        let (m, wide) = (RingPlatform::<T>::new(g), RingPlatform::<f64>::new(g));
        if m.through_joint(&Configuration::zeroed()).is_none() {
            return false;
        }
        let rr = g.ring_radius;
        let pose = super::super::away_from(home, offset, rr);
        let solved = wide.inverse(&Pose::from_array(pose)).ok().map(|q| q.0);
        for q in solved.into_iter().chain([*any]) {
            // The reference takes the inputs as rounded to `T`: what is compared is the arithmetic.
            let (pose, q) = (Pose::from_array(pose.map(T::of)), Actuators(q.map(T::of)));
            let c = m.configuration(&pose, &q);
            let widened = Pose::from_array(pose.to_array().map(T::to_f64));
            let reference = wide.configuration(&widened, &Actuators(q.0.map(T::to_f64)));
            let rows = wide.wrench_rows_scaled(&reference, 1.0 / rr);
            let norms: f64 = rows
                .iter()
                .map(|r| r.iter().map(|v| v * v).sum::<f64>().sqrt())
                .product();
            let lu = crate::kinematics::velocity::Lu6::in_place(&mut { rows }).determinant();
            let (through, squares) = wide.through_joint(&reference).unwrap();
            assert!(
                (through - lu).abs() <= 1e-12 * norms && (squares.sqrt() - norms).abs() <= 1e-12 * norms,
                "{}: {through} against the LU's {lu}, norms {} against {norms} at {widened:?}, {q:?}",
                squares.sqrt(),
                g.name
            );
            // Within what the LU itself gives in `f32` (7e-7 at worst over 25,000 poses of the workspace).
            let (index, old) = (m.singularity_of(&c).to_f64(), (lu / norms).abs());
            let tolerance = if T::EPS > 1e-10 { 1e-6 } else { 1e-12 };
            assert!(
                (index - old).abs() <= tolerance,
                "{}: index {index} against the LU's {old} at {widened:?}, {q:?}",
                g.name
            );
        }
        true
    }

    /// Platforms with the planar chain first, last, among rods and alone with others of its kind: every place the
    /// first planar chain and its tangent row can take among the rows.
    fn mixed_platforms() -> [RingGeometry; 5] {
        let chain = |kind: ChainKind, k: usize, n: usize| {
            let angle = core::f64::consts::TAU * k as f64 / n as f64 + 0.3;
            Chain {
                kind,
                platform_point: [0.6 * libm::cos(angle), 0.6 * libm::sin(angle), 0.0],
            }
        };
        let (plus, minus) = (ChainKind::Rod(Branch::Plus), ChainKind::Rod(Branch::Minus));
        let elbow = ChainKind::Elbow(crate::kinematics::presets::TRAINER_ELBOW_ARM);
        let limits = crate::kinematics::presets::TRAINER_MODEL.limits;
        let kinds: [&[ChainKind]; 5] = [
            &[plus, minus, plus, minus, ChainKind::Radial],
            &[ChainKind::Radial, plus, minus, plus, minus],
            &[ChainKind::Radial; 3],
            &[plus, ChainKind::Radial, minus, ChainKind::Radial],
            &[plus, minus, elbow, plus, minus],
        ];
        kinds.map(|kinds| {
            let chains: Vec<Chain> = kinds
                .iter()
                .enumerate()
                .map(|(k, &kind)| chain(kind, k, kinds.len()))
                .collect();
            RingGeometry::new("mixed", 1.0, 1.2, &chains, limits).unwrap()
        })
    }

    fn compare_index<T: Real>(offset: &[f64; 6], angles: &[f64; 6], lengths: &[f64; 2]) -> usize {
        let mut any = *angles;
        let mut compared = 0;
        for preset in Preset::ALL {
            let PresetGeometry::Ring(g) = preset.geometry() else {
                continue;
            };
            // The radial chains' lengths and the elbow chains' shoulders take the last two actuators.
            any[4] = lengths[0] * g.ring_radius;
            any[5] = lengths[1];
            compared += usize::from(compare_index_on::<T>(g, &preset.home(), offset, &any));
        }
        for g in mixed_platforms() {
            let home = [0.0, 0.0, 0.9, 0.0, 0.0, 0.0];
            // The last actuators are lengths or a shoulder, whichever the platform has.
            let any = core::array::from_fn(|i| {
                if i < g.chains().len() {
                    angles[i]
                } else {
                    lengths[i % 2]
                }
            });
            compared += usize::from(compare_index_on::<T>(&g, &home, offset, &any));
        }
        compared
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3_000))]

        /// Poses up to half a ring radius and 0.8 rad from home (inside the workspace and far beyond), and any
        /// carriage angles, lengths and shoulders.
        #[test]
        fn the_index_through_a_planar_chains_joint_is_the_lus(
            t in prop::array::uniform3(-0.5f64..0.5),
            r in prop::array::uniform3(-0.8f64..0.8),
            angles in prop::array::uniform6(-4.0f64..4.0),
            lengths in prop::array::uniform2(0.1f64..4.0),
        ) {
            let offset = [t[0], t[1], t[2], r[0], r[1], r[2]];
            prop_assert!(compare_index::<f32>(&offset, &angles, &lengths) >= 9);
            prop_assert!(compare_index::<f64>(&offset, &angles, &lengths) >= 9);
        }
    }

    fn compare_reach<T: Real>(offset: &[f64; 6]) -> usize {
        let mut solved = 0;
        for preset in Preset::ALL {
            let PresetGeometry::Ring(g) = preset.geometry() else {
                continue;
            };
            let m = RingPlatform::<T>::new(g);
            let (rr, home) = (g.ring_radius, preset.home());
            let pose = Pose::from_array(super::super::away_from(&home, offset, rr).map(T::of));
            let mut c = Configuration::zeroed();
            if m.solve(&pose, &mut c).is_ok() {
                let (chains, joints) = (c.reach, m.reach_of(&c.joints));
                assert!(
                    chains == joints,
                    "{}: {chains:?} != {joints:?} at {pose:?}",
                    preset.name()
                );
                solved += 1;
            }
        }
        solved
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3_000))]

        /// The reach margin the chains' solve gives is bit for bit that of the joints, wherever IK has a solution
        /// (inside the workspace and far beyond it).
        #[test]
        fn the_reach_from_the_chains_is_that_of_the_joints(
            t in prop::array::uniform3(-0.5f64..0.5),
            r in prop::array::uniform3(-0.8f64..0.8),
        ) {
            let offset = [t[0], t[1], t[2], r[0], r[1], r[2]];
            compare_reach::<f32>(&offset);
            compare_reach::<f64>(&offset);
        }
    }

    #[test]
    fn the_reach_from_the_chains_at_home() {
        assert!(compare_reach::<f32>(&[0.0; 6]) >= 5);
        assert!(compare_reach::<f64>(&[0.0; 6]) >= 5);
    }

    /// A singular wrench matrix (two chains' lines the same), rows of no length and entries that are not finite
    /// give the LU's index: 0.
    #[test]
    fn the_index_through_a_joint_at_the_edges() {
        let m = RingPlatform::<f32>::new(&crate::kinematics::presets::TRAINER_MODEL);
        let pose = Pose::from_array([0.0, 0.0, 0.227, 0.0, 0.0, 0.0]);
        let q = m.inverse(&pose).unwrap();
        let good = m.configuration(&pose, &q);
        assert!(m.singularity_of(&good) > 0.1);
        let mut same = good;
        same.dirs[1] = same.dirs[0];
        same.bases[1] = same.bases[0];
        assert!(m.singularity_of(&same) < 1e-6, "{}", m.singularity_of(&same));
        for value in [f32::NAN, f32::INFINITY, 0.0] {
            let mut bad = good;
            bad.dirs[3] = Vector3::new(value, value, value);
            bad.bases[3] = Vector3::new(value, value, value);
            assert_eq!(m.singularity_of(&bad), 0.0, "{value}");
        }
    }

    /// Carriages on top of each other, in a broken order and with one NaN angle.
    #[test]
    fn the_spacing_margin_at_the_edges() {
        let pi = core::f64::consts::PI;
        for angles in [
            [0.0; 6],
            [0.0, 0.0, pi, pi, -pi, -pi],
            [0.5, 0.1, 2.0, -2.0, 1.0, 3.0],
            [f64::NAN, 0.1, 2.0, -2.0, 1.0, 3.0],
            [f64::NAN; 6],
            [pi, -pi, pi, -pi, pi, -pi],
        ] {
            compare::<f32>(&angles);
            compare::<f64>(&angles);
        }
    }
}
