//! A vehicle's static stability, as the dissertation's chapter 5.2 lists the tests the platform runs on it: the
//! tip-over angle on a longitudinal incline (climbing) and on a lateral slope, the body's roll angle, and the critical
//! rollover speed in a turn "with the roll angle taken into account". The chapter names the tests and prints neither
//! formula nor figure; the formulas here are the standard quasi-static ones of vehicle dynamics (T. D. Gillespie,
//! *Fundamentals of Vehicle Dynamics*, SAE 1992, ch. 9 "Rollover"):
//!
//! - a rigid vehicle tips sideways when the lateral-to-normal load ratio reaches the static stability factor
//!   `T / (2 h)` (track `T`, centre-of-gravity height `h`): on a slope `tan theta = T / (2 h)`, in a turn
//!   `a_y / g = T / (2 h)`;
//! - lengthways the pivot is an axle: climbing, the rear axle at `b` behind the centre of gravity, `tan theta = b / h`;
//! - a suspended body rolls by `phi = R a_y / g` about its roll axis at height `h_r` (roll rate
//!   `R = m g (h - h_r) / (K - m g (h - h_r))` rad per unit load ratio, `K` the suspension's roll stiffness, the
//!   denominator the stiffness less the body's own overturning moment per radian), moving its centre of gravity
//!   outwards by `(h - h_r) phi`; the threshold falls to `a_y / g = (T / 2 h) / (1 + R (1 - h_r / h))`.
//!
//! On a slope the normal load is `g cos theta`, so the roll rate there is that of `g cos theta`: the slope's angle
//! with roll is the root of `tan theta (h + (h - h_r) R(g cos theta)) = T / 2`, found by bisection.

use core::fmt;

/// Standard gravity (m/s^2), as the rest of the core takes it.
pub const GRAVITY: f64 = crate::kinematics::GRAVITY;

/// Lengths beyond this (m) are not a vehicle's.
const MAX_LENGTH: f64 = 1e3;
/// Nor masses beyond this (kg).
const MAX_MASS: f64 = 1e6;
/// Nor roll stiffnesses beyond this (N m/rad).
const MAX_STIFFNESS: f64 = 1e9;

/// Why a vehicle cannot be analysed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum VehicleError {
    /// A value is NaN or infinite.
    NonFinite(&'static str),
    /// A length, the mass or the stiffness is zero, negative or beyond any vehicle (the field's name).
    OutOfRange(&'static str),
    /// The centre of gravity is not between the axles.
    OutsideWheelbase,
    /// The roll axis is not below the centre of gravity (`0 <= h_r < h`).
    RollCentre,
    /// The suspension's roll stiffness does not hold the body's own overturning moment (`K <= m g (h - h_r)`):
    /// the body would fall over on its springs.
    RollUnstable,
    /// A roll stiffness without the mass it carries.
    NoMass,
}

impl fmt::Display for VehicleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite(what) => write!(f, "{what} is not a finite number"),
            Self::OutOfRange(what) => write!(f, "{what} is zero, negative or beyond any vehicle's"),
            Self::OutsideWheelbase => f.write_str("the centre of gravity must lie between the axles"),
            Self::RollCentre => f.write_str("the roll centre must be at or above the ground and below the centre of gravity"),
            Self::RollUnstable => f.write_str(
                "the roll stiffness does not hold the body's own overturning moment (K <= m g (h - h_r)): it rolls over on its springs",
            ),
            Self::NoMass => f.write_str("a roll stiffness needs the mass it carries"),
        }
    }
}

impl core::error::Error for VehicleError {}

/// A suspended body's roll: stiffness, the mass it carries, and the roll axis's height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roll {
    /// Roll stiffness of the suspension (N m/rad), both axles together.
    pub stiffness: f64,
    /// The sprung mass (kg).
    pub mass: f64,
    /// Height of the roll axis above the ground (m).
    pub centre_height: f64,
}

