//! The cueing a telemetry stream runs, retuned live when its file changes: the classical washout or the optimal
//! cueing (`algorithm`), a new tuning blended in over [`HANDOVER_S`] from the running one, as the core's
//! [`ringpod_core::cueing::Live`] does for the washout alone. The same algorithm carries its state into the new
//! tuning (the washout's filters retuned without a bump, the optimal cueing's platform and perception states
//! kept); a change of algorithm starts the new one at neutral on the next sample and blends it in.

use ringpod_core::cueing::{Algorithm, ConfigError, CueConfig, SampleError, Telemetry, Washout, HANDOVER_S};

use crate::cueing::engine::Engine;
use crate::cueing::lap::{self, LapPreview};
use crate::cueing::lap_track::LapTrack;
use crate::cueing::optimal::{Counts, Envelope};
use crate::games::LapPosition;

/// The lap preview of a stream: the laps driven, and the stream's own clock (the sum of its samples' intervals:
/// no wall clock, so that the same stream gives the same preview).
#[derive(Debug, Clone)]
struct Laps {
    preview: LapPreview,
    track: LapTrack,
    clock: f64,
}

/// What the stream's clock skips at a restart (s): more than the preview's longest interval, so that it takes the
/// restart as a pause and does not follow the lap across it.
const RESTART_SKIP_S: f64 = 2.0;

/// A stream's cueing.
pub struct LiveCueing {
    config: CueConfig,
    /// The platform's envelope about home, once the stream knows the rig.
    envelope: Option<Envelope>,
    /// The running engine; none while the optimal cueing waits for the envelope.
    engine: Option<Engine>,
    /// The engine has taken no sample yet (its next is a first one).
    fresh: bool,
    /// The engine before the last change and the time since (s), blended out.
    fading: Option<(Engine, f64)>,
    /// A change that came during a handover: taken when it ends.
    pending: Option<CueConfig>,
    /// The offset the cueing had when it started again at neutral (a pause, a restarted game), and the time since
    /// (s): blended out over [`HANDOVER_S`], so that the heading the yaw followed, or a tilt held, does not jump.
    restarted_from: Option<([f64; 6], f64)>,
    /// The optimal cueing's counts of the engines that faded out.
    retired: Counts,
    /// Whether an optimal cueing has run.
    optimal_ran: bool,
    /// The lap preview, when on: kept across retunes (the laps driven do not depend on the tuning).
    laps: Option<Laps>,
}

