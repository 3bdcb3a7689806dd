//! Paper 002's matrix method for closed kinematic loops (SCREWS.md 2a): position by Gauss-Newton on the loop
//! closure, velocities, accelerations, and the mass term of a one-degree-of-freedom loop.
//!
//! Homogeneous 4x4 matrices with the 1 *first*: a point is `(1, x, y, z)` and a transform `[[1, 0], [r, L]]`
//! (`r` the child origin in the parent, `L` the rotation). A loop is `J1(q1) L1 J2(q2) L2 ... Jn(qn) Ln = E`, each
//! `J` a pair of the paper's table 1 ([`Joint`], one to three variables) and each `L` a constant link transform.
//! A loop's variables are those of its pairs in loop order; `input` always names a variable.
//!
//! Mechanisms of several loops and drives are trees of pairs closed by loop conditions ([`mechanism`]); their
//! equation of motion is in [`lagrange`], motions and forward dynamics in [`motion`], the ring platforms in
//! paper 002's terms in [`ring`].

mod guess;
pub mod lagrange;
pub mod mechanism;
pub mod motion;
mod pairs;
pub mod ring;
#[cfg(test)]
mod tests;

pub use guess::{frame, relative, values};
pub use lagrange::{pseudo_inertia, Body, Element, Energy, Model, State};
pub use mechanism::{Closure, Frames, Mechanism, Pair, GROUND};
pub use pairs::{inverse, rot_x, rot_z, translation, Joint};

use nalgebra::Matrix4;

use crate::kinematics::velocity::Lu6;

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

