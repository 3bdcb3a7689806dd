//! One control tick: the newest valid setpoint, interpolated and limited, through IK and the workspace checks to
//! motor step targets for the end of the next period.
//!
//! - Setpoints are checked when they arrive. Garbage is refused: not finite, not newer than the last, a gross jump
//!   (further from the previous setpoint than the platform travels at its velocity limits in the jump window: a
//!   broken source, not a fast one), or the controller not streaming. A refused setpoint moves nothing; its reason
//!   is counted and returned.
//! - Everything else is followed as closely as the envelope and the limits allow: a setpoint outside the workspace
//!   is limited into it ([`super::envelope`]), answered as limited and counted per check that bound it, with the
//!   largest correction kept; a setpoint faster than the velocity limits is followed at the limits.
//! - [`FollowMode::Interpolate`]: accepted setpoints are interpolated linearly over their own interval (60 Hz
//!   simulator output into a 1 kHz loop): the reference moves on the straight line from where it is to the new
//!   setpoint, a convex combination that never passes it. This delays motion by one setpoint interval, the price
//!   of a jitter-free path. [`FollowMode::Direct`] heads for each setpoint at once.
//! - Each pose axis follows the reference under its velocity and acceleration limits ([`AxisTracker`]); actuator
//!   speed and acceleration limits scale the whole pose step down when the mechanism needs it.
//! - IK takes the previous actuators (multi-turn carriages); a pose that fails IK or a check on the way is not
//!   commanded: the platform holds.
//! - No valid setpoint for the stream timeout: every axis brakes at its acceleration limit, and the stream resumes
//!   only when [`Pipeline::start`] is called again (an explicit command).

use crate::kinematics::{Actuators, AxisKind, Check, KinematicsError, Mechanism, MultiTurn, Pose};
use crate::real::{wrap_once, wrap_pi};
use crate::Real;

use super::envelope::{self, EnvelopeMargins};
use super::limits::{AxisTracker, MotionLimits};
use super::setpoint::{Accepted, LimitCounters, LimitReport, RejectCounters, RejectReason, Setpoint};
use super::steps::StepConverter;

/// Ticks a pipeline backs off the edge of the workspace before its trackers try again.
const BACK_OFF_TICKS: u16 = 200;

/// A pose that passed every check, with its actuators.
type Solved = (Pose<f32>, Actuators<f32>);

/// How the reference moves toward a new setpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FollowMode {
    /// Linearly over the setpoint's own interval: a smooth path, one interval behind the source.
    Interpolate,
    /// At once: the trackers head for the newest setpoint under the limits (no interval of delay; the path of a
    /// slow source is followed in steps).
    Direct,
}

/// Pipeline settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PipelineConfig {
    /// Control period (us); 1,000 for the default 1 kHz.
    pub tick_us: u32,
    /// No valid setpoint for this long while streaming is a stream loss (us).
    pub stream_timeout_us: u32,
    /// The longest interval interpolated over; a longer gap is treated as this long (us).
    pub max_interval_us: u32,
    /// A setpoint further from the previous one than any axis travels at its velocity limit in this window is a
    /// gross jump (refused); anything nearer is followed at the limits (us).
    pub gross_jump_us: u32,
    /// Room that a limited setpoint leaves inside each check.
    pub margins: EnvelopeMargins,
    /// IK + check evaluations the envelope search may spend on one setpoint (resolution `2^-(n-1)` of the segment).
    pub limit_evaluations: u8,
    /// How the reference moves toward a new setpoint.
    pub follow: FollowMode,
    /// Velocity and acceleration limits.
    pub limits: MotionLimits,
}

impl Default for PipelineConfig {
    fn default() -> Self {
        Self {
            tick_us: 1_000,
            stream_timeout_us: 100_000,
            max_interval_us: 50_000,
            gross_jump_us: 500_000,
            margins: EnvelopeMargins::default(),
            limit_evaluations: 8,
            follow: FollowMode::Interpolate,
            limits: MotionLimits::TRAINER_MODEL,
        }
    }
}

/// Something the supervisor must hear about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PipelineEvent {
    /// No valid setpoint within the timeout: braking to rest.
    StreamLost,
    /// The stopping ramp reached rest.
    AtRest,
    /// While braking, the path left the workspace: the platform was held where it was.
    MotionFault,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Hold,
    Streaming,
    Stopping,
    /// A trusted move of the controller's own (to the home pose after homing): no stream timeout.
    Moving,
}

