//! The edge of the workspace: the trackers move each axis on its own, so their path is not the straight line
//! between two targets (both inside) and may meet the edge. Staying inside comes first; then a way along or off
//! the edge that keeps the platform moving toward its target.

use crate::kinematics::{Mechanism, Pose};
use crate::Real;

use super::{delta, Mode, Pipeline, Solved};

/// Ticks a pipeline backs off the edge of the workspace before its trackers try again.
const BACK_OFF_TICKS: u16 = 200;

impl<M: Mechanism<f32>> Pipeline<M> {
    /// The trackers' path (per axis, not on the straight line between two targets) met the edge of the
    /// workspace. Staying inside comes first. Grazing it (at least half of the step stays inside), take that part.
    /// Otherwise head on a straight line for the target (which passed every check with a margin); failing that,
    /// back off toward the middle of the workspace (furthest from every edge) for [`BACK_OFF_TICKS`], with the yaw
    /// turning toward the target's, or at this yaw: the workspace is not convex and turns with the yaw, and
    /// trackers let loose at once would push straight back out. A sliver of a step is no way out: each way must
    /// keep at least half its step inside, and the longest part found is the last resort. Each step is at the
    /// speed the limits allow from here. Returns the step taken, or `None` when no part of any of them stays inside.
    pub(super) fn along_edge(&mut self, step: &[f32; 6], dt: f32) -> Option<([f32; 6], Solved)> {
        let mut best = self.inside_part(step);
        let grazing = best.as_ref().is_some_and(|(fraction, ..)| *fraction >= 0.5);
        if self.mode == Mode::Stopping || (self.backing_off == 0 && grazing) {
            return best.map(|(_, taken, found)| (taken, found));
        }
        let middle = |gamma| Pose { gamma, ..self.centre };
        let target = (self.backing_off == 0).then_some(self.segment.to);
        let goals = [
            target,
            Some(middle(self.segment.to.gamma)),
            Some(middle(self.pose.gamma)),
        ];
        for goal in goals.into_iter().flatten() {
            if goal != self.segment.to && self.backing_off == 0 {
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
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::fixture::{home_plus, inside, streaming, HOME};
    use super::super::segment::Segment;
    use super::super::PipelineConfig;
    use super::*;
    use crate::kinematics::RingPlatform;
    use crate::real::wrap_pi;

    type Trainer = Pipeline<RingPlatform<f32>>;

    /// How far below home the workspace ends (m), to the resolution of f32 there: the last inside point.
    fn floor_depth(p: &Trainer) -> f32 {
        let (mut lo, mut hi) = (0.0f32, 0.3f32);
        assert!(inside(p, &home_plus(2, -lo)) && !inside(p, &home_plus(2, -hi)));
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if inside(p, &home_plus(2, -mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// A streaming pipeline resting `above` metres over the workspace's floor, below home.
    fn over_the_floor(above: f32) -> (Trainer, f32) {
        let mut p = streaming();
        let depth = floor_depth(&p);
        p.reset(home_plus(2, above - depth)).unwrap();
        p.start();
        (p, depth)
    }

    fn down(by: f32) -> [f32; 6] {
        [0.0, 0.0, -by, 0.0, 0.0, 0.0]
    }

    #[test]
    fn a_grazing_step_takes_its_inside_part() {
        // 1 mm above the floor, 1.5 mm down: two thirds of the step stay inside.
        let (mut p, _) = over_the_floor(0.001);
        let (taken, (pose, _)) = p.along_edge(&down(0.0015), 1e-3).unwrap();
        let fraction = taken[2] / -0.0015;
        assert!((0.5..0.7).contains(&fraction), "{fraction}");
        assert!(inside(&p, &pose));
        assert_eq!(pose, p.stepped(&taken, 1.0));
        assert_eq!(p.backing_off, 0, "grazing is no reason to back off");
    }

    #[test]
    fn a_step_mostly_outside_heads_for_the_target_instead() {
        // 5 mm down from 1 mm above the floor: a sliver inside. The target (home) is straight up.
        let (mut p, _) = over_the_floor(0.001);
        p.segment = Segment::at(Pose::from_array(HOME));
        let (taken, (pose, _)) = p.along_edge(&down(0.005), 1e-3).unwrap();
        assert_eq!(taken, p.line_step(&Pose::from_array(HOME), 1e-3));
        assert!(taken[2] > 0.0, "up, toward the target: {taken:?}");
        assert!(inside(&p, &pose));
        assert_eq!(p.backing_off, 0, "the target could be headed for");
    }

    #[test]
    fn on_the_edge_with_the_target_beyond_it_backs_off_toward_the_middle() {
        // On the floor itself, the target below it (as no accepted setpoint is, but a tracker's overshoot is): no
        // part of the step and no line to the target stays inside, so back off toward the middle (home).
        let (mut p, depth) = over_the_floor(0.0);
        p.segment = Segment::at(home_plus(2, -depth - 0.01));
        p.velocity_before[2] = -0.05;
        let from = p.pose();
        let (taken, (pose, _)) = p.along_edge(&down(0.00005), 1e-3).unwrap();
        assert_eq!(p.backing_off, BACK_OFF_TICKS);
        assert!(taken[2] > 0.0 && pose.z > from.z, "up, toward the middle: {taken:?}");
        assert!(inside(&p, &pose));
        // No faster than the velocity limit allows.
        assert!(taken[2] <= (0.05 + 1.0 * 1e-3) * 1e-3 * 1.0001, "{taken:?}");
    }

    #[test]
    fn an_overshoot_into_the_edge_is_followed_inside_to_the_target() {
        // Heading down at full speed 0.5 mm over the floor, with the target where the platform is (as after a
        // tracker's overshoot): braking at the pose limit takes 1.25 mm, so the trackers' path crosses the floor.
        // Every tick stays inside; the platform still comes to rest on the target.
        let (mut p, _) = over_the_floor(0.0005);
        p.set_config(PipelineConfig {
            stream_timeout_us: u32::MAX,
            ..*p.config()
        });
        let (dt, v) = (1e-3, -p.config().limits.pose_velocity[2]);
        let target = p.pose();
        // The actuators move as the pose did on the tick before, so that their own limits let it go on.
        let before = p
            .mechanism()
            .inverse(&home_plus(2, target.z - HOME[2] - v * dt))
            .unwrap();
        let now = p.mechanism().inverse(&target).unwrap();
        p.actuator_velocity = core::array::from_fn(|i| wrap_pi(now.0[i] - before.0[i]) / dt);
        p.trackers[2].velocity = v;
        for _ in 0..2_000 {
            p.tick();
            assert!(inside(&p, &p.pose()), "{:?}", p.pose());
        }
        assert!(p.limited().edge_ticks > 0, "the edge was met");
        assert_eq!(p.held(), 0, "never stuck: a way along or off the edge was always found");
        assert!((p.pose().z - target.z).abs() < 1e-5, "{} vs {}", p.pose().z, target.z);
        assert!(p.at_rest());
    }
}
