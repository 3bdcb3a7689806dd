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
        let two_pi = T::two_pi();
        for (i, kind) in axes.iter().enumerate() {
            let (cur, nxt) = (self.within.0[i], next.0[i]);
            if *kind == AxisKind::Ring {
                let nxt = wrap_pi(nxt);
                let delta = wrap_pi(nxt - cur);
                // cur + delta equals nxt up to a whole turn: that turn is the crossing of +-pi.
                let crossed = ((cur + delta - nxt) / two_pi).round_();
                self.turns[i] = self.turns[i].saturating_add(crossed.to_f64() as i32);
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

    /// Step position of ring axis `i` for a drive with `steps_per_turn` steps per carriage revolution.
    pub fn ring_steps(&self, i: usize, steps_per_turn: i64) -> i64 {
        let turns = i64::from(self.turns.get(i).copied().unwrap_or(0));
        let within = self.within.0.get(i).copied().unwrap_or(T::zero());
        let frac = (within * T::of(steps_per_turn as f64) / T::two_pi()).round_();
        turns
            .saturating_mul(steps_per_turn)
            .saturating_add(frac.to_f64() as i64)
    }
}
