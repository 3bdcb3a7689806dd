//! Mechanisms of several loops and several degrees of freedom in paper 002's terms: a tree of pairs from the ground
//! (each pair moves its own link; links that branch carry several pairs), closed by loop conditions that weld two
//! links together, so that every loop `A_0a X (A_0b)^-1 = E` is the paper's `J1 L1 ... Jn Ln = E` read from a cut.
//!
//! Fixed capacities keep it free of allocation: [`MAX_PAIRS`] pairs, [`MAX_VARIABLES`] variables, [`MAX_LOOPS`]
//! loops and [`MAX_DRIVES`] drives (the variables given along a motion, the generalised coordinates).
//!
//! Every variable `v` has its base-frame twist `B_v = P_v Q_v P_v^-1` (`P_v` the frame before its motion, `Q_v` its
//! generator of table 2), so `dA_0i/dt = (sum over the variables on the path to link i of B_v q'_v) A_0i`. A loop's
//! closure derivative by `q_v` is `F (s_v B_v) A_0b` with `F = (A_0a X)^-1` and `s_v` = +1 on `b`'s path only, -1 on
//! `a`'s path only, 0 on both; at closure the velocity condition is `sum s_v B_v q'_v = 0` and the acceleration
//! condition `sum s_v (B_v q''_v + B'_v q'_v) = 0` with `B'_v = [W_v, B_v]`, `W_v` the twist of all before `v`.

use nalgebra::{Matrix4, SMatrix, SVector, Vector3, Vector4};

use super::pairs::{inverse, Joint};
use super::LoopError;

/// Pairs a mechanism may have.
pub const MAX_PAIRS: usize = 24;
/// Variables its pairs may have together.
pub const MAX_VARIABLES: usize = 42;
/// Loop conditions it may have.
pub const MAX_LOOPS: usize = 8;
/// Drives (given variables) it may have.
pub const MAX_DRIVES: usize = 6;

/// The link of a mechanism moved by pair `p` is link `p + 1`; link 0 is the ground.
pub const GROUND: usize = 0;

/// A pair of the tree: its joint, the link it hangs from, and where its frame sits on that link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    /// The pair's kind (table 1).
    pub joint: Joint,
    /// The link it hangs from: [`GROUND`] or `p + 1` of an earlier pair `p`.
    pub parent: usize,
    /// The pair's frame in its parent link's frame (the paper's constant link matrix).
    pub place: Matrix4<f64>,
}

/// A loop condition: the frame `X` on link `a` coincides with link `b`'s frame, `A_0a X = A_0b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closure {
    /// The link carrying the offset.
    pub a: usize,
    /// The link whose frame is welded to it.
    pub b: usize,
    /// `X`, link `b`'s frame in link `a`'s.
    pub offset: Matrix4<f64>,
}

/// A mechanism: a tree of pairs, loop conditions, and the variables that drive it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanism {
    pairs: [Pair; MAX_PAIRS],
    pair_count: usize,
    closures: [Closure; MAX_LOOPS],
    closure_count: usize,
    drives: [usize; MAX_DRIVES],
    drive_count: usize,
    /// Each variable's pair, and its index within the pair.
    owner: [(usize, usize); MAX_VARIABLES],
    /// The first variable of each pair.
    first: [usize; MAX_PAIRS],
    variable_count: usize,
    /// Bit `p` of `path[i]`: pair `p` lies on the path from the ground to link `i`.
    path: [u32; MAX_PAIRS + 1],
}

/// Everything position-dependent at one `q`: link frames and variable twists.
#[derive(Debug, Clone, Copy)]
pub struct Frames {
    /// `A_0i` of each link (index 0 the ground).
    pub links: [Matrix4<f64>; MAX_PAIRS + 1],
    /// `B_v` of each variable.
    pub twists: [Matrix4<f64>; MAX_VARIABLES],
}

/// The commutator `a b - b a`.
fn bracket(a: &Matrix4<f64>, b: &Matrix4<f64>) -> Matrix4<f64> {
    a * b - b * a
}

/// The 12 entries (rows 1..=3, columns 0..=3) a loop condition constrains.
fn entries(m: &Matrix4<f64>) -> [f64; 12] {
    core::array::from_fn(|k| m[(1 + k / 4, k % 4)])
}

type Square = SMatrix<f64, MAX_VARIABLES, MAX_VARIABLES>;
type Column = SVector<f64, MAX_VARIABLES>;

