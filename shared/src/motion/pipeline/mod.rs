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
//!
//! One [`Pipeline`] (its state and its public face here), its work in one file per job, each an `impl Pipeline`
//! block but the segment, which is a type of its own:
//! - `config`: [`PipelineConfig`] and [`FollowMode`].
//! - `acceptance`: what a setpoint (or a move of the controller's own) must pass to be taken, and taking it.
//! - `segment`: the reference's straight line from where it was to the newest target.
//! - `tick`: one control period, the mode's step through the rest, and the supervisor's events.
//! - `tracking`: the per-axis trackers toward the reference and the actuator limits on each step.
//! - `edge`: where the trackers' path meets the edge of the workspace.
//! - `workspace`: IK and every check of a pose on the way, and the part of a step that stays inside.

mod acceptance;
mod config;
mod edge;
#[cfg(test)]
mod fixture;
mod segment;
mod tick;
mod tracking;
mod workspace;

use crate::kinematics::{Actuators, AxisKind, KinematicsError, Mechanism, MultiTurn, Pose};
use crate::real::wrap_pi;

use super::limits::AxisTracker;
use super::setpoint::{LimitCounters, RejectCounters};
use super::spare::{SpareAxes, SPARE_AXES};
use super::steps::StepConverter;

pub use config::{FollowMode, PipelineConfig};
use segment::Segment;
pub use tick::HOLD_UP_LIMIT_US;

/// A pose that passed every check, with its actuators.
type Solved = (Pose<f32>, Actuators<f32>);

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
    segment: Segment,
    /// Sequence number, time and pose (as sent, unlimited) of the last accepted setpoint.
    last: Option<(u32, u64, Pose<f32>)>,
    /// Ticked time since the last accepted setpoint (or the stream's start): the stream timeout's measure.
    since_setpoint_us: u32,
    /// Passed time since then ([`Pipeline::pass`]): bounded by [`HOLD_UP_LIMIT_US`] alone.
    passed_us: u32,
    rejected: RejectCounters,
    limited: LimitCounters,
    applied: u32,
    held: u32,
    /// The spare axes 7 and 8: outside the mechanism, stopped and held with it.
    spare: SpareAxes,
}

/// `to - from` on one pose axis; the yaw (axis 5) the short way round, so that no path turns the long way.
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
            segment: Segment::at(pose),
            last: None,
            since_setpoint_us: 0,
            passed_us: 0,
            rejected: RejectCounters::default(),
            limited: LimitCounters::default(),
            applied: 0,
            held: 0,
            spare: SpareAxes::new(config.spare),
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
        self.segment.to
    }

    /// Actuator positions of the commanded pose.
    pub fn actuators(&self) -> &MultiTurn<f32> {
        &self.actuators
    }

    /// Motor step targets of the commanded pose.
    pub fn steps(&self) -> [i64; 6] {
        self.converter.to_steps(&self.actuators)
    }

    /// The spare axes.
    pub fn spare(&self) -> &SpareAxes {
        &self.spare
    }

    /// The spare axes are at `steps` (their counted steps, while they do not follow a stream), at rest.
    pub fn spare_at_steps(&mut self, steps: [i64; SPARE_AXES]) {
        self.spare.at_steps(steps);
    }

    /// Motor step targets of the spare axes' commanded positions.
    pub fn spare_steps(&self) -> [i64; SPARE_AXES] {
        self.spare.steps()
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

    /// Replaces the configuration (the controller allows it only at rest). The spare axes keep their positions.
    pub fn set_config(&mut self, config: PipelineConfig) {
        self.config = config;
        self.spare.configure(config.spare);
    }

    /// Whether every axis, the spare ones included, is at rest.
    pub fn at_rest(&self) -> bool {
        self.trackers.iter().all(|t| t.velocity == 0.0) && self.spare.at_rest()
    }

    /// Restarts at a known pose with zero speed (after homing). The pose must be reachable.
    pub fn reset(&mut self, pose: Pose<f32>) -> Result<(), KinematicsError> {
        let q = self.mechanism.inverse(&pose)?;
        self.actuators = MultiTurn::new(q);
        self.pose = pose;
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
        self.segment.rest_at(pose);
        self.spare.hold();
        self.last = None;
        self.mode = Mode::Hold;
        Ok(())
    }

    /// Sets the whole turns of the ring axes after a [`reset`](Self::reset), which starts at turn zero: a machine
    /// whose carriages went round since homing resumes at its counted steps.
    pub fn set_turns(&mut self, turns: [i32; 6]) {
        self.actuators.turns = turns;
    }

    /// Starts taking setpoints (explicit command), from where the platform is.
    pub fn start(&mut self) {
        self.mode = Mode::Streaming;
        self.segment.rest_at(self.pose);
        self.spare.hold();
        self.last = None;
        self.since_setpoint_us = 0;
        self.passed_us = 0;
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
        self.segment.collapse_to(self.pose);
        self.spare.hold();
    }
}
