//! Paper 003's three-DOF translational mechanism (SCREWS.md 3) and the Gram determinants of its wrenches, which the
//! paper draws over a slice of its workspace (its figs. 3-5).
//!
//! Three chains of five revolute joints `A`-`E`; chain `i`'s actuated joint `A` turns about the coordinate axis
//! `e_i` at `A = -OA e_i`, `B` and `C` turn about `u_i(theta_i)` (perpendicular to `e_i`, at the actuator's angle
//! `theta_i`), `D` and `E` about `e_i`, and `E`'s axis passes through the platform point `F`. The paper gives the
//! joints' axes and lengths (`AB = BC = CD = DE = 0.2`, `EF = 0.3`, `OA = 0.5` m) but its link layout only in a
//! figure; this is the layout SCREWS.md 3 assumes and its test pose (SCREWS.md 4, T5; the paper prints
//! no pose) confirms, with `v_i = e_i x u_i`:
//! `B = A + AB v`, `C = B + BC (cos(alpha) e_i + sin(alpha) v)`, `D = C + CD v`, `E = F - EF e_i`. In the plane
//! across `e_i` (right-handed: `(y, z)`, `(z, x)`, `(x, y)`), `u_i` lies at the angle `theta_i` and `v_i` a quarter
//! turn on. Each chain then has two elbows (the sign of `sin(alpha)`) and two sides (which way `v_i` turns from `F`).
//!
//! The Gram matrices take the wrenches as unit vectors about `F`, in SI units (SCREWS.md 1: the Euclidean product of
//! wrenches depends on both), so that each determinant is between 0 (the wrenches dependent) and 1 (orthogonal):
//! `G_C = W_C^T W_C` of the constraint wrenches, `G_A` of the actuation wrenches, `G` of all six. `det G_C` is
//! `det M_C^2` (the constraint couples' moments, `det M_C = s1 s2 s3 - c1 c2 c3`) and vanishes only at constraint
//! singularities; `det G = det [W_C | W_A]^2` vanishes at every singularity.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::line;
use super::reactions::{actuation_wrench, reactions};
use crate::kinematics::geometry::Branch;

/// Distance from the origin to each actuated joint `OA` (m).
pub const OA: f64 = 0.5;
/// Each of the links `AB`, `BC`, `CD`, `DE` (m).
pub const LINK: f64 = 0.2;
/// The last link `EF` (m).
pub const EF: f64 = 0.3;
/// The height of the paper's slice (m).
pub const SLICE_Z: f64 = -0.18;

/// How one chain is assembled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChainBranch {
    /// The sign of `sin(alpha)`: `C` on the `+v` or the `-v` side of `B`.
    pub elbow: Branch,
    /// `v_i` turned from `F`'s direction (in the plane across `e_i`) by `+delta` or `-delta`.
    pub side: Branch,
}

/// The assembly of the specification's test pose (SCREWS.md 4, T5): every elbow `Minus`, the sides mixed.
pub const MIXED: [ChainBranch; 3] = [
    ChainBranch {
        elbow: Branch::Minus,
        side: Branch::Plus,
    },
    ChainBranch {
        elbow: Branch::Minus,
        side: Branch::Plus,
    },
    ChainBranch {
        elbow: Branch::Minus,
        side: Branch::Minus,
    },
];

/// Why a point has no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TranslationalError {
    /// The point is not finite.
    NonFinite,
    /// Chain `i` (0-based) cannot reach the point.
    Unreachable(usize),
    /// Chain `i`'s actuation wrench is not defined (its passive joints and constraint leave no single direction).
    Degenerate(usize),
    /// The six wrenches are dependent (a singularity): no reactions balance a load.
    Singular,
}

impl core::fmt::Display for TranslationalError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFinite => f.write_str("the point is not finite"),
            Self::Unreachable(i) => write!(f, "chain {} cannot reach the point", i + 1),
            Self::Degenerate(i) => write!(f, "chain {}'s actuation wrench is not defined there", i + 1),
            Self::Singular => f.write_str("the wrenches are dependent there (a singularity)"),
        }
    }
}

