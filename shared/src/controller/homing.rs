//! Homing and jogging: the axes moved one at a time by the homing sequencer or a commissioning jog, and the
//! platform's pose found again from the axes' positions afterwards.

use super::Controller;
use crate::kinematics::{KinematicsError, Mechanism, MultiTurn, Pose};
use crate::motion::PipelineEvent;
use crate::safety::{Event, HomingSequencer, HomingStep};

/// Where homing is: one phase at a time, so that no two can be under way together.
// The sequencer holds its plan (about a hundred bytes); the controller holds one `Homing` in place and never moves
// it, and a board has no heap to box it.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Homing {
    /// Not homing.
    Idle,
    /// Re-homing a homed machine: the platform on its way, through the pipeline, to the parking pose near the
    /// switches, so that every search is as short as the first one was.
    Parking,
    /// The sequencer searching the switches axis by axis; `carry` is the fraction of a step (in step-microseconds)
    /// carried between ticks so that the average rate is exact.
    Searching { sequencer: HomingSequencer, carry: i64 },
    /// Every switch found: the platform on its way to the home pose.
    Returning,
}

impl Homing {
    /// The axis whose switch is being searched.
    pub(super) fn axis(&self) -> Option<u8> {
        match self {
            Homing::Searching { sequencer, .. } => sequencer.current_axis(),
            _ => None,
        }
    }
}

impl Controller {
    /// One tick of a jog: the axis a step further, the others where they are; done at the end of the last leg or
    /// when the axis's home switch closes, one tick later: the last leg's steps play in the period after the tick
    /// that planned them, and the next tick comes before that period ends (`motion::phase`), so ending the jog there
    /// would disable the drivers under its last steps.
    pub(super) fn jog_tick(&mut self, position: [i64; 6], tick_us: u32) -> [i64; 6] {
        let Some((jog, home_at_start)) = self.jog.as_mut() else {
            self.event(Event::JogDone);
            return position;
        };
        let a = jog.axis;
        let home_now = self.inputs.home & (1 << a) != 0;
        let next = if home_now && !*home_at_start {
            None
        } else {
            jog.next(position[a], tick_us)
        };
        match next {
            Some(p) => {
                let mut targets = position;
                targets[a] = p;
                targets
            }
            None if jog.settle() => position,
            None => {
                self.jog = None;
                position
            }
        }
    }

    /// After homing each axis's origin is known: step 0 is its value at the home pose, and its switch is at step
    /// `home_position`. Sets the converter's origins and finds the platform's pose at the axes' current positions
    /// by forward kinematics.
    pub(super) fn pose_after_homing(&mut self) -> Result<Pose<f32>, KinematicsError> {
        let mechanism = *self.pipeline.mechanism();
        let home = MultiTurn::new(mechanism.inverse(&self.home_pose)?);
        let converter = self.pipeline.converter_mut();
        for a in 0..6 {
            converter.set_home(a, &home, 0);
        }
        self.pose_at_steps(&self.scheduler.position())
    }

    /// Where re-homing starts: every axis two back-off distances before its switch (homed coordinates), found
    /// by forward kinematics.
    pub(super) fn parking_pose(&self) -> Result<Pose<f32>, KinematicsError> {
        let axes = &self.plan.config().axes;
        let steps = core::array::from_fn(|a| {
            let h = &axes[a];
            h.home_position - i64::from(h.toward) * 2 * i64::from(h.backoff_steps)
        });
        self.pose_at_steps(&steps)
    }

