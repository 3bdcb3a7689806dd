//! The arm of an elbow chain (dissertation ch. 5.1, fig. 5.2) in the carriage's vertical radial plane: a planar
//! two-link problem from the shoulder to the platform joint, in closed form.
//!
//! In that plane, with `u` the horizontal unit vector from the shoulder toward the ring axis and `z` up, a platform
//! joint at distance `rho` from the axis and height `Az` is at `(w, v) = (Rs - rho, Az - hs)` from the shoulder.
//! With `d^2 = w^2 + v^2`, `phi` the triangle's angle at the shoulder, `C = l1^2 + d^2 - l2^2 = 2 l1 d cos phi` and
//! `S = sqrt((d^2 - (l1 - l2)^2) ((l1 + l2)^2 - d^2)) = 2 l1 d sin phi` (the factored form keeps `sin phi`
//! accurate near the folded and stretched arm), the upper arm's direction is the shoulder-to-joint direction turned
//! by `+-phi`: `(cos s, sin s) = (w C -+ v S, v C +- w S) / (2 l1 d^2)`, one `atan2` for the angle.

use nalgebra::Vector3;

use crate::kinematics::geometry::{Elbow, ElbowBranch};
use crate::real::wrap_pi;
use crate::Real;

/// An elbow chain's arm in scalar type `T`, with the limits of its reach check.
#[derive(Debug, Clone, Copy)]
pub(super) struct Arm<T> {
    /// Actuator index of the shoulder angle.
    pub axis: usize,
    /// Shoulder radius `Rs` and height `hs` (m).
    pub rs: T,
    pub hs: T,
    /// Upper arm `l1` and forearm `l2` (m).
    pub l1: T,
    pub l2: T,
    /// `+1` for [`ElbowBranch::Up`], `-1` for down.
    sign: T,
    /// Shoulder-to-joint distances at the elbow angle limits `[min, max]` (m): the elbow's interior angle grows
    /// with that distance, so the limit on the angle is a limit on the distance.
    pub span: [T; 2],
    /// The shoulder's travel (rad) and its middle, the centre of the window IK returns angles in.
    pub travel: [T; 2],
    middle: T,
}

/// The shoulder angle, and its cosine and sine.
#[derive(Debug, Clone, Copy)]
pub(super) struct Shoulder<T> {
    pub angle: T,
    pub cos: T,
    pub sin: T,
}

impl<T: Real> Arm<T> {
    /// The arm of a validated chain, its shoulder angle at actuator `axis`.
    pub fn new(e: &Elbow, axis: usize) -> Self {
        let (l1, l2) = (T::of(e.upper_arm), T::of(e.forearm));
        // Law of cosines at the elbow in its half-angle form, `d^2 = (l1 - l2)^2 + 4 l1 l2 sin^2(angle / 2)`: a sum
        // of squares (never negative, no cancellation near a folded elbow), in `T`, so that an `f32` platform
        // computes it with the core's single-precision sine rather than software `f64`.
        let span = |angle: f64| {
            let half = (T::of(angle) * T::of(0.5)).sin_();
            let diff = l1 - l2;
            (diff * diff + T::of(4.0) * l1 * l2 * half * half).sqrt_()
        };
        Self {
            axis,
            rs: T::of(e.shoulder_radius),
            hs: T::of(e.shoulder_height),
            l1,
            l2,
            sign: match e.branch {
                ElbowBranch::Up => T::one(),
                ElbowBranch::Down => -T::one(),
            },
            span: e.elbow_angle.map(span),
            travel: e.shoulder_angle.map(T::of),
            middle: T::of(0.5 * (e.shoulder_angle[0] + e.shoulder_angle[1])),
        }
    }

    /// The joint's offset `(w, v)` from the shoulder in the arm's plane, for a joint `rho` from the ring axis at
    /// height `z`.
    fn offset(&self, rho: T, z: T) -> (T, T) {
        (self.rs - rho, z - self.hs)
    }

