//! What a setpoint must pass to be taken, and taking it: garbage (not finite, not newer than the last, a gross
//! jump, or no stream) is refused and changes nothing but its counter; everything else is limited into the
//! envelope and becomes the reference's next target. The controller's own moves are taken here too.

use crate::kinematics::{Check, Mechanism, Pose};

use super::super::envelope;
use super::super::setpoint::{Accepted, LimitReport, RejectReason, Setpoint};
use super::super::spare::SpareAxes;
use super::segment::{self, Segment};
use super::{delta, Mode, Pipeline};

impl<M: Mechanism<f32>> Pipeline<M> {
    /// Moves to `pose` on a straight line under the limits (the controller's own move, e.g. to the home pose after
    /// homing). The pose must pass every check; [`PipelineEvent::AtRest`](super::PipelineEvent::AtRest) follows
    /// when it is reached.
    pub fn move_to(&mut self, pose: Pose<f32>) -> Result<(), RejectReason> {
        let pose = pose.validated().map_err(|_| RejectReason::NonFinite)?;
        if self.solve(&pose).is_none() {
            return Err(RejectReason::Unreachable);
        }
        let ticks = segment::move_ticks(
            &self.pose,
            &pose,
            &self.config.limits.pose_velocity,
            self.config.tick_us,
        );
        self.segment = Segment::new(self.pose, pose, ticks);
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
        let limited = envelope::limit_in(
            &self.mechanism,
            &mut self.guard,
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
        let ticks = segment::setpoint_ticks(config.follow, interval_us, config.tick_us);
        self.segment = Segment::new(self.segment.reference(), limited.pose, ticks);
        self.spare.take(&sp.spare, ticks);
        self.last = Some((sp.seq, sp.time_us, sp.pose));
        self.since_setpoint_us = 0;
        self.passed_us = 0;
        self.applied = self.applied.saturating_add(1);
        Ok(accepted)
    }

    /// Refuses garbage; returns the interval to interpolate over (us).
    fn validate(&self, sp: &Setpoint) -> Result<u32, RejectReason> {
        if self.mode != Mode::Streaming {
            return Err(RejectReason::NotStreaming);
        }
        let pose = sp.pose.validated().map_err(|_| RejectReason::NonFinite)?;
        if !SpareAxes::finite(&sp.spare) {
            return Err(RejectReason::NonFinite);
        }
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
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::fixture::{holding, home_plus, streaming, HOME};
    use super::super::PipelineConfig;
    use super::*;
    use crate::kinematics::RingPlatform;

    fn at(seq: u32, time_us: u64, pose: Pose<f32>) -> Setpoint {
        Setpoint {
            seq,
            time_us,
            pose,
            aux: [None; 2],
            spare: [None; 2],
        }
    }

    /// The last accepted setpoint as the pipeline keeps it: sequence number, time, pose as sent.
    type Last = Option<(u32, u64, Pose<f32>)>;

    /// Everything a refusal must leave as it was: the target, the commanded pose, the steps, the applied count
    /// and the last accepted setpoint (what the next one is checked against).
    fn state(p: &Pipeline<RingPlatform<f32>>) -> (Pose<f32>, Pose<f32>, [i64; 6], u32, Last) {
        (p.target(), p.pose(), p.steps(), p.applied(), p.last)
    }

    #[test]
    fn nothing_is_taken_before_the_stream_starts() {
        let mut p = holding(PipelineConfig::default());
        let before = state(&p);
        assert_eq!(
            p.submit(&at(1, 1_000, home_plus(0, 0.001))),
            Err(RejectReason::NotStreaming)
        );
        assert_eq!(state(&p), before);
        assert_eq!(p.rejected().not_streaming, 1);
    }

    #[test]
    fn a_non_finite_setpoint_is_refused_and_changes_nothing() {
        let mut p = streaming();
        p.submit(&at(1, 10_000, home_plus(2, 0.001))).unwrap();
        let before = state(&p);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut pose = home_plus(2, 0.001);
            pose.beta = bad;
            assert_eq!(p.submit(&at(2, 20_000, pose)), Err(RejectReason::NonFinite));
            assert_eq!(state(&p), before);
        }
        assert_eq!(p.rejected().non_finite, 3);
        assert_eq!(p.rejected().total(), 3);
    }

    #[test]
    fn an_out_of_order_setpoint_is_stale() {
        let mut p = streaming();
        p.submit(&at(10, 100_000, home_plus(0, 0.001))).unwrap();
        let before = state(&p);
        let stale = [
            at(10, 110_000, home_plus(0, 0.002)), // the same sequence number again
            at(9, 110_000, home_plus(0, 0.002)),  // an older one
            at(11, 100_000, home_plus(0, 0.002)), // newer number, same time
            at(11, 90_000, home_plus(0, 0.002)),  // newer number, older time
            at(10 + u32::MAX / 2 + 1, 110_000, home_plus(0, 0.002)), // more than half the range ahead: behind
        ];
        for sp in &stale {
            assert_eq!(p.submit(sp), Err(RejectReason::Stale), "{sp:?}");
            assert_eq!(state(&p), before);
        }
        assert_eq!(p.rejected().stale, 5);
    }

    #[test]
    fn sequence_numbers_wrap() {
        let mut p = streaming();
        p.submit(&at(u32::MAX, 10_000, home_plus(0, 0.001))).unwrap();
        assert_eq!(p.submit(&at(0, 20_000, home_plus(0, 0.002))), Ok(Accepted::Applied));
        assert_eq!(p.applied(), 2);
    }

    #[test]
    fn a_gross_jump_is_refused_and_changes_nothing() {
        let mut p = streaming();
        let limits = p.config().limits;
        let window = p.config().gross_jump_us as f32 * 1e-6;
        // Just inside the window is followed (at the limits); just outside is a broken source.
        let near = limits.pose_velocity[0] * window * 0.99;
        assert_eq!(p.submit(&at(1, 10_000, home_plus(0, near))), Ok(Accepted::Applied));
        let before = state(&p);
        let far = home_plus(0, near + limits.pose_velocity[0] * window * 1.01);
        assert!(matches!(
            p.submit(&at(2, 20_000, far)),
            Err(RejectReason::GrossJump { .. })
        ));
        assert_eq!(state(&p), before);
        // Far out of reach as well: the answer names the check it fails.
        let out = home_plus(2, 1.0);
        assert_eq!(
            p.submit(&at(3, 30_000, out)),
            Err(RejectReason::GrossJump {
                outside: Some(Check::Reach)
            })
        );
        assert_eq!(state(&p), before);
        assert_eq!(p.rejected().gross_jump, 2);
    }

    #[test]
    fn a_setpoint_outside_the_workspace_is_limited_into_it() {
        let mut p = streaming();
        // 2 cm below the lowest heave the trainer model reaches in one step is still no gross jump from a pose
        // that is already low: walk down, then ask for more than there is.
        let mut k = 0;
        let answer = loop {
            k += 1;
            let answer = p
                .submit(&at(k, u64::from(k) * 100_000, home_plus(2, -0.02 * k as f32)))
                .unwrap();
            if matches!(answer, Accepted::Limited(_)) || k > 20 {
                break answer;
            }
        };
        let Accepted::Limited(report) = answer else {
            unreachable!("never limited down to {}", HOME[2] - 0.02 * k as f32);
        };
        assert!(report.translation > 0.0);
        assert!(
            p.target().z > HOME[2] - 0.02 * k as f32,
            "the target is the limited pose, not the one asked"
        );
        assert_eq!(p.limited().count, 1);
        assert_eq!(p.rejected().total(), 0);
    }

    #[test]
    fn a_move_refuses_what_it_cannot_reach() {
        let mut p = holding(PipelineConfig::default());
        let before = state(&p);
        assert_eq!(p.move_to(home_plus(2, 1.0)), Err(RejectReason::Unreachable));
        assert_eq!(p.move_to(home_plus(0, f32::NAN)), Err(RejectReason::NonFinite));
        assert_eq!(state(&p), before);
        assert_eq!(p.move_to(home_plus(0, 0.01)), Ok(()));
        assert_eq!(p.target(), home_plus(0, 0.01));
    }
}
