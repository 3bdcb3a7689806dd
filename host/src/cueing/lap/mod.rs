//! Lap preview: racing laps repeat, and a game's telemetry says where the car is on the lap. The laps driven
//! are kept (the vehicle's cue input against the lap distance, resampled to a fixed grid over the lap), the
//! current lap is aligned to the earlier lap that matches it best *by distance* (not time: a lap's pace differs),
//! and the optimal cueing's reference over its horizon is that lap's next seconds, instead of the last sample
//! held ([`super::optimal::Optimal::step`]'s `ahead`).
//!
//! A lap that departs from its match (off the track, into the pits, a spin, another track) is noticed when the
//! alignment's error stays above a threshold for a fraction of a second, or at once when the lap distance is not
//! a distance (not finite, backwards, a jump no speed explains); the preview then fades out at a bounded rate (its
//! share of the reference moves by at most `dt / fade_s` a sample: no jump) and comes back once the lap matches
//! again. A lap with a departure is not kept. Everything runs on the samples' own times: no clock, so the same
//! drive gives the same preview on any machine.
//!
//! The lap distance may be in any unit that grows along the lap and wraps at its end (metres: rF2/LMU `mLapDist`,
//! F1 `m_lapDistance`; a fraction: AC/ACC `normalizedCarPosition`, iRacing `LapDistPct`): the lap's length is
//! learned from the first wrap and the speed is the distance's own rate.

use ringpod_core::cueing::{Telemetry, G};
use serde::Serialize;

mod report;
pub use report::{Counts, State};

/// What the optimal cueing's reference over its horizon is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Preview {
    /// The last sample held (a live game gives nothing ahead).
    #[default]
    None,
    /// A recorded drive's own next samples (the future known: a yardstick, not a live cueing).
    Drive,
    /// The laps driven before, aligned by the lap distance (the drive's `lap_distance` column).
    Lap,
}

/// The telemetry CSV's optional column: the lap distance (any unit that grows along the lap and wraps).
pub const LAP_DISTANCE: &str = "lap_distance";

/// The preview's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Grid points over a lap.
    pub bins: usize,
    /// The current lap's recent stretch the alignment compares (s).
    pub window_s: f64,
    /// The alignment's search about the lap distance, either way (s at the current speed).
    pub max_shift_s: f64,
    /// The alignment's RMS specific-force error above which the lap departs (m/s^2)...
    pub threshold: f64,
    /// ...for this long (s).
    pub hold_s: f64,
    /// The preview's share fades from 1 to 0 (and back) over this (s).
    pub fade_s: f64,
    /// After a departure, the error below half the threshold for this long brings the preview back (s).
    pub rejoin_s: f64,
    /// Laps kept (the oldest dropped).
    pub max_laps: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            bins: 2048,
            window_s: 0.5,
            max_shift_s: 0.4,
            threshold: 3.0,
            hold_s: 0.15,
            fade_s: 0.5,
            rejoin_s: 1.0,
            max_laps: 8,
        }
    }
}

/// One sample of the vehicle's input: specific force (less g on z) and rates.
type Input = [f64; 6];

fn input(s: &Telemetry<f64>) -> Input {
    [s.force[0], s.force[1], s.force[2] - G, s.rate[0], s.rate[1], s.rate[2]]
}

/// A sample as recorded on the current lap.
#[derive(Debug, Clone, Copy)]
struct Raw {
    /// Time since the lap's start (s).
    t: f64,
    s: f64,
    v: Input,
}

/// A kept lap on the grid: the time since its start and the input at each grid point.
#[derive(Debug, Clone)]
struct Lap {
    number: usize,
    t: Vec<f64>,
    v: Vec<Input>,
}