    /// The shoulder angle that puts the arm's end at a joint `rho` from the ring axis at height `z`, within half a
    /// turn of the middle of the shoulder's travel; `None` when the arm cannot span the distance (or the joint is
    /// on the shoulder axis, where the angle is undefined).
    pub fn shoulder(&self, rho: T, z: T) -> Option<Shoulder<T>> {
        let (w, v) = self.offset(rho, z);
        let d2 = w * w + v * v;
        let (diff, sum) = (self.l1 - self.l2, self.l1 + self.l2);
        let inner = d2 - diff * diff;
        let outer = sum * sum - d2;
        let tiny = self.l1 * self.l1 * T::of(T::EPS * 16.0);
        // Written so that NaN fails.
        if !(inner >= T::zero() && outer >= T::zero() && d2 > tiny) {
            return None;
        }
        let c = self.l1 * self.l1 + d2 - self.l2 * self.l2;
        let s = (inner * outer).sqrt_() * self.sign;
        let scale = T::one() / ((self.l1 + self.l1) * d2);
        let (cos, sin) = ((w * c - v * s) * scale, (v * c + w * s) * scale);
        let angle = self.middle + wrap_pi(sin.atan2_(cos) - self.middle);
        Some(Shoulder { angle, cos, sin })
    }

    /// The elbow's centre for a carriage direction `(cq, sq)` (unit) and a shoulder angle's cosine and sine.
    pub fn elbow(&self, cq: T, sq: T, cs: T, ss: T) -> Vector3<T> {
        let r = self.rs - self.l1 * cs;
        Vector3::new(r * cq, r * sq, self.hs + self.l1 * ss)
    }

    /// The shoulder axis's point on the carriage's radius, for a carriage direction `(cq, sq)`.
    pub fn shoulder_point(&self, cq: T, sq: T) -> Vector3<T> {
        Vector3::new(self.rs * cq, self.rs * sq, self.hs)
    }

    /// Reach margin (m) of a joint `rho` from the ring axis at height `z`, defined whether or not the arm reaches:
    /// the shoulder-to-joint distance within the span of the elbow angle limits, and (when the arm reaches) the
    /// shoulder within its travel, as the arc its elbow moves (`l1` times the angle).
    pub fn reach(&self, rho: T, z: T) -> T {
        let (w, v) = self.offset(rho, z);
        let d = (w * w + v * v).sqrt_();
        let span = (d - self.span[0]).min_(self.span[1] - d);
        match self.shoulder(rho, z) {
            Some(s) => span
                .min_(self.l1 * (s.angle - self.travel[0]))
                .min_(self.l1 * (self.travel[1] - s.angle)),
            None => span,
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// The spans as the law of cosines gives them in `f64`, `sqrt(l1^2 + l2^2 - 2 l1 l2 cos(angle))`.
    fn law_of_cosines(l1: f64, l2: f64, angle: f64) -> f64 {
        libm::sqrt((l1 * l1 + l2 * l2 - 2.0 * l1 * l2 * libm::cos(angle)).max(0.0))
    }

    proptest! {
        /// The half-angle form in `f32` and `f64` against the law of cosines in `f64`, over arms of 1 cm to 1 m and
        /// every elbow angle from folded to straight.
        #[test]
        fn spans_match_the_law_of_cosines(
            l1 in 0.01f64..1.0,
            l2 in 0.01f64..1.0,
            a0 in 0.0f64..core::f64::consts::PI,
            a1 in 0.0f64..core::f64::consts::PI,
        ) {
            let e = Elbow {
                shoulder_radius: 0.2,
                shoulder_height: 0.0,
                upper_arm: l1,
                forearm: l2,
                branch: ElbowBranch::Up,
                shoulder_angle: [-1.0, 1.0],
                elbow_angle: [a0, a1],
            };
            let single = Arm::<f32>::new(&e, 4);
            let double = Arm::<f64>::new(&e, 4);
            for (k, angle) in [a0, a1].into_iter().enumerate() {
                let want = law_of_cosines(l1, l2, angle);
                // Compared as squares (the law of cosines' rounding, 1e-16 of (l1 + l2)^2, is a large share of a
                // folded elbow's small span): f64 to its rounding, f32 to a few of its ulps.
                let (s, d, want2, scale) = (f64::from(single.span[k]), double.span[k], want * want, (l1 + l2) * (l1 + l2));
                prop_assert!((d * d - want2).abs() <= 1e-15 * scale, "{d} {want}");
                prop_assert!((s * s - want2).abs() <= 1e-6 * scale, "{s} {want}");
            }
        }
    }
}
