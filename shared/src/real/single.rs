//! Single-precision functions for the MCU's scalar, each measured under QEMU against what it replaces.
//!
//! musl's `f32` functions (through `libm`) often compute in `f64`, which the Cortex-M4F has no hardware for, and
//! `libm::sqrtf` has no ARM code at all. These use only IEEE additions, multiplications, divisions and square roots
//! (Rust never contracts them into fused operations), so they give the same bits on every target, and the tests
//! below hold each to the correctly rounded value.

/// 4 / pi, the octants per radian.
const FOUR_OVER_PI: f32 = 1.273_239_5;

/// Sine and cosine in single precision, for `f32` (the MCU's scalar).
///
/// `libm::sinf` and `cosf` (musl's) evaluate their kernels in `f64`, which a Cortex-M4F has no hardware for: about
/// 1,300 instructions a call, measured under QEMU, and the pose rotation alone needs six. These are Cephes' `sinf`
/// and `cosf` (S. L. Moshier): the argument reduced by multiples of pi/4 with pi/4 split into three parts, so the
/// reduction is exact for |x| <= 8192, then minimax polynomials, all in `f32` (about 40 instructions; relative
/// error a few times 1e-8). Only IEEE additions and multiplications, which Rust never contracts into fused ones:
/// the same bits on every target.
///
/// Beyond 8192 rad (1,300 turns: no angle of a pose, a joint or a carriage, which are wrapped or limited long before)
/// the argument is first brought into `[-pi, pi]` by `libm::remainderf` modulo the `f32` nearest to 2 pi, exactly,
/// which is off the true reduction by |x| times 2.8e-8 rad. `libm::sinf` and `cosf` reduce huge arguments exactly, but
/// through musl's `f64` reduction (`rem_pio2_large`), about 8 KB of software floating point in the firmware for
/// arguments it never sees. NaN and infinities give NaN, as `libm` does.
pub(super) fn sincosf(x: f32) -> (f32, f32) {
    let ax = libm::fabsf(x);
    // On the bits, which order as the values for a magnitude, with NaN above every number: beyond 8192, an
    // infinity or NaN.
    if ax.to_bits() > 8192f32.to_bits() {
        if !ax.is_finite() {
            return (f32::NAN, f32::NAN);
        }
        return sincosf(libm::remainderf(x, core::f32::consts::TAU));
    }
    let octants = ax * FOUR_OVER_PI;
    if octants < 1.0 {
        // Octant 0 (every pose angle within pi/4, the common case): the reduction would subtract zero, so the
        // polynomials take `x` as it is. The sine's is odd and the cosine's even, and IEEE rounding is symmetric,
        // so this is bit for bit the general path's result, without its reduction and quadrant selection.
        return kernels(x);
    }
    reduced(ax, x)
}

/// Sine and cosine of `x` (magnitude `ax`, at most 8192) through the reduction by multiples of pi/4.
#[inline(always)]
fn reduced(ax: f32, x: f32) -> (f32, f32) {
    // pi/4 in three parts, the first two with trailing zero bits: their products with the octant are exact.
    const DP1: f32 = 0.785_156_25;
    const DP2: f32 = 2.418_756_5e-4;
    const DP3: f32 = 3.774_895e-8;
    let mut j = (ax * FOUR_OVER_PI) as u32;
    let mut y = j as f32;
    // Map zeros to the origin: octants 1, 3, 5, 7 round up to the next even one.
    if j & 1 != 0 {
        j += 1;
        y += 1.0;
    }
    let (s, c) = kernels(((ax - y * DP1) - y * DP2) - y * DP3);
    let (sin, cos) = match (j >> 1) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    };
    (if x < 0.0 { -sin } else { sin }, cos)
}

/// Cephes' minimax polynomials of the sine and the cosine on `[-pi/4, pi/4]`.
#[inline(always)]
fn kernels(z: f32) -> (f32, f32) {
    let zz = z * z;
    let s = ((-1.951_529_6e-4 * zz + 8.332_161e-3) * zz - 1.666_665_5e-1) * zz * z + z;
    let c = ((2.443_315_7e-5 * zz - 1.388_731_6e-3) * zz + 4.166_664_6e-2) * zz * zz - 0.5 * zz + 1.0;
    (s, c)
}

pub(super) fn sinf(x: f32) -> f32 {
    sincosf(x).0
}

