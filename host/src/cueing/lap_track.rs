//! A game's lap position ([`LapPosition`]) as the lap distance the preview follows: one number that grows along
//! the lap and wraps at the line.
//!
//! Two things the games' layouts need: Forza gives the distance travelled in the session and the lap's number
//! (the lap's distance is what was travelled since the number changed), and some layouts update the position
//! slower than the motion (rF2/LMU's scoring at 5 Hz against its telemetry at 50 Hz), so that it stands still for
//! several samples and then jumps. A position that has not changed is carried on at the rate of its last change
//! (for at most [`CARRY_S`]), and the distance given never goes back by less than a tenth of what was seen of the
//! lap (it holds until the game's value passes it): a wrap goes back by nearly a lap, a carry that ran ahead of the
//! game's next value is not a reversal.

use crate::games::LapPosition;

/// The longest a position that stands still is carried on (s): past it the game has stopped moving the car, or
/// stopped writing the position.
pub const CARRY_S: f64 = 0.5;

/// Turns lap positions into the lap distance.
#[derive(Debug, Clone, Default)]
pub struct LapTrack {
    /// Forza: the lap's number and the distance travelled when it began (none before the first change seen, or
    /// on the session's first lap, which begins at 0).
    lap_start: Option<(u32, Option<f64>)>,
    /// The last value the game gave (after Forza's subtraction), its time, and the rate of its last change.
    last: Option<(f64, f64)>,
    rate: f64,
    /// The last distance given, and the largest value seen (the lap's length, roughly).
    given: Option<f64>,
    seen_max: f64,
}

impl LapTrack {
    /// The lap distance at time `t` (s, increasing) of a sample at `position`; NaN when it is not known yet
    /// (Forza before its lap number first changes) or the game's value is not a number.
    pub fn distance(&mut self, t: f64, position: LapPosition) -> f64 {
        let raw = match position {
            LapPosition::Along(d) => d,
            LapPosition::Travelled { distance, lap } => {
                let start = match self.lap_start {
                    Some((n, start)) if n == lap => start,
                    previous => {
                        // The session's first lap begins at the line, at 0; a later one where its number changed;
                        // one under way when the stream joined, unknown.
                        let start = match previous {
                            None if lap == 0 => Some(0.0),
                            None => None,
                            Some(_) => Some(distance),
                        };
                        self.lap_start = Some((lap, start));
                        start
                    }
                };
                start.map_or(f64::NAN, |s| distance - s)
            }
        };
        if !raw.is_finite() {
            return raw;
        }
        self.seen_max = self.seen_max.max(raw);
        let carried = match self.last {
            Some((value, at)) if value == raw => raw + self.rate * (t - at).clamp(0.0, CARRY_S),
            Some((value, at)) => {
                let dt = t - at;
                self.rate = if raw > value && dt > 0.0 {
                    (raw - value) / dt
                } else {
                    0.0
                };
                self.last = Some((raw, t));
                raw
            }
            None => {
                self.last = Some((raw, t));
                raw
            }
        };
        let out = match self.given {
            // Behind what was given by less than a tenth of the lap: the carry ran ahead, hold.
            Some(g) if carried < g && g - carried < 0.1 * self.seen_max => g,
            _ => carried,
        };
        self.given = Some(out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_position_along_the_lap_passes_through_and_wraps() {
        let mut t = LapTrack::default();
        let d: Vec<f64> = [0.1, 0.5, 0.9, 0.02, 0.3]
            .iter()
            .enumerate()
            .map(|(k, &x)| t.distance(k as f64 * 0.1, LapPosition::Along(x)))
            .collect();
        assert_eq!(d, [0.1, 0.5, 0.9, 0.02, 0.3]);
    }

    /// rF2's scoring at 5 Hz under 50 Hz telemetry: carried on at its rate, never back by a small step, and the
    /// wrap still a wrap.
    #[test]
    fn a_slow_position_is_carried_on_and_never_steps_back() {
        let mut t = LapTrack::default();
        let mut out = Vec::new();
        for k in 0..200 {
            let time = k as f64 * 0.02;
            // The game's value: 40 m/s, updated every 0.2 s (10 samples), a 100 m lap.
            let game = (8.0 * (k / 10) as f64) % 100.0;
            out.push(t.distance(time, LapPosition::Along(game)));
        }
        let steps: Vec<f64> = out.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(
            steps.iter().all(|s| *s >= 0.0 || *s < -50.0),
            "no small step back: {steps:?}"
        );
        // Carried: between updates the distance moves on (all but the first update's samples).
        let still = steps[20..].iter().filter(|s| **s == 0.0).count();
        assert!(still < 10, "{still} samples stood still");
        assert!((out[150] - (40.0 * 3.0) % 100.0).abs() < 1.0, "{}", out[150]);
        assert_eq!(steps.iter().filter(|s| **s < -50.0).count(), 1, "one wrap at 2.5 s");
    }

    /// Forza: the distance since the lap number changed; nothing before a change seen (joined mid-lap), the
    /// first lap of a session from 0.
    #[test]
    fn forza_laps_from_the_distance_travelled_and_the_lap_number() {
        let mut t = LapTrack::default();
        let at =
            |t: &mut LapTrack, s: f64, distance: f64, lap: u32| t.distance(s, LapPosition::Travelled { distance, lap });
        assert!(at(&mut t, 0.0, 5000.0, 3).is_nan(), "joined mid-lap: not known");
        assert!(at(&mut t, 0.1, 5010.0, 3).is_nan(), "still not known");
        assert_eq!(at(&mut t, 1.0, 6000.0, 4), 0.0);
        assert_eq!(at(&mut t, 1.1, 6012.5, 4), 12.5);
        let mut fresh = LapTrack::default();
        assert_eq!(at(&mut fresh, 0.0, 3.0, 0), 3.0, "the first lap from the line");
        assert!(at(&mut fresh, 0.1, f64::NAN, 0).is_nan());
    }
}
