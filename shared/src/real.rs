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

impl_real!(f32, sinf, cosf, libm::atan2f, libm::acosf, asinf, sqrtf, libm::roundf);
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

/// Sine and cosine in single precision, for `f32` (the MCU's scalar).
///
/// `libm::sinf` and `cosf` (musl's) evaluate their kernels in `f64`, which a Cortex-M4F has no hardware for: about
/// 1,300 instructions a call, measured under QEMU, and the pose rotation alone needs six. These are Cephes' `sinf`
/// and `cosf` (S. L. Moshier): the argument reduced by multiples of pi/4 with pi/4 split into three parts, so the
/// reduction is exact for |x| <= 8192, then minimax polynomials, all in `f32` (about 40 instructions; relative
/// error a few times 1e-8). Only IEEE additions and multiplications, which Rust never contracts into fused ones:
/// the same bits on every target. NaN, infinities and |x| > 8192 go to `libm` (exact reduction of huge arguments).
fn sincosf(x: f32) -> (f32, f32) {
    const FOUR_OVER_PI: f32 = 1.273_239_5;
    const DP1: f32 = 0.785_156_25;
    const DP2: f32 = 2.418_756_5e-4;
    const DP3: f32 = 3.774_895e-8;
    let ax = libm::fabsf(x);
    if ax.is_nan() || ax > 8192.0 {
        return (libm::sinf(x), libm::cosf(x));
    }
    let mut j = (ax * FOUR_OVER_PI) as u32;
    let mut y = j as f32;
    // Map zeros to the origin: octants 1, 3, 5, 7 round up to the next even one.
    if j & 1 != 0 {
        j += 1;
        y += 1.0;
    }
    let z = ((ax - y * DP1) - y * DP2) - y * DP3;
    let zz = z * z;
    let s = ((-1.951_529_6e-4 * zz + 8.332_161e-3) * zz - 1.666_665_5e-1) * zz * z + z;
    let c = ((2.443_315_7e-5 * zz - 1.388_731_6e-3) * zz + 4.166_664_6e-2) * zz * zz - 0.5 * zz + 1.0;
    let (sin, cos) = match (j >> 1) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    };
    (if x < 0.0 { -sin } else { sin }, cos)
}

fn sinf(x: f32) -> f32 {
    sincosf(x).0
}

fn cosf(x: f32) -> f32 {
    sincosf(x).1
}

/// Square root in single precision: the FPU's `vsqrt.f32` on the Cortex-M4F, `libm` elsewhere.
///
/// `libm::sqrtf` has no ARM implementation and computes the root digit by digit in integers (measured under QEMU:
/// about 110 instructions a call, and the IK and checks of one pose take 36 of them). IEEE 754 requires the square
/// root to be correctly rounded, as VSQRT is and as `libm`'s is: the same bits either way, which the self-check's
/// digest confirms (host and M4F equal).
#[inline]
pub(crate) fn sqrtf(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let mut bits = x.to_bits();
        // Rust's `sreg` operands need the double-precision `vfp2` feature, which the M4F's single-precision FPU
        // target does not enable: the value travels in a core register, and s0 is saved and restored around it.
        // SAFETY: s0 and the stack are left as they were; only the FPU's sticky flags change.
        unsafe {
            core::arch::asm!(
                "vpush {{s0}}",
                "vmov s0, {0}",
                "vsqrt.f32 s0, s0",
                "vmov {0}, s0",
                "vpop {{s0}}",
                inout(reg) bits,
                options(pure, nomem, preserves_flags),
            );
        }
        f32::from_bits(bits)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// Arc sine in single precision: `atan2(x, sqrt((1 - x)(1 + x)))`.
///
/// musl's `asinf` evaluates its polynomial in `f64`, which the M4F computes in software: about 700 instructions a
/// call, measured under QEMU. The factored `1 - x^2` keeps its digits near `|x| = 1`; `atan2f` works in `f32`.
/// Within 4e-7 of the correctly rounded value (tested); outside `[-1, 1]` the root is NaN and so is the result.
fn asinf(x: f32) -> f32 {
    libm::atan2f(x, sqrtf((1.0 - x) * (1.0 + x)))
}

/// Wraps an angle into `(-pi, pi]`.
pub(crate) fn wrap_pi<T: Real>(a: T) -> T {
    // Differences of two wrapped angles, the common case (several a tick), are within three half-turns: one exact
    // addition. Beyond, atan2 of (sin, cos) is exact enough near the branch cut and never loops on huge inputs
    // (NaN goes that way too and stays NaN).
    if a.abs() < T::pi() * T::of(3.0) {
        wrap_once(a)
    } else {
        a.sin_().atan2_(a.cos_())
    }
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

#[cfg(test)]
mod tests {
    use super::{asinf, sincosf};

    #[test]
    fn single_precision_arc_sine_matches_libm() {
        let mut worst = 0.0f64;
        for i in -1_000_000..=1_000_000 {
            let x = i as f32 * 1e-6;
            worst = worst.max((f64::from(asinf(x)) - libm::asin(f64::from(x))).abs());
        }
        assert!(worst < 4e-7, "worst error {worst:e}");
        assert_eq!(asinf(1.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(asinf(-1.0), -core::f32::consts::FRAC_PI_2);
        assert_eq!(asinf(0.0), 0.0);
        assert!(asinf(1.0 + f32::EPSILON).is_nan() && asinf(f32::NAN).is_nan());
    }

    #[test]
    fn single_precision_sine_and_cosine_match_libm() {
        // Every 1/1000 rad over +-30 rad and a sweep up to the reduction's limit: within 2e-7 absolute of the
        // correctly rounded values (an f32 ulp at 1 is 1.2e-7).
        let mut worst = 0.0f64;
        let mut x = -30.0f64;
        while x < 30.0 {
            let (s, c) = sincosf(x as f32);
            let xf = f64::from(x as f32);
            worst = worst
                .max((f64::from(s) - libm::sin(xf)).abs())
                .max((f64::from(c) - libm::cos(xf)).abs());
            x += 1e-3;
        }
        let mut x = 30.0f64;
        while x < 8192.0 {
            let (s, c) = sincosf(x as f32);
            let xf = f64::from(x as f32);
            worst = worst
                .max((f64::from(s) - libm::sin(xf)).abs())
                .max((f64::from(c) - libm::cos(xf)).abs());
            x *= 1.001;
        }
        assert!(worst < 2e-7, "worst error {worst:e}");
        let (s, c) = sincosf(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
        assert_eq!(sincosf(0.0), (0.0, 1.0));
        assert_eq!(sincosf(1e6), (libm::sinf(1e6), libm::cosf(1e6)));
    }
}
