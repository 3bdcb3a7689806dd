//! The kinematic pairs of paper 002's table 1, their transforms and their generators (table 2).
//!
//! Every pair's frames share the z axis convention of the paper: the revolute, screw and cylindrical pairs turn
//! about z, the prismatic, screw and cylindrical pairs slide along it. A pair of several variables is a product of
//! elementary motions; the generator of variable `k` is `P G P^-1`, `P` the product of the motions before it and
//! `G` the elementary generator, so that `dA/dq_k = Q_k A` as in the paper.

use nalgebra::{Matrix4, Vector3};

/// A kinematic pair (table 1) joining two links of a loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Joint {
    /// Rotation about z by `gamma` (rad): one variable.
    Revolute,
    /// Slide along z by `s` (m): one variable.
    Prismatic,
    /// Rotation about z by `gamma` with the slide `pitch * gamma` along it (`pitch` in m/rad): one variable.
    Screw {
        /// The slide per radian of rotation (m/rad); a lead `h` per turn is `h / (2 pi)`.
        pitch: f64,
    },
    /// Rotation about z by `gamma` and slide along z by `s`, independent: variables `(gamma, s)`.
    Cylindrical,
    /// Hooke's joint, variables `(phi, theta)`: `Rz(phi) Rx(90 deg) Rz(theta + pi)`, the paper's table 1 with its
    /// third row read as `(-sin theta, -cos theta, 0)` so that the matrix is a rotation.
    Hooke,
    /// Spherical pair, the Euler angles `(psi, theta, phi)` about `Z_j`, the line of nodes and `Z_k`:
    /// `Rz(psi) Rx(theta) Rz(phi)`.
    Spherical,
}

/// The elementary generators: rotation about z, rotation about x, slide along z.
fn gen_rz() -> Matrix4<f64> {
    let mut g = Matrix4::zeros();
    g[(2, 1)] = 1.0;
    g[(1, 2)] = -1.0;
    g
}

fn gen_rx() -> Matrix4<f64> {
    let mut g = Matrix4::zeros();
    g[(3, 2)] = 1.0;
    g[(2, 3)] = -1.0;
    g
}

fn gen_tz() -> Matrix4<f64> {
    let mut g = Matrix4::zeros();
    g[(3, 0)] = 1.0;
    g
}

/// Conjugate `g` by the rigid motion `p`: `p g p^-1`.
fn conjugate(p: &Matrix4<f64>, g: &Matrix4<f64>) -> Matrix4<f64> {
    p * g * inverse(p)
}

/// The inverse of a rigid motion `[[1, 0], [r, L]]`: `[[1, 0], [-L^T r, L^T]]`.
pub fn inverse(a: &Matrix4<f64>) -> Matrix4<f64> {
    let l = a.fixed_view::<3, 3>(1, 1).transpose();
    let r = a.fixed_view::<3, 1>(1, 0).into_owned();
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(1, 1).copy_from(&l);
    m.fixed_view_mut::<3, 1>(1, 0).copy_from(&(-(l * r)));
    m
}

impl Joint {
    /// How many variables the pair has.
    pub const fn variables(self) -> usize {
        match self {
            Joint::Revolute | Joint::Prismatic | Joint::Screw { .. } => 1,
            Joint::Cylindrical | Joint::Hooke => 2,
            Joint::Spherical => 3,
        }
    }

    /// The pair's transform for its variables `q` (as many as [`Joint::variables`]; missing ones read as zero).
    pub fn transform(self, q: &[f64]) -> Matrix4<f64> {
        let v = |k: usize| q.get(k).copied().unwrap_or(0.0);
        match self {
            Joint::Revolute => rot_z(v(0)),
            Joint::Prismatic => slide_z(v(0)),
            Joint::Screw { pitch } => slide_z(pitch * v(0)) * rot_z(v(0)),
            Joint::Cylindrical => slide_z(v(1)) * rot_z(v(0)),
            Joint::Hooke => rot_z(v(0)) * rot_x(core::f64::consts::FRAC_PI_2) * rot_z(v(1) + core::f64::consts::PI),
            Joint::Spherical => rot_z(v(0)) * rot_x(v(1)) * rot_z(v(2)),
        }
    }

    /// The generator `Q_k` of variable `k` at `q`, with `dA/dq_k = Q_k A` (zero for `k` past the variables).
    pub fn generator(self, k: usize, q: &[f64]) -> Matrix4<f64> {
        let v = |k: usize| q.get(k).copied().unwrap_or(0.0);
        match (self, k) {
            (Joint::Revolute, 0) | (Joint::Cylindrical, 0) => gen_rz(),
            (Joint::Prismatic, 0) | (Joint::Cylindrical, 1) => gen_tz(),
            (Joint::Screw { pitch }, 0) => gen_rz() + gen_tz() * pitch,
            (Joint::Hooke, 0) | (Joint::Spherical, 0) => gen_rz(),
            (Joint::Hooke, 1) => conjugate(&(rot_z(v(0)) * rot_x(core::f64::consts::FRAC_PI_2)), &gen_rz()),
            (Joint::Spherical, 1) => conjugate(&rot_z(v(0)), &gen_rx()),
            (Joint::Spherical, 2) => conjugate(&(rot_z(v(0)) * rot_x(v(1))), &gen_rz()),
            _ => Matrix4::zeros(),
        }
    }
}

/// Translation by `r` (1-first layout).
pub fn translation(r: Vector3<f64>) -> Matrix4<f64> {
    let mut a = Matrix4::identity();
    a[(1, 0)] = r.x;
    a[(2, 0)] = r.y;
    a[(3, 0)] = r.z;
    a
}

fn slide_z(s: f64) -> Matrix4<f64> {
    translation(Vector3::new(0.0, 0.0, s))
}

/// Rotation about x by `a` (rad).
pub fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = (libm::sin(a), libm::cos(a));
    let mut m = Matrix4::identity();
    m[(2, 2)] = c;
    m[(2, 3)] = -s;
    m[(3, 2)] = s;
    m[(3, 3)] = c;
    m
}

/// Rotation about z by `a` (rad).
pub fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = (libm::sin(a), libm::cos(a));
    let mut m = Matrix4::identity();
    m[(1, 1)] = c;
    m[(1, 2)] = -s;
    m[(2, 1)] = s;
    m[(2, 2)] = c;
    m
}
