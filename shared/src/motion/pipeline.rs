//! One control tick: the newest valid setpoint, interpolated and limited, through IK and the workspace checks to
//! motor step targets for the end of the next period.
//!
//! - Setpoints are validated when they arrive: finite, newer than the last, reachable, inside every workspace check,
//!   and not a jump faster than the velocity limits allow over the time since the previous one. A rejected setpoint
//!   moves nothing; its reason is counted and returned.
//! - Accepted setpoints are interpolated linearly over their own interval (60 Hz simulator output into a 1 kHz loop):
//!   the reference moves on the straight line from where it is to the new setpoint, a convex combination that never
//!   passes it. This delays motion by one setpoint interval, the price of a jitter-free path.
//! - Each pose axis follows the reference under its velocity and acceleration limits ([`AxisTracker`]); actuator
//!   speed and acceleration limits scale the whole pose step down when the mechanism needs it.
//! - IK takes the previous actuators (multi-turn carriages); a pose that fails IK or a check on the way is not
//!   commanded: the platform holds.
//! - No valid setpoint for the stream timeout: every axis brakes at its acceleration limit, and the stream resumes
//!   only when [`Pipeline::start`] is called again (an explicit command).

use crate::kinematics::{Actuators, AxisKind, Check, KinematicsError, Mechanism, MultiTurn, Pose};
use crate::real::{wrap_once, wrap_pi};

use super::limits::{AxisTracker, MotionLimits};
use super::steps::StepConverter;

/// A pose setpoint from the host.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Setpoint {
    /// Sequence number, increasing by one per setpoint (wrapping).
    pub seq: u32,
    /// Host time stamp (us); the interval between setpoints is taken from it.
    pub time_us: u64,
    /// The pose.
    pub pose: Pose<f32>,
}

/// Why a setpoint was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum RejectReason {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// No IK solution.
    Unreachable,
    /// A workspace check fails.
    Workspace(Check),
    /// Reaching it would take more than the velocity limit (a jump).
    TooFast,
    /// Its sequence number or time stamp is not newer than the last accepted one.
    Stale,
    /// The controller is not streaming (not started, stopping, or after a stream loss).
    NotStreaming,
}

/// How many setpoints were rejected, per reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct RejectCounters {
    /// [`RejectReason::NonFinite`].
    pub non_finite: u32,
    /// [`RejectReason::Unreachable`].
    pub unreachable: u32,
    /// [`RejectReason::Workspace`], per check in the order of [`Check::ALL`].
    pub workspace: [u32; 6],
    /// [`RejectReason::TooFast`].
    pub too_fast: u32,
    /// [`RejectReason::Stale`].
    pub stale: u32,
    /// [`RejectReason::NotStreaming`].
    pub not_streaming: u32,
}

impl RejectCounters {
    fn count(&mut self, reason: RejectReason) {
        let c = match reason {
            RejectReason::NonFinite => &mut self.non_finite,
            RejectReason::Unreachable => &mut self.unreachable,
            RejectReason::Workspace(check) => {
                let i = Check::ALL.iter().position(|c| *c == check).unwrap_or(0);
                &mut self.workspace[i]
            }
            RejectReason::TooFast => &mut self.too_fast,
            RejectReason::Stale => &mut self.stale,
            RejectReason::NotStreaming => &mut self.not_streaming,
        };
        *c = c.saturating_add(1);
    }

    /// Total of all reasons.
    pub fn total(&self) -> u32 {
        let ws: u32 = self.workspace.iter().fold(0u32, |a, b| a.saturating_add(*b));
        [
            self.non_finite,
            self.unreachable,
            ws,
            self.too_fast,
            self.stale,
            self.not_streaming,
        ]
        .iter()
        .fold(0u32, |a, b| a.saturating_add(*b))
    }
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
    /// A setpoint may ask for up to `1 + jump_tolerance` times the velocity limit over its interval (jitter room).
    pub jump_tolerance: f32,
    /// Velocity and acceleration limits.
    pub limits: MotionLimits,
}

