//! Lines said for events that may come by the thousand (setpoints the device refuses, one per row of a bad file):
//! the first [`SAID_IN_FULL`] each on a line of its own, then a line a second at most with how many came since, and
//! at the end how many were not said yet. The report lists every one; stderr stays readable.

use std::time::{Duration, Instant};

/// Events said each on a line of their own before they are counted.
pub const SAID_IN_FULL: u32 = 10;
/// How often a count of the events since is said.
const SUMMARY_EVERY: Duration = Duration::from_secs(1);

/// The events of one kind so far.
#[derive(Debug, Default)]
pub struct Repeats {
    seen: u32,
    unsaid: u32,
    last_summary: Option<Instant>,
}

/// What to say of one more event.
#[derive(Debug, PartialEq)]
pub enum Say {
    /// It, on its own line.
    Line,
    /// A count of the events not said, this one included.
    Count(u32),
    /// Nothing yet: it is counted.
    Nothing,
}

impl Repeats {
    /// One more event at `now`.
    pub fn note(&mut self, now: Instant) -> Say {
        self.seen = self.seen.saturating_add(1);
        if self.seen <= SAID_IN_FULL {
            return Say::Line;
        }
        self.unsaid += 1;
        match self.last_summary {
            Some(t) if now.duration_since(t) < SUMMARY_EVERY => Say::Nothing,
            _ => {
                self.last_summary = Some(now);
                Say::Count(std::mem::take(&mut self.unsaid))
            }
        }
    }

    /// The events counted and not said yet (for a last line at the end); none after.
    pub fn unsaid(&mut self) -> u32 {
        std::mem::take(&mut self.unsaid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_are_said_then_a_count_a_second_and_the_rest_at_the_end() {
        let mut r = Repeats::default();
        let t0 = Instant::now();
        for _ in 0..SAID_IN_FULL {
            assert_eq!(r.note(t0), Say::Line);
        }
        assert_eq!(r.note(t0), Say::Count(1), "the first beyond is said as a count at once");
        for k in 0..500 {
            assert_eq!(r.note(t0 + Duration::from_millis(k)), Say::Nothing);
        }
        assert_eq!(r.note(t0 + SUMMARY_EVERY), Say::Count(501));
        assert_eq!(r.note(t0 + SUMMARY_EVERY), Say::Nothing);
        assert_eq!(r.unsaid(), 1);
        assert_eq!(r.unsaid(), 0, "said once");
    }
}