/// The motion pipeline of one mechanism, in f32 (what the MCU runs).
#[derive(Debug, Clone)]
pub struct Pipeline<M: Mechanism<f32>> {
    mechanism: M,
    /// Where the slow checks were last evaluated (see [`Mechanism::inverse_guarded`]).
    guard: M::Guard,
    axes: [AxisKind; 6],
    config: PipelineConfig,
    converter: StepConverter,
    mode: Mode,
    /// Commanded pose (yaw kept within a turn) and its per-axis trackers.
    pose: Pose<f32>,
    trackers: [AxisTracker; 6],
    /// Ticks left backing off the edge of the workspace toward its middle (see `along_edge`).
    backing_off: u16,
    /// The middle of the workspace (the pose the pipeline was made at: the home pose).
    centre: Pose<f32>,
    /// The trackers' speeds at the start of this tick (what the pose moved at in the last one).
    velocity_before: [f32; 6],
    /// Actuators of the commanded pose and their speeds.
    actuators: MultiTurn<f32>,
    actuator_velocity: [f32; 6],
    /// Interpolation segment: from, to, length and progress in ticks.
    from: Pose<f32>,
    to: Pose<f32>,
    segment_ticks: u32,
    segment_done: u32,
    /// Sequence number, time and pose (as sent, unlimited) of the last accepted setpoint.
    last: Option<(u32, u64, Pose<f32>)>,
    since_setpoint_us: u32,
    rejected: RejectCounters,
    limited: LimitCounters,
    applied: u32,
    held: u32,
}

#[inline]
fn delta(axis: usize, to: f32, from: f32) -> f32 {
    if axis == 5 {
        wrap_pi(to - from)
    } else {
        to - from
    }
}

impl<M: Mechanism<f32>> Pipeline<M> {
    /// A pipeline holding `pose`, which must be reachable (it is where homing left the platform).
    pub fn new(
        mechanism: M,
        config: PipelineConfig,
        converter: StepConverter,
        pose: Pose<f32>,
    ) -> Result<Self, KinematicsError> {
        let q = mechanism.inverse(&pose)?;
        let axes = mechanism.axes();
        Ok(Self {
            mechanism,
            guard: M::Guard::default(),
            axes,
            config,
            converter,
            mode: Mode::Hold,
            pose,
            trackers: [AxisTracker::default(); 6],
            velocity_before: [0.0; 6],
            backing_off: 0,
            centre: pose,
            actuators: MultiTurn::new(q),
            actuator_velocity: [0.0; 6],
            from: pose,
            to: pose,
            segment_ticks: 1,
            segment_done: 1,
            last: None,
            since_setpoint_us: 0,
            rejected: RejectCounters::default(),
            limited: LimitCounters::default(),
            applied: 0,
            held: 0,
        })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }

    /// The step converter (scales and homing offsets).
    pub fn converter(&self) -> &StepConverter {
        &self.converter
    }

    /// The step converter, to set homing offsets.
    pub fn converter_mut(&mut self) -> &mut StepConverter {
        &mut self.converter
    }

    /// The commanded pose.
    pub fn pose(&self) -> Pose<f32> {
        self.pose
    }

    /// The target the reference heads for: the last accepted setpoint as limited (yaw within a turn).
    pub fn target(&self) -> Pose<f32> {
        self.to
    }

    /// Actuator positions of the commanded pose.
    pub fn actuators(&self) -> &MultiTurn<f32> {
        &self.actuators
    }

    /// Motor step targets of the commanded pose.
    pub fn steps(&self) -> [i64; 6] {
        self.converter.to_steps(&self.actuators)
    }

    /// Rejected setpoints per reason.
    pub fn rejected(&self) -> &RejectCounters {
        &self.rejected
    }

    /// Setpoints limited into the envelope.
    pub fn limited(&self) -> &LimitCounters {
        &self.limited
    }

    /// Accepted setpoints (limited ones included).
    pub fn applied(&self) -> u32 {
        self.applied
    }

    /// Ticks on which the path failed IK or a check and the platform held.
    pub fn held(&self) -> u32 {
        self.held
    }

    /// The configuration.
    pub fn config(&self) -> &PipelineConfig {
        &self.config
    }

