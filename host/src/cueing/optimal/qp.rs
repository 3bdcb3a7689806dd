//! One axis's quadratic programme over the horizon, condensed (the inputs are the variables, the states their
//! linear function): its matrices are fixed by the configuration, so the solver is set up once and each sample
//! only changes the linear cost (the state and the reference) and the constraints' bounds (the state).
//!
//! Clarabel is an interior-point solver: it takes no warm start (an interior point cannot start from the last
//! solution, which lies on the constraints). What carries over from one sample to the next is its setup: the
//! equilibration, the KKT system's structure and its symbolic factorisation, updated in place.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{DMatrix, DVector};

use super::model::Linear;

/// The quadratic price of a state bound's slack (per unit squared) and its linear price (per unit): a bound
/// is given up only where nothing else is possible.
const SLACK_WEIGHT: f64 = 1e6;
const SLACK_PRICE: f64 = 1e3;

/// A bound on one linear function of the states at every step of the horizon, or on one input.
#[derive(Debug, Clone, Copy)]
pub enum Bound {
    /// `lo <= C x_k <= hi` for the state row `c` (its coefficients over the states).
    State {
        /// Which output row of the model (its `C` row) is bounded; its `D` part must be zero.
        output: usize,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// `|sum of inputs in mask| <= limit` at every step.
    Input {
        /// The inputs summed (a bit per input).
        mask: u8,
        /// The limit.
        limit: f64,
    },
}

/// What one axis's programme is made of.
pub struct Spec<'a> {
    /// The model.
    pub model: &'a Linear,
    /// Steps of the horizon.
    pub steps: usize,
    /// One step (s).
    pub h: f64,
    /// Weight of each output.
    pub output_weight: &'a [f64],
    /// Weight of each input (effort).
    pub input_weight: &'a [f64],
    /// The bounds.
    pub bounds: &'a [Bound],
    /// An output that may be given a price of its own at each solve ([`AxisQp::solve_priced`]).
    pub priced: Option<usize>,
}

/// Why a solve gave no plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveError {
    /// The solver ended without a solution (infeasible, out of iterations or time, numerical trouble).
    Status(SolverStatus),
    /// The solver refused the sample's data.
    Update,
}

/// One axis's programme, ready to solve from any state and reference.
pub struct AxisQp {
    solver: DefaultSolver<f64>,
    /// Outputs over the horizon from the initial state: `Y = psi x0 + gy U`.
    psi: DMatrix<f64>,
    gy: DMatrix<f64>,
    /// The cost's matrix over the inputs as set up, its stored entries (upper triangle, by columns, the slacks'
    /// after them), and whether the last solve changed it.
    p: DMatrix<f64>,
    stored: Vec<(usize, usize)>,
    priced: Option<usize>,
    p_changed: bool,
    /// `q = 2 gy' W (psi x0 - Yref)`: this matrix times the error.
    q_of_error: DMatrix<f64>,
    /// Constraint bounds `b = b0 - bx x0`.
    b0: DVector<f64>,
    bx: DMatrix<f64>,
    /// Each bound's first constraint row.
    bound_rows: Vec<usize>,
    inputs: usize,
    outputs: usize,
    steps: usize,
    slacks: usize,
}

