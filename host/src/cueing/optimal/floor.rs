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
use super::polytope::Polytope;
use super::qp::Bound;
use super::{cost_and_bounds, stimulus, Ranges, X, Y, Z};
use ringpod_core::cueing::CueConfig;

/// The price of each input squared, so that the programme has one solution where several motions perceive
/// alike (the tilt's and the rotation's parts of one angle); far below any error's.
const EFFORT: f64 = 1e-9;

/// Why a floor could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FloorError {
    /// The drive has fewer than two samples: no interval to perceive anything over.
    #[error("the drive has {0} samples; the floor needs two or more")]
    TooShort(usize),
    /// The drive has an interval that is not a step forward of at most a second (a gap starts the cueing
    /// again at neutral: the floor is of one continuous drive).
    #[error("row {0} is not 0 to 1 s after the row before: the floor needs a drive without gaps")]
    Interval(usize),
    /// The solver ended without a solution.
    #[error("the floor's programme ended without a solution ({0})")]
    Solver(String),
}

/// The floor of one drive.
#[derive(Debug, Clone)]
pub struct Floor {
    /// The least RMS perceived specific-force error on the model, x, y, z (m/s^2).
    pub force_rms: [f64; 3],
    /// The motion that reaches it: each sample's offset from neutral in platform axes (yaw none).
    pub offsets: Vec<[f64; 6]>,
    /// The intervals its figures count.
    pub scored: usize,
}