    /// Replaces the configuration (the controller allows it only at rest).
    pub fn set_config(&mut self, config: PipelineConfig) {
        self.config = config;
    }

    /// Whether every axis is at rest.
    pub fn at_rest(&self) -> bool {
        self.trackers.iter().all(|t| t.velocity == 0.0)
    }

    /// Restarts at a known pose with zero speed (after homing). The pose must be reachable.
    pub fn reset(&mut self, pose: Pose<f32>) -> Result<(), KinematicsError> {
        let q = self.mechanism.inverse(&pose)?;
        self.actuators = MultiTurn::new(q);
        self.pose = pose;
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
        self.from = pose;
        self.to = pose;
        self.segment_done = self.segment_ticks;
        self.last = None;
        self.mode = Mode::Hold;
        Ok(())
    }

    /// Starts taking setpoints (explicit command), from where the platform is.
    pub fn start(&mut self) {
        self.mode = Mode::Streaming;
        self.from = self.pose;
        self.to = self.pose;
        self.segment_done = self.segment_ticks;
        self.last = None;
        self.since_setpoint_us = 0;
    }

    /// Brakes to rest at the acceleration limits.
    pub fn stop(&mut self) {
        if self.mode == Mode::Streaming {
            self.mode = Mode::Stopping;
        }
    }

    /// Holds immediately (faults: the drivers are disabled anyway).
    pub fn halt(&mut self) {
        self.mode = Mode::Hold;
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
        self.from = self.pose;
        self.to = self.pose;
    }

    /// Moves to `pose` on a straight line under the limits (the controller's own move, e.g. to the home pose after
    /// homing). The pose must pass every check; [`PipelineEvent::AtRest`] follows when it is reached.
    pub fn move_to(&mut self, pose: Pose<f32>) -> Result<(), RejectReason> {
        let pose = pose.validated().map_err(|_| RejectReason::NonFinite)?;
        if self.solve(&pose).is_none() {
            return Err(RejectReason::Unreachable);
        }
        // Long enough that no axis needs more than half its velocity limit.
        let (a, b) = (self.pose.to_array(), pose.to_array());
        let mut seconds = 0.0f32;
        for i in 0..6 {
            seconds = seconds.max(libm::fabsf(delta(i, b[i], a[i])) / (0.5 * self.config.limits.pose_velocity[i]));
        }
        self.from = self.pose;
        self.to = Pose {
            gamma: wrap_pi(pose.gamma),
            ..pose
        };
        self.segment_ticks = ((seconds * 1e6) as u32 / self.config.tick_us.max(1)).max(1);
        self.segment_done = 0;
        self.mode = Mode::Moving;
        Ok(())
    }

    /// Checks and takes a setpoint, limited into the envelope where needed; a refused one changes nothing but its
    /// counter.
    pub fn submit(&mut self, sp: &Setpoint) -> Result<Accepted, RejectReason> {
        let interval_us = match self.validate(sp) {
            Ok(interval) => interval,
            Err(reason) => {
                self.rejected.count(reason);
                return Err(reason);
            }
        };
        let config = &self.config;
        let limited = envelope::limit(
            &self.mechanism,
            &self.centre,
            &sp.pose,
            &config.margins,
            config.limit_evaluations,
        );
        let accepted = match limited.bound_by {
            None => Accepted::Applied,
            Some(check) => {
                let (translation, rotation) = envelope::correction(&sp.pose, &limited.pose);
                let report = LimitReport {
                    check,
                    translation,
                    rotation,
                };
                self.limited.count(&report);
                Accepted::Limited(report)
            }
        };
        let ticks = match config.follow {
            FollowMode::Interpolate => (interval_us / config.tick_us.max(1)).max(1),
            FollowMode::Direct => 1,
        };
        self.from = self.reference();
        self.to = Pose {
            gamma: wrap_pi(limited.pose.gamma),
            ..limited.pose
        };
        self.segment_ticks = ticks;
        self.segment_done = 0;
        self.last = Some((sp.seq, sp.time_us, sp.pose));
        self.since_setpoint_us = 0;
        self.applied = self.applied.saturating_add(1);
        Ok(accepted)
    }