impl Default for PipelineConfig {
    fn default() -> Self {
        Self {
            tick_us: 1_000,
            stream_timeout_us: 100_000,
            max_interval_us: 50_000,
            jump_tolerance: 0.5,
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
    axes: [AxisKind; 6],
    config: PipelineConfig,
    converter: StepConverter,
    mode: Mode,
    /// Commanded pose (yaw kept within a turn) and its per-axis trackers.
    pose: Pose<f32>,
    trackers: [AxisTracker; 6],
    /// Actuators of the commanded pose and their speeds.
    actuators: MultiTurn<f32>,
    actuator_velocity: [f32; 6],
    /// Interpolation segment: from, to, length and progress in ticks.
    from: Pose<f32>,
    to: Pose<f32>,
    segment_ticks: u32,
    segment_done: u32,
    last: Option<(u32, u64, Pose<f32>)>,
    since_setpoint_us: u32,
    rejected: RejectCounters,
    applied: u32,
    held: u32,
}

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
            axes,
            config,
            converter,
            mode: Mode::Hold,
            pose,
            trackers: [AxisTracker::default(); 6],
            actuators: MultiTurn::new(q),
            actuator_velocity: [0.0; 6],
            from: pose,
            to: pose,
            segment_ticks: 1,
            segment_done: 1,
            last: None,
            since_setpoint_us: 0,
            rejected: RejectCounters::default(),
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

    /// Accepted setpoints.
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

    /// Validates and takes a setpoint; a rejected one changes nothing but its counter.
    pub fn submit(&mut self, sp: &Setpoint) -> Result<(), RejectReason> {
        let verdict = self.validate(sp);
        match verdict {
            Ok(interval_us) => {
                let ticks = (interval_us / self.config.tick_us.max(1)).max(1);
                self.from = self.reference();
                self.to = Pose {
                    gamma: wrap_pi(sp.pose.gamma),
                    ..sp.pose
                };
                self.segment_ticks = ticks;
                self.segment_done = 0;
                self.last = Some((sp.seq, sp.time_us, self.to));
                self.since_setpoint_us = 0;
                self.applied = self.applied.saturating_add(1);
                Ok(())
            }
            Err(reason) => {
                self.rejected.count(reason);
                Err(reason)
            }
        }
    }

    /// Returns the interval to interpolate over (us).
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
        let interval = interval.max(self.config.tick_us);
        let allowed = (1.0 + self.config.jump_tolerance) * interval as f32 * 1e-6;
        let target = pose.to_array();
        let from = from.to_array();
        for i in 0..6 {
            if libm::fabsf(delta(i, target[i], from[i])) > self.config.limits.pose_velocity[i] * allowed {
                return Err(RejectReason::TooFast);
            }
        }
        let (_, report) = self.mechanism.inverse_checked(&pose).map_err(|e| match e {
            KinematicsError::NonFinite => RejectReason::NonFinite,
            _ => RejectReason::Unreachable,
        })?;
        if let Some(check) = report.first_failure() {
            return Err(RejectReason::Workspace(check));
        }
        Ok(interval)
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
        let p = self.pose.to_array();
        let candidate = |s: f32| {
            Pose::from_array(core::array::from_fn(|i| {
                if i == 5 {
                    wrap_once(p[i] + step[i] * s)
                } else {
                    p[i] + step[i] * s
                }
            }))
        };
        let Some((full, q_full)) = self.solve(&candidate(1.0)) else {
            return false;
        };
        let limits = self.config.limits;
        // Largest fraction of the step that keeps every actuator inside its speed and acceleration limits
        // (actuator motion is linear in the step over one tick).
        let mut scale = 1.0f32;
        for i in 0..6 {
            let d = self.actuator_delta(i, &q_full);
            if d == 0.0 {
                continue;
            }
            let v_prev = self.actuator_velocity[i];
            let hi = limits.actuator_velocity[i].min(v_prev + limits.actuator_acceleration[i] * dt) * dt;
            let lo = (-limits.actuator_velocity[i]).max(v_prev - limits.actuator_acceleration[i] * dt) * dt;
            let bound = if d > 0.0 { hi / d } else { lo / d };
            scale = scale.min(bound.max(0.0));
        }
        let (pose, q) = if scale < 1.0 {
            let Some(scaled) = self.solve(&candidate(scale)) else {
                return false;
            };
            for t in &mut self.trackers {
                t.velocity *= scale;
            }
            scaled
        } else {
            (full, q_full)
        };
        let mut next = self.actuators;
        next.follow(&q, &self.axes);
        for i in 0..6 {
            self.actuator_velocity[i] = (next.total(i) - self.actuators.total(i)) as f32 / dt;
        }
        self.actuators = next;
        self.pose = pose;
        true
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

    fn solve(&self, pose: &Pose<f32>) -> Option<(Pose<f32>, Actuators<f32>)> {
        let (q, report) = self.mechanism.inverse_checked(pose).ok()?;
        report.all_pass().then_some((*pose, q))
    }

    fn halt_in_place(&mut self) {
        self.held = self.held.saturating_add(1);
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
    }
}
