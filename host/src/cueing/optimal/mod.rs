//! The optimal (model-predictive) cueing: at each telemetry sample, one quadratic programme per platform axis
//! over a horizon ([`qp`]) plans the platform's motion so that what the rider perceives ([`model`], the core's
//! perception model) follows what the vehicle's occupant perceives, within the rig's envelope about home and its
//! velocity, acceleration and tilt-rate limits; the first step of the plan is applied, and the next sample plans
//! again from where it led.
//!
//! The reference is the last sample held over the horizon (a game gives no preview), or, for a recorded drive,
//! the drive's own next samples (`preview`). Yaw follows the classical washout's heading channel (a ring
//! platform turns without limit: nothing to optimise). Each solve is bounded by its iterations, not by a clock,
//! so that the same drive gives the same motion on any machine under any load (a solve's time is measured and a
//! late one counted, never acted on). A solve that fails or does not converge within them falls back (counted)
//! without a jump: the axis follows the last plan that was solved, step by step, over the first half
//! of that plan's horizon (what the optimiser meant to do from there); past it, the classical washout that runs
//! alongside on the same samples gives its *change* over the sample, carried on from where the platform is.
//! Taking the washout's position instead would jump between two different trajectories: felt as a false cue.

pub mod floor;
pub mod heave;
pub mod model;
pub mod polytope;
pub mod price;
pub mod qp;
pub mod tilt;

use std::time::Instant;

use nalgebra::DVector;
use ringpod_core::cueing::{self, ConfigError, CueConfig, SampleError, Telemetry, Washout, G};
use ringpod_core::kinematics::{Pose, RingPlatform};

use model::{Discrete, Linear};
use qp::{AxisQp, Bound, Spec};

/// Per axis of the platform's offset `[x, y, z, alpha, beta]` the range about home (m, rad) in which the pose
/// passes every check, found one axis at a time.
pub type Ranges = [(f64, f64); 5];

/// The envelope an optimiser plans in: the ranges, and the rig about its neutral pose where it is known, from
/// which the roll and pitch's shared room is scanned ([`tilt`]). Without the rig each angle keeps to its range.
#[derive(Debug, Clone, Copy)]
pub struct Envelope {
    /// Each axis's range about home.
    pub ranges: Ranges,
    /// The rig and its neutral pose.
    pub rig: Option<(RingPlatform<f64>, Pose<f64>)>,
}

impl From<Ranges> for Envelope {
    fn from(ranges: Ranges) -> Self {
        Self { ranges, rig: None }
    }
}

/// What the optimal cueing did, sample by sample.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Counts {
    /// Samples planned.
    pub samples: usize,
    /// Samples where an axis fell back (its solve failed or did not converge within its iterations).
    pub fallbacks: usize,
    /// Of the axes that fell back, sample by sample: those that followed their last plan...
    pub followed_plan: usize,
    /// ...and those past their last plan's horizon, which took the classical washout's change.
    pub took_classical: usize,
    /// Samples whose solves took longer than the budget (measured and counted; the plan was used all the same).
    pub late: usize,
    /// Each sample's solve time, the three axes together (s).
    #[serde(skip)]
    pub solve_s: Vec<f64>,
}

impl Counts {
    /// Adds another run's counts (an engine retired while streaming, another drive of a bench).
    pub fn add(&mut self, other: &Counts) {
        self.samples += other.samples;
        self.fallbacks += other.fallbacks;
        self.late += other.late;
        self.followed_plan += other.followed_plan;
        self.took_classical += other.took_classical;
        self.solve_s.extend_from_slice(&other.solve_s);
    }

    /// The solve time per sample: p50, p99 and max (ms); zeros before any.
    pub fn solve_ms(&self) -> [f64; 3] {
        let mut times = self.solve_s.clone();
        if times.is_empty() {
            return [0.0; 3];
        }
        times.sort_by(f64::total_cmp);
        let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize] * 1000.0;
        [at(0.5), at(0.99), at(1.0)]
    }
}