    /// Refuses garbage; returns the interval to interpolate over (us).
    fn validate(&self, sp: &Setpoint) -> Result<u32, RejectReason> {
        if self.mode != Mode::Streaming {
            return Err(RejectReason::NotStreaming);
        }
        let pose = sp.pose.validated().map_err(|_| RejectReason::NonFinite)?;
        let (from, interval) = match self.last {
            Some((seq, time, last_pose)) => {
                // Sequence numbers wrap: newer means a forward distance of less than half the range.
                let ahead = sp.seq.wrapping_sub(seq);
                if ahead == 0 || ahead > u32::MAX / 2 || sp.time_us <= time {
                    return Err(RejectReason::Stale);
                }
                let dt = (sp.time_us - time).min(u64::from(self.config.max_interval_us)) as u32;
                (last_pose, dt)
            }
            // The first setpoint of a stream starts from the commanded pose, over the longest interval.
            None => (self.pose, self.config.max_interval_us),
        };
        let window = self.config.gross_jump_us as f32 * 1e-6;
        let (target, from) = (pose.to_array(), from.to_array());
        let jump = (0..6).any(|i| {
            let d = libm::fabsf(delta(i, target[i], from[i]));
            // NaN compares as nothing: a jump.
            !matches!(
                d.partial_cmp(&(self.config.limits.pose_velocity[i] * window)),
                Some(core::cmp::Ordering::Less | core::cmp::Ordering::Equal)
            )
        });
        if jump {
            let outside = match self.mechanism.inverse_checked(&pose) {
                Ok((_, report)) => report.first_failure(),
                Err(_) => Some(Check::Reach),
            };
            return Err(RejectReason::GrossJump { outside });
        }
        Ok(interval.max(self.config.tick_us))
    }

    /// Where the interpolated reference is now.
    fn reference(&self) -> Pose<f32> {
        if self.segment_done >= self.segment_ticks {
            return self.to;
        }
        let f = self.segment_done as f32 / self.segment_ticks as f32;
        let (a, b) = (self.from.to_array(), self.to.to_array());
        Pose::from_array(core::array::from_fn(|i| {
            let v = a[i] + delta(i, b[i], a[i]) * f;
            if i == 5 {
                wrap_once(v)
            } else {
                v
            }
        }))
    }

    /// One control period: advances the commanded pose and returns the motor step targets for the end of the
    /// period, with an event for the supervisor when one happened.
    pub fn tick(&mut self) -> ([i64; 6], Option<PipelineEvent>) {
        let dt = self.config.tick_us as f32 * 1e-6;
        let mut event = None;
        if self.mode == Mode::Streaming {
            self.since_setpoint_us = self.since_setpoint_us.saturating_add(self.config.tick_us);
            if self.since_setpoint_us > self.config.stream_timeout_us {
                self.mode = Mode::Stopping;
                event = Some(PipelineEvent::StreamLost);
            }
        }
        let limits = self.config.limits;
        let mut step = [0.0f32; 6];
        self.velocity_before = self.trackers.map(|t| t.velocity);
        match self.mode {
            Mode::Hold => {}
            Mode::Streaming | Mode::Moving => {
                if self.segment_done < self.segment_ticks {
                    self.segment_done += 1;
                }
                let r = self.reference().to_array();
                let end = self.to.to_array();
                let p = self.pose.to_array();
                for i in 0..6 {
                    let error = delta(i, r[i], p[i]);
                    // Brake for where the reference stops (the setpoint), not for where it is now: a reference
                    // that stops at the end of its segment is then never passed.
                    let to_end = delta(i, end[i], p[i]);
                    // Ahead of the moving reference but short of the setpoint (braking is limited): wait for the
                    // reference rather than back up, so a monotone stream gives a monotone motion.
                    let (error, stop_distance) = if to_end * error >= 0.0 {
                        (error, to_end)
                    } else {
                        (0.0, to_end)
                    };
                    let v = self.trackers[i].step(
                        error,
                        stop_distance,
                        dt,
                        limits.pose_velocity[i],
                        limits.pose_acceleration[i],
                    );
                    step[i] = v * dt;
                }
            }
            Mode::Stopping => {
                for ((s, t), a) in step.iter_mut().zip(&mut self.trackers).zip(limits.pose_acceleration) {
                    *s = t.brake(dt, a) * dt;
                }
            }
        }
        if step.iter().any(|s| *s != 0.0) && !self.advance(&step, dt) {
            if matches!(self.mode, Mode::Stopping | Mode::Moving) {
                event = Some(PipelineEvent::MotionFault);
            }
            self.halt_in_place();
        }
        let arrived = self.mode == Mode::Moving && self.segment_done >= self.segment_ticks && self.settled(dt);
        if arrived {
            self.trackers = [AxisTracker::default(); 6];
        }
        if (self.mode == Mode::Stopping || arrived) && self.at_rest() && event.is_none() {
            self.mode = Mode::Hold;
            event = Some(PipelineEvent::AtRest);
        }
        (self.steps(), event)
    }