/// One closed loop of `N` pairs, each followed by a constant link transform.
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
    /// How many variables the loop's pairs have together.
    pub fn variables(&self) -> usize {
        self.joints.iter().map(|j| j.variables()).sum()
    }

    /// Each pair's transform at `q` (the loop's variables), or `Shape` when `q` is not as long as the variables.
    fn pair_transforms<const V: usize>(&self, q: &[f64; V]) -> Result<[Matrix4<f64>; N], LoopError> {
        if self.variables() != V {
            return Err(LoopError::Shape);
        }
        let mut at = 0;
        Ok(core::array::from_fn(|i| {
            let n = self.joints[i].variables();
            let t = self.joints[i].transform(&q[at..at + n]);
            at += n;
            t
        }))
    }

    /// The closure product `J1 L1 ... Jn Ln` at `q`.
    pub fn closure<const V: usize>(&self, q: &[f64; V]) -> Result<Matrix4<f64>, LoopError> {
        let t = self.pair_transforms(q)?;
        Ok((0..N).fold(Matrix4::identity(), |m, k| m * t[k] * self.links[k]))
    }

    /// `B_v = (J1 L1 ... L_(i-1)) Q_v (J_i L_i ... Jn Ln)` for each variable `v` of pair `i`: the derivative of the
    /// closure by `q_v` (at closure, the base-frame twist of that variable's motion).
    pub fn derivatives<const V: usize>(&self, q: &[f64; V]) -> Result<[Matrix4<f64>; V], LoopError> {
        let t = self.pair_transforms(q)?;
        let mut after = [Matrix4::identity(); N];
        let mut acc = Matrix4::identity();
        for i in (0..N).rev() {
            acc = t[i] * self.links[i] * acc;
            after[i] = acc;
        }
        let mut out = [Matrix4::zeros(); V];
        let (mut before, mut v) = (Matrix4::<f64>::identity(), 0);
        for i in 0..N {
            let n = self.joints[i].variables();
            for k in 0..n {
                out[v + k] = before * self.joints[i].generator(k, &q[v..v + n]) * after[i];
            }
            before = before * t[i] * self.links[i];
            v += n;
        }
        Ok(out)
    }

    /// Closes the loop by Gauss-Newton with variable `input` held at its value in `q`: `dq = (B^T B)^-1 B^T W` over
    /// the 12 entries, repeated until no step exceeds `tolerance`. Returns the variables and the iterations used.
    pub fn close<const V: usize>(
        &self,
        input: usize,
        q: &[f64; V],
        tolerance: f64,
        max_iterations: u32,
    ) -> Result<([f64; V], u32), LoopError> {
        if input >= V || V > 7 {
            return Err(LoopError::Shape);
        }
        let mut q = *q;
        for iteration in 1..=max_iterations {
            let residual = entries(&(Matrix4::identity() - self.closure(&q)?));
            let b = self.derivatives(&q)?;
            let (unknown, columns, count) = unknowns(input, &b);
            let step = least_squares(&columns[..count], &residual)?;
            let mut largest = 0.0f64;
            for (i, k) in unknown.iter().take(count).enumerate() {
                q[*k] += step[i];
                largest = largest.max(libm::fabs(step[i]));
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

    /// Rates of the variables for the input rate `rate` of variable `input`, at a closed `q`: `sum B_v q'_v = 0`.
    pub fn rates<const V: usize>(&self, input: usize, q: &[f64; V], rate: f64) -> Result<[f64; V], LoopError> {
        if input >= V {
            return Err(LoopError::Shape);
        }
        let b = self.derivatives(q)?;
        let fixed: [f64; 12] = entries(&(-b[input] * rate));
        solve_unknowns(input, &b, &fixed, rate)
    }

    /// Accelerations of the variables for the input's rate and acceleration, at a closed `q` with rates `qd`:
    /// `sum B_v q''_v = -sum_(u<v) q'_u q'_v (B_u B_v - B_v B_u)`. It holds for pairs of several variables too:
    /// each variable moves by a constant generator conjugated by all that precedes it in the loop (the cylindrical
    /// pair's two motions commute, so their order does not matter), which is what the formula assumes.
    pub fn accelerations<const V: usize>(
        &self,
        input: usize,
        q: &[f64; V],
        qd: &[f64; V],
        accel: f64,
    ) -> Result<[f64; V], LoopError> {
        if input >= V {
            return Err(LoopError::Shape);
        }
        let b = self.derivatives(q)?;
        let mut rhs = -b[input] * accel;
        for k in 0..V {
            for j in 0..k {
                rhs -= (b[j] * b[k] - b[k] * b[j]) * (qd[j] * qd[k]);
            }
        }
        solve_unknowns(input, &b, &entries(&rhs), accel)
    }

    /// The generalised mass `M` of a one-degree-of-freedom loop driven by variable `input`, at a closed `q`, for
    /// links with pseudo-inertias `inertia[i]` (about the frame of link `i`, the frame after pair `i`; `None` for
    /// the ground link): `M = sum tr(C_i J_i C_i^T)`, `C_i = (sum_(v up to pair i) B_v dq_v/dq_s) A_0i`.
    pub fn mass<const V: usize>(
        &self,
        input: usize,
        q: &[f64; V],
        inertia: &[Option<Matrix4<f64>>; N],
    ) -> Result<f64, LoopError> {
        let t = self.pair_transforms(q)?;
        let b = self.derivatives(q)?;
        let ratios = self.rates(input, q, 1.0)?;
        let (mut frame, mut twist, mut total, mut v) = (Matrix4::identity(), Matrix4::zeros(), 0.0, 0);
        for i in 0..N {
            frame *= t[i];
            for _ in 0..self.joints[i].variables() {
                twist += b[v] * ratios[v];
                v += 1;
            }
            if let Some(j) = &inertia[i] {
                let c = twist * frame;
                total += (c * j * c.transpose()).trace();
            }
            frame *= self.links[i];
        }
        Ok(total)
    }
}

/// Solves `sum B_v x_v = rhs` for the variables other than `input`, which is `known`.
fn solve_unknowns<const V: usize>(
    input: usize,
    b: &[Matrix4<f64>; V],
    rhs: &[f64; 12],
    known: f64,
) -> Result<[f64; V], LoopError> {
    if input >= V || V > 7 {
        return Err(LoopError::Shape);
    }
    let (unknown, columns, count) = unknowns(input, b);
    let x = least_squares(&columns[..count], rhs)?;
    let mut out = [0.0; V];
    out[input] = known;
    for (i, k) in unknown.iter().take(count).enumerate() {
        out[*k] = x[i];
    }
    Ok(out)
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