/// What a stream's optimal cueing did (`--report-json`'s `datagrams.optimal`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CountsReport {
    /// The counts.
    #[serde(flatten)]
    pub counts: Counts,
    /// The solve time per sample, p50, p99, max (ms).
    pub solve_ms: [f64; 3],
}

impl From<Counts> for CountsReport {
    fn from(counts: Counts) -> Self {
        Self {
            solve_ms: counts.solve_ms(),
            counts,
        }
    }
}

/// One axis: its programme, the platform's state (with the rider's perception of it) and the vehicle's
/// perception, which gives the reference.
struct Axis {
    model: Linear,
    qp: AxisQp,
    perception: Linear,
    /// The perception at the horizon's step.
    perception_h: Discrete,
    x: DVector<f64>,
    vehicle: DVector<f64>,
    /// Both models at the last sample interval (most sources keep one).
    at_dt: Option<(f64, Discrete, Discrete)>,
    /// The last plan solved (every step's inputs; empty before the first) and how long it has run (s).
    plan: DVector<f64>,
    plan_age: f64,
    /// The classical washout's channels of this axis at the last sample (`[position, tilt, rotation]`).
    classical: [f64; 3],
}

/// Which way an axis's angle turns the platform: x's angle is minus the pitch (a pitch-up, `beta < 0`, gives a
/// forward force), y's is the roll.
const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;

/// The optimal cueing, one instance per stream.
pub struct Optimal {
    config: CueConfig,
    classical: Washout<f64>,
    axes: [Axis; 3],
    /// The roll and pitch's shared room, where the rig is known.
    tilt: Option<tilt::Sharing>,
    /// The tilts' loss of vertical force given to the heave, within its room beside the tilts; none (the default):
    /// [`Optimal::give_heave_the_tilt_loss`].
    loss: Option<heave::Loss>,
    ranges: Ranges,
    counts: Counts,
}