impl Lap {
    /// Grid position `x` (in bins, fractional), clamped to the lap.
    fn at(&self, x: f64) -> (f64, Input) {
        let n = self.t.len();
        let x = x.clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n - 2);
        let f = x - i as f64;
        let (a, b) = (&self.v[i], &self.v[i + 1]);
        (
            self.t[i] + (self.t[i + 1] - self.t[i]) * f,
            core::array::from_fn(|j| a[j] + (b[j] - a[j]) * f),
        )
    }

    /// The grid position (fractional) the lap reached at time `t` since its start; past its end, wrapped to its
    /// start (the next lap, approximately this one again).
    fn position_at(&self, t: f64) -> f64 {
        let end = self.t[self.t.len() - 1];
        let t = if t > end && end > 0.0 { (t - end).min(end) } else { t };
        let j = self.t.partition_point(|&x| x <= t);
        if j == 0 {
            return 0.0;
        }
        if j >= self.t.len() {
            return (self.t.len() - 1) as f64;
        }
        let (a, b) = (self.t[j - 1], self.t[j]);
        (j - 1) as f64 + if b > a { (t - a) / (b - a) } else { 0.0 }
    }
}

/// The lap preview of one stream or drive.
#[derive(Debug, Clone)]
pub struct LapPreview {
    settings: Settings,
    /// The lap's length (in the distance's unit), learned at the first wrap.
    length: Option<f64>,
    laps: Vec<Lap>,
    current: Vec<Raw>,
    lap: usize,
    /// The current lap's start time and the last sample's time and distance.
    start_t: f64,
    last: Option<(f64, f64)>,
    /// The distance's rate, smoothed (unit per s).
    speed: f64,
    clean: bool,
    /// The matched lap (its index in `laps`) and shift (bins).
    matched: Option<(usize, f64)>,
    error: f64,
    over_s: f64,
    under_s: f64,
    departed: bool,
    confidence: f64,
    counts: Counts,
}

impl LapPreview {
    /// A preview with no lap yet.
    pub fn new(settings: Settings) -> Self {
        Self {
            // A grid of two points at least: a lap's lookups interpolate between neighbours.
            settings: Settings {
                bins: settings.bins.max(2),
                ..settings
            },
            length: None,
            laps: Vec::new(),
            current: Vec::new(),
            lap: 0,
            start_t: 0.0,
            last: None,
            speed: 0.0,
            clean: true,
            matched: None,
            error: 0.0,
            over_s: 0.0,
            under_s: 0.0,
            departed: false,
            confidence: 0.0,
            counts: Counts::default(),
        }
    }

    /// What it did so far.
    pub fn counts(&self) -> Counts {
        Counts {
            state: Some(self.state()),
            ..self.counts
        }
    }

    /// Its present state.
    pub fn state(&self) -> State {
        State {
            lap: self.lap,
            matched: self.matched.map(|(m, _)| self.laps[m].number),
            confidence: self.confidence,
            error: self.error,
        }
    }

    /// The grid's spacing (distance per bin).
    fn bin(&self) -> Option<f64> {
        self.length.map(|l| l / self.settings.bins as f64)
    }

    /// One sample at time `t` (s, increasing) with the lap distance `distance` (NaN where the source has none).
    pub fn observe(&mut self, t: f64, distance: f64, sample: &Telemetry<f64>) {
        let mut dt = self.last.map_or(0.0, |(lt, _)| t - lt);
        if self.last.is_some() && !(dt > 0.0 && dt <= 1.0) {
            // A pause or time not moving on: the lap cannot be followed across it.
            self.depart(true);
            self.last = None;
            dt = 0.0;
        }
        let v = input(sample);
        if !distance.is_finite() || !v.iter().all(|x| x.is_finite()) {
            self.counts.bad_distance += 1;
            self.depart(true);
            // The time moves on (the fade's rate is per second); the distance stays the last good one.
            if let Some((_, ls)) = self.last {
                self.last = Some((t, ls));
            }
            return self.fade(dt);
        }
        match self.last {
            None => self.start_lap(t, distance, false),
            Some((_, ls)) => {
                let length = self.length.unwrap_or(ls);
                if distance < ls - 0.5 * length {
                    self.start_lap(t, distance, true);
                } else if distance < ls {
                    // Backwards: a spin, reversing, or the source's jitter. Not recorded; more than a bin is a
                    // departure.
                    self.counts.bad_distance += 1;
                    if ls - distance > self.bin().unwrap_or(0.0).max(1e-9) {
                        self.depart(true);
                    }
                    self.last = Some((t, ls));
                    return self.fade(dt);
                } else {
                    let step = distance - ls;
                    let limit = 3.0 * self.speed.max(0.0) * dt + self.bin().unwrap_or(f64::INFINITY) * 4.0;
                    if self.speed > 0.0 && step > limit {
                        // A jump no speed explains: the pits, a reset to the track.
                        self.counts.bad_distance += 1;
                        self.depart(true);
                    } else {
                        let rate = step / dt;
                        let a = (dt / 0.2).min(1.0);
                        self.speed += (rate - self.speed) * a;
                    }
                }
            }
        }
        self.last = Some((t, distance));
        self.current.push(Raw {
            t: t - self.start_t,
            s: distance,
            v,
        });
        self.align();
        self.detect(dt);
        self.fade(dt);
    }

