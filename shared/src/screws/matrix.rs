//! Paper 002's matrix method for closed kinematic loops (SCREWS.md 2a): position by Gauss-Newton on the loop
//! closure, velocities, accelerations, and the mass term of a one-degree-of-freedom loop.
//!
//! Homogeneous 4x4 matrices with the 1 *first*: a point is `(1, x, y, z)` and a transform `[[1, 0], [r, L]]`
//! (`r` the child origin in the parent, `L` the rotation). A loop is `J1(q1) L1 J2(q2) L2 ... Jn(qn) Ln = E`, each
//! `J` a joint (a rotation about its z axis, or a slide along it) and each `L` a constant link transform.

use nalgebra::{Matrix4, Vector3};

use crate::kinematics::velocity::Lu6;

/// A joint of a loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Joint {
    /// Rotation about the joint frame's z axis by `q` (rad).
    Revolute,
    /// Slide along the joint frame's z axis by `q` (m).
    Prismatic,
}

impl Joint {
    /// The joint's transform at `q`.
    pub fn transform(self, q: f64) -> Matrix4<f64> {
        match self {
            Joint::Revolute => rot_z(q),
            Joint::Prismatic => translation(Vector3::new(0.0, 0.0, q)),
        }
    }

    /// The generator `Q` with `dJ/dq = Q J`.
    pub fn generator(self) -> Matrix4<f64> {
        let mut g = Matrix4::zeros();
        match self {
            Joint::Revolute => {
                g[(2, 1)] = 1.0;
                g[(1, 2)] = -1.0;
            }
            Joint::Prismatic => g[(3, 0)] = 1.0,
        }
        g
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

/// Why a loop computation has no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopError {
    /// The loop has more than six unknown joints, or its input is not one of its joints.
    Shape,
    /// The least-squares system is singular (a dead centre).
    Singular,
    /// Gauss-Newton did not converge within the iterations allowed.
    NoConvergence,
    /// A value is not finite.
    NonFinite,
}

/// One closed loop of `N` joints, each followed by a constant link transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loop<const N: usize> {
    /// The joints, in loop order.
    pub joints: [Joint; N],
    /// The link transform after each joint.
    pub links: [Matrix4<f64>; N],
}

/// The 12 entries (rows 1..=3, columns 0..=3) that a loop closure constrains.
fn entries(m: &Matrix4<f64>) -> [f64; 12] {
    core::array::from_fn(|k| m[(1 + k / 4, k % 4)])
}

/// Least squares `B x = r` over the 12 entries for the columns `cols` (at most six): normal equations by LU.
fn least_squares(columns: &[[f64; 12]], r: &[f64; 12]) -> Result<[f64; 6], LoopError> {
    let k = columns.len();
    if k > 6 {
        return Err(LoopError::Shape);
    }
    let dot = |a: &[f64; 12], b: &[f64; 12]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // Unused unknowns get identity rows: the 6x6 decomposition solves any k <= 6.
    let mut normal = [[0.0; 6]; 6];
    let mut rhs = [0.0; 6];
    for i in 0..6 {
        if i < k {
            for j in 0..k {
                normal[i][j] = dot(&columns[i], &columns[j]);
            }
            rhs[i] = dot(&columns[i], r);
        } else {
            normal[i][i] = 1.0;
        }
    }
    Lu6::in_place(&mut normal).solve(&rhs).ok_or(LoopError::Singular)
}

/// The joints other than `input` (at most six are used), and their columns of the closure's derivatives.
fn unknowns<const N: usize>(input: usize, b: &[Matrix4<f64>; N]) -> ([usize; 6], [[f64; 12]; 6], usize) {
    let mut unknown = [0; 6];
    let mut columns = [[0.0; 12]; 6];
    let mut count = 0;
    for k in (0..N).filter(|k| *k != input).take(6) {
        unknown[count] = k;
        columns[count] = entries(&b[k]);
        count += 1;
    }
    (unknown, columns, count)
}

impl<const N: usize> Loop<N> {
    /// The closure product `J1 L1 ... Jn Ln` at `q`.
    pub fn closure(&self, q: &[f64; N]) -> Matrix4<f64> {
        (0..N).fold(Matrix4::identity(), |m, k| {
            m * self.joints[k].transform(q[k]) * self.links[k]
        })
    }

    /// `B_k = (J1 L1 ... L_(k-1)) Q_k (J_k L_k ... Jn Ln)`: the derivative of the closure by `q_k` (at closure,
    /// the base-frame twist of joint `k`).
    pub fn derivatives(&self, q: &[f64; N]) -> [Matrix4<f64>; N] {
        let before: [Matrix4<f64>; N] = {
            let mut acc = Matrix4::identity();
            core::array::from_fn(|k| {
                let here = acc;
                acc = acc * self.joints[k].transform(q[k]) * self.links[k];
                here
            })
        };
        core::array::from_fn(|k| {
            let after = (k..N).fold(Matrix4::identity(), |m, j| {
                m * self.joints[j].transform(q[j]) * self.links[j]
            });
            before[k] * self.joints[k].generator() * after
        })
    }

