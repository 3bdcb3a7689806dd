//! A washout that takes a new configuration while it runs (live tuning), without a jump.
//!
//! The hand-over: the new washout starts from the old one's state ([`Washout::retuned`]: channels, heading, each
//! filter's output and its rate carried), and for [`HANDOVER_S`] both run on the same samples while the offset
//! moves from the old one's to the new one's with the weight `w = 3 s^2 - 2 s^3` (`s` the fraction of the second
//! gone; a smooth step, flat at both ends). Between two samples the offset then changes by `(1 - w)` times the old
//! washout's own change plus `w` times the new one's (each no larger than the motion gives it) plus the change of
//! `w` (at most `1.5 dt / HANDOVER_S`) times the difference of the two offsets; at the switch itself nothing moves.
//! A configuration that arrives during a hand-over waits for its end (at most a second), so that no third
//! washout is blended in.

use super::{ConfigError, CueConfig, SampleError, Telemetry, Washout};
use crate::Real;

/// How long a hand-over from one configuration to the next lasts (s).
pub const HANDOVER_S: f64 = 1.0;

/// A washout that can be retuned while it runs.
#[derive(Debug, Clone)]
pub struct Live<T: Real> {
    /// The current configuration's washout (during a hand-over, the one blended in).
    washout: Washout<T>,
    /// During a hand-over: the previous washout and the time since the hand-over began (s).
    fading: Option<(Washout<T>, T)>,
    /// A configuration waiting for the hand-over in progress to end.
    pending: Option<CueConfig>,
}

impl<T: Real> Live<T> {
    /// At neutral; the configuration must be valid.
    pub fn new(config: CueConfig) -> Result<Self, ConfigError> {
        Ok(Self {
            washout: Washout::new(config)?,
            fading: None,
            pending: None,
        })
    }

    /// The configuration in force (the newest, once a hand-over has begun; a pending one not yet).
    pub fn config(&self) -> &CueConfig {
        self.washout.config()
    }

    /// Whether a hand-over is in progress.
    pub fn handing_over(&self) -> bool {
        self.fading.is_some()
    }

    /// Hands over to `config`: checked now (an invalid one is refused with its key, and the running one keeps
    /// going), blended in over [`HANDOVER_S`] from the next sample. Returns whether anything changes (a
    /// configuration equal to the one in force, or to the one waiting, changes nothing).
    pub fn retune(&mut self, config: CueConfig) -> Result<bool, ConfigError> {
        config.validate()?;
        if self.fading.is_some() {
            let changes = self.pending.map_or(config != *self.washout.config(), |p| p != config);
            self.pending = Some(config);
            return Ok(changes);
        }
        if config == *self.washout.config() {
            return Ok(false);
        }
        let new = self.washout.retuned(config)?;
        let old = core::mem::replace(&mut self.washout, new);
        self.fading = Some((old, T::zero()));
        Ok(true)
    }

    /// The weight of the new washout in the offset.
    fn weight(elapsed: T) -> T {
        let s = elapsed / T::of(HANDOVER_S);
        let s = if s > T::one() { T::one() } else { s };
        s * s * (T::of(3.0) - T::of(2.0) * s)
    }

    /// The first sample of a stream: [`Washout::begin`].
    pub fn begin(&mut self, sample: &Telemetry<T>) -> Result<[T; 6], SampleError> {
        if let Some((old, _)) = &mut self.fading {
            old.begin(sample)?;
        }
        self.washout.begin(sample)?;
        Ok(self.offset())
    }

    /// One sample `dt` seconds after the last: [`Washout::step`], blended during a hand-over.
    pub fn step(&mut self, sample: &Telemetry<T>, dt: T) -> Result<[T; 6], SampleError> {
        // Both washouts refuse the same samples, before they change anything.
        self.washout.step(sample, dt)?;
        if let Some((old, elapsed)) = &mut self.fading {
            old.step(sample, dt)?;
            *elapsed += dt;
        }
        let offset = self.offset();
        if self.fading.as_ref().is_some_and(|(_, e)| *e >= T::of(HANDOVER_S)) {
            self.fading = None;
            if let Some(config) = self.pending.take() {
                // Valid when it was taken; a refusal here could not happen and would leave things as they are.
                let _ = self.retune(config);
            }
        }
        Ok(offset)
    }

    /// The current offset from neutral, in platform axes.
    pub fn offset(&self) -> [T; 6] {
        let new = self.washout.offset();
        match &self.fading {
            None => new,
            Some((old, elapsed)) => {
                let w = Self::weight(*elapsed);
                let old = old.offset();
                core::array::from_fn(|i| old[i] + w * (new[i] - old[i]))
            }
        }
    }

    /// Back to neutral ([`Washout::reset`]); a hand-over in progress ends, and a waiting configuration takes
    /// over at once (from neutral there is nothing to blend).
    pub fn reset(&mut self) {
        self.fading = None;
        if let Some(config) = self.pending.take() {
            if let Ok(w) = self.washout.retuned(config) {
                self.washout = w;
            }
        }
        self.washout.reset();
    }
}