    /// Puts the pipeline where the counted steps say the axes are, whole carriage turns included, so that homing
    /// again after a power-down, a jog or a fault can park near the switches as a homed machine does: without it
    /// the search starts wherever the platform stopped (a turned ring, or linear actuators further from their
    /// switches than their search). False where the steps give no pose, or a pose whose steps are not the counted
    /// ones to within a quarter back-off (a far forward solution): homing then searches from where it is.
    pub(super) fn resume_from_steps(&mut self) -> bool {
        let position = self.scheduler.position();
        let mechanism = *self.pipeline.mechanism();
        let Ok(q_home) = mechanism.inverse(&self.home_pose) else {
            return false;
        };
        let axes = mechanism.axes();
        let totals = crate::motion::actuators_at_steps(&self.config.scales, &axes, &q_home, &position);
        let guess = crate::kinematics::start_from_home(&mechanism, &totals, &self.home_pose);
        let options = crate::kinematics::NewtonOptions {
            max_distance: crate::kinematics::FROM_HOME_DISTANCE as f32,
            ..Default::default()
        };
        let Ok(found) = mechanism.forward(&totals, &guess, &options) else {
            return false;
        };
        if self.pipeline.reset(found.pose).is_err() {
            return false;
        }
        let within = self.pipeline.actuators().within;
        let turns = core::array::from_fn(|a| match axes[a] {
            crate::kinematics::AxisKind::Ring => {
                libm::roundf((totals.0[a] - within.0[a]) / core::f32::consts::TAU) as i32
            }
            _ => 0,
        });
        self.pipeline.set_turns(turns);
        let steps = self.pipeline.converter().to_steps(self.pipeline.actuators());
        let homing = &self.plan.config().axes;
        (0..6).all(|a| (steps[a] - position[a]).abs() <= i64::from(homing[a].backoff_steps / 4))
    }

    /// The pose at motor step positions in homed coordinates (step 0 of each axis at the home pose).
    pub(super) fn pose_at_steps(&self, position: &[i64; 6]) -> Result<Pose<f32>, KinematicsError> {
        let mechanism = *self.pipeline.mechanism();
        let home = mechanism.inverse(&self.home_pose)?;
        let q = crate::motion::actuators_at_steps(&self.config.scales, &mechanism.axes(), &home, position);
        let options = crate::kinematics::NewtonOptions::default();
        Ok(mechanism.forward(&q, &self.home_pose, &options)?.pose)
    }

    pub(super) fn homing_tick(&mut self, position: [i64; 6], tick_us: u32) -> [i64; 6] {
        match self.homing {
            Homing::Idle => position,
            Homing::Parking | Homing::Returning => self.homing_move_tick(),
            Homing::Searching { .. } => self.search_tick(position, tick_us),
        }
    }

    /// A tick of the pipeline's move to the parking pose or back home; its end starts the search or ends homing.
    fn homing_move_tick(&mut self) -> [i64; 6] {
        let (targets, event) = self.pipeline.tick();
        match event {
            Some(PipelineEvent::AtRest) if self.homing == Homing::Parking => {
                self.homing = Homing::Searching {
                    sequencer: HomingSequencer::new(self.plan, &targets),
                    carry: 0,
                };
            }
            Some(PipelineEvent::AtRest) => {
                self.homing = Homing::Idle;
                self.event(Event::HomingDone);
            }
            Some(PipelineEvent::MotionFault) => self.event(Event::MotionFault),
            _ => {}
        }
        targets
    }

    /// A tick of the switch search: one axis moves at its rate until its switch, which sets its origin.
    fn search_tick(&mut self, position: [i64; 6], tick_us: u32) -> [i64; 6] {
        let Homing::Searching { sequencer, carry } = &mut self.homing else {
            return position;
        };
        match sequencer.update(&position, self.inputs.home) {
            HomingStep::Move { axis, rate } => {
                // Steps this period at `rate`, the fraction carried so that the average rate is exact.
                let total = i64::from(rate) * i64::from(tick_us) + *carry;
                let steps = total / 1_000_000;
                *carry = total % 1_000_000;
                let mut t = position;
                t[usize::from(axis % 6)] += steps;
                t
            }
            HomingStep::Homed { axis, .. } => {
                // The switch defines this axis's origin: here it is at step `home_position`.
                *carry = 0;
                let a = usize::from(axis % 6);
                let mut p = position;
                p[a] = self.plan.config().axes[a].home_position;
                self.scheduler.set_position(p);
                p
            }
            HomingStep::Done => {
                self.homing = Homing::Idle;
                let started = self
                    .pose_after_homing()
                    .ok()
                    .and_then(|pose| self.pipeline.reset(pose).ok());
                self.origins = started.is_some();
                if started.is_some() && self.pipeline.move_to(self.home_pose).is_ok() {
                    self.homing = Homing::Returning;
                } else {
                    self.event(Event::HomingFailed);
                }
                self.scheduler.position()
            }
            HomingStep::Failed(_) => {
                self.homing = Homing::Idle;
                self.event(Event::HomingFailed);
                position
            }
        }
    }
}