    /// Starts a lap at this sample; `wrapped`: the last one was completed (kept if whole and clean).
    fn start_lap(&mut self, t: f64, distance: f64, wrapped: bool) {
        if wrapped {
            self.counts.laps += 1;
            let last = self.current.last().map_or(distance, |r| r.s);
            let length = *self.length.get_or_insert(last);
            if self.clean {
                if let Some(lap) = self.resample(length) {
                    self.laps.push(lap);
                    self.counts.kept += 1;
                    if self.laps.len() > self.settings.max_laps {
                        self.laps.remove(0);
                        self.matched = None;
                    }
                }
            }
            self.lap += 1;
        }
        self.current.clear();
        self.start_t = t;
        self.clean = !self.departed;
        // The match's shift carries over (the alignment searches about it); the grid position starts again.
    }

    /// The current lap on the grid, if it covers the lap (from its first 2 % to its last 2 %).
    fn resample(&self, length: f64) -> Option<Lap> {
        let (first, last) = (self.current.first()?, self.current.last()?);
        if first.s > 0.02 * length || last.s < 0.98 * length || self.current.len() < 2 {
            return None;
        }
        let n = self.settings.bins;
        let (mut t, mut v) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        let mut i = 0;
        for j in 0..=n {
            let s = length * j as f64 / n as f64;
            while i + 2 < self.current.len() && self.current[i + 1].s < s {
                i += 1;
            }
            let (a, b) = (&self.current[i], &self.current[i + 1]);
            let f = if b.s > a.s {
                ((s - a.s) / (b.s - a.s)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            t.push(a.t + (b.t - a.t) * f);
            v.push(core::array::from_fn(|k| a.v[k] + (b.v[k] - a.v[k]) * f));
        }
        Some(Lap { number: self.lap, t, v })
    }

    /// Aligns the current lap's recent stretch to every kept lap at every shift in the search: the least
    /// RMS specific-force error wins, a change of shift or lap priced so that the match does not hop on noise.
    fn align(&mut self) {
        let (Some(bin), Some(&now)) = (self.bin(), self.current.last()) else {
            return;
        };
        if self.laps.is_empty() {
            return;
        }
        let from = now.t - self.settings.window_s;
        let window: Vec<&Raw> = {
            let recent: Vec<&Raw> = self.current.iter().rev().take_while(|r| r.t >= from).collect();
            let every = (recent.len() / 25).max(1);
            recent.into_iter().step_by(every).collect()
        };
        let reach = ((self.settings.max_shift_s * self.speed.max(0.0)) / bin)
            .ceil()
            .min(200.0) as i64;
        let (prev_lap, prev_shift) = self.matched.map_or((usize::MAX, 0.0), |(m, s)| (m, s));
        let seconds_per_bin = if self.speed > 0.0 { bin / self.speed } else { 0.0 };
        let mut best = (f64::INFINITY, 0, 0.0, 0.0);
        for (m, lap) in self.laps.iter().enumerate() {
            for d in -reach..=reach {
                let shift = d as f64;
                let mut sum = 0.0;
                for r in &window {
                    let (_, v) = lap.at(r.s / bin + shift);
                    sum += (0..3).map(|k| (r.v[k] - v[k]).powi(2)).sum::<f64>();
                }
                let error = sum / window.len() as f64;
                let moved = (shift - prev_shift) * seconds_per_bin / 0.1;
                let price = 0.05 * moved * moved + if m == prev_lap { 0.0 } else { 0.2 };
                if error + price < best.0 {
                    best = (error + price, m, shift, error);
                }
            }
        }
        if best.0.is_finite() {
            self.error = best.3.sqrt();
            // A match is taken only where it matches: off the track the best shift is noise, and the preview
            // keeps the last good one while it fades.
            if self.error <= self.settings.threshold {
                self.matched = Some((best.1, best.2));
            }
        }
    }

    /// Departure: the alignment's error above the threshold for `hold_s`; rejoin: below half of it for
    /// `rejoin_s` (a departure counts once a lap was matched).
    fn detect(&mut self, dt: f64) {
        if self.laps.is_empty() {
            return;
        }
        let s = &self.settings;
        if self.error > s.threshold {
            self.over_s += dt;
            self.under_s = 0.0;
            if self.over_s >= s.hold_s && self.matched.is_some() {
                self.depart(false);
            }
        } else {
            self.over_s = 0.0;
            if self.error < 0.5 * s.threshold {
                self.under_s += dt;
            } else {
                self.under_s = 0.0;
            }
            if self.departed && self.under_s >= s.rejoin_s {
                self.departed = false;
            }
        }
    }

    /// The lap departs (`lost`: the lap distance itself cannot be followed, and the match is dropped).
    fn depart(&mut self, lost: bool) {
        if !self.departed {
            self.departed = true;
            self.counts.departures += 1;
        }
        self.clean = false;
        self.under_s = 0.0;
        if lost {
            self.matched = None;
        }
    }

    /// The preview's share moves towards 1 (matched, not departed) or 0 by at most `dt / fade_s`.
    fn fade(&mut self, dt: f64) {
        let target = if self.matched.is_some() && !self.departed {
            1.0
        } else {
            0.0
        };
        let step = dt / self.settings.fade_s;
        self.confidence += (target - self.confidence).clamp(-step, step);
        if self.confidence > 0.0 {
            self.counts.previewed_s += dt;
        }
        if self.departed {
            self.counts.departed_s += dt;
        }
    }

    /// The reference's samples at `k h` ahead (`k = 1..=steps`): the matched lap's, from where it was at this
    /// lap's distance and on at the pace the speeds' ratio gives, blended with `held` (the present sample) by the
    /// preview's share; nothing (the sample held) without a share.
    pub fn ahead(&self, held: &Telemetry<f64>, steps: usize, h: f64) -> Vec<Telemetry<f64>> {
        let (Some((m, shift)), Some(bin), Some((_, s))) = (self.matched, self.bin(), self.last) else {
            return Vec::new();
        };
        if self.confidence <= 0.0 {
            return Vec::new();
        }
        let lap = &self.laps[m];
        let x = s / bin + shift;
        let (t0, _) = lap.at(x);
        let (ta, _) = lap.at(x - 1.0);
        let (tb, _) = lap.at(x + 1.0);
        let lap_speed = if tb > ta { 2.0 * bin / (tb - ta) } else { self.speed };
        let pace = if lap_speed > 0.0 {
            (self.speed / lap_speed).clamp(0.5, 2.0)
        } else {
            1.0
        };
        let now = input(held);
        let c = self.confidence;
        (1..=steps)
            .map(|k| {
                let (_, v) = lap.at(lap.position_at(t0 + k as f64 * h * pace));
                let b: Input = core::array::from_fn(|j| now[j] + c * (v[j] - now[j]));
                Telemetry {
                    force: [b[0], b[1], b[2] + G],
                    rate: [b[3], b[4], b[5]],
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests;