/// A vehicle: its wheels' rectangle and its centre of gravity, rigid or on a suspension that rolls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vehicle {
    /// Track (m): between the wheels' contact centres across.
    pub track: f64,
    /// Wheelbase (m).
    pub wheelbase: f64,
    /// Height of the centre of gravity above the ground (m).
    pub cg_height: f64,
    /// Distance of the centre of gravity ahead of the rear axle (m).
    pub cg_from_rear: f64,
    /// The suspension's roll, or none for a rigid vehicle.
    pub roll: Option<Roll>,
}

/// The four figures of chapter 5.2's tests for one vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stability {
    /// Tip-over angle climbing a longitudinal incline, over the rear axle (rad).
    pub incline: f64,
    /// Tip-over angle descending, over the front axle (rad).
    pub decline: f64,
    /// Tip-over angle on a lateral slope, with the body's roll (rad).
    pub slope: f64,
    /// The body's roll relative to its axles at the slope's tip-over (rad; 0 when rigid).
    pub roll_at_slope: f64,
    /// The roll rate on level ground: body roll per unit of lateral-to-normal load ratio (rad; 0 when rigid).
    pub roll_rate: f64,
    /// The lateral acceleration that rolls it over on level ground, in g (the static stability factor when rigid).
    pub rollover_g: f64,
}

impl Vehicle {
    /// A rigid vehicle, checked.
    pub fn new(track: f64, wheelbase: f64, cg_height: f64, cg_from_rear: f64) -> Result<Self, VehicleError> {
        Self::with_roll(track, wheelbase, cg_height, cg_from_rear, None)
    }