    /// Closes the loop by Gauss-Newton with joint `input` held at its value in `q`: returns the joint values and
    /// the iterations used, stopping when no step exceeds `tolerance`.
    pub fn close(
        &self,
        input: usize,
        q: &[f64; N],
        tolerance: f64,
        max_iterations: u32,
    ) -> Result<([f64; N], u32), LoopError> {
        if input >= N || N > 7 {
            return Err(LoopError::Shape);
        }
        let mut q = *q;
        for iteration in 1..=max_iterations {
            let residual = entries(&(Matrix4::identity() - self.closure(&q)));
            let b = self.derivatives(&q);
            let (unknown, columns, count) = unknowns(input, &b);
            let step = least_squares(&columns[..count], &residual)?;
            let mut largest = 0.0f64;
            for (i, k) in unknown.iter().take(count).enumerate() {
                q[*k] += step[i];
                largest = largest.max(step[i].abs());
            }
            if !q.iter().all(|v| v.is_finite()) {
                return Err(LoopError::NonFinite);
            }
            if largest <= tolerance {
                return Ok((q, iteration));
            }
        }
        Err(LoopError::NoConvergence)
    }

    /// Joint rates for the input rate `rate` of joint `input`, at a closed `q`: `sum B_k q'_k = 0`.
    pub fn rates(&self, input: usize, q: &[f64; N], rate: f64) -> Result<[f64; N], LoopError> {
        let b = self.derivatives(q);
        let fixed: [f64; 12] = entries(&(-b[input] * rate));
        self.solve_unknowns(input, &b, &fixed, rate)
    }

    /// Joint accelerations for the input's rate and acceleration, at a closed `q` with rates `qd`:
    /// `sum B_k q''_k = -sum_(j<k) q'_j q'_k (B_j B_k - B_k B_j)`.
    pub fn accelerations(&self, input: usize, q: &[f64; N], qd: &[f64; N], accel: f64) -> Result<[f64; N], LoopError> {
        let b = self.derivatives(q);
        let mut rhs = -b[input] * accel;
        for k in 0..N {
            for j in 0..k {
                rhs -= (b[j] * b[k] - b[k] * b[j]) * (qd[j] * qd[k]);
            }
        }
        self.solve_unknowns(input, &b, &entries(&rhs), accel)
    }

    fn solve_unknowns(
        &self,
        input: usize,
        b: &[Matrix4<f64>; N],
        rhs: &[f64; 12],
        known: f64,
    ) -> Result<[f64; N], LoopError> {
        if input >= N || N > 7 {
            return Err(LoopError::Shape);
        }
        let (unknown, columns, count) = unknowns(input, b);
        let x = least_squares(&columns[..count], rhs)?;
        let mut out = [0.0; N];
        out[input] = known;
        for (i, k) in unknown.iter().take(count).enumerate() {
            out[*k] = x[i];
        }
        Ok(out)
    }

    /// The generalised mass `M` of a one-degree-of-freedom loop driven by joint `input`, at a closed `q`, for links
    /// with pseudo-inertias `inertia[i]` (about the frame of link `i`, the frame after joint `i`; `None` for the
    /// ground link): `M = sum tr(C_i J_i C_i^T)`, `C_i = (sum_(k<=i) B_k dq_k/dq_s) A_0i`.
    pub fn mass(&self, input: usize, q: &[f64; N], inertia: &[Option<Matrix4<f64>>; N]) -> Result<f64, LoopError> {
        let b = self.derivatives(q);
        let ratios = self.rates(input, q, 1.0)?;
        let mut frame = Matrix4::identity();
        let mut twist = Matrix4::zeros();
        let mut total = 0.0;
        for i in 0..N {
            frame *= self.joints[i].transform(q[i]);
            twist += b[i] * ratios[i];
            if let Some(j) = &inertia[i] {
                let c = twist * frame;
                total += (c * j * c.transpose()).trace();
            }
            frame *= self.links[i];
        }
        Ok(total)
    }
}

/// The pseudo-inertia `[[m, m c^T], [m c, S]]` (1-first layout, `S = integral of r r^T dm`) of a uniform thin rod of
/// mass `m` from the frame origin along +x to length `a`.
pub fn rod_along_x(m: f64, a: f64) -> Matrix4<f64> {
    let mut j = Matrix4::zeros();
    j[(0, 0)] = m;
    j[(0, 1)] = m * a / 2.0;
    j[(1, 0)] = m * a / 2.0;
    j[(1, 1)] = m * a * a / 3.0;
    j
}
