//! One control period: the step the mode asks for, taken through the workspace and the limits, and what the
//! supervisor must hear about it.

use crate::kinematics::Mechanism;

use super::super::limits::AxisTracker;
use super::{Mode, Pipeline, PipelineEvent};

/// Longest a stream goes without a setpoint, hold-ups included ([`Pipeline::pass`]): longer than any hold-up a
/// device recovers from (a flash sector erase stalls a board about 2 s).
pub const HOLD_UP_LIMIT_US: u32 = 5_000_000;

impl<M: Mechanism<f32>> Pipeline<M> {
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
        self.velocity_before = self.trackers.map(|t| t.velocity);
        let step = match self.mode {
            Mode::Hold => [0.0f32; 6],
            Mode::Streaming | Mode::Moving => self.track(dt),
            Mode::Stopping => self.brake(dt),
        };
        if step.iter().any(|s| *s != 0.0) && !self.advance(&step, dt) {
            if matches!(self.mode, Mode::Stopping | Mode::Moving) {
                event = Some(PipelineEvent::MotionFault);
            }
            self.halt_in_place();
        }
        // The spare axes follow their own references (no IK, no workspace): braking with the platform, resting
        // when it holds.
        if self.spare.any() && self.mode != Mode::Hold {
            self.spare.tick(dt, self.mode == Mode::Stopping);
        }
        let arrived = self.mode == Mode::Moving && self.segment.finished() && self.settled(dt);
        if arrived {
            self.trackers = [AxisTracker::default(); 6];
        }
        if (self.mode == Mode::Stopping || arrived) && self.at_rest() && event.is_none() {
            self.mode = Mode::Hold;
            event = Some(PipelineEvent::AtRest);
        }
        (self.steps(), event)
    }

    /// A control period passed rather than ticked (`Controller::pass`: a hold-up of the control loop cost it, and
    /// the motors did not move in it): nothing moves. It does not count toward the stream timeout, which is for a
    /// host that is gone, not for a device that was held up; but a stream with no setpoint for
    /// [`HOLD_UP_LIMIT_US`] of periods, ticked and passed, is lost all the same, so that a control loop that stays
    /// behind (and passes every period) still ends a stream whose host has gone.
    pub fn pass(&mut self) -> Option<PipelineEvent> {
        if self.mode != Mode::Streaming {
            return None;
        }
        self.passed_us = self.passed_us.saturating_add(self.config.tick_us);
        if self.passed_us.saturating_add(self.since_setpoint_us) > HOLD_UP_LIMIT_US {
            self.mode = Mode::Stopping;
            return Some(PipelineEvent::StreamLost);
        }
        None
    }

    /// The path failed IK or a check: nothing moved, so nothing may keep a speed it did not have.
    fn halt_in_place(&mut self) {
        self.held = self.held.saturating_add(1);
        self.trackers = [AxisTracker::default(); 6];
        self.actuator_velocity = [0.0; 6];
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::fixture::{home_plus, streaming};
    use super::*;
    use crate::motion::setpoint::{RejectReason, Setpoint};

    #[test]
    fn a_lost_stream_brakes_to_rest_and_waits_for_a_new_start() {
        let mut p = streaming();
        let timeout_ticks = p.config().stream_timeout_us / p.config().tick_us;
        let sp = |seq: u32| Setpoint {
            seq,
            time_us: u64::from(seq) * 10_000,
            pose: home_plus(0, 0.002 * seq as f32),
            aux: [None; 2],
            spare: [None; 2],
        };
        p.submit(&sp(1)).unwrap();
        let mut events = [None; 2];
        for tick in 1..=1_000u32 {
            let (_, event) = p.tick();
            if let Some(e) = event {
                let k = usize::from(events[0].is_some());
                events[k] = Some((tick, e));
            }
        }
        assert_eq!(events[0], Some((timeout_ticks + 1, PipelineEvent::StreamLost)));
        assert!(matches!(events[1], Some((_, PipelineEvent::AtRest))), "{events:?}");
        assert!(p.at_rest());
        assert_eq!(
            p.submit(&sp(2)),
            Err(RejectReason::NotStreaming),
            "no resuming without a command"
        );
        p.start();
        assert!(p.submit(&sp(2)).is_ok());
    }

    /// Passed periods neither move nor count toward the stream timeout, so a hold-up longer than the timeout with a
    /// setpoint after it goes on; a stream with no setpoint for the hold-up limit, passed or ticked, is lost.
    #[test]
    fn passed_periods_are_bounded_by_the_hold_up_limit_not_the_timeout() {
        let mut p = streaming();
        let tick_us = p.config().tick_us;
        let timeout_ticks = p.config().stream_timeout_us / tick_us;
        let sp = |seq: u32| Setpoint {
            seq,
            time_us: u64::from(seq) * 10_000,
            pose: home_plus(0, 0.002),
            aux: [None; 2],
            spare: [None; 2],
        };
        p.submit(&sp(1)).unwrap();
        let steps = p.steps();
        for _ in 0..(10 * timeout_ticks) {
            assert_eq!(p.pass(), None);
        }
        assert_eq!(p.steps(), steps, "a pass moves nothing");
        // A setpoint after the hold-up: the stream goes on, both counts start again.
        p.submit(&sp(2)).unwrap();
        for _ in 0..timeout_ticks {
            assert_eq!(p.tick().1, None);
        }
        // A control loop that stays behind: passes alone end the stream at the limit.
        p.submit(&sp(3)).unwrap();
        let limit = HOLD_UP_LIMIT_US / tick_us;
        let lost = (1..=limit + 1).find(|_| p.pass().is_some());
        assert_eq!(lost, Some(limit + 1));
        assert_eq!(p.submit(&sp(4)), Err(RejectReason::NotStreaming));
        // Ticks and passes add up toward the limit; the ticks alone toward the timeout.
        p.start();
        p.submit(&sp(5)).unwrap();
        for _ in 0..timeout_ticks {
            assert_eq!(p.tick().1, None);
        }
        let lost = (1..=limit).find(|_| p.pass().is_some());
        assert_eq!(lost, Some(limit - timeout_ticks + 1));
    }

    #[test]
    fn a_halt_holds_at_once() {
        let mut p = streaming();
        p.submit(&Setpoint {
            seq: 1,
            time_us: 10_000,
            pose: home_plus(1, 0.01),
            aux: [None; 2],
            spare: [None; 2],
        })
        .unwrap();
        for _ in 0..100 {
            p.tick();
        }
        assert!(!p.at_rest());
        p.halt();
        assert!(p.at_rest());
        assert_eq!(p.target(), p.pose(), "nothing left to head for");
        let steps = p.steps();
        for _ in 0..10 {
            assert_eq!(p.tick(), (steps, None));
        }
    }
}