    /// Moves the commanded pose by `step`, scaled down if an actuator would exceed its limits. False when the new
    /// pose fails IK or a check (nothing moved).
    fn advance(&mut self, step: &[f32; 6], dt: f32) -> bool {
        let mut step = *step;
        // Backing off the edge: the trackers wait until the platform is well inside again.
        let tracker = if self.backing_off > 0 && self.mode != Mode::Stopping {
            self.backing_off -= 1;
            None
        } else {
            self.solve(&self.stepped(&step, 1.0))
        };
        let (full, q_full) = match tracker {
            Some(found) => found,
            None => {
                let Some((taken, found)) = self.along_edge(&step, dt) else {
                    return false;
                };
                step = taken;
                for (t, s) in self.trackers.iter_mut().zip(step) {
                    t.velocity = s / dt;
                }
                self.limited.edge_ticks = self.limited.edge_ticks.saturating_add(1);
                found
            }
        };
        // Scale the step down until every actuator stays inside its speed and acceleration limits. Actuator motion
        // is nearly linear in the step over one tick, so one scaling nearly always suffices; a second catches the
        // curvature of a long step.
        let (mut pose, mut q) = (full, q_full);
        for _ in 0..3 {
            let scale = self.actuator_scale(&q, dt);
            if scale >= 1.0 {
                break;
            }
            step = step.map(|s| s * scale);
            let mut taken = scale;
            // On the edge (a margin within rounding of zero) a shorter step in the same direction may fail where
            // the longer one passed: take the part of it that stays inside.
            let scaled = match self.solve(&self.stepped(&step, 1.0)) {
                Some(found) => found,
                None => {
                    let Some((fraction, part, found)) = self.inside_part(&step) else {
                        return false;
                    };
                    step = part;
                    taken *= fraction;
                    found
                }
            };
            for t in &mut self.trackers {
                t.velocity *= taken;
            }
            self.limited.actuator_ticks = self.limited.actuator_ticks.saturating_add(1);
            (pose, q) = scaled;
        }
        let mut next = self.actuators;
        next.follow(&q, &self.axes);
        for i in 0..6 {
            self.actuator_velocity[i] = next.delta_from(&self.actuators, i) / dt;
        }
        self.actuators = next;
        self.pose = pose;
        true
    }

    /// The largest fraction of the move to `q` that keeps every actuator inside its speed and acceleration limits.
    fn actuator_scale(&self, q: &Actuators<f32>, dt: f32) -> f32 {
        let limits = &self.config.limits;
        let mut scale = 1.0f32;
        for i in 0..6 {
            let d = self.actuator_delta(i, q);
            if d == 0.0 {
                continue;
            }
            let v_prev = self.actuator_velocity[i];
            let hi = limits.actuator_velocity[i].min_(v_prev + limits.actuator_acceleration[i] * dt) * dt;
            let lo = (-limits.actuator_velocity[i]).max_(v_prev - limits.actuator_acceleration[i] * dt) * dt;
            let bound = if d > 0.0 { hi / d } else { lo / d };
            scale = scale.min_(bound.max_(0.0));
        }
        scale
    }

    /// The commanded pose moved by `s` times `step`.
    fn stepped(&self, step: &[f32; 6], s: f32) -> Pose<f32> {
        let p = self.pose.to_array();
        Pose::from_array(core::array::from_fn(|i| {
            let v = p[i] + step[i] * s;
            if i == 5 {
                wrap_once(v)
            } else {
                v
            }
        }))
    }