pub(super) fn cosf(x: f32) -> f32 {
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
        // Rust's `sreg` operand class needs the double-precision `vfp2` feature, which the M4F's single-precision
        // FPU target does not enable; a named register does not: the value travels in a core register through s15
        // (caller-saved, declared clobbered).
        // SAFETY: only s15 (declared) and the FPU's sticky flags change.
        unsafe {
            core::arch::asm!(
                "vmov s15, {0}",
                "vsqrt.f32 s15, s15",
                "vmov {0}, s15",
                inout(reg) bits,
                out("s15") _,
                options(pure, nomem, nostack, preserves_flags),
            );
        }
        f32::from_bits(bits)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// Arc sine in single precision: Cephes' `asinf` (S. L. Moshier).
///
/// musl's `asinf` evaluates its polynomial in `f64`, which the M4F computes in software: about 700 instructions a
/// call, measured under QEMU. Cephes' works in `f32`: a degree-11 odd polynomial on `|x| <= 1/2`, and above it
/// `asin(x) = pi/2 - 2 asin(sqrt((1 - x) / 2))`, whose argument is exact (`1 - x` by Sterbenz's lemma, the half a
/// shift of the exponent). About 30 instructions, where `atan2(x, sqrt((1 - x)(1 + x)))` took 70 (a call, two
/// divisions, the quadrant's selection). Within 4e-7 of the correctly rounded value (tested); outside `[-1, 1]`
/// and for NaN the result is NaN.
///
/// Never inlined: the cone margin's two calls took 300 B of flash inlined, for a call's few instructions each.
#[inline(never)]
pub(super) fn asinf(x: f32) -> f32 {
    let a = libm::fabsf(x);
    // A NaN passes through the polynomial as NaN.
    if a > 1.0 {
        return f32::NAN;
    }
    let (z, r, upper) = if a > 0.5 {
        let z = 0.5 * (1.0 - a);
        (z, sqrtf(z), true)
    } else {
        (a * a, a, false)
    };
    let poly =
        ((((4.216_32e-2 * z + 2.418_131e-2) * z + 4.547_002_6e-2) * z + 7.495_300_3e-2) * z + 1.666_675_2e-1) * z * r
            + r;
    let angle = if upper {
        core::f32::consts::FRAC_PI_2 - (poly + poly)
    } else {
        poly
    };
    if x.is_sign_negative() {
        -angle
    } else {
        angle
    }
}

/// Four-quadrant arctangent of `y / x` in single precision.
///
/// musl's `atan2f` is correct but takes about 90 instructions a call on the M4F (with its `atanf`), and IK needs one
/// per chain. This reduces to `atan(t)` with `0 <= t <= 1` (the smaller of `|x|`, `|y|` over the larger), then
/// Cephes' `atanf` (S. L. Moshier): `t > tan(pi/8)` maps to `pi/4 + atan((t - 1) / (t + 1))`, and a degree-9
/// odd polynomial covers `|t| <= tan(pi/8)`. Within 3e-7 of the correctly rounded value (tested; an ulp at pi is
/// 2.4e-7). Zeros, infinities and NaN go to `libm` (their signed-zero and infinite quadrant rules).
///
/// Never inlined: LTO inlined it at a dozen sites (IK, the checks, FK, the tick, homing), 6.8 KB of the firmware's
/// flash for a call's saving of a few instructions at each.
#[inline(never)]
pub(super) fn atan2f(y: f32, x: f32) -> f32 {
    // Magnitudes as bits: for non-negative floats the bits order as the values do, with the infinities above every
    // finite value and NaN above them. So the larger magnitude alone tells whether both are zero, or either is
    // infinite or NaN: one test where comparisons of the floats took a dozen instructions.
    let (bx, by) = (x.to_bits() & 0x7fff_ffff, y.to_bits() & 0x7fff_ffff);
    let swapped = by > bx;
    let (small, large) = if swapped { (bx, by) } else { (by, bx) };
    if large.wrapping_sub(1) >= 0x7f7f_ffff {
        return libm::atan2f(y, x);
    }
    atan2_of_ratio(f32::from_bits(small) / f32::from_bits(large), swapped, y, x)
}

/// `atan2(y, x)` from `t`, the smaller magnitude over the larger (`0 <= t <= 1`), and whether `|y|` is the larger.
#[inline(always)]
fn atan2_of_ratio(t: f32, swapped: bool, y: f32, x: f32) -> f32 {
    const TAN_PI_8: f32 = 0.414_213_57;
    const FRAC_PI_4: f32 = core::f32::consts::FRAC_PI_4;
    const FRAC_PI_2: f32 = core::f32::consts::FRAC_PI_2;
    const PI: f32 = core::f32::consts::PI;
    let (base, t) = if t > TAN_PI_8 {
        (FRAC_PI_4, (t - 1.0) / (t + 1.0))
    } else {
        (0.0, t)
    };
    let z = t * t;
    let poly = (((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t + t;
    let mut angle = base + poly;
    if swapped {
        angle = FRAC_PI_2 - angle;
    }
    if x < 0.0 {
        angle = PI - angle;
    }
    if y.is_sign_negative() {
        -angle
    } else {
        angle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_precision_arc_sine_matches_libm() {
        let mut worst = 0.0f64;
        for i in -1_000_000..=1_000_000 {
            let x = i as f32 * 1e-6;
            worst = worst.max((f64::from(asinf(x)) - libm::asin(f64::from(x))).abs());
        }
        // 1.6e-7 measured; an ulp at pi/2 is 1.2e-7.
        assert!(worst < 2e-7, "worst error {worst:e}");
        assert!(asinf(-0.0).is_sign_negative() && asinf(-0.0) == 0.0);
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
        for inf in [f32::INFINITY, f32::NEG_INFINITY] {
            let (s, c) = sincosf(inf);
            assert!(s.is_nan() && c.is_nan());
        }
    }

    #[test]
    fn huge_arguments_are_reduced_within_their_documented_error() {
        // Beyond 8192 rad: within |x| * 2.8e-8 (the f32 2 pi's error per turn) plus the kernel's 2e-7.
        let mut x = 8192.0f32;
        while x < 3.0e38 {
            for v in [x, -x, x * 1.37] {
                let (s, c) = sincosf(v);
                let bound = f64::from(v).abs() * 2.8e-8 + 2e-7;
                assert!((f64::from(s) - libm::sin(f64::from(v))).abs() <= bound, "sin {v}");
                assert!((f64::from(c) - libm::cos(f64::from(v))).abs() <= bound, "cos {v}");
                assert!(
                    s.abs() <= 1.0 && c.abs() <= 1.0 && (s * s + c * c - 1.0).abs() < 1e-6,
                    "{v}"
                );
            }
            x *= 1.9;
        }
    }

    #[test]
    fn rounding_to_an_integer_matches_libm() {
        use crate::Real;
        let mut x = -3.0e9f32;
        let mut k = 0u32;
        while x < 3.0e9 {
            for v in [x, x + 0.5, x - 0.5, x + 0.499_999_97, -x] {
                assert_eq!(v.round_to_i64(), libm::roundf(v) as i64, "{v}");
            }
            x = x * 0.999 + 0.37 * (k % 7) as f32 - 1.3;
            x = if x.abs() < 1.0 { x + 7.0 } else { x };
            k += 1;
            if k > 200_000 {
                break;
            }
        }
        for v in [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.499_999_97,
            -0.499_999_97,
            8_388_609.0,
            2.0e9,
            -2.2e9,
        ] {
            assert_eq!(v.round_to_i64(), libm::roundf(v) as i64, "{v}");
        }
        for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30] {
            assert_eq!(v.round_to_i64(), libm::roundf(v) as i64, "{v}");
        }
    }

    #[test]
    fn single_precision_arc_tangent_matches_libm() {
        // Every direction on circles of several radii, and ratios near 0, 1 and tan(pi/8) where the reduction
        // switches: within 3e-7 of the correctly rounded angle.
        let mut worst = 0.0f64;
        for r in [1e-20f64, 1e-3, 0.2, 1.0, 7.5, 1e20] {
            for i in 0..200_000 {
                let a = (i as f64 / 100_000.0 - 1.0) * core::f64::consts::PI;
                let (y, x) = ((r * a.sin()) as f32, (r * a.cos()) as f32);
                let exact = libm::atan2(f64::from(y), f64::from(x));
                worst = worst.max((f64::from(atan2f(y, x)) - exact).abs());
            }
        }
        for k in -2_000..2_000 {
            let t = 0.414_213_57f32 + k as f32 * 1e-7;
            worst = worst.max((f64::from(atan2f(t, 1.0)) - libm::atan2(f64::from(t), 1.0)).abs());
        }
        assert!(worst < 3e-7, "worst error {worst:e}");
        assert_eq!(atan2f(0.0, 1.0), 0.0);
        assert!(atan2f(-0.0, 1.0).is_sign_negative());
        assert_eq!(atan2f(1.0, 0.0), core::f32::consts::FRAC_PI_2);
        assert_eq!(atan2f(0.0, -1.0), libm::atan2f(0.0, -1.0));
        assert_eq!(atan2f(-0.0, -0.0), libm::atan2f(-0.0, -0.0));
        assert_eq!(atan2f(f32::INFINITY, 1.0), libm::atan2f(f32::INFINITY, 1.0));
        assert!(atan2f(f32::NAN, 1.0).is_nan() && atan2f(1.0, f32::NAN).is_nan());
    }

    /// `atan2f` as it tested its inputs on the floats, the form its bit tests replaced (the arctangent of the ratio
    /// is the same code): the reference that they change nothing.
    fn atan2f_float_tests(y: f32, x: f32) -> f32 {
        let (ax, ay) = (libm::fabsf(x), libm::fabsf(y));
        if !(ax < f32::INFINITY && ay < f32::INFINITY && (ax > 0.0 || ay > 0.0)) {
            return libm::atan2f(y, x);
        }
        let swapped = ay > ax;
        atan2_of_ratio(if swapped { ax / ay } else { ay / ax }, swapped, y, x)
    }

    /// `sincosf` as it reduced every argument, octant 0 included: the reference that the shortcut changes nothing.
    fn sincosf_always_reduced(x: f32) -> (f32, f32) {
        let ax = libm::fabsf(x);
        if !ax.is_finite() {
            return (f32::NAN, f32::NAN);
        }
        if ax > 8192.0 {
            return sincosf(libm::remainderf(x, core::f32::consts::TAU));
        }
        reduced(ax, x)
    }

    /// Equal bits, or both NaN.
    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Special values and their neighbours: zeros, subnormals, the switch points, infinities, NaN.
    const EDGES: [f32; 14] = [
        0.0,
        -0.0,
        f32::MIN_POSITIVE,
        1e-45,
        -1e-45,
        f32::from_bits(core::f32::consts::FRAC_PI_4.to_bits() - 1),
        core::f32::consts::FRAC_PI_4,
        -core::f32::consts::FRAC_PI_4,
        1.0,
        8192.0,
        -8192.001,
        f32::MAX,
        f32::INFINITY,
        f32::NAN,
    ];

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        #[test]
        fn arc_tangent_bit_tests_change_no_result(y in proptest::num::f32::ANY, x in proptest::num::f32::ANY) {
            proptest::prop_assert!(same(atan2f(y, x), atan2f_float_tests(y, x)), "atan2f({y:e}, {x:e})");
        }

        #[test]
        fn arc_tangent_bit_tests_change_no_angle_of_a_pose(y in -1.0f32..1.0, x in -1.0f32..1.0) {
            proptest::prop_assert!(same(atan2f(y, x), atan2f_float_tests(y, x)), "atan2f({y:e}, {x:e})");
        }

        #[test]
        fn sine_and_cosine_without_reduction_in_octant_0_change_no_result(x in proptest::num::f32::ANY) {
            let ((s, c), (rs, rc)) = (sincosf(x), sincosf_always_reduced(x));
            proptest::prop_assert!(same(s, rs) && same(c, rc), "sincosf({x:e})");
        }

        #[test]
        fn sine_and_cosine_of_pose_angles_unchanged(x in -4.0f32..4.0) {
            let ((s, c), (rs, rc)) = (sincosf(x), sincosf_always_reduced(x));
            proptest::prop_assert!(same(s, rs) && same(c, rc), "sincosf({x:e})");
        }
    }

    #[test]
    fn special_values_keep_their_results() {
        for a in EDGES.iter().flat_map(|&v| [v, -v]) {
            let (s, c) = sincosf(a);
            let (rs, rc) = sincosf_always_reduced(a);
            assert!(same(s, rs) && same(c, rc), "sincosf({a:e})");
            for b in EDGES.iter().flat_map(|&v| [v, -v]) {
                assert!(same(atan2f(a, b), atan2f_float_tests(a, b)), "atan2f({a:e}, {b:e})");
            }
        }
    }
}
