//! The scalar type of the core: `f32` on the MCU, `f64` for analysis, both through `libm`.

use nalgebra::RealField;

mod single;

pub(crate) use single::sqrtf;
use single::{asinf, atan2f, cosf, sincosf, sinf};

/// A floating-point scalar for the kinematics.
///
/// Every transcendental function goes through `libm` explicitly (never the `std` float methods, which
/// call the platform's C library): that is what makes host and Cortex-M results bit-identical.
/// Addition, multiplication, division and square root are correctly rounded IEEE-754 operations on both.
pub trait Real: RealField + Copy + Default + core::fmt::Debug + core::fmt::Display {
    /// Converts a constant (geometry, limits, tolerances are stored as `f64`).
    fn of(v: f64) -> Self;
    /// Widens to `f64` (for reports and error messages).
    fn to_f64(self) -> f64;
    /// Sine.
    fn sin_(self) -> Self;
    /// Cosine.
    fn cos_(self) -> Self;
    /// Sine and cosine at once (for `f32` one reduction and both polynomials, half the cost of the two).
    fn sin_cos_(self) -> (Self, Self);
    /// Converts to an integer, as `as` does (saturating; NaN is 0). Not through `f64`: on the M4F that is a
    /// software conversion.
    fn to_i64(self) -> i64;
    /// An integer as this type (rounded to nearest).
    fn of_i32(v: i32) -> Self;
    /// Rounds half away from zero to an integer: `round_().to_i64()`, the same value, with the truncation done by
    /// the conversion (one VCVT on the M4F) instead of by `libm`'s bit operations as well.
    #[inline]
    fn round_to_i64(self) -> i64 {
        // libm's round is trunc(x + copysign(0.5 - 0.25 eps, x)); `to_i64` truncates. The constant is exact in
        // either type. An infinity or NaN stays one through the addition and converts as its rounding does
        // (saturated, or 0), so it needs no test of its own (a proptest over any bits holds this to libm).
        let half = Self::of(0.5 - 0.25 * Self::EPS);
        (self + if self < Self::zero() { -half } else { half }).to_i64()
    }
    /// Four-quadrant arctangent of `self / x`.
    fn atan2_(self, x: Self) -> Self;
    /// Arc cosine; the caller keeps the argument inside `[-1, 1]`.
    fn acos_(self) -> Self;
    /// Arc sine; the caller keeps the argument inside `[-1, 1]`.
    fn asin_(self) -> Self;
    /// Square root.
    fn sqrt_(self) -> Self;
    /// Rounds half away from zero.
    fn round_(self) -> Self;
    /// True unless NaN or infinite.
    fn finite(self) -> bool;
    /// The smaller of two values by one comparison: `other` when it is smaller, else `self` (a NaN `other` is
    /// ignored, as by `min`). `f32::min` is a call to `fminf` on the M4F, which has no VMINNM before ARMv8: 20
    /// instructions a call, measured, and the checks of one pose take twenty.
    #[inline]
    fn min_(self, other: Self) -> Self {
        if other < self {
            other
        } else {
            self
        }
    }
    /// The larger of two values by one comparison (see [`Real::min_`]).
    #[inline]
    fn max_(self, other: Self) -> Self {
        if other > self {
            other
        } else {
            self
        }
    }
    /// Machine epsilon of the type.
    const EPS: f64;
}