impl core::error::Error for TranslationalError {}

/// One chain placed at a point: its actuator angle and joint centres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chain {
    /// The actuator's angle `theta_i` (rad, in `(-pi, pi]` plus the turn the closed form gives: compare modulo 2 pi).
    pub theta: f64,
    /// Joint centres `A, B, C, D, E` (m).
    pub joints: [Vector3<f64>; 5],
    /// The axis of `A`, `D`, `E` (`e_i`) and of `B`, `C` (`u_i`).
    pub axes: [Vector3<f64>; 2],
}

fn e(i: usize) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    v[i % 3] = 1.0;
    v
}

/// Places chain `i` (0, 1, 2) so that `E`'s axis passes through `f`.
pub fn chain(i: usize, f: &Vector3<f64>, branch: ChainBranch) -> Result<Chain, TranslationalError> {
    if !f.iter().all(|v| v.is_finite()) {
        return Err(TranslationalError::NonFinite);
    }
    let unreachable = TranslationalError::Unreachable(i);
    let (ei, ep, eq) = (e(i), e(i + 1), e(i + 2));
    // D's and E's coordinates along e_i agree (DE lies across e_i): A_e + BC cos(alpha) = F_e - EF.
    let cos_alpha = (f.dot(&ei) - EF + OA) / LINK;
    if cos_alpha.abs() > 1.0 {
        return Err(unreachable);
    }
    let sin_alpha = libm::sqrt(1.0 - cos_alpha * cos_alpha)
        * match branch.elbow {
            Branch::Plus => 1.0,
            Branch::Minus => -1.0,
        };
    // Across e_i, D is `rho` from the axis along v, E at F's own (p, q), and DE = LINK.
    let rho = LINK * (2.0 + sin_alpha);
    let (fp, fq) = (f.dot(&ep), f.dot(&eq));
    let r = libm::sqrt(fp * fp + fq * fq);
    if r == 0.0 {
        return Err(unreachable);
    }
    let cos_delta = (rho * rho + r * r - LINK * LINK) / (2.0 * rho * r);
    if !cos_delta.is_finite() || cos_delta.abs() > 1.0 {
        return Err(unreachable);
    }
    let delta = libm::acos(cos_delta)
        * match branch.side {
            Branch::Plus => 1.0,
            Branch::Minus => -1.0,
        };
    let v_angle = libm::atan2(fq, fp) + delta;
    let theta = v_angle - core::f64::consts::FRAC_PI_2;
    let (s, c) = libm::sincos(theta);
    let u = ep * c + eq * s;
    let v = ei.cross(&u);
    let a = -OA * ei;
    let b = a + LINK * v;
    let cc = b + LINK * (cos_alpha * ei + sin_alpha * v);
    let d = cc + LINK * v;
    let end = f - EF * ei;
    Ok(Chain {
        theta,
        joints: [a, b, cc, d, end],
        axes: [ei, u],
    })
}

/// The unit wrenches of the mechanism at a point, about it: each chain's constraint couple `[0; u_i x e_i]` and
/// the direction of its actuation wrench.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wrenches {
    /// The chains.
    pub chains: [Chain; 3],
    /// `w_C1..3`.
    pub constraints: [Vector6<f64>; 3],
    /// `w_A1..3`, unit length (their reactions' scale, unit work on the actuator, is left out: SCREWS.md 2b).
    pub actuation: [Vector6<f64>; 3],
}