    /// The trackers' path (per axis, not on the straight line between two targets) met the edge of the
    /// workspace. Staying inside comes first. Grazing it (at least half of the step stays inside), take that part.
    /// Otherwise head on a straight line for the target (which passed every check with a margin); failing that,
    /// back off toward the middle of the workspace (furthest from every edge) for [`BACK_OFF_TICKS`], with the yaw
    /// turning toward the target's, or at this yaw: the workspace is not convex and turns with the yaw, and
    /// trackers let loose at once would push straight back out. A sliver of a step is no way out: each way must
    /// keep at least half its step inside, and the longest part found is the last resort. Each step is at the
    /// speed the limits allow from here. Returns the step taken, or `None` when no part of any of them stays inside.
    fn along_edge(&mut self, step: &[f32; 6], dt: f32) -> Option<([f32; 6], Solved)> {
        let mut best = self.inside_part(step);
        let grazing = best.as_ref().is_some_and(|(fraction, ..)| *fraction >= 0.5);
        if self.mode == Mode::Stopping || (self.backing_off == 0 && grazing) {
            return best.map(|(_, taken, found)| (taken, found));
        }
        let middle = |gamma| Pose { gamma, ..self.centre };
        let target = (self.backing_off == 0).then_some(self.to);
        let goals = [target, Some(middle(self.to.gamma)), Some(middle(self.pose.gamma))];
        for goal in goals.into_iter().flatten() {
            if goal != self.to && self.backing_off == 0 {
                // Heading for the target failed: back off the edge toward the middle for a while, so that the
                // trackers do not push straight back out (a stall on the edge).
                self.backing_off = BACK_OFF_TICKS;
            }
            let line = self.line_step(&goal, dt);
            if let Some(found) = self.solve(&self.stepped(&line, 1.0)) {
                return Some((line, found));
            }
            // A sliver of a step is no way out: try the next way, and keep the longest part found for the last.
            match self.inside_part(&line) {
                Some((fraction, taken, found)) if fraction >= 0.5 => return Some((taken, found)),
                Some(part) if best.as_ref().is_none_or(|b| part.0 > b.0) => best = Some(part),
                _ => {}
            }
        }
        best.map(|(_, taken, found)| (taken, found))
    }

    /// A step on the straight line toward `goal`, at the largest speed at which no axis exceeds its velocity
    /// limit or gains more than its acceleration allows, and that does not pass the goal within the tick.
    fn line_step(&self, goal: &Pose<f32>, dt: f32) -> [f32; 6] {
        let limits = &self.config.limits;
        let (p, t) = (self.pose.to_array(), goal.to_array());
        let error: [f32; 6] = core::array::from_fn(|i| delta(i, t[i], p[i]));
        let mut k = 1.0 / dt;
        for (i, e) in error.iter().enumerate() {
            let e = libm::fabsf(*e);
            if e > 0.0 {
                let gain = limits.pose_acceleration[i] * dt;
                let v = limits.pose_velocity[i].min_(libm::fabsf(self.velocity_before[i]) + gain);
                k = k.min_(v / e);
            }
        }
        error.map(|e| e * k * dt)
    }

    /// The largest part of a step (bisection, 6 evaluations: to 1/64) whose pose passes every check.
    fn inside_part(&mut self, step: &[f32; 6]) -> Option<(f32, [f32; 6], Solved)> {
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        let mut best = None;
        for _ in 0..6 {
            let mid = 0.5 * (lo + hi);
            match self.solve(&self.stepped(step, mid)) {
                Some(found) => {
                    lo = mid;
                    best = Some((mid, step.map(|s| s * mid), found));
                }
                None => hi = mid,
            }
        }
        best
    }

    /// Every axis within a micrometre (microradian) of the reference and slow enough to stop in one tick.
    fn settled(&self, dt: f32) -> bool {
        let (p, r) = (self.pose.to_array(), self.reference().to_array());
        (0..6).all(|i| {
            libm::fabsf(delta(i, r[i], p[i])) <= 1e-6
                && libm::fabsf(self.trackers[i].velocity) <= self.config.limits.pose_acceleration[i] * dt
        })
    }

    fn actuator_delta(&self, i: usize, q: &Actuators<f32>) -> f32 {
        let d = q.0[i] - self.actuators.within.0[i];
        if self.axes[i] == AxisKind::Ring {
            wrap_pi(d)
        } else {
            d
        }
    }

    /// IK and every check of a pose near the commanded one (the slow checks proved where they can be).
    fn solve(&mut self, pose: &Pose<f32>) -> Option<Solved> {
        let (q, report) = self.mechanism.inverse_guarded(pose, &mut self.guard).ok()?;
        report.all_pass().then_some((*pose, q))
    }

    fn halt_in_place(&mut self) {
        self.held = self.held.saturating_add(1);
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
    }
}
