//! Following the reference: each pose axis under its velocity and acceleration limits, then the whole step scaled
//! down where an actuator would pass its own limits (a stepper driven past them loses steps).

use crate::kinematics::{Actuators, AxisKind, Mechanism};
use crate::real::wrap_pi;
use crate::Real;

use super::{delta, Mode, Pipeline};

impl<M: Mechanism<f32>> Pipeline<M> {
    /// The pose step of this tick toward the reference, one tracker per axis (the segment advanced by a tick).
    pub(super) fn track(&mut self, dt: f32) -> [f32; 6] {
        let limits = self.config.limits;
        let mut step = [0.0f32; 6];
        self.segment.advance();
        let r = self.segment.reference().to_array();
        let end = self.segment.to.to_array();
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
        step
    }

    /// The pose step of this tick braking every axis to rest at its acceleration limit.
    pub(super) fn brake(&mut self, dt: f32) -> [f32; 6] {
        let limits = self.config.limits;
        let mut step = [0.0f32; 6];
        for ((s, t), a) in step.iter_mut().zip(&mut self.trackers).zip(limits.pose_acceleration) {
            *s = t.brake(dt, a) * dt;
        }
        step
    }

    /// Moves the commanded pose by `step`, scaled down if an actuator would exceed its limits. False when the new
    /// pose fails IK or a check (nothing moved).
    pub(super) fn advance(&mut self, step: &[f32; 6], dt: f32) -> bool {
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
            // Only the limit in the direction of the move is computed.
            let bound = if d > 0.0 {
                limits.actuator_velocity[i].min_(v_prev + limits.actuator_acceleration[i] * dt) * dt / d
            } else {
                (-limits.actuator_velocity[i]).max_(v_prev - limits.actuator_acceleration[i] * dt) * dt / d
            };
            scale = scale.min_(bound.max_(0.0));
        }
        scale
    }

    /// How far actuator `i` moves from the commanded actuators to `q` (a carriage the short way round).
    fn actuator_delta(&self, i: usize, q: &Actuators<f32>) -> f32 {
        let d = q.0[i] - self.actuators.within.0[i];
        if self.axes[i] == AxisKind::Ring {
            wrap_pi(d)
        } else {
            d
        }
    }

    /// Every axis within a micrometre (microradian) of the reference and slow enough to stop in one tick.
    pub(super) fn settled(&self, dt: f32) -> bool {
        let (p, r) = (self.pose.to_array(), self.segment.reference().to_array());
        (0..6).all(|i| {
            libm::fabsf(delta(i, r[i], p[i])) <= 1e-6
                && libm::fabsf(self.trackers[i].velocity) <= self.config.limits.pose_acceleration[i] * dt
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::fixture::{holding, home_plus, streaming};
    use super::super::{FollowMode, PipelineConfig, PipelineEvent};
    use crate::kinematics::{Mechanism, Pose};
    use crate::motion::setpoint::Setpoint;

    /// Per-axis speeds of the commanded pose over the last tick.
    fn speeds(before: &Pose<f32>, after: &Pose<f32>, dt: f32) -> [f32; 6] {
        let (a, b) = (before.to_array(), after.to_array());
        core::array::from_fn(|i| (b[i] - a[i]) / dt)
    }

    #[test]
    fn the_pose_follows_within_its_velocity_and_acceleration_limits() {
        // Direct: the trackers see the whole step at once, the hardest case for the limits.
        // No stream timeout: one setpoint is followed to its end.
        let mut p = holding(PipelineConfig {
            follow: FollowMode::Direct,
            stream_timeout_us: u32::MAX,
            ..PipelineConfig::default()
        });
        p.start();
        let limits = p.config().limits;
        let dt = 1e-3;
        // Surge and sway, which the trainer's actuators follow at the pose limits (heave or a rotation on top needs
        // more than the actuators' own limits allow and is scaled down: `the_actuator_limits_scale_a_step_down`).
        let pose = Pose::new(0.02, -0.02, home_plus(2, 0.0).z, 0.0, 0.0, 0.0);
        p.submit(&Setpoint {
            seq: 1,
            time_us: 1_000,
            pose,
            aux: [None; 2],
            spare: [None; 2],
        })
        .unwrap();
        let target = p.target().to_array();
        let (mut last, mut velocity) = (p.pose(), [0.0f32; 6]);
        let mut fastest = [0.0f32; 6];
        for _ in 0..2_000 {
            p.tick();
            // The trackers hold the limits exactly; the pose's own differences, in f32, nearly.
            let v = p.trackers.map(|t| t.velocity);
            let moved = speeds(&last, &p.pose(), dt);
            for i in 0..6 {
                assert!(v[i].abs() <= limits.pose_velocity[i], "axis {i}: {}", v[i]);
                let gained = (v[i] - velocity[i]).abs();
                assert!(
                    gained <= limits.pose_acceleration[i] * dt * 1.0001,
                    "axis {i}: {gained}"
                );
                assert!(
                    moved[i].abs() <= limits.pose_velocity[i] * 1.001 + 1e-4,
                    "axis {i}: {}",
                    moved[i]
                );
                fastest[i] = fastest[i].max(v[i].abs());
            }
            (last, velocity) = (p.pose(), v);
        }
        assert!(
            fastest[0] == limits.pose_velocity[0],
            "x reached its velocity limit: {fastest:?}"
        );
        let at = p.pose().to_array();
        for i in 0..6 {
            assert!(
                (at[i] - target[i]).abs() < 1e-5,
                "axis {i} arrived: {} vs {}",
                at[i],
                target[i]
            );
        }
        assert!(p.at_rest());
        let free = (p.limited().actuator_ticks, p.limited().edge_ticks, p.held());
        assert_eq!(free, (0, 0, 0), "a free path: only the pose limits shaped it");
    }

    #[test]
    fn stopping_brakes_at_the_acceleration_limit_to_rest() {
        let mut p = holding(PipelineConfig {
            stream_timeout_us: u32::MAX,
            ..PipelineConfig::default()
        });
        p.start();
        let limits = p.config().limits;
        let dt = 1e-3;
        p.submit(&Setpoint {
            seq: 1,
            time_us: 1_000,
            pose: home_plus(1, 0.02),
            aux: [None; 2],
            spare: [None; 2],
        })
        .unwrap();
        for _ in 0..200 {
            p.tick();
        }
        let moving = p.trackers[1].velocity;
        assert!(moving > 0.0, "under way");
        p.stop();
        let mut ticks = 0;
        let mut last = p.trackers[1].velocity;
        loop {
            let (_, event) = p.tick();
            ticks += 1;
            let v = p.trackers[1].velocity;
            assert!(
                v <= last && last - v <= limits.pose_acceleration[1] * dt * 1.0001,
                "{last} -> {v}"
            );
            last = v;
            if event == Some(PipelineEvent::AtRest) {
                break;
            }
            assert!(ticks < 1_000, "never at rest");
        }
        let least = (moving / (limits.pose_acceleration[1] * dt)).floor() as u32;
        assert!(ticks >= least && ticks <= least + 2, "{ticks} ticks from {moving} m/s");
        assert!(p.at_rest());
    }

    #[test]
    fn the_actuator_limits_scale_a_step_down() {
        let mut p = streaming();
        let dt = 1e-3;
        // A step the pose limits would never allow in one tick (1 cm of heave): the carriages' speed bounds it.
        let q = p.mechanism().inverse_checked(&home_plus(2, 0.01)).unwrap().0;
        let scale = p.actuator_scale(&q, dt);
        assert!(scale > 0.0 && scale < 1.0, "{scale}");
        let limits = p.config().limits;
        for i in 0..6 {
            let moved = (p.actuator_delta(i, &q) * scale).abs();
            // From rest, the acceleration bounds the first tick: v <= a dt.
            let bound = limits.actuator_velocity[i].min(limits.actuator_acceleration[i] * dt) * dt;
            assert!(moved <= bound * 1.0001, "actuator {i}: {moved} > {bound}");
        }
        // A tiny step passes unscaled.
        let q = p.mechanism().inverse_checked(&home_plus(2, 1e-6)).unwrap().0;
        assert_eq!(p.actuator_scale(&q, dt), 1.0);
        // And the step taken by `advance` stays within those bounds too.
        assert!(p.advance(&[0.0, 0.0, 0.01, 0.0, 0.0, 0.0], dt));
        assert!(p.limited().actuator_ticks >= 1);
        assert!(p.pose().z > home_plus(2, 0.0).z && p.pose().z < home_plus(2, 0.01).z);
    }
}
