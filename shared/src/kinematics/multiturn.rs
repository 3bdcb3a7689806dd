//! Multi-turn carriage positions for continuous yaw (KINEMATICS.md 3, last point).
//!
//! Precision decision: a carriage position is kept as a whole number of turns (`i32`) plus an angle in
//! `(-pi, pi]`. An `f32` angle of 10,000 turns (62,832 rad) has an ulp of 0.0039 rad, about 16 steps of the model
//! (4,000 steps/rad): accumulating the angle in one float would drift by steps per turn. Split this way, the
//! fraction keeps its full precision forever, and the step count is `turns * steps_per_turn + round(angle *
//! steps_per_turn / 2pi)`, exact integer arithmetic for the whole turns.

use super::{Actuators, AxisKind, KinematicsError, Mechanism, Pose};
use crate::real::wrap_pi;
use crate::Real;

/// The whole turn in `x`, an angle that is a multiple of a turn up to rounding: 1 from half a turn up, -1 from half
/// a turn down, else 0 (NaN too). That is `round(x / 2pi)` clamped to one turn, by two comparisons where the
/// division and the rounding take about twenty instructions on the M4F: `x / 2pi >= 1/2` exactly when `x >= pi`,
/// since the float pi is half the float 2pi and the float below pi divides to at least an ulp of 1/2 below it in
/// either type (a test holds the two to each other over any bits).
#[inline]
fn crossing<T: Real>(x: T) -> i32 {
    if x >= T::pi() {
        1
    } else if x <= -T::pi() {
        -1
    } else {
        0
    }
}

/// Actuator positions with whole turns kept apart for the ring axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MultiTurn<T> {
    /// Whole turns of each axis (always 0 for non-ring axes).
    pub turns: [i32; 6],
    /// Ring axes: angle within the turn, in `(-pi, pi]`; other axes: their plain value.
    pub within: Actuators<T>,
}

impl<T: Real> MultiTurn<T> {
    /// Starts at turn zero from an IK solution.
    pub fn new(q: Actuators<T>) -> Self {
        Self {
            turns: [0; 6],
            within: q,
        }
    }

    /// Moves to `next` (an IK solution, ring angles in `(-pi, pi]`) along the branch nearest the current position:
    /// a ring axis never jumps by a turn; a step of more than half a turn is taken the short way round.
    pub fn follow(&mut self, next: &Actuators<T>, axes: &[AxisKind; 6]) {
        for (i, kind) in axes.iter().enumerate() {
            let (cur, nxt) = (self.within.0[i], next.0[i]);
            if *kind == AxisKind::Ring {
                let nxt = wrap_pi(nxt);
                let delta = wrap_pi(nxt - cur);
                // cur + delta equals nxt up to a whole turn: that turn is the crossing of +-pi.
                self.turns[i] = self.turns[i].saturating_add(crossing(cur + delta - nxt));
                self.within.0[i] = nxt;
            } else {
                self.within.0[i] = nxt;
            }
        }
    }

    /// IK at `pose`, taking the branch nearest to this position; on error the position is unchanged.
    pub fn inverse_near<M: Mechanism<T>>(&mut self, mechanism: &M, pose: &Pose<T>) -> Result<(), KinematicsError> {
        let q = mechanism.inverse(pose)?;
        self.follow(&q, &mechanism.axes());
        Ok(())
    }

    /// The full value of axis `i` as `f64` (turns times 2 pi plus the angle within the turn).
    pub fn total(&self, i: usize) -> f64 {
        let turns = self.turns.get(i).copied().unwrap_or(0) as f64;
        let within = self.within.0.get(i).map_or(0.0, |w| w.to_f64());
        turns * core::f64::consts::TAU + within
    }

    /// How far axis `i` is from where it is in `earlier` (ring axes across whole turns), in this type: the
    /// whole turns that differ times 2 pi plus the difference within the turn. Exact for the turn or so one
    /// control period moves; not through `f64` (software arithmetic on the M4F).
    pub fn delta_from(&self, earlier: &Self, i: usize) -> T {
        let i = i.min(5);
        let turns = self.turns[i].saturating_sub(earlier.turns[i]);
        T::of_i32(turns) * T::two_pi() + (self.within.0[i] - earlier.within.0[i])
    }

    /// Step position of ring axis `i` for a drive with `steps_per_turn` steps per carriage revolution.
    pub fn ring_steps(&self, i: usize, steps_per_turn: i64) -> i64 {
        let turns = i64::from(self.turns.get(i).copied().unwrap_or(0));
        let within = self.within.0.get(i).copied().unwrap_or(T::zero());
        // A count that fits an i32 converts without f64 (software on the M4F), and times i32 turns it cannot
        // overflow (one SMULL, where a saturating i64 product is a library call). Larger counts take the general
        // way, with the same rounding (i64 -> f64 -> T).
        let (per_turn, whole) = match i32::try_from(steps_per_turn) {
            Ok(n) => (T::of_i32(n), turns * i64::from(n)),
            Err(_) => (T::of(steps_per_turn as f64), turns.saturating_mul(steps_per_turn)),
        };
        let frac = (within * per_turn / T::two_pi()).round_to_i64();
        whole.saturating_add(frac)
    }
}

#[cfg(test)]
mod tests {
    use super::crossing;
    use crate::Real;

    /// The crossing by its definition: the turns of the quotient, rounded and clamped.
    fn rounded<T: Real>(x: T) -> i32 {
        (x / T::two_pi()).round_to_i64().clamp(-1, 1) as i32
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]

        #[test]
        fn crossing_is_the_rounded_quotient(bits in proptest::num::u32::ANY, wide in proptest::num::u64::ANY) {
            let (x, y) = (f32::from_bits(bits), f64::from_bits(wide));
            proptest::prop_assert_eq!(crossing(x), rounded(x), "{:e}", x);
            proptest::prop_assert_eq!(crossing(y), rounded(y), "{:e}", y);
        }
    }

    /// Around both half turns, to the ulp, and the special values.
    #[test]
    fn crossing_at_the_half_turns() {
        fn around<T: Real>(v: T, up: impl Fn(T) -> T, down: impl Fn(T) -> T) {
            let (mut a, mut b) = (v, v);
            for _ in 0..64 {
                for x in [a, b, -a, -b] {
                    assert_eq!(crossing(x), rounded(x), "{x:?}");
                }
                (a, b) = (up(a), down(b));
            }
        }
        around(core::f32::consts::PI, f32::next_up, f32::next_down);
        around(core::f64::consts::PI, f64::next_up, f64::next_down);
        for x in [
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MAX,
            f32::MIN_POSITIVE,
        ] {
            assert_eq!(crossing(x), rounded(x), "{x:e}");
            assert_eq!(crossing(f64::from(x)), rounded(f64::from(x)), "{x:e}");
        }
        assert_eq!(
            (crossing(core::f32::consts::PI), crossing(-core::f32::consts::PI)),
            (1, -1)
        );
        assert_eq!(crossing(core::f32::consts::PI.next_down()), 0);
    }
}
