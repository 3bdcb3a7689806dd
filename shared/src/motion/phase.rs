//! Where the control tick falls in the step generator's period, and how to move it there.
//!
//! The step generator takes one period of moves from its queue at each of its period boundaries and plays it in
//! the next period (the DMA plays one half of its ring while the other is written). A setpoint therefore reaches
//! the motors one period after the first boundary that follows the tick that planned it, plus the time the tick
//! waited for that boundary. Two free-running clocks leave that wait anywhere in a period, and any catch-up after
//! a hold-up leaves a period queued for good. A tick held a fixed `lead` before the boundary has its moves taken
//! at that boundary: the shortest path from setpoint to step that still leaves the tick (and a link frame that
//! may be running when it falls due) time to finish.

/// The control tick's wanted phase in the step generator's period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TickPhase {
    period_us: u32,
    lead_us: u32,
    tolerance_us: u32,
}

/// A [`TickPhase`] that cannot be: the lead and the tolerance must fit in the period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BadPhase;

impl TickPhase {
    /// A tick `lead_us` before each boundary of a `period_us` period, moved when it is more than `tolerance_us`
    /// off (the clocks' jitter and a tick's own delays stay inside it, so a steady loop is never moved).
    pub fn new(period_us: u32, lead_us: u32, tolerance_us: u32) -> Result<Self, BadPhase> {
        let fits = period_us > 0
            && lead_us > tolerance_us
            && lead_us.checked_add(tolerance_us).is_some_and(|late| late < period_us);
        if fits {
            Ok(Self {
                period_us,
                lead_us,
                tolerance_us,
            })
        } else {
            Err(BadPhase)
        }
    }

    /// The lead for a period of `period_us`: 350 us (a tick costs about 60 us on the F411 at 100 MHz and a link
    /// frame that runs when the tick falls due as much again), or two fifths of a shorter period; moved when 100 us
    /// (or a tenth of the period) off.
    pub fn for_period(period_us: u32) -> Result<Self, BadPhase> {
        Self::new(period_us, 350.min(period_us / 5 * 2), 100.min(period_us / 10))
    }

    /// The phase the tick keeps: microseconds after a boundary.
    pub fn wanted_us(&self) -> u32 {
        self.period_us - self.lead_us
    }

    /// For a tick that started at `tick_us` when the generator's last boundary was at `boundary_us` (both device
    /// microseconds, wrapping): `None` when the tick is where it should be, else the time from this tick's start
    /// to the next one that is (less than a period). Moving a tick later leaves a period without one (the queue
    /// covers it); moving it earlier gives one period two ticks, and the second finds its period queued.
    pub fn correction(&self, tick_us: u32, boundary_us: u32) -> Option<u32> {
        let since = tick_us.wrapping_sub(boundary_us) % self.period_us;
        let delay = (self.wanted_us() + self.period_us - since) % self.period_us;
        let off = delay.min(self.period_us - delay);
        (off > self.tolerance_us).then_some(delay)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_tick_in_place_stays_and_one_off_is_moved_to_the_wanted_phase() {
        let p = TickPhase::for_period(1000).unwrap();
        assert_eq!(p.wanted_us(), 650);
        // Boundaries at ...000; a tick at 650 after one is in place, 80 us either side too.
        assert_eq!(p.correction(10_650, 10_000), None);
        assert_eq!(p.correction(10_730, 10_000), None);
        assert_eq!(p.correction(10_570, 10_000), None);
        // 70 us before the boundary (as the QEMU controller's clocks fell): next tick 720 us later, at 650.
        assert_eq!(p.correction(10_930, 10_000), Some(720));
        // Right after a boundary: next tick 640 us later.
        assert_eq!(p.correction(11_010, 10_000), Some(640));
        // The boundary seen is several periods old (the generator's record lags): the phase is the same.
        assert_eq!(p.correction(15_930, 10_000), Some(720));
        // Across the counter's wrap.
        assert_eq!(p.correction(330, u32::MAX - 999), Some(320));
    }

    #[test]
    fn phases_that_do_not_fit_are_refused() {
        assert_eq!(TickPhase::new(0, 0, 0), Err(BadPhase));
        assert_eq!(TickPhase::new(1000, 100, 100), Err(BadPhase));
        assert_eq!(TickPhase::new(1000, 950, 100), Err(BadPhase));
        assert_eq!(TickPhase::new(1000, u32::MAX, 1), Err(BadPhase));
        assert!(TickPhase::for_period(1).is_err());
        assert!(TickPhase::for_period(100).is_ok());
        assert!(TickPhase::for_period(20_000).is_ok());
    }

    proptest! {
        #[test]
        fn a_moved_tick_lands_on_the_wanted_phase(
            period in 30u32..100_000,
            boundary in any::<u32>(),
            tick in any::<u32>(),
        ) {
            let p = TickPhase::for_period(period).unwrap();
            let phase = |t: u32| t.wrapping_sub(boundary) % period;
            match p.correction(tick, boundary) {
                Some(delay) => {
                    prop_assert!(delay < period);
                    prop_assert_eq!(phase(tick.wrapping_add(delay)), p.wanted_us());
                }
                None => {
                    let d = phase(tick).abs_diff(p.wanted_us());
                    prop_assert!(d.min(period - d) <= p.tolerance_us);
                }
            }
        }
    }
}
