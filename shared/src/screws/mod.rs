//! Screws (SCREWS.md): Plücker lines, twists and wrenches as `[direction; moment]` six-vectors, their reciprocal
//! product, paper 002's matrix method for closed loops ([`matrix`]), paper 003's generalised reactions
//! ([`reactions`]) and the dissertation's structural analysis ([`structure`], with each mechanism's chains in
//! [`layouts`]); paper 003's three-DOF translational mechanism and its Gram determinants ([`translational`]).

pub mod chains;
pub mod layouts;
pub mod matrix;
pub mod reactions;
pub mod structure;
pub mod tool;
pub mod translational;

use nalgebra::{Vector3, Vector6};

/// The unit line along `u` (normalised here) through `p`, about the origin `o`: `[u; (p - o) x u]`.
pub fn line(u: &Vector3<f64>, p: &Vector3<f64>, o: &Vector3<f64>) -> Vector6<f64> {
    let n = u.norm();
    let u = if n > 0.0 { u / n } else { *u };
    let m = (p - o).cross(&u);
    Vector6::new(u.x, u.y, u.z, m.x, m.y, m.z)
}

/// The reciprocal product `t . w = t_direction . w_moment + t_moment . w_direction`: the power of a wrench on a
/// twist, the same about any origin; zero when the wrench does no work on the twist.
pub fn reciprocal(t: &Vector6<f64>, w: &Vector6<f64>) -> f64 {
    t.fixed_rows::<3>(0).dot(&w.fixed_rows::<3>(3)) + t.fixed_rows::<3>(3).dot(&w.fixed_rows::<3>(0))
}

/// The twist `[w; v]` of a body about origin `o` read from a velocity matrix of the matrix method (1-first layout):
/// `w = (M[3][2], M[1][3], M[2][1])`, `v = (M[1][0], M[2][0], M[3][0])`.
pub fn twist_of(m: &nalgebra::Matrix4<f64>) -> Vector6<f64> {
    Vector6::new(m[(3, 2)], m[(1, 3)], m[(2, 1)], m[(1, 0)], m[(2, 0)], m[(3, 0)])
}