/// The mechanism's wrenches at platform point `f`, its chains assembled as `branches`.
pub fn wrenches(f: &Vector3<f64>, branches: [ChainBranch; 3]) -> Result<Wrenches, TranslationalError> {
    let mut chains = [chain(0, f, branches[0])?; 3];
    for (i, slot) in chains.iter_mut().enumerate().skip(1) {
        *slot = chain(i, f, branches[i])?;
    }
    let mut constraints = [Vector6::zeros(); 3];
    let mut actuation = [Vector6::zeros(); 3];
    for (i, ch) in chains.iter().enumerate() {
        let [ei, u] = ch.axes;
        let m = u.cross(&ei);
        constraints[i] = Vector6::new(0.0, 0.0, 0.0, m.x, m.y, m.z);
        let [a, b, c, d, end] = ch.joints;
        let passive = [line(&u, &b, f), line(&u, &c, f), line(&ei, &d, f), line(&ei, &end, f)];
        let w =
            actuation_wrench(&line(&ei, &a, f), &passive, &constraints[i]).ok_or(TranslationalError::Degenerate(i))?;
        let n = w.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(TranslationalError::Degenerate(i));
        }
        actuation[i] = w / n;
    }
    Ok(Wrenches {
        chains,
        constraints,
        actuation,
    })
}

/// The determinants at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GramDeterminants {
    /// The actuator angles (rad).
    pub theta: [f64; 3],
    /// `det M_C = s1 s2 s3 - c1 c2 c3`: its sign tells the two sides of the constraint singularity apart.
    pub det_mc: f64,
    /// `det G_C` (constraint wrenches).
    pub constraints: f64,
    /// `det G_A` (actuation wrenches).
    pub actuation: f64,
    /// `det G` (all six).
    pub all: f64,
}

/// The Gram determinants at platform point `f`.
pub fn gram(f: &Vector3<f64>, branches: [ChainBranch; 3]) -> Result<GramDeterminants, TranslationalError> {
    let w = wrenches(f, branches)?;
    let all: [Vector6<f64>; 6] = core::array::from_fn(|k| if k < 3 { w.constraints[k] } else { w.actuation[k - 3] });
    let g3 = |v: &[Vector6<f64>; 3]| Matrix3::from_fn(|r, c| v[r].dot(&v[c])).determinant();
    let g = Matrix6::from_fn(|r, c| all[r].dot(&all[c])).determinant();
    let theta = w.chains.map(|c| c.theta);
    let (s, c) = (theta.map(libm::sin), theta.map(libm::cos));
    Ok(GramDeterminants {
        theta,
        det_mc: s[0] * s[1] * s[2] - c[0] * c[1] * c[2],
        constraints: g3(&w.constraints),
        actuation: g3(&w.actuation),
        all: g,
    })
}

/// The load of paper 003's figs. 3 and 5 as ringpod draws them, `[force; couple]` about `F`: the paper does not say
/// which it used. A pure force is all taken by the actuators once projected (the projected constraint reactions are
/// `W_C^+ P`, the couple's share), so the load is 1 N down with a couple of 0.1 N m about each axis.
pub const FIG_LOAD: [f64; 6] = [0.0, 0.0, -1.0, 0.1, 0.1, 0.1];

/// The largest constraint reaction at a point, `r_max = max |r_Ci|` (the paper's fig. 3 unprojected, fig. 5 with
/// the actuation wrenches projected onto the complement of the constraints' span), for a load `p` on the platform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaxReactions {
    /// Fig. 3: it grows near actuation singularities as well as near the constraint singularity.
    pub unprojected: f64,
    /// Fig. 5: it grows only near the constraint singularity.
    pub projected: f64,
}

/// [`MaxReactions`] at platform point `f` for the load `p` (N, N m), the actuation wrenches of unit length as in
/// [`wrenches`] (their reactions' scale is theirs, the constraint reactions are in N m).
pub fn max_reactions(
    f: &Vector3<f64>,
    branches: [ChainBranch; 3],
    p: &Vector6<f64>,
) -> Result<MaxReactions, TranslationalError> {
    let w = wrenches(f, branches)?;
    let r = reactions(&w.actuation, &w.constraints, p).ok_or(TranslationalError::Singular)?;
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let out = MaxReactions {
        unprojected: largest(&r.constraints[..3]),
        projected: largest(&r.constraints_projected[..3]),
    };
    if out.unprojected.is_finite() && out.projected.is_finite() {
        Ok(out)
    } else {
        Err(TranslationalError::Singular)
    }
}