/// What bounds the floor's motion.
#[derive(Debug, Clone, Copy)]
pub enum Room<'a> {
    /// Each axis's range about home, found with the other axes at home: every axis on its own.
    Ranges(&'a Ranges),
    /// An outer polytope of the rig's envelope: the axes together, as the rig couples them.
    Envelope(&'a Polytope),
    /// An optimal cueing's own room (its file's): its shares of the ranges, within its tilt limit.
    Shares(&'a Ranges, &'a CueConfig),
}

/// The floor of a drive (`samples` at times `t`) in `room`, the platform facing `forward`.
#[cfg(test)]
pub fn floor(t: &[f64], samples: &[Telemetry<f64>], room: Room, forward: Forward) -> Result<Floor, FloorError> {
    floor_from(t, samples, room, None, forward, 0)
}

/// [`floor`] of the samples from index `from` on: the error before it is not priced (the motion is free to
/// prepare), nor counted. With `limits`, an optimal cueing's (its file's) velocity, acceleration, tilt-rate and
/// rotation-rate limits hold too, and its perceived rotation's error is priced at its weight, as in its
/// programmes: what that cueing could reach in `room` with the whole drive known and no horizon.
pub fn floor_from(
    t: &[f64],
    samples: &[Telemetry<f64>],
    room: Room,
    limits: Option<&CueConfig>,
    forward: Forward,
    from: usize,
) -> Result<Floor, FloorError> {
    if t.len() < 2 || samples.len() != t.len() {
        return Err(FloorError::TooShort(t.len().min(samples.len())));
    }
    if let Some(k) = (1..t.len()).find(|&k| !(t[k] - t[k - 1] > 0.0 && t[k] - t[k - 1] <= 1.0)) {
        return Err(FloorError::Interval(k));
    }
    let n = t.len().saturating_sub(1);
    let mut base = 0;
    let rotation = |i: usize| match limits {
        // The rotation keys are per rotation (roll 0, pitch 1): x's is the pitch, y's the roll.
        Some(config) if i != Z => config.optimal.rotation_weight[1 - i],
        _ => 0.0,
    };
    let parts = [X, Y, Z].map(|i| {
        let part = Part::new(i, base, rotation(i));
        base += n * part.block();
        part
    });
    let variables = base;
    let mut qp = Sparse::default();
    for part in &parts {
        part.dynamics(&mut qp, t, samples, from);
    }
    qp.equalities = qp.b.len();
    match room {
        Room::Ranges(ranges) => {
            for part in &parts {
                part.bound(&mut qp, ranges, n);
            }
        }
        Room::Envelope(polytope) => within(&mut qp, &parts, polytope, forward, n),
        Room::Shares(ranges, config) => {
            for part in &parts {
                part.limit(&mut qp, &cost_and_bounds(part.i, config, ranges).2, Kind::Room, n);
            }
        }
    }
    if let Some(config) = limits {
        // The ranges only size the programme's bounds here; the rates are what is taken.
        for part in &parts {
            part.limit(
                &mut qp,
                &cost_and_bounds(part.i, config, &[(-1.0, 1.0); 5]).2,
                Kind::Rates,
                n,
            );
        }
    }
    let x = solve(&qp, variables)?;
    let mut force_rms = [0.0; 3];
    for part in &parts {
        // Error k is sample k + 1's.
        let first = from.saturating_sub(1).min(n);
        let sum: f64 = (first..n).map(|k| x[part.error(k)].powi(2)).sum();
        force_rms[part.i] = (sum / (n - first).max(1) as f64).sqrt();
    }
    let offsets = std::iter::once([0.0; 6])
        .chain((0..n).map(|k| {
            let [px, py, pz, roll, pitch] = vehicle(&parts, &x, k);
            cueing::to_platform(forward, [px, py, pz], roll, pitch, 0.0)
        }))
        .collect();
    Ok(Floor {
        force_rms,
        offsets,
        scored: n - from.saturating_sub(1).min(n),
    })
}

/// Bounds the programme by every face of the polytope at every sample. (Adding only the faces a solution
/// crossed, round by round, was measured slower: the solutions swing across most faces before they settle, and
/// each round is a whole solve.)
fn within(qp: &mut Sparse, parts: &[Part; 3], polytope: &Polytope, forward: Forward, n: usize) {
    // The platform's offset is linear in the vehicle's axes: column j is vehicle axis j's.
    let columns: [[f64; 6]; 5] = core::array::from_fn(|j| {
        let e: [f64; 5] = core::array::from_fn(|m| f64::from(u8::from(m == j)));
        cueing::to_platform(forward, [e[0], e[1], e[2]], e[3], e[4], 0.0)
    });
    // a . (L v) <= b as a row on the vehicle's axes: (L' a) . v.
    let rows: Vec<([f64; 5], f64)> = polytope
        .faces
        .iter()
        .map(|(a, b)| (core::array::from_fn(|j| (0..5).map(|m| columns[j][m] * a[m]).sum()), *b))
        .collect();
    for k in 0..n {
        for (on, b) in &rows {
            face_row(qp, parts, k, on, *b);
        }
    }
}

/// Where each vehicle axis's bounded output sits in the programme: `[px, py, pz, roll, pitch]` as (axis,
/// output, sign). x's angle is minus the pitch, y's the roll.
const VEHICLE: [(usize, usize, f64); 5] = [(X, 2, 1.0), (Y, 2, 1.0), (Z, 1, 1.0), (Y, 4, 1.0), (X, 4, -1.0)];

/// The vehicle's axes `[px, py, pz, roll, pitch]` at sample `k` of the solution `x`.
fn vehicle(parts: &[Part; 3], x: &[f64], k: usize) -> [f64; 5] {
    VEHICLE.map(|(i, output, sign)| {
        let part = &parts[i];
        let c = &part.model.c;
        sign * (0..c.ncols())
            .map(|col| c[(output, col)] * x[part.state(k) + col])
            .sum::<f64>()
    })
}

/// The row `on . v(k) <= b` on the vehicle's axes at sample `k`.
fn face_row(qp: &mut Sparse, parts: &[Part; 3], k: usize, on: &[f64; 5], b: f64) {
    let row = qp.b.len();
    // Two outputs of one axis may share a state: sum before pushing.
    let mut entries: Vec<(usize, f64)> = Vec::new();
    for ((i, output, sign), weight) in VEHICLE.iter().zip(on) {
        let part = &parts[*i];
        let c = &part.model.c;
        for col in 0..c.ncols() {
            let v = sign * weight * c[(*output, col)];
            let at = part.state(k) + col;
            match entries.iter_mut().find(|(c, _)| *c == at) {
                Some(e) => e.1 += v,
                None => entries.push((at, v)),
            }
        }
    }
    for (col, v) in entries {
        qp.a.push(row, col, v);
    }
    qp.b.push(b);
}

/// One axis's part of the programme: per sample after the first its state, the input held over the interval
/// before it, and its error, from `base` on.
struct Part {
    i: usize,
    model: Linear,
    perception: Linear,
    base: usize,
    /// The weight of the perceived rotation's error, against the force's 1; 0: not priced (no variable).
    rotation: f64,
}

impl Part {
    fn new(i: usize, base: usize, rotation: f64) -> Self {
        let (model, perception) = if i == Z {
            (model::vertical(), model::perception(false))
        } else {
            (model::horizontal(), model::perception(true))
        };
        Self {
            i,
            model,
            perception,
            base,
            rotation,
        }
    }

    fn block(&self) -> usize {
        let (nx, nu, _) = self.model.dims();
        nx + nu + 1 + usize::from(self.rotation > 0.0)
    }

    fn state(&self, k: usize) -> usize {
        self.base + k * self.block()
    }

    fn input(&self, k: usize) -> usize {
        self.state(k) + self.model.dims().0
    }

    fn error(&self, k: usize) -> usize {
        let (nx, nu, _) = self.model.dims();
        self.state(k) + nx + nu
    }

    /// The dynamics and the error's definition, as equalities; the error's square and the effort as the cost.
    fn dynamics(&self, qp: &mut Sparse, t: &[f64], samples: &[Telemetry<f64>], from: usize) {
        let (nx, nu, _) = self.model.dims();
        let model = &self.model;
        let reference = vehicle_perceived(&self.perception, t, samples, self.i, 0);
        let rotation = (self.rotation > 0.0).then(|| vehicle_perceived(&self.perception, t, samples, self.i, 1));
        let mut discrete = None;
        for k in 0..t.len().saturating_sub(1) {
            let d = discretised(&mut discrete, model, t[k + 1] - t[k]);
            // x_k - A x_(k-1) - B u = 0 (the platform at neutral before the first interval).
            for r in 0..nx {
                let row = qp.b.len();
                qp.a.push(row, self.state(k) + r, 1.0);
                for c in 0..nx {
                    if k > 0 {
                        qp.a.push(row, self.state(k - 1) + c, -d.a[(r, c)]);
                    }
                }
                for c in 0..nu {
                    qp.a.push(row, self.input(k) + c, -d.b[(r, c)]);
                }
                qp.b.push(0.0);
            }
            // e - (C x + D u) = -reference: the perceived force's error (and the rotation's, output 1).
            let errors = [(0, 1.0, &reference)]
                .into_iter()
                .chain(rotation.as_ref().map(|r| (1, self.rotation, r)));
            for (output, weight, reference) in errors {
                let (row, e) = (qp.b.len(), self.error(k) + output);
                qp.a.push(row, e, 1.0);
                for c in 0..nx {
                    qp.a.push(row, self.state(k) + c, -model.c[(output, c)]);
                }
                for c in 0..nu {
                    qp.a.push(row, self.input(k) + c, -model.d[(output, c)]);
                }
                qp.b.push(-reference[k + 1]);
                if k + 1 >= from {
                    qp.p.push(e, e, 2.0 * weight);
                }
            }
            for c in 0..nu {
                qp.p.push(self.input(k) + c, self.input(k) + c, 2.0 * EFFORT);
            }
        }
    }

    /// Each bounded output within its range, at every sample.
    fn bound(&self, qp: &mut Sparse, ranges: &Ranges, n: usize) {
        let bounds: Vec<Bound> = bounded_outputs(self.i, ranges)
            .into_iter()
            .map(|(output, (lo, hi))| Bound::State { output, lo, hi })
            .collect();
        self.limit(qp, &bounds, Kind::Room, n);
    }
}

/// An optimal cueing's bounds of one kind: on where the platform is, or on how fast it moves.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Room,
    Rates,
}

