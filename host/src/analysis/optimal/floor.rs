//! The floor: the least perceived specific-force error any motion inside the envelope's ranges can give on a
//! drive. One programme per axis over the whole drive, every sample known in advance, bounded by nothing but
//! the ranges about home the optimal cueing plans in: no velocity, acceleration or rate limit, and the rotation a
//! tilt makes not priced. Its cost is the perceived force error of the optimiser's own linearised model
//! ([`super::model`]); `sin(tilt) = tilt` gives a tilt more force than it has, so the linearisation only lowers
//! the floor. Every cueing that keeps within the ranges (the bench reports each one's share of them) perceives
//! at least this error on the model; the floor's own motion, scored by the bench like any other, shows how
//! near the bench's finite differences and filters come to it.
//!
//! The programme is sparse (states, inputs and errors of every sample are variables, the dynamics equality
//! constraints), so a minute's drive at 100 Hz is a few tens of thousands of variables: one interior-point
//! solve per axis.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use ringpod_core::cueing::{self, Forward, Telemetry};

use super::model::{self, Discrete, Linear};
use super::{stimulus, Ranges, X, Y, Z};

/// The price of each input squared, so that the programme has one solution where several motions perceive
/// alike (the tilt's and the rotation's parts of one angle); far below any error's.
const EFFORT: f64 = 1e-9;

/// Why a floor could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FloorError {
    /// The drive has an interval that is not a step forward of at most a second (a gap starts the cueing
    /// again at neutral: the floor is of one continuous drive).
    #[error("row {0} is not 0 to 1 s after the row before: the floor needs a drive without gaps")]
    Interval(usize),
    /// The solver ended without a solution.
    #[error("the {axis} axis's programme ended without a solution ({status})")]
    Solver {
        /// Which axis.
        axis: &'static str,
        /// Clarabel's status.
        status: String,
    },
}

/// The floor of one drive.
#[derive(Debug, Clone)]
pub struct Floor {
    /// The least RMS perceived specific-force error on the model, x, y, z (m/s^2).
    pub force_rms: [f64; 3],
    /// The motion that reaches it: each sample's offset from neutral in platform axes (yaw none).
    pub offsets: Vec<[f64; 6]>,
}

/// The floor of a drive (`samples` at times `t`) in `ranges`, the platform facing `forward`.
pub fn floor(t: &[f64], samples: &[Telemetry<f64>], ranges: &Ranges, forward: Forward) -> Result<Floor, FloorError> {
    if let Some(k) = (1..t.len()).find(|&k| !(t[k] - t[k - 1] > 0.0 && t[k] - t[k - 1] <= 1.0)) {
        return Err(FloorError::Interval(k));
    }
    let mut force_rms = [0.0; 3];
    let mut paths = Vec::with_capacity(3);
    for (i, name) in [(X, "x"), (Y, "y"), (Z, "z")] {
        let (p, angle, rms) = axis(i, t, samples, ranges).map_err(|status| FloorError::Solver {
            axis: name,
            status: format!("{status:?}"),
        })?;
        force_rms[i] = rms;
        paths.push((p, angle));
    }
    let offsets = (0..t.len())
        .map(|k| {
            let translation = [paths[X].0[k], paths[Y].0[k], paths[Z].0[k]];
            // x's angle is minus the pitch, y's the roll (as the optimal cueing's axes).
            cueing::to_platform(forward, translation, paths[Y].1[k], -paths[X].1[k], 0.0)
        })
        .collect();
    Ok(Floor { force_rms, offsets })
}

/// One axis's sparse programme, as Clarabel takes it: `min z'Pz/2 + q'z` with `A z + s = b`, the first
/// `equalities` rows' `s` zero and the rest's at least zero.
#[derive(Default)]
struct Sparse {
    p: Triplets,
    a: Triplets,
    b: Vec<f64>,
    equalities: usize,
}

