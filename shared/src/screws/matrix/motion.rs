//! Motions of a [`Model`] in its drives: the closed state, rates and accelerations of every variable for the drives'
//! values, rates and accelerations (warm-started along a path), the inverse dynamics along it, and forward dynamics
//! (the drives' accelerations for given drive forces) integrated by the classical fourth-order Runge-Kutta scheme.

use nalgebra::{Matrix6, Vector6};

use super::lagrange::{Model, State};
use super::mechanism::{Frames, MAX_DRIVES, MAX_VARIABLES};
use super::LoopError;

/// Closure tolerance (largest Gauss-Newton step) and iterations allowed at each point of a motion.
pub const TOLERANCE: f64 = 1e-13;
/// Gauss-Newton iterations allowed at each point of a motion.
pub const ITERATIONS: u32 = 40;

/// The drives' values and rates after a step, and every variable closed there.
pub type Stepped = ([f64; MAX_DRIVES], [f64; MAX_DRIVES], [f64; MAX_VARIABLES]);

/// One point of a motion, solved.
#[derive(Debug, Clone, Copy)]
pub struct Solved {
    /// Positions and rates of every variable.
    pub state: State,
    /// Accelerations of every variable.
    pub qdd: [f64; MAX_VARIABLES],
    /// Link frames and variable twists.
    pub frames: Frames,
    /// The drives' generalised forces (N or N m, in drive order).
    pub forces: [f64; MAX_DRIVES],
}

impl Model {
    fn drive_count(&self) -> usize {
        self.mechanism.drives().len()
    }

    /// Closes the mechanism with the drives at `u`, starting from `guess` (the previous point along a path).
    pub fn closed(&self, guess: &[f64; MAX_VARIABLES], u: &[f64]) -> Result<[f64; MAX_VARIABLES], LoopError> {
        if u.len() != self.drive_count() {
            return Err(LoopError::Shape);
        }
        let mut q = *guess;
        for (d, value) in self.mechanism.drives().iter().zip(u) {
            q[*d] = *value;
        }
        Ok(self.mechanism.close(&q, TOLERANCE, ITERATIONS)?.0)
    }

    /// Inverse dynamics at one point: the drives at `u` with rates `ud` and accelerations `udd`.
    pub fn solve_point(
        &self,
        guess: &[f64; MAX_VARIABLES],
        u: &[f64],
        ud: &[f64],
        udd: &[f64],
    ) -> Result<Solved, LoopError> {
        let q = self.closed(guess, u)?;
        let frames = self.mechanism.frames(&q)?;
        let qd = self.mechanism.rates(&frames, ud)?;
        let qdd = self.mechanism.accelerations(&frames, &qd, udd)?;
        let state = State { q, qd };
        let forces = self.drive_forces(&frames, &state, &qdd)?;
        Ok(Solved {
            state,
            qdd,
            frames,
            forces,
        })
    }

    /// Forward dynamics at one point: the drives' accelerations under the drive forces `tau`, from
    /// `M u'' = tau - tau(u'' = 0)`. Returns them with the closed state.
    pub fn drive_accelerations(
        &self,
        guess: &[f64; MAX_VARIABLES],
        u: &[f64],
        ud: &[f64],
        tau: &[f64],
    ) -> Result<([f64; MAX_DRIVES], State), LoopError> {
        let d = self.drive_count();
        if tau.len() != d || !tau.iter().all(|v| v.is_finite()) {
            return Err(if tau.len() != d {
                LoopError::Shape
            } else {
                LoopError::NonFinite
            });
        }
        let zero = [0.0; MAX_DRIVES];
        let at_rest = self.solve_point(guess, u, ud, &zero[..d])?;
        let m = self.mass(&at_rest.frames)?;
        // Unused drives get identity rows, so one 6 x 6 decomposition serves any count.
        let matrix = Matrix6::from_fn(|a, b| {
            if a < d && b < d {
                m[a][b]
            } else {
                f64::from(u8::from(a == b))
            }
        });
        let rhs = Vector6::from_fn(|a, _| if a < d { tau[a] - at_rest.forces[a] } else { 0.0 });
        let x = matrix.lu().solve(&rhs).ok_or(LoopError::Singular)?;
        Ok((core::array::from_fn(|a| if a < d { x[a] } else { 0.0 }), at_rest.state))
    }

    /// One RK4 step of `dt` from the drives at `u` with rates `ud` under drive forces `tau(t)` (held over the step
    /// as sampled at its start, middle and end). Returns the new `u`, `ud` and the closed variables there.
    pub fn step(
        &self,
        guess: &[f64; MAX_VARIABLES],
        u: &[f64; MAX_DRIVES],
        ud: &[f64; MAX_DRIVES],
        dt: f64,
        tau: impl Fn(f64) -> [f64; MAX_DRIVES],
    ) -> Result<Stepped, LoopError> {
        let d = self.drive_count();
        let add = |x: &[f64; MAX_DRIVES], k: &[f64; MAX_DRIVES], h: f64| -> [f64; MAX_DRIVES] {
            core::array::from_fn(|a| x[a] + k[a] * h)
        };
        let mut q = *guess;
        let mut slope = |x: &[f64; MAX_DRIVES], v: &[f64; MAX_DRIVES], t: f64| {
            let (acc, state) = self.drive_accelerations(&q, &x[..d], &v[..d], &tau(t)[..d])?;
            q = state.q;
            Ok::<_, LoopError>((*v, acc))
        };
        let (k1x, k1v) = slope(u, ud, 0.0)?;
        let (k2x, k2v) = slope(&add(u, &k1x, dt / 2.0), &add(ud, &k1v, dt / 2.0), dt / 2.0)?;
        let (k3x, k3v) = slope(&add(u, &k2x, dt / 2.0), &add(ud, &k2v, dt / 2.0), dt / 2.0)?;
        let (k4x, k4v) = slope(&add(u, &k3x, dt), &add(ud, &k3v, dt), dt)?;
        let combine = |x: &[f64; MAX_DRIVES],
                       a: &[f64; MAX_DRIVES],
                       b: &[f64; MAX_DRIVES],
                       c: &[f64; MAX_DRIVES],
                       e: &[f64; MAX_DRIVES]| {
            core::array::from_fn(|k| x[k] + dt / 6.0 * (a[k] + 2.0 * b[k] + 2.0 * c[k] + e[k]))
        };
        let u1 = combine(u, &k1x, &k2x, &k3x, &k4x);
        let ud1 = combine(ud, &k1v, &k2v, &k3v, &k4v);
        let q1 = self.closed(&q, &u1[..d])?;
        Ok((u1, ud1, q1))
    }
}