impl Part {
    /// The velocity's output: a rate, bounded with the inputs; the other bounded outputs are the room.
    fn velocity(&self) -> usize {
        if self.i == Z {
            2
        } else {
            3
        }
    }

    /// Each of an optimal cueing's bounds of `kind` at every sample: a bounded output (its `D` part zero)
    /// within its interval, an input sum within its limit.
    fn limit(&self, qp: &mut Sparse, bounds: &[Bound], kind: Kind, n: usize) {
        let (nx, nu, _) = self.model.dims();
        let of = |bound: &Bound| match bound {
            Bound::State { output, .. } if *output != self.velocity() => Kind::Room,
            _ => Kind::Rates,
        };
        for bound in bounds.iter().filter(|b| of(b) == kind) {
            for k in 0..n {
                let (coefficients, first, lo, hi): (Vec<f64>, usize, f64, f64) = match *bound {
                    Bound::State { output, lo, hi } => (
                        (0..nx).map(|c| self.model.c[(output, c)]).collect(),
                        self.state(k),
                        lo,
                        hi,
                    ),
                    Bound::Input { mask, limit } => {
                        let on = (0..nu).map(|j| f64::from(u8::from(mask & (1 << j) != 0))).collect();
                        (on, self.input(k), -limit, limit)
                    }
                };
                for (sign, limit) in [(1.0, hi), (-1.0, -lo)] {
                    let row = qp.b.len();
                    for (c, v) in coefficients.iter().enumerate() {
                        qp.a.push(row, first + c, sign * v);
                    }
                    qp.b.push(limit);
                }
            }
        }
    }
}