impl Mechanism {
    /// A mechanism of `pairs` (each hanging from the ground or an earlier pair's link), `closures` between its links,
    /// driven by the variables `drives`. `Shape` when a capacity is exceeded, a parent or link does not exist yet, a
    /// drive is out of range or repeated, or the loop conditions cannot determine the rest (fewer than six conditions
    /// per undriven variable); `NonFinite` for a non-finite placement.
    pub fn new(pairs: &[Pair], closures: &[Closure], drives: &[usize]) -> Result<Self, LoopError> {
        if pairs.len() > MAX_PAIRS || closures.len() > MAX_LOOPS || drives.len() > MAX_DRIVES {
            return Err(LoopError::Shape);
        }
        let blank = Pair {
            joint: Joint::Revolute,
            parent: GROUND,
            place: Matrix4::identity(),
        };
        let mut m = Mechanism {
            pairs: [blank; MAX_PAIRS],
            pair_count: pairs.len(),
            closures: [Closure {
                a: GROUND,
                b: GROUND,
                offset: Matrix4::identity(),
            }; MAX_LOOPS],
            closure_count: closures.len(),
            drives: [0; MAX_DRIVES],
            drive_count: drives.len(),
            owner: [(0, 0); MAX_VARIABLES],
            first: [0; MAX_PAIRS],
            variable_count: 0,
            path: [0; MAX_PAIRS + 1],
        };
        for (p, pair) in pairs.iter().enumerate() {
            if pair.parent > p {
                return Err(LoopError::Shape);
            }
            if !pair.place.iter().all(|v| v.is_finite()) {
                return Err(LoopError::NonFinite);
            }
            m.pairs[p] = *pair;
            m.path[p + 1] = m.path[pair.parent] | (1 << p);
            m.first[p] = m.variable_count;
            for k in 0..pair.joint.variables() {
                let v = m.variable_count + k;
                *m.owner.get_mut(v).ok_or(LoopError::Shape)? = (p, k);
            }
            m.variable_count += pair.joint.variables();
        }
        for (c, closure) in closures.iter().enumerate() {
            let valid = closure.a <= pairs.len() && closure.b <= pairs.len() && closure.a != closure.b;
            if !valid {
                return Err(LoopError::Shape);
            }
            if !closure.offset.iter().all(|v| v.is_finite()) {
                return Err(LoopError::NonFinite);
            }
            m.closures[c] = *closure;
        }
        for (k, d) in drives.iter().enumerate() {
            if *d >= m.variable_count || drives[..k].contains(d) {
                return Err(LoopError::Shape);
            }
            m.drives[k] = *d;
        }
        if m.variable_count - drives.len() > 6 * closures.len() {
            return Err(LoopError::Shape);
        }
        Ok(m)
    }

    /// How many variables the pairs have together.
    pub fn variables(&self) -> usize {
        self.variable_count
    }

    /// How many links, the ground included.
    pub fn links(&self) -> usize {
        self.pair_count + 1
    }