#[derive(Default)]
struct Triplets {
    rows: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl Triplets {
    fn push(&mut self, row: usize, col: usize, val: f64) {
        if val != 0.0 {
            self.rows.push(row);
            self.cols.push(col);
            self.vals.push(val);
        }
    }

    fn csc(self, rows: usize, cols: usize) -> CscMatrix<f64> {
        CscMatrix::new_from_triplets(rows, cols, self.rows, self.cols, self.vals)
    }
}

/// Axis `i`: its positions and angles at every sample (neutral at the first) and the RMS error it leaves.
fn axis(
    i: usize,
    t: &[f64],
    samples: &[Telemetry<f64>],
    ranges: &Ranges,
) -> Result<(Vec<f64>, Vec<f64>, f64), SolverStatus> {
    let (model, perception) = if i == Z {
        (model::vertical(), model::perception(false))
    } else {
        (model::horizontal(), model::perception(true))
    };
    let (nx, nu, _) = model.dims();
    let reference = vehicle_perceived(&perception, t, samples, i);
    // Per sample after the first: its state, the input held over the interval before it, its error.
    let block = nx + nu + 1;
    let n = t.len().saturating_sub(1);
    let (state, input, error) = (
        |k: usize| k * block,
        |k: usize| k * block + nx,
        |k: usize| k * block + nx + nu,
    );
    let mut qp = Sparse::default();
    let mut discrete = None;
    for k in 0..n {
        let d = discretised(&mut discrete, &model, t[k + 1] - t[k]);
        // x_k - A x_(k-1) - B u = 0 (the platform at neutral before the first interval).
        for r in 0..nx {
            let row = qp.b.len();
            qp.a.push(row, state(k) + r, 1.0);
            for c in 0..nx {
                if k > 0 {
                    qp.a.push(row, state(k - 1) + c, -d.a[(r, c)]);
                }
            }
            for c in 0..nu {
                qp.a.push(row, input(k) + c, -d.b[(r, c)]);
            }
            qp.b.push(0.0);
        }
        // e - (C x + D u) = -reference: the perceived force's error.
        let row = qp.b.len();
        qp.a.push(row, error(k), 1.0);
        for c in 0..nx {
            qp.a.push(row, state(k) + c, -model.c[(0, c)]);
        }
        for c in 0..nu {
            qp.a.push(row, input(k) + c, -model.d[(0, c)]);
        }
        qp.b.push(-reference[k + 1]);
        qp.p.push(error(k), error(k), 2.0);
        for c in 0..nu {
            qp.p.push(input(k) + c, input(k) + c, 2.0 * EFFORT);
        }
    }
    qp.equalities = qp.b.len();
    for (output, (lo, hi)) in bounded_outputs(i, ranges) {
        for k in 0..n {
            for (sign, limit) in [(1.0, hi), (-1.0, -lo)] {
                let row = qp.b.len();
                for c in 0..nx {
                    qp.a.push(row, state(k) + c, sign * model.c[(output, c)]);
                }
                qp.b.push(limit);
            }
        }
    }
    let x = solve(qp, n * block)?;
    let angle_of = |k: usize| if i == Z { 0.0 } else { x[state(k) + 2] + x[state(k) + 3] };
    let mut p = vec![0.0];
    let mut angle = vec![0.0];
    let mut sum = 0.0;
    for k in 0..n {
        p.push(x[state(k)]);
        angle.push(angle_of(k));
        sum += x[error(k)].powi(2);
    }
    Ok((p, angle, (sum / n.max(1) as f64).sqrt()))
}

/// The bounded outputs of axis `i`'s model and their ranges: the position, and on x and y the angle (x's is
/// minus the pitch, index 4 of the ranges; y's the roll, index 3).
fn bounded_outputs(i: usize, ranges: &Ranges) -> Vec<(usize, (f64, f64))> {
    match i {
        X => vec![(2, ranges[0]), (4, (-ranges[4].1, -ranges[4].0))],
        Y => vec![(2, ranges[1]), (4, ranges[3])],
        _ => vec![(1, ranges[2])],
    }
}

fn solve(qp: Sparse, variables: usize) -> Result<Vec<f64>, SolverStatus> {
    let rows = qp.b.len();
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 200,
        ..DefaultSettings::default()
    };
    let cones = [
        SupportedConeT::ZeroConeT(qp.equalities),
        SupportedConeT::NonnegativeConeT(rows - qp.equalities),
    ];
    let q = vec![0.0; variables];
    let (p, a) = (qp.p.csc(variables, variables), qp.a.csc(rows, variables));
    let mut solver = DefaultSolver::new(&p, &q, &a, &qp.b, &cones, settings).map_err(|_| SolverStatus::Unsolved)?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(solver.solution.x.clone()),
        status => Err(status),
    }
}

/// The vehicle's perceived force on axis `i` at every sample, its perception settled on the first sample (as
/// the optimal cueing's `begin`) and run on each sample's stimulus held over the interval before it.
fn vehicle_perceived(perception: &Linear, t: &[f64], samples: &[Telemetry<f64>], i: usize) -> Vec<f64> {
    let Some(first) = samples.first() else {
        return Vec::new();
    };
    let r = stimulus(i, first);
    let rhs = -(&perception.b * &r);
    let mut z = perception.a.clone().lu().solve(&rhs).unwrap_or_else(|| rhs * 0.0);
    let mut out = vec![perception.output(&z, &r)[0]];
    let mut discrete = None;
    for k in 1..samples.len() {
        let d = discretised(&mut discrete, perception, t[k] - t[k - 1]);
        let r = stimulus(i, &samples[k]);
        z = &d.a * &z + &d.b * &r;
        out.push(perception.output(&z, &r)[0]);
    }
    out
}

