//! The workspace on the way: IK and every check of a pose near the commanded one, and the part of a step that
//! stays inside. Nothing is commanded that has not passed here.

use crate::kinematics::{Mechanism, Pose};
use crate::real::wrap_once;

use super::{Pipeline, Solved};

impl<M: Mechanism<f32>> Pipeline<M> {
    /// IK and every check of a pose near the commanded one (the slow checks proved where they can be).
    pub(super) fn solve(&mut self, pose: &Pose<f32>) -> Option<Solved> {
        let (q, report) = self.mechanism.inverse_guarded(pose, &mut self.guard).ok()?;
        report.all_pass().then_some((*pose, q))
    }

    /// The commanded pose moved by `s` times `step` (the yaw kept within a turn by one exact addition).
    pub(super) fn stepped(&self, step: &[f32; 6], s: f32) -> Pose<f32> {
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

    /// The largest part of a step (bisection, 6 evaluations: to 1/64) whose pose passes every check.
    pub(super) fn inside_part(&mut self, step: &[f32; 6]) -> Option<(f32, [f32; 6], Solved)> {
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
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::fixture::{home_plus, inside, streaming, HOME};
    use super::*;
    use core::f32::consts::PI;

    #[test]
    fn solve_takes_only_poses_that_pass_every_check() {
        let mut p = streaming();
        let home = Pose::from_array(HOME);
        let (pose, q) = p.solve(&home).unwrap();
        assert_eq!(pose, home);
        assert_eq!(q, p.mechanism().inverse(&home).unwrap());
        assert!(p.solve(&home_plus(2, 1.0)).is_none(), "out of reach");
        assert!(
            p.solve(&home_plus(3, 1.2)).is_none(),
            "rolled far past the joints' cones"
        );
    }

    #[test]
    fn a_step_keeps_the_yaw_within_a_turn() {
        let mut p = streaming();
        p.pose.gamma = 3.0;
        let step = [0.001, 0.0, 0.0, 0.0, 0.0, 0.2];
        let half = p.stepped(&step, 0.5);
        assert_eq!(half.gamma, 3.0 + 0.1);
        assert_eq!(half.x, 0.0005);
        // 3.2 rad is past the seam: one turn less, by one exact addition.
        let full = p.stepped(&step, 1.0);
        assert!(full.gamma > -PI && full.gamma <= PI, "{}", full.gamma);
        assert!((full.gamma - (3.2 - 2.0 * PI)).abs() < 1e-6, "{}", full.gamma);
    }

    #[test]
    fn the_inside_part_of_a_step_is_inside_and_the_rest_is_not() {
        let mut p = streaming();
        // Straight up, from home to well out of reach: inside, then outside, with one crossing.
        let step = [0.0, 0.0, 0.2, 0.0, 0.0, 0.0];
        let (fraction, part, (pose, _)) = p.inside_part(&step).unwrap();
        assert!(fraction > 0.0 && fraction < 1.0, "{fraction}");
        assert_eq!(part[2], 0.2 * fraction);
        assert_eq!(pose, p.stepped(&step, fraction));
        assert!(inside(&p, &pose));
        assert!(!inside(&p, &p.stepped(&step, fraction + 1.0 / 64.0)), "maximal to 1/64");
        // A step that leaves at once has no inside part.
        let out = [0.0, 0.0, 20.0, 0.0, 0.0, 0.0];
        assert!(p.inside_part(&out).is_none());
        // One that stays inside is taken to 63/64 (the bisection never evaluates the whole step).
        let (fraction, ..) = p.inside_part(&[0.0, 0.0, 1e-4, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(fraction, 63.0 / 64.0);
    }
}