/// The sparse programme, as Clarabel takes it: `min z'Pz/2 + q'z` with `A z + s = b`, the first `equalities`
/// rows' `s` zero and the rest's at least zero.
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

    fn csc(&self, rows: usize, cols: usize) -> CscMatrix<f64> {
        CscMatrix::new_from_triplets(rows, cols, self.rows.clone(), self.cols.clone(), self.vals.clone())
    }
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

/// The regularisation of the solver's KKT system, the default first: on a rig in other units (chapter 4's
/// rotopod, normalised) the default's factorisation can fail on the envelope's many faces, where a stronger one
/// solves the same programme (to a few parts in 10^7 of its floor, measured).
const REGULARISATION: [f64; 3] = [1e-8, 1e-7, 1e-6];

fn solve(qp: &Sparse, variables: usize) -> Result<Vec<f64>, FloorError> {
    let rows = qp.b.len();
    let cones = [
        SupportedConeT::ZeroConeT(qp.equalities),
        SupportedConeT::NonnegativeConeT(rows - qp.equalities),
    ];
    let q = vec![0.0; variables];
    let (p, a) = (qp.p.csc(variables, variables), qp.a.csc(rows, variables));
    let failed = |status: SolverStatus| FloorError::Solver(format!("{status:?}"));
    let mut status = SolverStatus::Unsolved;
    for regularisation in REGULARISATION {
        let settings = DefaultSettings {
            verbose: false,
            max_iter: 200,
            static_regularization_constant: regularisation,
            ..DefaultSettings::default()
        };
        let mut solver =
            DefaultSolver::new(&p, &q, &a, &qp.b, &cones, settings).map_err(|_| failed(SolverStatus::Unsolved))?;
        solver.solve();
        status = solver.solution.status;
        match status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => return Ok(solver.solution.x.clone()),
            SolverStatus::NumericalError | SolverStatus::InsufficientProgress => {}
            _ => break,
        }
    }
    Err(failed(status))
}