impl Optimal {
    /// Sets the programmes up for `config` in `envelope` (about home).
    pub fn new(config: CueConfig, envelope: &Envelope) -> Result<Self, ConfigError> {
        let classical = Washout::new(config)?;
        let ranges = &envelope.ranges;
        let tilt = envelope.rig.map(|(mechanism, neutral)| {
            let base = [X, Y].map(|i| angle_bounds(i, &config, ranges));
            let closing = [X, Y].map(|i| config.tilt_rate_deg[i].to_radians());
            tilt::Sharing::new(mechanism, neutral, config.forward, base, closing)
        });
        Ok(Self {
            config,
            classical,
            axes: [X, Y, Z].map(|i| Axis::new(i, &config, ranges)),
            tilt,
            loss: None,
            ranges: *ranges,
            counts: Counts::default(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CueConfig {
        &self.config
    }

    /// What it did so far.
    pub fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The first sample of a stream: the vehicle's perception settled on it (a drive that starts in a corner is
    /// perceived as in it), the platform at neutral.
    pub fn begin(&mut self, sample: &Telemetry<f64>) -> Result<[f64; 6], SampleError> {
        self.classical.begin(sample)?;
        for (i, axis) in self.axes.iter_mut().enumerate() {
            let r = stimulus(i, sample);
            // Steady state: A z + B r = 0.
            let rhs = -(&axis.perception.b * &r);
            axis.vehicle = axis.perception.a.clone().lu().solve(&rhs).unwrap_or_else(|| rhs * 0.0);
            axis.x.fill(0.0);
            axis.plan = DVector::zeros(0);
        }
        for i in 0..3 {
            self.axes[i].classical = self.classical_channels(i);
        }
        Ok(self.offset())
    }

    /// One sample after `dt` seconds; `ahead` holds the drive's next samples at the horizon's steps (preview),
    /// or nothing (the sample held). Returns the offset from neutral in platform axes.
    pub fn step(
        &mut self,
        sample: &Telemetry<f64>,
        dt: f64,
        ahead: &[Telemetry<f64>],
    ) -> Result<[f64; 6], SampleError> {
        self.classical.step(sample, dt)?;
        let started = Instant::now();
        let budget = self.config.optimal.budget_ms / 1000.0;
        let mut fell_back = false;
        let mut late = false;
        let h = self.config.optimal.step_s;
        let order = self.tilt.as_mut().map_or([X, Y, Z], |t| t.order(sample.force));
        let before = [X, Y].map(|i| self.axes[i].x[2] + self.axes[i].x[3]);
        for i in order {
            // z plans last, with the loss of vertical force of both tilts as they move now and as planned.
            let loss = if i == Z { self.tilt_loss(before, h) } else { None };
            let yaw = self.classical.channels().yaw;
            if i == Z {
                self.heave_room(h, yaw, dt);
            } else if let Some(t) = self.tilt.as_mut() {
                let (lo, hi) = t.bound_over(i, i == order[0], &self.axes, h, yaw, dt);
                self.axes[i].qp.set_state_bound(tilt::ANGLE_BOUND, lo, hi);
            }
            let classical = self.classical_channels(i);
            let price = self.angle_price(i, h);
            let axis = &mut self.axes[i];
            let (d_model, d_perception) = axis.at(dt);
            let r = stimulus(i, sample);
            axis.vehicle = &d_perception.a * &axis.vehicle + &d_perception.b * &r;
            let mut reference = axis.reference(&r, ahead, i);
            if let Some((perceived, _)) = &loss {
                let ny = axis.qp.outputs();
                for (k, p) in perceived.iter().enumerate() {
                    reference[k * ny] -= p;
                }
            }
            let t0 = Instant::now();
            let solved = axis.qp.solve(&axis.x, &reference, &price);
            // Measured and counted, never acted on: the motion does not depend on the machine's speed or load.
            late |= t0.elapsed().as_secs_f64() > budget;
            match solved {
                Ok((plan, _)) => {
                    axis.plan = plan;
                    axis.plan_age = 0.0;
                    axis.follow_plan(&d_model, dt, h);
                }
                Err(_) => {
                    fell_back = true;
                    if axis.follow_plan(&d_model, dt, h) {
                        self.counts.followed_plan += 1;
                    } else {
                        let change = [0, 1, 2].map(|j| classical[j] - axis.classical[j]);
                        axis.carry(&d_model, change, dt);
                        self.counts.took_classical += 1;
                    }
                }
            }
            if let (Some((_, now)), Some(l)) = (&loss, self.loss.as_mut()) {
                l.carry(&mut axis.x, *now, dt);
            }
            axis.classical = classical;
        }
        self.counts.samples += 1;
        self.counts.fallbacks += usize::from(fell_back);
        self.counts.late += usize::from(late);
        self.counts.solve_s.push(started.elapsed().as_secs_f64());
        Ok(self.offset())
    }

    /// The classical washout's channels of axis `i` at its last sample: position and the angle's two parts.
    fn classical_channels(&self, i: usize) -> [f64; 3] {
        let c = self.classical.channels();
        match i {
            X => [c.translation[0], -c.tilt[1], -c.rotation[1]],
            Y => [c.translation[1], c.tilt[0], c.rotation[0]],
            _ => [c.translation[2], 0.0, 0.0],
        }
    }

    /// The offset from neutral in platform axes.
    pub fn offset(&self) -> [f64; 6] {
        let [x, y, z] = &self.axes;
        let angle = |a: &Axis| a.x[2] + a.x[3];
        let roll = angle(y);
        let pitch = -angle(x);
        let yaw = self.classical.channels().yaw;
        cueing::to_platform(self.config.forward, [x.x[0], y.x[0], z.x[0]], roll, pitch, yaw)
    }

    /// Back to neutral (yaw kept): the next sample is a first one.
    pub fn reset(&mut self) {
        self.classical.reset();
        for a in &mut self.axes {
            a.x.fill(0.0);
            a.vehicle.fill(0.0);
            a.plan = DVector::zeros(0);
        }
    }

    /// The same cueing under another configuration from here on: the platform's and the perception's states
    /// carried (the models are the same whatever the configuration), the programmes set up anew; the counts
    /// start again (the old cueing keeps its own while it fades out).
    pub fn retuned(&self, config: CueConfig, envelope: &Envelope) -> Result<Self, ConfigError> {
        let mut new = Self::new(config, envelope)?;
        new.classical = self.classical.retuned(config)?;
        for (n, o) in new.axes.iter_mut().zip(&self.axes) {
            n.x.copy_from(&o.x);
            n.vehicle.copy_from(&o.vehicle);
            n.classical = o.classical;
            // The models are the configuration's too: the plan solved under the old one is still a motion of
            // this platform, and a solve under the new one that falls back follows it.
            n.plan.clone_from(&o.plan);
            n.plan_age = o.plan_age;
        }
        new.give_heave_the_tilt_loss(self.loss.is_some());
        Ok(new)
    }
}

/// The vehicle's stimulus of axis `i`: `[specific force, rate]` (x: the pitch rate's negative, as x's angle is
/// minus the pitch), `[specific force less g]` on z.
fn stimulus(i: usize, s: &Telemetry<f64>) -> DVector<f64> {
    match i {
        X => DVector::from_vec(vec![s.force[0], -s.rate[1]]),
        Y => DVector::from_vec(vec![s.force[1], s.rate[0]]),
        _ => DVector::from_vec(vec![s.force[2] - G]),
    }
}

/// Horizontal axis `i`'s own interval on its angle: its share of the range, within the tilt limit. x's angle
/// is minus the pitch (index 4 of the ranges), y's the roll (index 3); the tilt keys are per force axis (x 0,
/// y 1).
fn angle_bounds(i: usize, config: &CueConfig, ranges: &Ranges) -> (f64, f64) {
    let tilt = config.optimal.tilt_share;
    let (lo, hi) = if i == X {
        (-ranges[4].1 * tilt, -ranges[4].0 * tilt)
    } else {
        (ranges[3].0 * tilt, ranges[3].1 * tilt)
    };
    let limit = config.tilt_limit_deg[i].to_radians();
    (lo.max(-limit), hi.min(limit))
}

/// Axis `i`'s weights (per output), effort weights (per input) and bounds.
fn cost_and_bounds(i: usize, config: &CueConfig, ranges: &Ranges) -> (Vec<f64>, Vec<f64>, Vec<Bound>) {
    let o = &config.optimal;
    let share = o.envelope_share;
    let (lo, hi) = (ranges[i].0 * share, ranges[i].1 * share);
    let (v, a) = (o.max_velocity[i], o.max_acceleration[i]);
    let speed = |output| Bound::State { output, lo: -v, hi: v };
    if i == Z {
        return (
            vec![o.force_weight[i], o.position_weight[i], o.velocity_weight[i]],
            vec![o.acceleration_weight[i]],
            vec![
                Bound::State { output: 1, lo, hi },
                speed(2),
                Bound::Input { mask: 1, limit: a },
            ],
        );
    }
    let (alo, ahi) = angle_bounds(i, config, ranges);
    // The rotation keys are per rotation (roll 0, pitch 1): x's is the pitch, y's the roll.
    let rot = 1 - i;
    (
        vec![
            o.force_weight[i],
            o.rotation_weight[rot],
            o.position_weight[i],
            o.velocity_weight[i],
            o.tilt_weight[i],
        ],
        vec![o.acceleration_weight[i], o.rate_weight[i], o.rate_weight[i]],
        vec![
            Bound::State { output: 2, lo, hi },
            speed(3),
            Bound::State {
                output: 4,
                lo: alo,
                hi: ahi,
            },
            Bound::Input { mask: 1, limit: a },
            Bound::Input {
                mask: 2,
                limit: config.tilt_rate_deg[i].to_radians(),
            },
            Bound::Input {
                mask: 6,
                limit: o.max_rate_deg[i].to_radians(),
            },
        ],
    )
}

impl Axis {
    /// Axis `i` at neutral, its programme set up.
    fn new(i: usize, config: &CueConfig, ranges: &Ranges) -> Self {
        let o = &config.optimal;
        let (model, perception) = if i == Z {
            (model::vertical(), model::perception(false))
        } else {
            (model::horizontal(), model::perception(true))
        };
        let (weights, effort, bounds) = cost_and_bounds(i, config, ranges);
        let spec = Spec {
            model: &model,
            steps: o.horizon as usize,
            h: o.step_s,
            output_weight: &weights,
            input_weight: &effort,
            bounds: &bounds,
            priced: (i != Z).then_some(price::ANGLE),
        };
        let qp = AxisQp::new(&spec, o.iterations);
        let (nx, np) = (model.dims().0, perception.dims().0);
        Self {
            perception_h: perception.discretise(o.step_s),
            x: DVector::zeros(nx),
            vehicle: DVector::zeros(np),
            model,
            qp,
            perception,
            at_dt: None,
            plan: DVector::zeros(0),
            plan_age: 0.0,
            classical: [0.0; 3],
        }
    }

    /// The models discretised at `dt`, kept for the next sample of the same interval.
    fn at(&mut self, dt: f64) -> (Discrete, Discrete) {
        match &self.at_dt {
            Some((d, m, p)) if *d == dt => (m.clone(), p.clone()),
            _ => {
                let (m, p) = (self.model.discretise(dt), self.perception.discretise(dt));
                self.at_dt = Some((dt, m.clone(), p.clone()));
                (m, p)
            }
        }
    }

    /// The reference over the horizon: the vehicle's perception run on from its state, each step's stimulus the
    /// sample held or the previewed one; the other outputs (position, velocity, angle) towards zero.
    fn reference(&self, r: &DVector<f64>, ahead: &[Telemetry<f64>], i: usize) -> DVector<f64> {
        let n = self.qp.steps();
        let ny = self.qp.outputs();
        let mut out = DVector::zeros(n * ny);
        let mut z = self.vehicle.clone();
        let d = &self.perception_h;
        for k in 0..n {
            let rk = ahead.get(k).map_or_else(|| r.clone(), |s| stimulus(i, s));
            z = &d.a * &z + &d.b * &rk;
            let y = self.perception.output(&z, &rk);
            for (j, v) in y.iter().enumerate() {
                out[k * ny + j] = *v;
            }
        }
        out
    }

    /// One sample of `dt` along the last plan (`d` the model at `dt`, `h` the plan's step): the input of the
    /// plan's step it has reached. False, and nothing moved, past the first half of the plan's horizon or before
    /// any plan: a plan's later steps are shaped by where its horizon ends (nothing is priced beyond it, so it
    /// spends the envelope there: a swing from one bound to the other), not by the drive.
    fn follow_plan(&mut self, d: &Discrete, dt: f64, h: f64) -> bool {
        let nu = d.b.ncols();
        // The age is a whole number of samples: a hair under a step boundary is still that step.
        let k = ((self.plan_age + 1e-9) / h) as usize;
        let steps = self.plan.len() / nu;
        if k >= steps.div_ceil(2) {
            return false;
        }
        let u = self.plan.rows(k * nu, nu).into_owned();
        self.x = &d.a * &self.x + &d.b * &u;
        self.plan_age += dt;
        true
    }

    /// One sample of `dt` carrying the classical washout's change `[position, tilt, rotation]` over it on from
    /// where the platform is: the position and the angles move by exactly that, the velocity is the change's,
    /// and the rider's perception of the platform runs on the inputs that make it (`d` the model at `dt`).
    fn carry(&mut self, d: &Discrete, [dp, dtilt, drotation]: [f64; 3], dt: f64) {
        let (p, v) = (self.x[0] + dp, dp / dt);
        let mut u = DVector::zeros(d.b.ncols());
        u[0] = (v - self.x[1]) / dt;
        if u.len() == 3 {
            u[1] = dtilt / dt;
            u[2] = drotation / dt;
        }
        self.x = &d.a * &self.x + &d.b * &u;
        self.x[0] = p;
        self.x[1] = v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn ranges() -> Ranges {
        [(-0.05, 0.05), (-0.05, 0.05), (-0.03, 0.03), (-0.3, 0.3), (-0.3, 0.3)]
    }

    fn sample(ax: f64) -> Telemetry<f64> {
        Telemetry {
            force: [ax, 0.0, G],
            rate: [0.0; 3],
        }
    }

    /// The optimal cueing with a budget no solve runs past (the tests run on a loaded machine; the budget is only
    /// counted, and [`the_motion_does_not_depend_on_the_time_a_solve_takes`] shows it).
    pub(super) fn patient() -> CueConfig {
        let mut c = CueConfig {
            algorithm: cueing::Algorithm::Optimal,
            ..CueConfig::default()
        };
        c.optimal.budget_ms = 1000.0;
        c
    }

    /// [`patient`] with the tuned classical's tilt: 20 deg at 18.75 deg/s, 0.95 of the ranges.
    pub(super) fn tilting() -> CueConfig {
        let mut c = patient();
        c.tilt_limit_deg = [20.0; 2];
        c.tilt_rate_deg = [18.75; 2];
        c.optimal.tilt_share = 0.95;
        c
    }

    #[test]
    fn braking_is_cued_by_moving_back_and_pitching_nose_down() {
        let mut o = Optimal::new(patient(), &ranges().into()).unwrap();
        o.begin(&sample(0.0)).unwrap();
        let r = &mut o.axes[X];
        let reference = r.reference(&stimulus(X, &sample(-6.0)), &[], X);
        let solved = r.qp.solve(&r.x, &reference, &[]);
        assert!(solved.is_ok(), "{solved:?}");
        let mut last = [0.0; 6];
        for _ in 0..100 {
            last = o.step(&sample(-6.0), 0.01, &[]).unwrap();
        }
        assert_eq!(
            o.counts().fallbacks,
            0,
            "{:?}",
            (o.counts().late, o.counts().solve_s.iter().cloned().fold(0.0, f64::max))
        );
        assert!(last[4] > 0.01, "{last:?}");
        // Within the envelope it plans in (a share of the ranges), which the slacks' price keeps.
        let (share, tilt) = (o.config.optimal.envelope_share, o.config.optimal.tilt_share);
        assert!(
            last[0].abs() <= 0.05 * share + 1e-3 && last[4] <= 0.3 * tilt + 1e-3,
            "{last:?}"
        );
    }

    /// The largest change of each offset component from one sample to the next over `samples` samples.
    fn largest_steps(o: &mut Optimal, samples: usize, force: impl Fn(usize) -> f64) -> [f64; 6] {
        let mut last = o.offset();
        let mut largest = [0.0f64; 6];
        for k in 0..samples {
            let now = o.step(&sample(force(k)), 0.01, &[]).unwrap();
            for j in 0..6 {
                largest[j] = largest[j].max((now[j] - last[j]).abs());
            }
            last = now;
        }
        largest
    }

    /// The same drive with a budget every solve runs past (0.01 ms) and with one none does: the same motion, bit
    /// for bit, and the late solves counted. A clock that decided would make it differ from machine to machine.
    #[test]
    fn the_motion_does_not_depend_on_the_time_a_solve_takes() {
        let drive = |budget_ms: f64| {
            let mut c = patient();
            c.optimal.budget_ms = budget_ms;
            let mut o = Optimal::new(c, &ranges().into()).unwrap();
            o.begin(&sample(0.0)).unwrap();
            let poses: Vec<[f64; 6]> = (0..200)
                .map(|k| o.step(&sample(if k < 100 { -6.0 } else { 3.0 }), 0.01, &[]).unwrap())
                .collect();
            (poses, o.counts().clone())
        };
        let (hurried, late) = drive(0.01);
        let (patient, on_time) = drive(1000.0);
        assert_eq!(hurried, patient);
        assert_eq!((late.late, late.fallbacks), (200, 0), "{late:?}");
        assert_eq!((on_time.late, on_time.fallbacks), (0, 0), "{on_time:?}");
    }

    /// Braking held, the platform pitched to its tilt (0.285 rad, a loss of 0.40 m/s^2 of vertical force): given
    /// the loss, the heave moves to make up what it can of it while the tilt comes in, and the rider's perceived
    /// vertical force (the delivered force with the tilt's cosines, through the core's perception) strays less
    /// from the vehicle's (level: none); without it the heave stays at home.
    #[test]
    fn the_heave_makes_up_the_tilts_loss_of_vertical_force() {
        use ringpod_core::cueing::perception::Perception;
        let drive = |on: bool| {
            let mut o = Optimal::new(tilting(), &ranges().into()).unwrap();
            o.give_heave_the_tilt_loss(on);
            o.begin(&sample(0.0)).unwrap();
            let dt = 0.01;
            let offsets: Vec<[f64; 6]> = (0..300).map(|_| o.step(&sample(-4.0), dt, &[]).unwrap()).collect();
            let mut p = Perception::<f64>::new();
            p.begin([0.0; 3], [0.0; 3]);
            let mut sum = 0.0;
            for k in 1..offsets.len() - 1 {
                let z = |j: usize| offsets[j][2];
                let accel = (z(k + 1) - 2.0 * z(k) + z(k - 1)) / (dt * dt);
                let f = cueing::delivered([0.0, 0.0, accel], offsets[k][3], offsets[k][4]);
                sum += p.step([0.0, 0.0, f[2] - G], [0.0; 3], dt).force[2].powi(2);
            }
            let travel = offsets.iter().map(|o| o[2].abs()).fold(0.0, f64::max);
            ((sum / (offsets.len() - 2) as f64).sqrt(), travel, offsets[299][4])
        };
        let (without, still, pitch) = drive(false);
        let (with, travel, _) = drive(true);
        assert!(pitch > 0.25, "pitched {pitch}");
        // It cannot hold a sustained force: it falls while the loss is small and is caught as it grows, to its
        // range's low end (15 mm), so the loss is felt later and less at its onset. 0.651 against 0.661 m/s^2.
        assert!(still < 1e-4 && travel > 0.01, "{still} {travel}");
        assert!(
            with < 0.99 * without,
            "perceived vertical error {with} with the loss given, {without} without"
        );
    }

    #[test]
    fn an_unconverged_solve_follows_the_last_plan_then_the_washouts_change_without_a_jump() {
        let mut o = Optimal::new(patient(), &ranges().into()).unwrap();
        o.begin(&sample(0.0)).unwrap();
        let solved = largest_steps(&mut o, 100, |_| -6.0);
        assert_eq!(o.counts().fallbacks, 0);
        // From here no solve converges: one iteration is less than any solve takes.
        let mut hurried = patient();
        hurried.optimal.iterations = 1;
        let mut o = o.retuned(hurried, &ranges().into()).unwrap();
        let fell_back = largest_steps(&mut o, 300, |k| if k < 150 { -6.0 } else { 2.0 });
        let c = o.counts();
        assert_eq!((c.samples, c.fallbacks), (300, 300));
        // Each axis follows its plan over the first half of its horizon (4 steps of 0.15 s: 60 samples), then the
        // washout.
        let half = 60;
        assert!((3 * (half - 1)..=3 * (half + 1)).contains(&c.followed_plan), "{c:?}");
        assert_eq!(c.followed_plan + c.took_classical, 3 * 300, "{c:?}");
        // No jump: no sample moves the platform further than a solved one did, or than the washout's own steps.
        let mut washout = Washout::new(patient()).unwrap();
        washout.begin(&sample(0.0)).unwrap();
        let mut last = *washout.channels();
        let mut washout_step = 0.0f64;
        for k in 0..400 {
            washout.step(&sample(if k < 250 { -6.0 } else { 2.0 }), 0.01).unwrap();
            let now = *washout.channels();
            let moved = (0..3).map(|j| (now.translation[j] - last.translation[j]).abs());
            washout_step = moved.fold(washout_step, f64::max);
            last = now;
        }
        let bound = solved[0].max(washout_step) * 1.5 + 1e-6;
        assert!(fell_back[0] <= bound, "surge step {} > {bound}", fell_back[0]);
        let angle_bound = solved[4].max(patient().tilt_rate_deg[0].to_radians() * 0.01) * 1.5 + 1e-6;
        assert!(
            fell_back[4] <= angle_bound,
            "pitch step {} > {angle_bound}",
            fell_back[4]
        );
    }
}