    /// A vehicle with or without a rolling suspension, checked.
    pub fn with_roll(
        track: f64,
        wheelbase: f64,
        cg_height: f64,
        cg_from_rear: f64,
        roll: Option<Roll>,
    ) -> Result<Self, VehicleError> {
        let positive = |what: &'static str, v: f64| {
            if !v.is_finite() {
                Err(VehicleError::NonFinite(what))
            } else if v <= 0.0 || v > MAX_LENGTH {
                Err(VehicleError::OutOfRange(what))
            } else {
                Ok(v)
            }
        };
        positive("track", track)?;
        positive("wheelbase", wheelbase)?;
        positive("cg_height", cg_height)?;
        if !cg_from_rear.is_finite() {
            return Err(VehicleError::NonFinite("cg_from_rear"));
        }
        if cg_from_rear <= 0.0 || cg_from_rear >= wheelbase {
            return Err(VehicleError::OutsideWheelbase);
        }
        if let Some(r) = roll {
            if !r.mass.is_finite() {
                return Err(VehicleError::NonFinite("mass"));
            }
            if r.mass <= 0.0 {
                return Err(VehicleError::NoMass);
            }
            if r.mass > MAX_MASS {
                return Err(VehicleError::OutOfRange("mass"));
            }
            if !r.stiffness.is_finite() {
                return Err(VehicleError::NonFinite("roll_stiffness"));
            }
            if r.stiffness <= 0.0 || r.stiffness > MAX_STIFFNESS {
                return Err(VehicleError::OutOfRange("roll_stiffness"));
            }
            if !r.centre_height.is_finite() {
                return Err(VehicleError::NonFinite("roll_centre_height"));
            }
            if r.centre_height < 0.0 || r.centre_height >= cg_height {
                return Err(VehicleError::RollCentre);
            }
            // Unstable on level ground; on a slope the normal load is smaller, so level ground is the worst case.
            if r.stiffness <= r.mass * GRAVITY * (cg_height - r.centre_height) {
                return Err(VehicleError::RollUnstable);
            }
        }
        Ok(Self {
            track,
            wheelbase,
            cg_height,
            cg_from_rear,
            roll,
        })
    }

    /// The static stability factor `T / (2 h)`.
    pub fn stability_factor(&self) -> f64 {
        self.track / (2.0 * self.cg_height)
    }

    /// Body roll per unit of lateral-to-normal load ratio under a normal acceleration `normal` (m/s^2): 0 when
    /// rigid.
    pub fn roll_rate(&self, normal: f64) -> f64 {
        match self.roll {
            None => 0.0,
            Some(r) => {
                let arm = self.cg_height - r.centre_height;
                let moment = r.mass * normal * arm;
                moment / (r.stiffness - moment)
            }
        }
    }

    /// The lateral-to-normal load ratio that tips it under a normal acceleration `normal` (m/s^2).
    fn lateral_threshold(&self, normal: f64) -> f64 {
        let arm = self.roll.map_or(0.0, |r| self.cg_height - r.centre_height);
        0.5 * self.track / (self.cg_height + arm * self.roll_rate(normal))
    }

    /// The figures of chapter 5.2's tests.
    pub fn stability(&self) -> Stability {
        let h = self.cg_height;
        // Bisection on tan(theta) - threshold(g cos theta): negative at 0, and not negative at the rigid angle (the
        // threshold with roll is at most the rigid one).
        let f = |theta: f64| libm::tan(theta) - self.lateral_threshold(GRAVITY * libm::cos(theta));
        let (mut lo, mut hi) = (0.0, libm::atan(self.stability_factor()));
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let slope = 0.5 * (lo + hi);
        Stability {
            incline: libm::atan(self.cg_from_rear / h),
            decline: libm::atan((self.wheelbase - self.cg_from_rear) / h),
            slope,
            roll_at_slope: self.roll_rate(GRAVITY * libm::cos(slope)) * libm::tan(slope),
            roll_rate: self.roll_rate(GRAVITY),
            rollover_g: self.lateral_threshold(GRAVITY),
        }
    }

    /// The critical rollover speed (m/s) in a level turn of `radius` (m): `sqrt(a_y R)` at the rollover threshold.
    pub fn critical_speed(&self, radius: f64) -> Result<f64, VehicleError> {
        if !radius.is_finite() {
            return Err(VehicleError::NonFinite("radius"));
        }
        if radius <= 0.0 || radius > 1e5 {
            return Err(VehicleError::OutOfRange("radius"));
        }
        Ok(libm::sqrt(self.stability().rollover_g * GRAVITY * radius))
    }

    /// How far inside its wheels' rectangle the centre of gravity stands (m; negative: it tips) under an effective
    /// gravity `g` in the vehicle's frame (x forward, y left, z up from the ground; `g.z < 0` when upright),
    /// with the body rolled by its suspension: the centre of gravity, moved sideways by the roll, projected along
    /// `g` onto the ground, against the nearer edge across and the nearer axle. Upside down (`g.z >= 0`) or
    /// non-finite is `-inf`.
    pub fn margin(&self, g: [f64; 3]) -> f64 {
        let normal = -g[2];
        if !normal.is_finite() || normal <= 0.0 || !g[0].is_finite() || !g[1].is_finite() {
            return f64::NEG_INFINITY;
        }
        let h = self.cg_height;
        let (lateral, longitudinal) = (g[1] / normal, g[0] / normal);
        let arm = self.roll.map_or(0.0, |r| self.cg_height - r.centre_height);
        let y = lateral * (h + arm * self.roll_rate(normal));
        let x = longitudinal * h;
        let across = 0.5 * self.track - y.abs();
        let along = if x >= 0.0 {
            self.wheelbase - self.cg_from_rear - x
        } else {
            self.cg_from_rear + x
        };
        across.min(along)
    }
}

/// The effective gravity (m/s^2) in the frame of a platform rolled by `alpha` about X and pitched by `beta` about Y
/// (the source's `R = Rz(gamma) Ry(beta) Rx(alpha)`; yaw does not change it): `R^T (0, 0, -g)`. A negative pitch
/// lifts the platform's +X: a vehicle facing +X climbs.
pub fn gravity_in_platform(alpha: f64, beta: f64) -> [f64; 3] {
    let (sa, ca) = (libm::sin(alpha), libm::cos(alpha));
    let (sb, cb) = (libm::sin(beta), libm::cos(beta));
    [GRAVITY * sb, -GRAVITY * cb * sa, -GRAVITY * cb * ca]
}
