//! The scalar type of the core: `f32` on the MCU, `f64` for analysis, both through `libm`.

use nalgebra::RealField;

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
    /// Machine epsilon of the type.
    const EPS: f64;
}

macro_rules! impl_real {
    ($t:ty, $sin:path, $cos:path, $atan2:path, $acos:path, $asin:path, $sqrt:path, $round:path) => {
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
            #[inline]
            fn finite(self) -> bool {
                self.is_finite()
            }
            const EPS: f64 = <$t>::EPSILON as f64;
        }
    };
}

impl_real!(
    f32,
    libm::sinf,
    libm::cosf,
    libm::atan2f,
    libm::acosf,
    libm::asinf,
    libm::sqrtf,
    libm::roundf
);
impl_real!(
    f64,
    libm::sin,
    libm::cos,
    libm::atan2,
    libm::acos,
    libm::asin,
    libm::sqrt,
    libm::round
);

/// Wraps an angle into `(-pi, pi]`.
pub(crate) fn wrap_pi<T: Real>(a: T) -> T {
    // atan2 of (sin, cos) is exact enough near the branch cut and never loops on huge inputs.
    a.sin_().atan2_(a.cos_())
}

/// Brings an angle that is at most one turn outside `(-pi, pi]` back into it, by one exact addition: unlike
/// [`wrap_pi`] it leaves angles already in range untouched, so a yaw integrated tick by tick keeps its precision.
pub(crate) fn wrap_once<T: Real>(a: T) -> T {
    if a > T::pi() {
        a - T::two_pi()
    } else if a <= -T::pi() {
        a + T::two_pi()
    } else {
        a
    }
}