impl AxisQp {
    /// Sets the programme up; `iterations` bounds each solve's work (no clock: the same inputs give the same plan
    /// on any machine).
    pub fn new(spec: &Spec, iterations: u32) -> Self {
        let (nx, nu, ny) = spec.model.dims();
        let (n, m) = (spec.steps, spec.model);
        let d = m.discretise(spec.h);
        // States over the horizon: X = phi x0 + gamma U (x_1 .. x_N).
        let mut phi = DMatrix::zeros(n * nx, nx);
        let mut gamma = DMatrix::zeros(n * nx, n * nu);
        let mut power = DMatrix::identity(nx, nx);
        let mut markov = Vec::with_capacity(n);
        for k in 0..n {
            markov.push(&power * &d.b);
            power = &d.a * &power;
            phi.view_mut((k * nx, 0), (nx, nx)).copy_from(&power);
        }
        for k in 0..n {
            for j in 0..=k {
                gamma.view_mut((k * nx, j * nu), (nx, nu)).copy_from(&markov[k - j]);
            }
        }
        let mut cb = DMatrix::zeros(n * ny, n * nx);
        let mut db = DMatrix::zeros(n * ny, n * nu);
        for k in 0..n {
            cb.view_mut((k * ny, k * nx), (ny, nx)).copy_from(&m.c);
            db.view_mut((k * ny, k * nu), (ny, nu)).copy_from(&m.d);
        }
        let psi = &cb * &phi;
        let gy = &cb * &gamma + &db;
        let w = DVector::from_fn(n * ny, |i, _| spec.output_weight[i % ny]);
        let gyw = gy.transpose() * DMatrix::from_diagonal(&w);
        let mut p = &gyw * &gy * 2.0;
        for i in 0..n * nu {
            p[(i, i)] += 2.0 * spec.input_weight[i % nu];
        }
        let q_of_error = gyw * 2.0;
        let (a, b0, bx, bound_rows) = constraints(spec, &psi, &gy, nx, nu, ny);
        // One slack per state bound, shared by the horizon's steps, priced far above any cue: the programme is
        // feasible from any state (a state a fallback left outside a bound, or one the model's linearisation
        // did not foresee), and a plan that can keep within every bound does.
        let slacks = a.ncols() - n * nu;
        let full = {
            let mut full = DMatrix::zeros(n * nu + slacks, n * nu + slacks);
            full.view_mut((0, 0), (n * nu, n * nu)).copy_from(&p);
            for j in 0..slacks {
                full[(n * nu + j, n * nu + j)] = 2.0 * SLACK_WEIGHT;
            }
            full
        };
        // The entries stored: the cost's own, and those a price on the priced output can make.
        let mut pattern = full.map(|v| v != 0.0);
        if let Some(o) = spec.priced {
            for k in 0..n {
                let row = gy.row(k * ny + o);
                for (i, j) in (0..n * nu).flat_map(|j| (0..=j).map(move |i| (i, j))) {
                    pattern[(i, j)] |= row[i] != 0.0 && row[j] != 0.0;
                }
            }
        }
        let stored: Vec<(usize, usize)> = (0..full.ncols())
            .flat_map(|j| (0..=j).map(move |i| (i, j)))
            .filter(|&ij| pattern[ij])
            .collect();
        let settings = DefaultSettings {
            verbose: false,
            presolve_enable: false,
            input_sparse_dropzeros: false,
            time_limit: f64::INFINITY,
            max_iter: iterations,
            tol_gap_abs: 1e-6,
            tol_gap_rel: 1e-6,
            tol_feas: 1e-7,
            ..DefaultSettings::default()
        };
        let q = vec![0.0; n * nu + slacks];
        let cones = [SupportedConeT::NonnegativeConeT(a.nrows())];
        let p_csc = {
            let (rows, cols) = stored.iter().copied().unzip();
            let vals = stored.iter().map(|&ij| full[ij]).collect();
            CscMatrix::new_from_triplets(full.nrows(), full.ncols(), rows, cols, vals)
        };
        let solver = DefaultSolver::new(&p_csc, &q, &csc(&a), b0.as_slice(), &cones, settings)
            .expect("the programme's dimensions agree by construction");
        Self {
            solver,
            psi,
            gy,
            p: full,
            stored,
            priced: spec.priced,
            p_changed: false,
            q_of_error,
            b0,
            bx,
            bound_rows,
            inputs: nu,
            outputs: ny,
            steps: n,
            slacks,
        }
    }

    /// Moves state bound `index` (its place in the spec's bounds) to `lo..=hi` from the next solve on.
    pub fn set_state_bound(&mut self, index: usize, lo: f64, hi: f64) {
        let Some(&start) = self.bound_rows.get(index) else {
            return;
        };
        for k in 0..self.steps {
            self.b0[start + 2 * k] = hi;
            self.b0[start + 2 * k + 1] = -lo;
        }
    }