/// The handover's weight of the new engine after `elapsed` seconds: smooth from 0 to 1 over [`HANDOVER_S`].
fn weight(elapsed: f64) -> f64 {
    let s = (elapsed / HANDOVER_S).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

impl LiveCueing {
    /// The cueing of `config`; the optimal cueing is set up when the envelope is known ([`LiveCueing::place`]).
    pub fn new(config: CueConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let engine = match config.algorithm {
            Algorithm::Classical => Some(Engine::Classical(Box::new(Washout::new(config)?))),
            Algorithm::Optimal => None,
        };
        Ok(Self {
            config,
            envelope: None,
            engine,
            fresh: true,
            fading: None,
            pending: None,
            restarted_from: None,
            retired: Counts::default(),
            optimal_ran: false,
            laps: None,
        })
    }

    /// With the lap preview on or off: on, the optimal cueing's reference over its horizon is the best matching
    /// earlier lap's next seconds wherever the samples carry a lap position ([`LiveCueing::step_at`]); the
    /// classical washout has no horizon and is not changed.
    pub fn with_lap_preview(mut self, on: bool) -> Self {
        self.laps = on.then(|| Laps {
            preview: LapPreview::new(lap::Settings::default()),
            track: LapTrack::default(),
            clock: 0.0,
        });
        self
    }

    /// What the lap preview did and its state, when it is on.
    pub fn lap_counts(&self) -> Option<lap::Counts> {
        self.laps.as_ref().map(|l| l.preview.counts())
    }

    /// The lap preview's reference for the running engine after `dt` more seconds at `sample`, on `lap`: empty
    /// without a preview, a lap position or a horizon.
    fn ahead(&mut self, sample: &Telemetry<f64>, dt: f64, lap: Option<LapPosition>) -> Vec<Telemetry<f64>> {
        let Some(laps) = &mut self.laps else {
            return Vec::new();
        };
        laps.clock += dt.max(0.0);
        if let Some(position) = lap {
            let d = laps.track.distance(laps.clock, position);
            laps.preview.observe(laps.clock, d, sample);
        }
        match self.engine.as_ref().and_then(Engine::horizon) {
            Some((n, h)) => laps.preview.ahead(sample, n, h),
            None => Vec::new(),
        }
    }

    /// The platform's envelope about home: the optimal cueing plans in it.
    pub fn place(&mut self, envelope: Envelope) {
        self.envelope = Some(envelope);
        if self.engine.is_none() {
            // The configuration was checked when it was taken: the engine accepts it.
            self.engine = Engine::new(self.config, &envelope).ok();
            self.fresh = true;
        }
    }

    /// The running configuration.
    #[cfg(test)]
    pub fn config(&self) -> &CueConfig {
        &self.config
    }

    /// Whether a handover is under way.
    #[cfg(test)]
    pub fn handing_over(&self) -> bool {
        self.fading.is_some()
    }

    /// Takes a new configuration; returns whether it changes anything. A refused one changes nothing.
    pub fn retune(&mut self, config: CueConfig) -> Result<bool, ConfigError> {
        config.validate()?;
        if self.fading.is_some() {
            let changes = self.pending.map_or(config != self.config, |p| p != config);
            self.pending = Some(config);
            return Ok(changes);
        }
        if config == self.config {
            return Ok(false);
        }
        let new = match (&self.engine, self.envelope, config.algorithm) {
            (Some(Engine::Classical(w)), _, Algorithm::Classical) => {
                Some(Engine::Classical(Box::new(w.retuned(config)?)))
            }
            (Some(Engine::Optimal(o)), Some(r), Algorithm::Optimal) => {
                Some(Engine::Optimal(Box::new(o.retuned(config, &r)?)))
            }
            (_, _, Algorithm::Classical) => {
                self.fresh = true;
                Some(Engine::Classical(Box::new(Washout::new(config)?)))
            }
            (_, Some(r), Algorithm::Optimal) => {
                self.fresh = true;
                Some(Engine::new(config, &r)?)
            }
            (_, None, Algorithm::Optimal) => None,
        };
        self.config = config;
        let old = core::mem::replace(&mut self.engine, new);
        self.fade_out();
        match old {
            Some(e) if self.engine.is_some() => self.fading = Some((e, 0.0)),
            Some(e) => self.retire(e.counts().cloned()),
            None => {}
        }
        Ok(true)
    }

    /// The optimal cueing's counts over the whole stream (every engine it ran, faded out or running); none if
    /// it never ran.
    pub fn optimal_counts(&self) -> Option<Counts> {
        let running = [self.engine.as_ref(), self.fading.as_ref().map(|f| &f.0)];
        let any = self.optimal_ran || running.iter().flatten().any(|e| e.counts().is_some());
        any.then(|| {
            let mut all = self.retired.clone();
            for c in running.into_iter().flatten().filter_map(Engine::counts) {
                all.add(c);
            }
            all
        })
    }

    /// Ends the handover: the old engine's counts kept.
    fn fade_out(&mut self) {
        if let Some((old, _)) = self.fading.take() {
            self.retire(old.counts().cloned());
        }
    }

    fn retire(&mut self, counts: Option<Counts>) {
        if let Some(c) = counts {
            self.retired.add(&c);
            self.optimal_ran = true;
        }
    }

    /// The first sample of a stream.
    #[cfg(test)]
    pub fn begin(&mut self, sample: &Telemetry<f64>) -> Result<[f64; 6], SampleError> {
        self.begin_at(sample, None)
    }

    /// The first sample of a stream, on `lap` when the source says where the vehicle is on its lap.
    pub fn begin_at(&mut self, sample: &Telemetry<f64>, lap: Option<LapPosition>) -> Result<[f64; 6], SampleError> {
        // Observed only: a first sample has no interval to plan over.
        let _ = self.ahead(sample, 0.0, lap);
        if let Some((old, _)) = &mut self.fading {
            old.begin(sample)?;
        }
        if let Some(e) = &mut self.engine {
            e.begin(sample)?;
            self.fresh = false;
        }
        Ok(self.offset())
    }

    /// One sample after `dt` seconds.
    pub fn step(&mut self, sample: &Telemetry<f64>, dt: f64) -> Result<[f64; 6], SampleError> {
        self.step_at(sample, dt, None)
    }

    /// One sample after `dt` seconds, on `lap` when the source says where the vehicle is on its lap.
    pub fn step_at(
        &mut self,
        sample: &Telemetry<f64>,
        dt: f64,
        lap: Option<LapPosition>,
    ) -> Result<[f64; 6], SampleError> {
        let ahead = self.ahead(sample, dt, lap);
        let horizon = self.engine.as_ref().and_then(Engine::horizon);
        if let Some(e) = &mut self.engine {
            if self.fresh {
                e.begin(sample)?;
                self.fresh = false;
            } else {
                e.step(sample, dt, &ahead)?;
            }
        }
        if let Some((old, elapsed)) = &mut self.fading {
            // The reference is made for the running engine's horizon: an old engine of another takes none.
            let old_ahead = if old.horizon() == horizon { &ahead[..] } else { &[] };
            old.step(sample, dt, old_ahead)?;
            *elapsed += dt;
        }
        if let Some((_, elapsed)) = &mut self.restarted_from {
            *elapsed += dt;
        }
        let offset = self.offset();
        if self.restarted_from.is_some_and(|(_, e)| e >= HANDOVER_S) {
            self.restarted_from = None;
        }
        if self.fading.as_ref().is_some_and(|(_, e)| *e >= HANDOVER_S) {
            self.fade_out();
            if let Some(config) = self.pending.take() {
                let _ = self.retune(config);
            }
        }
        Ok(offset)
    }

    /// The offset from neutral: the running engine's, blended from the old one during a handover; neutral while
    /// the optimal cueing waits for the envelope (no sample is cued before the stream knows its rig).
    pub fn offset(&self) -> [f64; 6] {
        let new = self.engine.as_ref().map_or([0.0; 6], Engine::offset);
        let running = match &self.fading {
            None => new,
            Some((old, elapsed)) => {
                let w = weight(*elapsed);
                let old = old.offset();
                core::array::from_fn(|i| old[i] + w * (new[i] - old[i]))
            }
        };
        match self.restarted_from {
            None => running,
            Some((held, elapsed)) => {
                let w = weight(elapsed);
                core::array::from_fn(|i| held[i] + w * (running[i] - held[i]))
            }
        }
    }

    /// Back to neutral (a gap, a restarted game): the handover ends, a pending change is taken, and the offset the
    /// cueing had is blended out over [`HANDOVER_S`] rather than left in one step.
    pub fn reset(&mut self) {
        if let Some(laps) = &mut self.laps {
            laps.clock += RESTART_SKIP_S;
        }
        self.restarted_from = Some((self.offset(), 0.0));
        self.fade_out();
        if let Some(config) = self.pending.take() {
            let _ = self.retune(config);
            self.fade_out();
        }
        if let Some(e) = &mut self.engine {
            e.reset();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::cueing::G;

    fn ranges() -> crate::cueing::optimal::Ranges {
        [(-0.05, 0.05), (-0.05, 0.05), (-0.03, 0.03), (-0.3, 0.3), (-0.3, 0.3)]
    }

    fn braking() -> Telemetry<f64> {
        Telemetry {
            force: [-6.0, 0.0, G],
            rate: [0.0; 3],
        }
    }

    /// From the classical washout to the optimal cueing mid-stream: no jump, the new one blended in over the
    /// handover, and then alone.
    #[test]
    fn a_change_of_algorithm_blends_in_without_a_jump() {
        let mut c = LiveCueing::new(CueConfig::default()).unwrap();
        c.place(ranges().into());
        c.begin(&braking()).unwrap();
        let mut last = [0.0; 6];
        for _ in 0..50 {
            last = c.step(&braking(), 0.01).unwrap();
        }
        let optimal = CueConfig {
            algorithm: Algorithm::Optimal,
            ..CueConfig::default()
        };
        assert!(c.retune(optimal).unwrap());
        assert!(c.handing_over());
        let next = c.step(&braking(), 0.01).unwrap();
        for i in 0..6 {
            assert!((next[i] - last[i]).abs() < 2e-3, "axis {i}: {} -> {}", last[i], next[i]);
        }
        for _ in 0..100 {
            c.step(&braking(), 0.01).unwrap();
        }
        assert!(!c.handing_over());
        assert!(matches!(c.engine, Some(Engine::Optimal(_))));
        assert!(
            !c.retune(optimal).unwrap(),
            "the same configuration again changes nothing"
        );
    }

    /// A pause after a long braking: the tilt the washout held (nose down, gravity's share backwards) is not left
    /// in one step when the cueing starts again at neutral; it is blended out over the handover, the heading kept.
    #[test]
    fn a_restart_after_a_pause_blends_out_what_was_held() {
        let mut c = LiveCueing::new(CueConfig::default()).unwrap();
        c.begin(&braking()).unwrap();
        let before = (0..300).map(|_| c.step(&braking(), 0.01).unwrap()).last().unwrap();
        assert!(before[4] > 0.02, "the tilt held: {before:?}");
        c.reset();
        let rest = Telemetry {
            force: [0.0, 0.0, G],
            rate: [0.0; 3],
        };
        let first = c.begin(&rest).unwrap();
        for i in 0..6 {
            assert!(
                (first[i] - before[i]).abs() < 1e-9,
                "axis {i}: {first:?} after {before:?}"
            );
        }
        let mut last = first;
        for _ in 0..150 {
            let next = c.step(&rest, 0.01).unwrap();
            assert!((next[4] - last[4]).abs() < 0.005, "{} -> {}", last[4], next[4]);
            last = next;
        }
        assert!(
            last[..5].iter().all(|v| v.abs() < 1e-9),
            "at neutral after the handover: {last:?}"
        );
        assert_eq!(last[5], before[5], "the heading is kept");
    }

    #[test]
    fn the_optimal_cueing_waits_for_the_envelope() {
        let optimal = CueConfig {
            algorithm: Algorithm::Optimal,
            ..CueConfig::default()
        };
        let mut c = LiveCueing::new(optimal).unwrap();
        assert!(c.engine.is_none());
        assert_eq!(c.begin(&braking()).unwrap(), [0.0; 6]);
        c.place(ranges().into());
        c.begin(&braking()).unwrap();
        let o = (0..30).map(|_| c.step(&braking(), 0.01).unwrap()).last().unwrap();
        // Braking: nose down, gravity's share backwards (the optimiser may move either way meanwhile).
        assert!(o[4] > 0.005, "braking: nose down: {o:?}");
    }

    /// Every optimal engine's samples counted, running, fading out or gone: a retune of the optimal cueing
    /// and a change to the washout lose none; the washout alone reports none.
    #[test]
    fn the_optimal_counts_add_up_across_retunes() {
        let optimal = CueConfig {
            algorithm: Algorithm::Optimal,
            ..CueConfig::default()
        };
        let mut c = LiveCueing::new(optimal).unwrap();
        c.place(ranges().into());
        c.begin(&braking()).unwrap();
        let steps = |c: &mut LiveCueing, n: usize| {
            for _ in 0..n {
                c.step(&braking(), 0.01).unwrap();
            }
        };
        steps(&mut c, 30);
        let mut heavier = optimal;
        heavier.optimal.force_weight = [2.0; 3];
        assert!(c.retune(heavier).unwrap());
        steps(&mut c, 150);
        assert!(c.retune(CueConfig::default()).unwrap());
        steps(&mut c, 150);
        // The handover lasts 100 samples, in which the old engine plans too: 30 + 100, then 150 + 100.
        let counts = c.optimal_counts().unwrap();
        assert_eq!(counts.samples, 380, "{counts:?}");
        assert_eq!(counts.solve_s.len(), 380);
        assert!(LiveCueing::new(CueConfig::default())
            .unwrap()
            .optimal_counts()
            .is_none());
    }

    /// The laps driven are the stream's, not the tuning's: a reload of the cueing file keeps them, the match
    /// and the preview's share, and the new engine plans on the preview at once.
    #[test]
    fn a_retune_keeps_the_lap_preview() {
        let optimal = CueConfig {
            algorithm: Algorithm::Optimal,
            ..CueConfig::default()
        };
        let mut c = LiveCueing::new(optimal).unwrap().with_lap_preview(true);
        c.place(ranges().into());
        // Laps of 4 s: braking over the first second, at rest after.
        let at = |k: usize| {
            let s = (k % 400) as f64 / 400.0;
            let force = if s < 0.25 { [-6.0, 0.0, G] } else { [1.0, 0.0, G] };
            (Telemetry { force, rate: [0.0; 3] }, Some(LapPosition::Along(s)))
        };
        let (first, lap) = at(0);
        c.begin_at(&first, lap).unwrap();
        for k in 1..1000 {
            let (s, lap) = at(k);
            c.step_at(&s, 0.01, lap).unwrap();
        }
        let before = c.lap_counts().unwrap();
        assert_eq!((before.laps, before.kept), (2, 2), "{before:?}");
        assert_eq!(before.state.unwrap().confidence, 1.0);
        let mut heavier = optimal;
        heavier.optimal.force_weight = [2.0; 3];
        assert!(c.retune(heavier).unwrap());
        let (s, lap) = at(1000);
        assert_eq!(c.ahead(&s, 0.01, lap).len(), 8, "the new engine's horizon previewed");
        let after = c.lap_counts().unwrap();
        assert_eq!((after.laps, after.kept), (before.laps, before.kept));
        assert_eq!(after.state.unwrap().matched, before.state.unwrap().matched);
        assert_eq!(after.state.unwrap().confidence, 1.0);
    }
}
