//! The initial guess of paper 002: each pair frame from three points of a sketch (its origin, a point on +X and one
//! on +Z, in the base frame), the pair's transform `A_ij = A_0i^-1 A_0j`, and the pair's variables read from it.
//!
//! The paper gives only the revolute angle, `gamma = -arcsin a32`, which covers half a turn; every angle here is an
//! `atan2` of two entries of the same matrix, which gives the whole turn and agrees with the arcsin where it holds.

use nalgebra::{Matrix4, Vector3};

use super::pairs::{inverse, Joint};
use super::LoopError;

/// The frame `A_0k = [[1, 0], [r_o, e_x e_y e_z]]` through the origin `o` with `x` on its +X axis and `z` on its +Z
/// axis: `e_x`, `e_z` normalised, `e_y = e_z x e_x`. A sketch's directions are seldom exactly perpendicular, so
/// `e_x` is first made perpendicular to `e_z` (the paper assumes they are); a zero, parallel or non-finite
/// direction is refused.
pub fn frame(o: &Vector3<f64>, x: &Vector3<f64>, z: &Vector3<f64>) -> Result<Matrix4<f64>, LoopError> {
    let unit = |v: Vector3<f64>| {
        let n = libm::sqrt(v.dot(&v));
        if n > 1e-12 && n.is_finite() {
            Ok(v / n)
        } else {
            Err(LoopError::NonFinite)
        }
    };
    let ez = unit(z - o)?;
    let ex = unit((x - o) - ez * (x - o).dot(&ez))?;
    let ey = ez.cross(&ex);
    let mut a = Matrix4::identity();
    a.fixed_view_mut::<3, 1>(1, 0).copy_from(o);
    a.fixed_view_mut::<3, 1>(1, 1).copy_from(&ex);
    a.fixed_view_mut::<3, 1>(1, 2).copy_from(&ey);
    a.fixed_view_mut::<3, 1>(1, 3).copy_from(&ez);
    Ok(a)
}

/// The transform between two frames of the base: `A_ij = A_0i^-1 A_0j`.
pub fn relative(a_0i: &Matrix4<f64>, a_0j: &Matrix4<f64>) -> Matrix4<f64> {
    inverse(a_0i) * a_0j
}

/// The variables of `joint` read from its transform `a` (unused entries zero). A screw's angle is its slide over
/// the pitch when the pitch is not zero (a whole number of turns is then kept), else the angle of its rotation.
pub fn values(joint: Joint, a: &Matrix4<f64>) -> [f64; 3] {
    let e = |r: usize, c: usize| a[(r, c)];
    let turn = libm::atan2(e(2, 1), e(1, 1));
    match joint {
        Joint::Revolute => [turn, 0.0, 0.0],
        Joint::Prismatic => [e(3, 0), 0.0, 0.0],
        Joint::Screw { pitch } if pitch != 0.0 => [e(3, 0) / pitch, 0.0, 0.0],
        Joint::Screw { .. } => [turn, 0.0, 0.0],
        Joint::Cylindrical => [turn, e(3, 0), 0.0],
        // Rz(phi) Rx(90) Rz(theta + pi): column 3 is (sin phi, -cos phi, 0), row 3 is (-sin theta, -cos theta, 0).
        Joint::Hooke => [libm::atan2(e(1, 3), -e(2, 3)), libm::atan2(-e(3, 1), -e(3, 2)), 0.0],
        // Rz(psi) Rx(theta) Rz(phi): column 3 is sin theta (sin psi, -cos psi), row 3 is sin theta (sin phi,
        // cos phi) and a33 = cos theta; theta is taken in [0, pi].
        Joint::Spherical => {
            let s = libm::sqrt(e(1, 3) * e(1, 3) + e(2, 3) * e(2, 3));
            [
                libm::atan2(e(1, 3), -e(2, 3)),
                libm::atan2(s, e(3, 3)),
                libm::atan2(e(3, 1), e(3, 2)),
            ]
        }
    }
}