macro_rules! impl_real {
    ($t:ty, $sin:path, $cos:path, $sincos:path, $atan2:path, $acos:path, $asin:path, $sqrt:path, $round:path) => {
        impl Real for $t {
            #[inline]
            fn of(v: f64) -> Self {
                v as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn sin_(self) -> Self {
                $sin(self)
            }
            #[inline]
            fn cos_(self) -> Self {
                $cos(self)
            }
            #[inline]
            fn sin_cos_(self) -> (Self, Self) {
                $sincos(self)
            }
            #[inline]
            fn to_i64(self) -> i64 {
                // Through i32 where it fits: one VCVT on the M4F, where a conversion to i64 is a library call.
                // The same value either way (both truncate; NaN is 0 and does not pass the test).
                if self.abs() < 2_147_483_648.0 {
                    self as i32 as i64
                } else {
                    self as i64
                }
            }
            #[inline]
            fn of_i32(v: i32) -> Self {
                v as $t
            }
            #[inline]
            fn atan2_(self, x: Self) -> Self {
                $atan2(self, x)
            }
            #[inline]
            fn acos_(self) -> Self {
                $acos(self)
            }
            #[inline]
            fn asin_(self) -> Self {
                $asin(self)
            }
            #[inline]
            fn sqrt_(self) -> Self {
                $sqrt(self)
            }
            #[inline]
            fn round_(self) -> Self {
                $round(self)
            }
            /// One comparison of the magnitude (a NaN fails it, an infinity exceeds the largest finite value):
            /// `is_finite` tests the exponent's bits, which on the M4F first moves the value to a core register,
            /// about a dozen instructions where this is four (measured).
            #[inline]
            fn finite(self) -> bool {
                self.abs() <= <$t>::MAX
            }
            const EPS: f64 = <$t>::EPSILON as f64;
        }
    };
}

impl_real!(
    f32,
    sinf,
    cosf,
    sincosf,
    atan2f,
    libm::acosf,
    asinf,
    sqrtf,
    libm::roundf
);
impl_real!(
    f64,
    libm::sin,
    libm::cos,
    libm::sincos,
    libm::atan2,
    libm::acos,
    libm::asin,
    libm::sqrt,
    libm::round
);

/// Euclidean length of a 3-vector through [`Real::sqrt_`]: nalgebra's `norm()` takes its root from simba, which is
/// `libm`'s software `sqrtf` on the M4F (about 45 instructions instead of one).
#[inline]
pub(crate) fn length<T: Real>(v: &nalgebra::Vector3<T>) -> T {
    (v.x * v.x + v.y * v.y + v.z * v.z).sqrt_()
}

/// Wraps an angle into `(-pi, pi]`.
#[inline]
pub(crate) fn wrap_pi<T: Real>(a: T) -> T {
    // Differences of two wrapped angles, the common case (several a tick), are within three half-turns: one exact
    // addition. Beyond, atan2 of (sin, cos) is exact enough near the branch cut and never loops on huge inputs
    // (NaN goes that way too and stays NaN).
    if a.abs() < T::pi() * T::of(3.0) {
        wrap_once(a)
    } else {
        let (s, c) = a.sin_cos_();
        s.atan2_(c)
    }
}

/// Brings an angle that is at most one turn outside `(-pi, pi]` back into it, by one exact addition: unlike
/// [`wrap_pi`] it leaves angles already in range untouched, so a yaw integrated tick by tick keeps its precision.
#[inline]
pub(crate) fn wrap_once<T: Real>(a: T) -> T {
    if a > T::pi() {
        a - T::two_pi()
    } else if a <= -T::pi() {
        a + T::two_pi()
    } else {
        a
    }
}

/// Brings an angle into `[0, 2 pi)`, as `libm::fmod(a, 2 pi)` does for the non-negative sums it serves, by one
/// floor: f64 `fmod` is an exact bit-by-bit remainder that costs 1.6 kB of flash, a floor about a tenth of that. Off
/// by at most a few ulps of a turn, never outside the range (NaN stays NaN).
#[inline]
pub(crate) fn wrap_turn(a: f64) -> f64 {
    let turn = core::f64::consts::TAU;
    let r = a - turn * libm::floor(a / turn);
    if r >= turn || r < 0.0 {
        0.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::Real;

    proptest::proptest! {
        #[test]
        fn wrap_turn_is_fmod_within_ulps(a in -1.0e3f64..1.0e3, b in -1.0e3f64..1.0e3) {
            let x = a - b;
            let f = libm::fmod(x, core::f64::consts::TAU);
            let (w, f) = (super::wrap_turn(x), if f < 0.0 { f + core::f64::consts::TAU } else { f });
            proptest::prop_assert!((0.0..core::f64::consts::TAU).contains(&w), "{x}: {w}");
            let d = (w - f).abs();
            proptest::prop_assert!(d < 1e-12 || (core::f64::consts::TAU - d) < 1e-12, "{x}: {w} vs {f}");
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        #[test]
        fn finite_is_is_finite(bits in proptest::num::u32::ANY, wide in proptest::num::u64::ANY) {
            let (x, y) = (f32::from_bits(bits), f64::from_bits(wide));
            proptest::prop_assert_eq!(x.finite(), x.is_finite(), "{:e}", x);
            proptest::prop_assert_eq!(y.finite(), y.is_finite(), "{:e}", y);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        #[test]
        fn round_to_i64_is_libm_round_converted(bits in proptest::num::u32::ANY, wide in proptest::num::u64::ANY) {
            let (x, y) = (f32::from_bits(bits), f64::from_bits(wide));
            proptest::prop_assert_eq!(x.round_to_i64(), libm::roundf(x) as i64, "{:e}", x);
            proptest::prop_assert_eq!(y.round_to_i64(), libm::round(y) as i64, "{:e}", y);
        }
    }

    #[test]
    fn finite_at_the_edges() {
        for v in [
            0.0,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
        ] {
            for x in [v, -v] {
                assert_eq!(x.finite(), x.is_finite(), "{x:e}");
            }
        }
        for v in [
            0.0,
            f64::MIN_POSITIVE,
            f64::from_bits(1),
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
        ] {
            for x in [v, -v] {
                assert_eq!(x.finite(), x.is_finite(), "{x:e}");
            }
        }
    }
}