    /// Steps of the horizon.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Outputs per step.
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// Solves from state `x0` towards `reference` (every output at every step, `N * outputs`), the priced output
    /// (the spec's) given a price of its own at this solve, `sum_k w_k (y_k - target_k)^2` with `price[k] = (w_k,
    /// target_k)` for the first steps (none past them, none at all when empty: the cost as set up). Returns the
    /// plan (every step's inputs, `N * inputs`) and the solver's iterations. A price changes the cost's matrix,
    /// which the solver takes in place (its structure kept); the same inputs give the same plan.
    pub fn solve(
        &mut self,
        x0: &DVector<f64>,
        reference: &DVector<f64>,
        price: &[(f64, f64)],
    ) -> Result<(DVector<f64>, u32), SolveError> {
        let error = &self.psi * x0 - reference;
        let mut q: Vec<f64> = (&self.q_of_error * error).iter().copied().collect();
        let mut p = None;
        if let Some(o) = self.priced.filter(|_| price.iter().any(|&(w, _)| w != 0.0)) {
            let mut extra = self.p.clone();
            for (k, &(w, target)) in price
                .iter()
                .enumerate()
                .take(self.steps)
                .filter(|(_, (w, _))| *w != 0.0)
            {
                let row = k * self.outputs + o;
                let g = self.gy.row(row);
                let e = (self.psi.row(row) * x0)[0] - target;
                for j in 0..g.len() {
                    q[j] += 2.0 * w * g[j] * e;
                    for i in 0..=j {
                        extra[(i, j)] += 2.0 * w * g[i] * g[j];
                    }
                }
            }
            p = Some(extra);
        }
        if p.is_some() || self.p_changed {
            let m = p.as_ref().unwrap_or(&self.p);
            let values: Vec<f64> = self.stored.iter().map(|&ij| m[ij]).collect();
            self.solver.update_P(&values).map_err(|_| SolveError::Update)?;
            self.p_changed = p.is_some();
        }
        q.resize(self.steps * self.inputs + self.slacks, SLACK_PRICE);
        let b: Vec<f64> = (&self.b0 - &self.bx * x0).iter().copied().collect();
        self.solver.update_q(&q).map_err(|_| SolveError::Update)?;
        self.solver.update_b(&b).map_err(|_| SolveError::Update)?;
        self.solver.solve();
        let s = &self.solver.solution;
        match s.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => Ok((
                DVector::from_column_slice(&s.x[..self.steps * self.inputs]),
                s.iterations,
            )),
            status => Err(SolveError::Status(status)),
        }
    }
}

/// The constraints `A U <= b0 - bx x0`, and each bound's first row.
fn constraints(
    spec: &Spec,
    psi: &DMatrix<f64>,
    gy: &DMatrix<f64>,
    nx: usize,
    nu: usize,
    ny: usize,
) -> (DMatrix<f64>, DVector<f64>, DMatrix<f64>, Vec<usize>) {
    let n = spec.steps;
    let slacks = spec.bounds.iter().filter(|b| matches!(b, Bound::State { .. })).count();
    // Each bound two rows a step; each slack its own row (at least zero).
    let rows = 2 * n * spec.bounds.len() + slacks;
    let mut a = DMatrix::zeros(rows, n * nu + slacks);
    let mut b0 = DVector::zeros(rows);
    let mut bx = DMatrix::zeros(rows, nx);
    let mut r = 0;
    let mut slack = n * nu;
    let mut starts = Vec::with_capacity(spec.bounds.len());
    for bound in spec.bounds {
        starts.push(r);
        for k in 0..n {
            match *bound {
                Bound::State { output, lo, hi } => {
                    let row = k * ny + output;
                    for (sign, limit) in [(1.0, hi), (-1.0, -lo)] {
                        a.view_mut((r, 0), (1, n * nu)).copy_from(&(gy.row(row) * sign));
                        a[(r, slack)] = -1.0;
                        bx.row_mut(r).copy_from(&(psi.row(row) * sign));
                        b0[r] = limit;
                        r += 1;
                    }
                }
                Bound::Input { mask, limit } => {
                    for sign in [1.0, -1.0] {
                        for i in (0..nu).filter(|i| mask & (1 << i) != 0) {
                            a[(r, k * nu + i)] = sign;
                        }
                        b0[r] = limit;
                        r += 1;
                    }
                }
            }
        }
        if matches!(bound, Bound::State { .. }) {
            slack += 1;
        }
    }
    // -s <= 0.
    for j in n * nu..n * nu + slacks {
        a[(r, j)] = -1.0;
        r += 1;
    }
    (a, b0, bx, starts)
}