/// The vehicle's perceived force (`output` 0) or rotation (1) on axis `i` at every sample, its perception settled
/// on the first sample (as the optimal cueing's `begin`) and run on each sample's stimulus held over the interval
/// before it.
fn vehicle_perceived(perception: &Linear, t: &[f64], samples: &[Telemetry<f64>], i: usize, output: usize) -> Vec<f64> {
    let Some(first) = samples.first() else {
        return Vec::new();
    };
    let r = stimulus(i, first);
    let rhs = -(&perception.b * &r);
    let mut z = perception.a.clone().lu().solve(&rhs).unwrap_or_else(|| rhs * 0.0);
    let mut out = vec![perception.output(&z, &r)[output]];
    let mut discrete = None;
    for k in 1..samples.len() {
        let d = discretised(&mut discrete, perception, t[k] - t[k - 1]);
        let r = stimulus(i, &samples[k]);
        z = &d.a * &z + &d.b * &r;
        out.push(perception.output(&z, &r)[output]);
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
    use super::super::polytope::directions;
    use super::*;
    use ringpod_core::cueing::perception::Perception;
    use ringpod_core::cueing::G;
    use ringpod_core::kinematics::presets::{Preset, PresetGeometry, TRAINER_MODEL};
    use ringpod_core::kinematics::{Pose, RingPlatform};

    /// 6 s at 100 Hz: at rest, then braking at 3 m/s^2 and turning left at 2 m/s^2 from 1 s to 4 s, ramped
    /// over half a second, with `sign` on the braking (-1 accelerates instead).
    fn drive(sign: f64) -> (Vec<f64>, Vec<Telemetry<f64>>) {
        drive_of(3.0 * sign, 2.0)
    }

    /// The same with braking `brake` and a left turn's force `turn` (m/s^2).
    fn drive_of(brake: f64, turn: f64) -> (Vec<f64>, Vec<Telemetry<f64>>) {
        let t: Vec<f64> = (0..600).map(|k| f64::from(k) * 0.01).collect();
        let ramp = |t: f64| ((t - 1.0) / 0.5).clamp(0.0, 1.0) * ((4.5 - t) / 0.5).clamp(0.0, 1.0);
        let samples = t
            .iter()
            .map(|&t| Telemetry {
                force: [-brake * ramp(t), turn * ramp(t), G],
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
        let f = floor(&t, &samples, Room::Ranges(&wide()), Forward::PlusX).unwrap();
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
        let f = floor(&t, &samples, Room::Ranges(&wide()), Forward::PlusX).unwrap();
        assert!(f.force_rms[0] > 0.5 && f.force_rms[1] < 1e-3, "{:?}", f.force_rms);
    }

    /// Without room to move, the floor is the whole of what the vehicle's occupant perceives: the same figure
    /// the bench gives a platform held at neutral (its Tustin filters against the model's hold), to 1 %.
    #[test]
    fn without_room_the_floor_is_what_the_vehicle_perceives() {
        let (t, samples) = drive(1.0);
        let none = [(-1e-9, 1e-9); 5];
        let f = floor(&t, &samples, Room::Ranges(&none), Forward::PlusX).unwrap();
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

    /// An optimal cueing's room and limits loosened past the drive's needs and its rotation unpriced leave the
    /// floor of the ranges; a slow tilt with the rotation priced keeps the motion within every limit and costs
    /// error.
    #[test]
    fn within_an_optimal_cueings_limits_the_floor_keeps_to_them() {
        let (t, samples) = drive(1.0);
        let ranges = wide();
        let free = floor(&t, &samples, Room::Ranges(&ranges), Forward::PlusX).unwrap();
        let mut loose = CueConfig {
            tilt_limit_deg: [90.0; 2],
            tilt_rate_deg: [1000.0; 2],
            ..CueConfig::default()
        };
        let o = &mut loose.optimal;
        (o.envelope_share, o.tilt_share, o.rotation_weight) = (1.0, 1.0, [0.0; 2]);
        (o.max_velocity, o.max_acceleration, o.max_rate_deg) = ([100.0; 3], [1000.0; 3], [1e4; 2]);
        let within = |config| {
            floor_from(
                &t,
                &samples,
                Room::Shares(&ranges, config),
                Some(config),
                Forward::PlusX,
                0,
            )
        };
        let same = within(&loose).unwrap();
        for i in 0..3 {
            assert!(
                (same.force_rms[i] - free.force_rms[i]).abs() < 1e-4,
                "{same:?} against {free:?}"
            );
        }
        let mut slow = CueConfig {
            tilt_rate_deg: [3.0; 2],
            ..CueConfig::default()
        };
        slow.optimal.envelope_share = 0.2;
        let limited = within(&slow).unwrap();
        assert!(
            limited.force_rms[0] > free.force_rms[0] + 0.1,
            "{limited:?} against {free:?}"
        );
        let rate = slow.optimal.max_rate_deg[1].to_radians();
        let (speed, angle) = (slow.optimal.max_velocity[0], slow.tilt_limit_deg[0].to_radians());
        for (k, w) in limited.offsets.windows(2).enumerate() {
            let dt = t[k + 1] - t[k];
            assert!(
                (w[1][4] - w[0][4]).abs() <= rate * dt + 1e-6,
                "pitch rate at {k}: {w:?}"
            );
            assert!(
                (w[1][0] - w[0][0]).abs() <= speed * dt * 1.5 + 1e-6,
                "surge speed at {k}: {w:?}"
            );
            assert!(w[1][4].abs() <= angle + 1e-6, "pitch at {k}: {w:?}");
            for (i, (lo, hi)) in ranges.iter().take(3).enumerate() {
                assert!(
                    w[1][i] >= 0.2 * lo - 1e-6 && w[1][i] <= 0.2 * hi + 1e-6,
                    "{i} at {k}: {w:?}"
                );
            }
        }
    }

    /// Inside the trainer model's outer polytope, the floor's motion keeps every face, facing either way, and
    /// it perceives no more error than the best motion inside a box the polytope holds.
    #[test]
    fn inside_the_envelope_the_floor_keeps_every_face_and_beats_any_box_it_holds() {
        let mechanism = RingPlatform::new(&TRAINER_MODEL);
        let neutral = Pose::from_array(Preset::TrainerModel.home());
        let ranges: Ranges = [
            (-0.129, 0.129),
            (-0.055, 0.095),
            (-0.067, 0.059),
            (-0.454, 0.384),
            (-0.358, 0.358),
        ];
        let outer = Polytope::of(&mechanism, &neutral, &ranges, &directions(2), 200);
        let inner = ranges.map(|(lo, hi)| (0.4 * lo, 0.4 * hi));
        for corner in 0..32 {
            let c: [f64; 5] = core::array::from_fn(|j| if corner >> j & 1 == 1 { inner[j].1 } else { inner[j].0 });
            assert!(outer.holds(&c), "{c:?}");
        }
        // Braking and turning harder than the envelope's room for tilt: the motion presses on its faces.
        let (t, samples) = drive_of(5.0, 4.0);
        let total = |f: &Floor| f.force_rms.iter().map(|r| r * r).sum::<f64>().sqrt();
        for forward in [Forward::PlusX, Forward::PlusY, Forward::MinusY] {
            let f = floor(&t, &samples, Room::Envelope(&outer), forward).unwrap();
            let mut nearest = f64::MIN;
            for o in &f.offsets {
                for (a, b) in &outer.faces {
                    let at: f64 = a.iter().zip(o).map(|(p, q)| p * q).sum();
                    assert!(at <= b + 1e-6, "{forward:?}: {o:?} crosses {a:?} <= {b}");
                    nearest = nearest.max(at - b);
                }
            }
            // Held on the polytope's own faces, not short of them.
            assert!(nearest > -1e-4, "{forward:?}: {nearest}");
            let boxed = floor(&t, &samples, Room::Ranges(&inner), forward).unwrap();
            assert!(
                total(&f) <= total(&boxed) + 1e-6,
                "{:?} against {:?}",
                f.force_rms,
                boxed.force_rms
            );
            // It does use the room past the box: the braking's pitch goes further.
            let pitch = f.offsets.iter().map(|o| o[3].abs().max(o[4].abs())).fold(0.0, f64::max);
            assert!(pitch > 0.4 * 0.358, "{pitch}");
        }
    }

    /// The shipped example drive.
    fn example_drive() -> (Vec<f64>, Vec<Telemetry<f64>>) {
        let text = include_str!("../../../../docs/drive-telemetry.csv");
        text.lines()
            .skip(1)
            .map(|line| {
                let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
                let sample = Telemetry {
                    force: [v[1], v[2], v[3]],
                    rate: [v[4], v[5], v[6]],
                };
                (v[0], sample)
            })
            .unzip()
    }

    /// Chapter 4's rotopod (normalised units, a workspace much larger than the trainer model's) has a floor
    /// inside its envelope too, keeping every face: its programme needs a stronger regularisation than the
    /// solver's default.
    #[test]
    fn the_rotopods_envelope_has_a_floor() {
        let PresetGeometry::Ring(g) = Preset::RotopodCh4.geometry() else {
            unreachable!("the rotopod is a ring platform")
        };
        let mechanism = RingPlatform::new(g);
        let neutral = Pose::from_array(Preset::RotopodCh4.home());
        let ranges = crate::cueing::engine::ranges(&mechanism, &neutral);
        let outer = Polytope::of(&mechanism, &neutral, &ranges, &directions(3), 2000);
        let (t, samples) = example_drive();
        let f = floor(&t, &samples, Room::Envelope(&outer), Forward::PlusX).unwrap();
        assert!(
            f.force_rms.iter().all(|r| r.is_finite()) && f.force_rms[0] > 0.01,
            "{:?}",
            f.force_rms
        );
        for o in &f.offsets {
            for (a, b) in &outer.faces {
                let at: f64 = a.iter().zip(o).map(|(p, q)| p * q).sum();
                assert!(at <= b + 1e-6, "{o:?} crosses {a:?} <= {b}");
            }
        }
    }

    #[test]
    fn a_gap_or_a_drive_too_short_is_said() {
        let (mut t, samples) = drive(1.0);
        for v in &mut t[200..] {
            *v += 2.0;
        }
        let e = floor(&t, &samples, Room::Ranges(&wide()), Forward::PlusX).unwrap_err();
        assert_eq!(e, FloorError::Interval(200));
        // One sample, or none: nothing to solve, said rather than handed to the solver.
        for n in [0, 1] {
            let e = floor(&t[..n], &samples[..n], Room::Ranges(&wide()), Forward::PlusX).unwrap_err();
            assert_eq!(e, FloorError::TooShort(n));
        }
    }
}
