//! Tip-over under a quasi-static inertial load (KINEMATICS.md 4.6 extended): the support polygon of the carriages,
//! a payload's centre of mass projected onto the ring plane along the effective gravity `g - a`, and the largest
//! lateral acceleration `a` before that projection leaves the polygon.
//!
//! With the centre of mass `C` at height `h` above the ring plane and a lateral acceleration `a` of the platform,
//! the line through `C` along `g - a = (-ax, -ay, -g)` meets the plane at `(Cx - ax h / g, Cy - ay h / g)`: the
//! projection moves against the acceleration by `|a| h / g`. An edge at distance `d` inside, with inward normal
//! `n`, is reached when `|a| (n . u) h / g = d` for an acceleration along the unit vector `u`; the weakest
//! direction over all of them is `u = n` of the nearest edge, where `|a| = g d / h`.

use core::fmt;

use nalgebra::Vector3;

use super::RingPlatform;
use crate::kinematics::{KinematicsError, Pose};
use crate::Real;

/// Standard gravity (m/s^2), as the statics take it.
pub const GRAVITY: f64 = 9.80665;

/// Why a tip-over analysis has no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum TipOverError {
    /// A corner, the centre of mass or the acceleration has a NaN or infinite coordinate.
    NonFinite,
    /// The support polygon has fewer than three corners or no area.
    Degenerate,
    /// The centre of mass is not above the support plane (`h <= 0`): it cannot tip over the polygon's edges.
    NotAbove,
    /// The pose has no inverse kinematics (no carriages to stand on).
    Kinematics(KinematicsError),
}

impl fmt::Display for TipOverError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => f.write_str("input has a NaN or infinite coordinate"),
            Self::Degenerate => f.write_str("the support polygon has fewer than three corners or no area"),
            Self::NotAbove => f.write_str("the centre of mass is not above the ring plane"),
            Self::Kinematics(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for TipOverError {}

impl From<KinematicsError> for TipOverError {
    fn from(e: KinematicsError) -> Self {
        Self::Kinematics(e)
    }
}

/// A centre of mass over a convex support polygon in the plane `z = 0`, ready to be loaded laterally.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipOver<T: Real> {
    /// The polygon's corners (only `x`, `y` count), counter-clockwise; the first `corners` are used.
    pub polygon: [Vector3<T>; 6],
    /// How many corners.
    pub corners: usize,
    /// The centre of mass in the base frame.
    pub com: Vector3<T>,
    /// Gravity (m/s^2).
    pub gravity: T,
    /// Distance of the centre of mass's vertical projection inside the polygon (negative outside).
    pub static_margin: T,
    /// The smallest lateral acceleration over all directions that tips it: `g d / h` with `d` the distance to
    /// the nearest edge (0 when the projection is outside already).
    pub weakest: T,
    /// The direction of that acceleration (rad, counter-clockwise from base X): the nearest edge's inward normal.
    pub weakest_direction: T,
}

/// The centre of mass under one lateral acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loaded<T> {
    /// Where the effective gravity through the centre of mass meets the ring plane (`x`, `y`).
    pub point: [T; 2],
    /// That point's distance inside the polygon (negative outside: it tips).
    pub margin: T,
    /// The largest acceleration in the same direction before tipping, minus the one given (negative: it tips).
    pub acceleration_margin: T,
    /// The point is outside the polygon.
    pub tips: bool,
}

impl<T: Real> TipOver<T> {
    /// The analysis of a centre of mass `com` (base frame, `z` its height above the polygon's plane) over the
    /// convex polygon of `corners` (in either orientation; at most six, their `z` ignored), under `gravity`.
    pub fn new(corners: &[Vector3<T>], com: Vector3<T>, gravity: T) -> Result<Self, TipOverError> {
        let n = corners.len();
        if !(3..=6).contains(&n) {
            return Err(TipOverError::Degenerate);
        }
        let finite = |v: &Vector3<T>| v.x.finite() && v.y.finite() && v.z.finite();
        if !corners.iter().all(finite) || !finite(&com) || !gravity.finite() || gravity <= T::zero() {
            return Err(TipOverError::NonFinite);
        }
        if com.z <= T::zero() {
            return Err(TipOverError::NotAbove);
        }
        let mut polygon = [Vector3::zeros(); 6];
        polygon[..n].copy_from_slice(corners);
        // Twice the signed area; clockwise corners are turned around.
        let mut area = T::zero();
        let mut extent = T::zero();
        for k in 0..n {
            let (p, q) = (polygon[k], polygon[(k + 1) % n]);
            area += p.x * q.y - q.x * p.y;
            extent = extent.max_(p.x.abs()).max_(p.y.abs());
        }
        if area.abs() <= extent * extent * T::of(T::EPS * 64.0) {
            return Err(TipOverError::Degenerate);
        }
        if area < T::zero() {
            polygon[..n].reverse();
        }
        let mut t = Self {
            polygon,
            corners: n,
            com,
            gravity,
            static_margin: T::zero(),
            weakest: T::zero(),
            weakest_direction: T::zero(),
        };
        let (margin, normal) = t.nearest(com.x, com.y);
        t.static_margin = margin;
        t.weakest = gravity * margin.max_(T::zero()) / com.z;
        t.weakest_direction = normal[1].atan2_(normal[0]);
        Ok(t)
    }