/// A dense matrix as compressed columns, zeros left out.
fn csc(m: &DMatrix<f64>) -> CscMatrix<f64> {
    let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if m[(i, j)] != 0.0 {
                rows.push(i);
                cols.push(j);
                vals.push(m[(i, j)]);
            }
        }
    }
    CscMatrix::new_from_triplets(m.nrows(), m.ncols(), rows, cols, vals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vertical axis's programme over 8 steps of 0.15 s: the force weighed 1, the position 10.
    fn vertical<'a>(model: &'a Linear, bounds: &'a [Bound], priced: Option<usize>) -> Spec<'a> {
        Spec {
            model,
            steps: 8,
            h: 0.15,
            output_weight: &[1.0, 10.0, 1.0],
            input_weight: &[0.001],
            bounds,
            priced,
        }
    }

    /// The solve is bounded by its iterations, not a clock: too few and it fails (its status says so), enough and
    /// it solves, the same plan bit for bit each time.
    #[test]
    fn a_solve_is_bounded_by_its_iterations_and_repeats_bit_for_bit() {
        let model = super::super::model::vertical();
        let bounds = [
            Bound::State {
                output: 1,
                lo: -0.03,
                hi: 0.03,
            },
            Bound::Input { mask: 1, limit: 5.0 },
        ];
        let spec = vertical(&model, &bounds, None);
        let x0 = DVector::zeros(model.dims().0);
        let reference = DVector::from_element(8 * 3, 2.0);
        let mut starved = AxisQp::new(&spec, 1);
        assert!(matches!(
            starved.solve(&x0, &reference, &[]),
            Err(SolveError::Status(SolverStatus::MaxIterations))
        ));
        let mut qp = AxisQp::new(&spec, 60);
        let (first, iterations) = qp.solve(&x0, &reference, &[]).unwrap();
        assert!(iterations > 1 && iterations < 60, "{iterations}");
        for _ in 0..5 {
            assert_eq!(qp.solve(&x0, &reference, &[]).unwrap().0, first);
        }
    }

    /// A price on an output pulls the plan's output towards its centre at the steps priced, in proportion to its
    /// weight; the next solve without it is the unpriced plan again (the cost's matrix restored, to rounding: the
    /// solver scales the values it is given anew).
    #[test]
    fn a_price_pulls_its_output_and_leaves_with_its_solve() {
        let model = super::super::model::vertical();
        let bounds = [Bound::State {
            output: 1,
            lo: -0.05,
            hi: 0.05,
        }];
        let spec = vertical(&model, &bounds, Some(1));
        let x0 = DVector::zeros(model.dims().0);
        let reference = DVector::from_fn(8 * 3, |i, _| if i % 3 == 0 { 2.0 } else { 0.0 });
        let mut qp = AxisQp::new(&spec, 60);
        // The position at each step of a plan (output 1, from rest).
        let gy = qp.gy.clone();
        let positions = |plan: &DVector<f64>| (0..8).map(|k| (gy.row(k * 3 + 1) * plan)[0]).collect::<Vec<f64>>();
        let (free, _) = qp.solve(&x0, &reference, &[]).unwrap();
        let (priced, _) = qp.solve(&x0, &reference, &[(1e5, -0.01); 8]).unwrap();
        let (light, _) = qp.solve(&x0, &reference, &[(1e2, -0.01); 8]).unwrap();
        let (again, _) = qp.solve(&x0, &reference, &[]).unwrap();
        assert!((&again - &free).amax() < 1e-9, "{again} {free}");
        // How far the positions are from the centre, all steps together.
        let off = |plan: &DVector<f64>| positions(plan).iter().map(|p| (p + 0.01).abs()).sum::<f64>();
        let (o_free, o_light, o_priced) = (off(&free), off(&light), off(&priced));
        assert!(
            o_priced < 0.05 * o_free && o_priced < o_light && o_light < o_free,
            "{o_priced} {o_light} {o_free}"
        );
        // A price on the first steps alone leaves the plan's end to the cost as set up.
        let (first, _) = qp.solve(&x0, &reference, &[(1e5, -0.01); 2]).unwrap();
        assert!(
            (positions(&first)[1] + 0.01).abs() < 1e-3 && first != priced,
            "{:?}",
            positions(&first)
        );
    }
}
