//! The reference's path: a straight line from where the reference was to the newest target, walked a tick at a
//! time. A convex combination of its ends never passes the target, so the trackers behind it never overshoot.

use crate::kinematics::Pose;
use crate::real::{wrap_once, wrap_pi};

use super::delta;
use super::FollowMode;

/// Interpolation segment: from, to, length and progress in ticks. Finished (`done >= ticks`), the reference is at
/// `to` and stays there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Segment {
    pub(super) from: Pose<f32>,
    /// The target (yaw within a turn).
    pub(super) to: Pose<f32>,
    ticks: u32,
    done: u32,
}

impl Segment {
    /// Resting at `pose`: a finished segment of one tick.
    pub(super) fn at(pose: Pose<f32>) -> Self {
        Self {
            from: pose,
            to: pose,
            ticks: 1,
            done: 1,
        }
    }

    /// From `from` to `to` (its yaw wrapped into a turn, as the commanded pose's is) over `ticks`, not yet begun.
    pub(super) fn new(from: Pose<f32>, to: Pose<f32>, ticks: u32) -> Self {
        Self {
            from,
            to: Pose {
                gamma: wrap_pi(to.gamma),
                ..to
            },
            ticks,
            done: 0,
        }
    }

    /// Ends the segment at `pose`: the reference is there from now on.
    pub(super) fn rest_at(&mut self, pose: Pose<f32>) {
        self.collapse_to(pose);
        self.done = self.ticks;
    }

    /// Both ends at `pose` (the progress kept: every point of the segment is `pose`).
    pub(super) fn collapse_to(&mut self, pose: Pose<f32>) {
        self.from = pose;
        self.to = pose;
    }

    /// Whether the reference has reached the target.
    pub(super) fn finished(&self) -> bool {
        self.done >= self.ticks
    }

    /// One tick along the segment (none past its end).
    pub(super) fn advance(&mut self) {
        if self.done < self.ticks {
            self.done += 1;
        }
    }

    /// Where the interpolated reference is now.
    pub(super) fn reference(&self) -> Pose<f32> {
        if self.done >= self.ticks {
            return self.to;
        }
        let f = self.done as f32 / self.ticks as f32;
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
}

/// Ticks of the segment to a setpoint `interval_us` after the last: its own interval when interpolating (at
/// least one tick), one tick when heading for it directly.
pub(super) fn setpoint_ticks(follow: FollowMode, interval_us: u32, tick_us: u32) -> u32 {
    match follow {
        FollowMode::Interpolate => (interval_us / tick_us.max(1)).max(1),
        FollowMode::Direct => 1,
    }
}

/// Ticks of a move of the controller's own from `from` to `to`: long enough that no axis needs more than half its
/// velocity limit, so the trackers keep up with the reference and the move stays on its straight line.
pub(super) fn move_ticks(from: &Pose<f32>, to: &Pose<f32>, pose_velocity: &[f32; 6], tick_us: u32) -> u32 {
    let (a, b) = (from.to_array(), to.to_array());
    let mut seconds = 0.0f32;
    for i in 0..6 {
        seconds = seconds.max(libm::fabsf(delta(i, b[i], a[i])) / (0.5 * pose_velocity[i]));
    }
    ((seconds * 1e6) as u32 / tick_us.max(1)).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;

    const FROM: Pose<f32> = Pose::new(0.0, 0.0, 0.2, 0.0, 0.0, 0.0);
    const TO: Pose<f32> = Pose::new(0.01, -0.02, 0.21, 0.05, -0.1, 0.3);

    #[test]
    fn the_reference_starts_at_from_and_ends_exactly_at_to() {
        let mut s = Segment::new(FROM, TO, 20);
        assert_eq!(s.reference(), FROM);
        assert!(!s.finished());
        for _ in 0..20 {
            s.advance();
        }
        assert!(s.finished());
        assert_eq!(
            s.reference(),
            TO,
            "the end is the target itself, not a sum that rounds near it"
        );
        s.advance();
        assert_eq!(s.reference(), TO, "no step past the end");
    }

    #[test]
    fn the_reference_moves_monotonically_and_never_passes_the_target() {
        let mut s = Segment::new(FROM, TO, 37);
        let (from, to) = (FROM.to_array(), TO.to_array());
        let mut last = s.reference().to_array();
        while !s.finished() {
            s.advance();
            let now = s.reference().to_array();
            for i in 0..6 {
                let direction = (to[i] - from[i]).signum();
                assert!((now[i] - last[i]) * direction >= 0.0, "axis {i} went back");
                assert!((to[i] - now[i]) * direction >= 0.0, "axis {i} passed the target");
            }
            last = now;
        }
    }

    #[test]
    fn the_yaw_crosses_the_seam_the_short_way() {
        // From just below +pi to just above -pi is 0.2 rad forward, not 6.08 back through zero.
        let from = Pose {
            gamma: PI - 0.1,
            ..FROM
        };
        let to = Pose {
            gamma: -PI + 0.1,
            ..FROM
        };
        let mut s = Segment::new(from, to, 10);
        let mut last = s.reference().gamma;
        while !s.finished() {
            s.advance();
            let now = s.reference().gamma;
            assert!(now > -PI && now <= PI, "within a turn: {now}");
            assert!(
                wrap_pi(now - last) > 0.0 && wrap_pi(now - last) < 0.021,
                "{last} -> {now}"
            );
            last = now;
        }
        assert_eq!(last, to.gamma);
    }

    #[test]
    fn a_resting_or_collapsed_segment_stays_put() {
        let mut s = Segment::new(FROM, TO, 10);
        s.advance();
        s.collapse_to(TO);
        assert_eq!(s.reference(), TO, "both ends at one pose: every point is that pose");
        s.rest_at(FROM);
        assert!(s.finished());
        assert_eq!(s.reference(), FROM);
        assert_eq!(Segment::at(TO).reference(), TO);
        assert!(Segment::at(TO).finished());
    }

    #[test]
    fn segment_lengths_follow_the_mode_and_the_limits() {
        assert_eq!(setpoint_ticks(FollowMode::Interpolate, 16_667, 1_000), 16);
        assert_eq!(
            setpoint_ticks(FollowMode::Interpolate, 300, 1_000),
            1,
            "at least one tick"
        );
        assert_eq!(setpoint_ticks(FollowMode::Direct, 16_667, 1_000), 1);
        // 2 cm at 0.05 m/s, half of it used: 0.8 s; the 0.3 rad of yaw at 1.9 rad/s needs less.
        let v = [0.05, 0.05, 0.05, 1.0, 1.0, 1.9];
        let ticks = move_ticks(&FROM, &TO, &v, 1_000);
        assert!((799..=800).contains(&ticks), "{ticks}");
        let (a, b) = (FROM.to_array(), TO.to_array());
        // Truncated to whole ticks: at most one tick short of the exact duration.
        for i in 0..6 {
            let speed = (b[i] - a[i]).abs() / ((ticks + 1) as f32 * 1e-3);
            assert!(speed <= 0.5 * v[i], "axis {i}: {speed}");
        }
        assert_eq!(move_ticks(&FROM, &FROM, &v, 1_000), 1, "no move still takes a tick");
    }
}