    /// The pairs, in tree order.
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs[..self.pair_count]
    }

    /// The driven variables, in drive order.
    pub fn drives(&self) -> &[usize] {
        &self.drives[..self.drive_count]
    }

    /// The first variable of pair `p` (its others follow).
    pub fn first_variable(&self, p: usize) -> usize {
        self.first.get(p).copied().unwrap_or(self.variable_count)
    }

    /// Whether variable `v` moves link `i` (its pair lies on the path from the ground to the link).
    pub fn moves(&self, v: usize, i: usize) -> bool {
        match (self.owner.get(v), self.path.get(i)) {
            (Some((p, _)), Some(path)) if v < self.variable_count => path & (1 << p) != 0,
            _ => false,
        }
    }

    /// Link frames and variable twists at `q` (`Shape` when `q` is shorter than the variables).
    pub fn frames(&self, q: &[f64]) -> Result<Frames, LoopError> {
        if q.len() < self.variable_count {
            return Err(LoopError::Shape);
        }
        if !q[..self.variable_count].iter().all(|v| v.is_finite()) {
            return Err(LoopError::NonFinite);
        }
        let mut f = Frames {
            links: [Matrix4::identity(); MAX_PAIRS + 1],
            twists: [Matrix4::zeros(); MAX_VARIABLES],
        };
        for (p, pair) in self.pairs().iter().enumerate() {
            let n = pair.joint.variables();
            let at = &q[self.first[p]..self.first[p] + n];
            let before = f.links[pair.parent] * pair.place;
            let back = inverse(&before);
            for k in 0..n {
                f.twists[self.first[p] + k] = before * pair.joint.generator(k, at) * back;
            }
            f.links[p + 1] = before * pair.joint.transform(at);
        }
        Ok(f)
    }

    /// The sign of variable `v` in loop `c`: +1 on `b`'s path only, -1 on `a`'s only, 0 on both or neither.
    fn sign(&self, c: &Closure, v: usize) -> f64 {
        match (self.moves(v, c.a), self.moves(v, c.b)) {
            (false, true) => 1.0,
            (true, false) => -1.0,
            _ => 0.0,
        }
    }

    /// Whether variable `v` is driven.
    fn driven(&self, v: usize) -> bool {
        self.drives().contains(&v)
    }

    /// Least squares over every loop's 12 entries: `sum over undriven v of column(c, v) x_v = rhs(c)`, by the
    /// paper's normal equations `(B^T B)^-1 B^T W`. Driven variables' `x` are zero.
    fn solve(
        &self,
        column: impl Fn(&Closure, usize) -> [f64; 12],
        rhs: impl Fn(&Closure) -> [f64; 12],
    ) -> Result<[f64; MAX_VARIABLES], LoopError> {
        let n = self.variable_count;
        let mut normal = Square::zeros();
        let mut right = Column::zeros();
        for c in &self.closures[..self.closure_count] {
            let cols: [[f64; 12]; MAX_VARIABLES] = core::array::from_fn(|v| {
                if v < n && !self.driven(v) {
                    column(c, v)
                } else {
                    [0.0; 12]
                }
            });
            let r = rhs(c);
            let dot = |a: &[f64; 12], b: &[f64; 12]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            for i in 0..n {
                right[i] += dot(&cols[i], &r);
                for j in 0..n {
                    normal[(i, j)] += dot(&cols[i], &cols[j]);
                }
            }
        }
        // Driven and unused variables get identity rows: one decomposition of the fixed size solves any count.
        for i in 0..MAX_VARIABLES {
            if i >= n || self.driven(i) {
                normal[(i, i)] = 1.0;
                right[i] = 0.0;
            }
        }
        let x = normal.lu().solve(&right).ok_or(LoopError::Singular)?;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(LoopError::Singular);
        }
        Ok(core::array::from_fn(|i| x[i]))
    }

    /// Closes every loop by Gauss-Newton with the driven variables held at their values in `q`: each step is the
    /// least-squares `(B^T B)^-1 B^T W` over all loops' entries, until no step exceeds `tolerance`. Returns the
    /// variables and the iterations used. Along a path, pass the previous pose as `q` (a warm start).
    pub fn close(
        &self,
        q: &[f64; MAX_VARIABLES],
        tolerance: f64,
        max_iterations: u32,
    ) -> Result<([f64; MAX_VARIABLES], u32), LoopError> {
        let mut q = *q;
        for iteration in 1..=max_iterations {
            let f = self.frames(&q)?;
            let cut = |c: &Closure| inverse(&(f.links[c.a] * c.offset));
            let step = self.solve(
                |c, v| entries(&(cut(c) * f.twists[v] * f.links[c.b] * self.sign(c, v))),
                |c| entries(&(Matrix4::identity() - cut(c) * f.links[c.b])),
            )?;
            let mut largest = 0.0f64;
            for (v, s) in q.iter_mut().zip(&step).take(self.variable_count) {
                *v += s;
                largest = largest.max(libm::fabs(*s));
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

    /// The largest entry of any loop's `A_0a X (A_0b)^-1 - E` at `q`: zero when closed.
    pub fn closure_error(&self, q: &[f64]) -> Result<f64, LoopError> {
        let f = self.frames(q)?;
        let mut worst = 0.0f64;
        for c in &self.closures[..self.closure_count] {
            let e = f.links[c.a] * c.offset * inverse(&f.links[c.b]) - Matrix4::identity();
            worst = worst.max(e.amax());
        }
        Ok(worst)
    }

    /// Rates of every variable at a closed `q` for the drives' rates `drive_rates`: `sum s_v B_v q'_v = 0`.
    pub fn rates(&self, f: &Frames, drive_rates: &[f64]) -> Result<[f64; MAX_VARIABLES], LoopError> {
        let given = self.given(drive_rates)?;
        let mut out = self.solve(
            |c, v| entries(&(f.twists[v] * self.sign(c, v))),
            |c| entries(&-self.sum(f, c, &given)),
        )?;
        self.put(&mut out, drive_rates);
        Ok(out)
    }

    /// Accelerations of every variable at a closed `q` with rates `qd`, for the drives' accelerations:
    /// `sum s_v B_v q''_v = -sum s_v [W_v, B_v] q'_v`.
    pub fn accelerations(
        &self,
        f: &Frames,
        qd: &[f64; MAX_VARIABLES],
        drive_accelerations: &[f64],
    ) -> Result<[f64; MAX_VARIABLES], LoopError> {
        let given = self.given(drive_accelerations)?;
        let drift = self.twist_drifts(f, qd);
        let mut out = self.solve(
            |c, v| entries(&(f.twists[v] * self.sign(c, v))),
            |c| {
                let mut r = -self.sum(f, c, &given);
                for v in 0..self.variable_count {
                    r -= drift[v] * (qd[v] * self.sign(c, v));
                }
                entries(&r)
            },
        )?;
        self.put(&mut out, drive_accelerations);
        Ok(out)
    }

    /// `B'_v = [W_v, B_v]` of every variable for rates `qd`, `W_v` the twist of the variables before `v`: those of
    /// the pairs on its pair's path from the ground and the earlier ones of its own pair.
    pub fn twist_drifts(&self, f: &Frames, qd: &[f64; MAX_VARIABLES]) -> [Matrix4<f64>; MAX_VARIABLES] {
        core::array::from_fn(|v| {
            if v >= self.variable_count {
                return Matrix4::zeros();
            }
            let (p, k) = self.owner[v];
            let mut w = self.link_twist(f, qd, self.pairs[p].parent);
            let earlier = self.first[p]..self.first[p] + k;
            w += f.twists[earlier.clone()]
                .iter()
                .zip(&qd[earlier])
                .fold(Matrix4::zeros(), |m, (b, r)| m + b * *r);
            bracket(&w, &f.twists[v])
        })
    }

    /// The twist `W_i = sum over the variables moving link i of B_v q'_v`, with `dA_0i/dt = W_i A_0i`.
    pub fn link_twist(&self, f: &Frames, qd: &[f64; MAX_VARIABLES], i: usize) -> Matrix4<f64> {
        (0..self.variable_count)
            .filter(|v| self.moves(*v, i))
            .fold(Matrix4::zeros(), |w, v| w + f.twists[v] * qd[v])
    }

    /// `dW_i/dt` for rates `qd` and accelerations `qdd`: `sum B_v q''_v + [W_v, B_v] q'_v` over the variables
    /// moving link `i`; `d2A_0i/dt2 = (W'_i + W_i W_i) A_0i`.
    pub fn link_twist_rate(
        &self,
        f: &Frames,
        qd: &[f64; MAX_VARIABLES],
        qdd: &[f64; MAX_VARIABLES],
        i: usize,
    ) -> Matrix4<f64> {
        let drift = self.twist_drifts(f, qd);
        (0..self.variable_count)
            .filter(|v| self.moves(*v, i))
            .fold(Matrix4::zeros(), |w, v| w + f.twists[v] * qdd[v] + drift[v] * qd[v])
    }

    /// A point `r` of link `i` (in the link's frame): its position `R = A_0i r` (eq. 5), velocity `W_i A_0i r`
    /// (eq. 6) and acceleration `(W'_i + W_i W_i) A_0i r` in the base, for rates `qd` and accelerations `qdd`.
    pub fn point(
        &self,
        f: &Frames,
        qd: &[f64; MAX_VARIABLES],
        qdd: &[f64; MAX_VARIABLES],
        i: usize,
        r: &Vector3<f64>,
    ) -> [Vector3<f64>; 3] {
        let frame = f.links.get(i).copied().unwrap_or_else(Matrix4::identity);
        let at = frame * Vector4::new(1.0, r.x, r.y, r.z);
        let w = self.link_twist(f, qd, i);
        let wd = self.link_twist_rate(f, qd, qdd, i);
        let tail = |v: Vector4<f64>| Vector3::new(v[1], v[2], v[3]);
        [tail(at), tail(w * at), tail((wd + w * w) * at)]
    }

    /// The drives' values spread over the variables (zero elsewhere); `Shape` for a wrong count.
    fn given(&self, drive_values: &[f64]) -> Result<[f64; MAX_VARIABLES], LoopError> {
        if drive_values.len() != self.drive_count {
            return Err(LoopError::Shape);
        }
        if !drive_values.iter().all(|v| v.is_finite()) {
            return Err(LoopError::NonFinite);
        }
        let mut out = [0.0; MAX_VARIABLES];
        self.put(&mut out, drive_values);
        Ok(out)
    }

    fn put(&self, out: &mut [f64; MAX_VARIABLES], drive_values: &[f64]) {
        for (d, value) in self.drives().iter().zip(drive_values) {
            out[*d] = *value;
        }
    }

    /// `sum s_v B_v x_v` over loop `c`.
    fn sum(&self, f: &Frames, c: &Closure, x: &[f64; MAX_VARIABLES]) -> Matrix4<f64> {
        (0..self.variable_count).fold(Matrix4::zeros(), |m, v| m + f.twists[v] * (x[v] * self.sign(c, v)))
    }
}