    /// The edges as (a point on it, unit inward normal), zero-length edges left out.
    fn edges(&self) -> impl Iterator<Item = (Vector3<T>, [T; 2])> + '_ {
        let n = self.corners;
        (0..n).filter_map(move |k| {
            let (p0, p1) = (self.polygon[k], self.polygon[(k + 1) % n]);
            let (ex, ey) = (p1.x - p0.x, p1.y - p0.y);
            let len = (ex * ex + ey * ey).sqrt_();
            // Counter-clockwise: the inside is on the left, the inward normal is the edge turned by +90 deg.
            (len > T::zero()).then(|| (p0, [-ey / len, ex / len]))
        })
    }

    /// The signed distance of a point inside the polygon (the smallest over the edges' lines) and that edge's
    /// inward normal.
    fn nearest(&self, x: T, y: T) -> (T, [T; 2]) {
        let mut best = (T::max_value().unwrap_or(T::one()), [T::one(), T::zero()]);
        for (p0, n) in self.edges() {
            let d = n[0] * (x - p0.x) + n[1] * (y - p0.y);
            if d < best.0 {
                best = (d, n);
            }
        }
        best
    }

    /// The largest lateral acceleration along `direction` (rad, counter-clockwise from base X) before the centre
    /// of mass's projection leaves the polygon; 0 when it is outside without any.
    pub fn limit(&self, direction: T) -> T {
        if self.static_margin < T::zero() {
            return T::zero();
        }
        let (s, c) = direction.sin_cos_();
        let mut limit = T::max_value().unwrap_or(T::one());
        for (p0, n) in self.edges() {
            let toward = n[0] * c + n[1] * s;
            if toward > T::zero() {
                let d = n[0] * (self.com.x - p0.x) + n[1] * (self.com.y - p0.y);
                limit = limit.min_(self.gravity * d / (self.com.z * toward));
            }
        }
        limit
    }

    /// The centre of mass under a lateral acceleration `[ax, ay]` (m/s^2, base frame) of the platform.
    pub fn under(&self, accel: [T; 2]) -> Result<Loaded<T>, TipOverError> {
        if !accel[0].finite() || !accel[1].finite() {
            return Err(TipOverError::NonFinite);
        }
        let k = self.com.z / self.gravity;
        let point = [self.com.x - accel[0] * k, self.com.y - accel[1] * k];
        let (margin, _) = self.nearest(point[0], point[1]);
        let size = (accel[0] * accel[0] + accel[1] * accel[1]).sqrt_();
        let limit = if size > T::zero() {
            self.limit(accel[1].atan2_(accel[0]))
        } else {
            self.weakest
        };
        Ok(Loaded {
            point,
            margin,
            acceleration_margin: limit - size,
            tips: margin < T::zero(),
        })
    }
}

impl<T: Real> RingPlatform<T> {
    /// Tip-over of a payload whose centre of mass is `com` in the platform frame, at a pose: the support polygon
    /// is the carriages' (as [`crate::kinematics::Check::Stability`] takes it, in their order around the ring),
    /// the ring plane its plane.
    pub fn tip_over(&self, pose: &Pose<T>, com: Vector3<T>) -> Result<TipOver<T>, TipOverError> {
        if !(com.x.finite() && com.y.finite() && com.z.finite()) {
            return Err(TipOverError::NonFinite);
        }
        let q = <Self as crate::kinematics::Mechanism<T>>::inverse(self, pose)?;
        let c = self.configuration(pose, &q);
        let order = self.ring_order(&q);
        let mut corners = [Vector3::zeros(); 6];
        for (corner, &i) in corners.iter_mut().zip(&order).take(self.n) {
            *corner = c.carriages[i];
        }
        let at = c.rotation * com + pose.position();
        TipOver::new(&corners[..self.n], at, T::of(GRAVITY))
    }
}