/// `linear` discretised at `dt`, kept while the intervals stay the same (most drives keep one).
fn discretised<'a>(cache: &'a mut Option<(f64, Discrete)>, linear: &Linear, dt: f64) -> &'a Discrete {
    if cache.as_ref().is_some_and(|(h, _)| *h != dt) {
        *cache = None;
    }
    &cache.get_or_insert_with(|| (dt, linear.discretise(dt))).1
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::cueing::perception::Perception;
    use ringpod_core::cueing::G;

    /// 6 s at 100 Hz: at rest, then braking at 3 m/s^2 and turning left at 2 m/s^2 from 1 s to 4 s, ramped
    /// over half a second, with `sign` on the braking (-1 accelerates instead).
    fn drive(sign: f64) -> (Vec<f64>, Vec<Telemetry<f64>>) {
        let t: Vec<f64> = (0..600).map(|k| f64::from(k) * 0.01).collect();
        let ramp = |t: f64| ((t - 1.0) / 0.5).clamp(0.0, 1.0) * ((4.5 - t) / 0.5).clamp(0.0, 1.0);
        let samples = t
            .iter()
            .map(|&t| Telemetry {
                force: [-3.0 * sign * ramp(t), 2.0 * ramp(t), G],
                rate: [0.0; 3],
            })
            .collect();
        (t, samples)
    }

    /// Room for the tilt the drive's forces need, but on x only for braking: the pitch's range is nose-up only
    /// (beta >= 0, x's angle <= 0).
    fn wide() -> Ranges {
        [(-0.5, 0.5), (-0.5, 0.5), (-0.1, 0.1), (-0.5, 0.5), (0.0, 0.5)]
    }

    #[test]
    fn where_the_ranges_hold_the_drive_the_floor_is_no_error_and_keeps_to_them() {
        let (t, samples) = drive(1.0);
        let f = floor(&t, &samples, &wide(), Forward::PlusX).unwrap();
        assert!(f.force_rms.iter().all(|r| *r < 1e-3), "{:?}", f.force_rms);
        // Braking pitches the nose up (beta > 0), a left turn's force rolls the platform left (alpha > 0).
        let held = f.offsets[300];
        assert!(held[4] > 0.25 && held[3] > 0.15, "{held:?}");
        for o in &f.offsets {
            for (i, (lo, hi)) in wide().iter().enumerate() {
                assert!(o[i] >= lo - 1e-6 && o[i] <= hi + 1e-6, "{i}: {o:?}");
            }
        }
        // Accelerating needs the nose down, which the pitch's range does not allow: on x the floor is an error.
        let (t, samples) = drive(-1.0);
        let f = floor(&t, &samples, &wide(), Forward::PlusX).unwrap();
        assert!(f.force_rms[0] > 0.5 && f.force_rms[1] < 1e-3, "{:?}", f.force_rms);
    }

    /// Without room to move, the floor is the whole of what the vehicle's occupant perceives: the same figure
    /// the bench gives a platform held at neutral (its Tustin filters against the model's hold), to 1 %.
    #[test]
    fn without_room_the_floor_is_what_the_vehicle_perceives() {
        let (t, samples) = drive(1.0);
        let none = [(-1e-9, 1e-9); 5];
        let f = floor(&t, &samples, &none, Forward::PlusX).unwrap();
        let mut p = Perception::<f64>::new();
        let less_g = |s: &Telemetry<f64>| [s.force[0], s.force[1], s.force[2] - G];
        p.begin(less_g(&samples[0]), [0.0; 3]);
        let mut sum = [0.0; 3];
        for s in &samples[1..] {
            let felt = p.step(less_g(s), [0.0; 3], 0.01);
            for (total, f) in sum.iter_mut().zip(felt.force) {
                *total += f * f;
            }
        }
        let at_rest = sum.map(|v| (v / (samples.len() - 1) as f64).sqrt());
        for i in 0..2 {
            assert!(
                (f.force_rms[i] - at_rest[i]).abs() < 0.01 * at_rest[i],
                "{i}: {:?} against {at_rest:?}",
                f.force_rms
            );
        }
    }

    #[test]
    fn a_gap_in_the_drive_is_said() {
        let (mut t, samples) = drive(1.0);
        for v in &mut t[200..] {
            *v += 2.0;
        }
        let e = floor(&t, &samples, &wide(), Forward::PlusX).unwrap_err();
        assert_eq!(e, FloorError::Interval(200));
    }
}
