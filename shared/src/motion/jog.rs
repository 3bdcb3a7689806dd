//! Commissioning moves of one axis: a jog (one leg of a signed step count) or a buzz (ten small back-and-forth
//! legs, as Klipper's STEPPER_BUZZ), run at a fixed step rate while the other axes hold.

/// Back-and-forth legs of a buzz.
pub const BUZZ_CYCLES: usize = 10;

const MAX_LEGS: usize = 2 * BUZZ_CYCLES;

/// A commissioning move in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Jog {
    /// The axis that moves.
    pub axis: usize,
    legs: [i32; MAX_LEGS],
    count: usize,
    leg: usize,
    /// Where the current leg ends (steps).
    target: i64,
    /// Step rate (steps/s).
    rate: u32,
    /// Step-time carried between ticks (steps x us).
    carry: u64,
    /// Periods held since the last leg ended.
    settled: u8,
}

/// Periods a jog holds, drivers enabled, after its last steps were planned, beyond the period that plays them: a
/// board takes a tick's moves at the next period boundary and plays them in the ring's half after it, so the last
/// steps may still be at the pins when the tick after next writes the outputs.
pub const SETTLE_PERIODS: u8 = 1;

impl Jog {
    /// One leg of `steps` from `from`.
    pub fn one_leg(axis: usize, from: i64, steps: i32, rate: u32) -> Self {
        let mut legs = [0; MAX_LEGS];
        legs[0] = steps;
        Self::with_legs(axis, from, legs, 1, rate)
    }

    /// [`BUZZ_CYCLES`] times `+amplitude` then `-amplitude` from `from`: ends where it started.
    pub fn buzz(axis: usize, from: i64, amplitude: i32, rate: u32) -> Self {
        let legs = core::array::from_fn(|i| if i % 2 == 0 { amplitude } else { -amplitude });
        Self::with_legs(axis, from, legs, MAX_LEGS, rate)
    }

    /// Once every leg is done: `true` for each of the [`SETTLE_PERIODS`] periods the jog still holds.
    pub fn settle(&mut self) -> bool {
        let holding = self.settled < SETTLE_PERIODS;
        self.settled = self.settled.saturating_add(1);
        holding
    }

    fn with_legs(axis: usize, from: i64, legs: [i32; MAX_LEGS], count: usize, rate: u32) -> Self {
        Self {
            axis,
            legs,
            count,
            leg: 0,
            target: from.saturating_add(i64::from(legs[0])),
            rate,
            carry: 0,
            settled: 0,
        }
    }

    /// The axis's position at the end of the next tick of `tick_us`, from `position`; `None` once every leg is
    /// done.
    pub fn next(&mut self, position: i64, tick_us: u32) -> Option<i64> {
        while position == self.target {
            self.leg += 1;
            if self.leg >= self.count {
                return None;
            }
            self.target = position.saturating_add(i64::from(self.legs[self.leg]));
        }
        self.carry = self.carry.saturating_add(u64::from(self.rate) * u64::from(tick_us));
        let steps = (self.carry / 1_000_000) as i64;
        self.carry %= 1_000_000;
        let left = self.target - position;
        Some(position + left.signum() * steps.min(left.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(mut j: Jog, mut p: i64) -> (i64, usize, i64) {
        let (mut ticks, mut furthest) = (0, 0i64);
        while let Some(next) = j.next(p, 1000) {
            assert!((next - p).abs() <= 2, "at most rate x tick per tick");
            p = next;
            furthest = furthest.max(p.abs());
            ticks += 1;
            assert!(ticks < 100_000);
        }
        (p, ticks, furthest)
    }

    #[test]
    fn a_jog_ends_at_its_distance_at_its_rate() {
        let (end, ticks, _) = run(Jog::one_leg(2, 100, -500, 2000), 100);
        assert_eq!(end, -400);
        assert_eq!(ticks, 250, "500 steps at 2000 steps/s in 1 ms ticks");
    }

    #[test]
    fn a_buzz_returns_where_it_started() {
        let (end, ticks, furthest) = run(Jog::buzz(0, 0, 100, 2000), 0);
        assert_eq!(end, 0);
        assert_eq!(furthest, 100);
        assert_eq!(ticks, 20 * 50);
    }
}
