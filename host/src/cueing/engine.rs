//! The cueing a configuration asks for (`algorithm`): the core's classical washout or the host's optimal cueing,
//! behind one interface for `cue`, the bench and the workbench.

use ringpod_core::cueing::{Algorithm, ConfigError, CueConfig, SampleError, Telemetry, Washout};
use ringpod_core::kinematics::workspace::Check;
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins};

use super::optimal::{Counts, Envelope, Optimal, Ranges};
use crate::analysis::mechanism::AnyMechanism;

/// A running cueing.
pub enum Engine {
    /// The classical washout.
    Classical(Box<Washout<f64>>),
    /// The optimal cueing.
    Optimal(Box<Optimal>),
}

/// The envelope about `neutral` the optimal cueing plans in: each axis's range from the workspace scan.
pub fn ranges(mechanism: &RingPlatform<f64>, neutral: &Pose<f64>) -> Ranges {
    crate::analysis::workspace::ranges_about_home(&AnyMechanism::Ring(Box::new(*mechanism)), neutral.to_array())
}

/// The envelope about `neutral` the optimal cueing plans in: the ranges, and the rig for the tilt's shared room;
/// or the check `neutral` fails. Every cueing moves the platform about its neutral pose and the envelope limiter
/// cuts each pose back along the ray from it, so from a neutral pose outside the envelope no pose is inside: every
/// one would be cut towards, or held at, a pose the platform cannot take.
pub fn envelope(mechanism: &RingPlatform<f64>, neutral: &Pose<f64>) -> Result<Envelope, Check> {
    if let Some(check) = envelope::limit(mechanism, neutral, neutral, &EnvelopeMargins::default(), 1).bound_by {
        return Err(check);
    }
    Ok(Envelope {
        ranges: ranges(mechanism, neutral),
        rig: Some((*mechanism, *neutral)),
    })
}

impl Engine {
    /// The engine of `config` for a platform whose envelope about home is `envelope`.
    pub fn new(config: CueConfig, envelope: &Envelope) -> Result<Self, ConfigError> {
        Ok(match config.algorithm {
            Algorithm::Classical => Self::Classical(Box::new(Washout::new(config)?)),
            Algorithm::Optimal => Self::Optimal(Box::new(Optimal::new(config, envelope)?)),
        })
    }

    /// The first sample of a stream.
    pub fn begin(&mut self, sample: &Telemetry<f64>) -> Result<[f64; 6], SampleError> {
        match self {
            Self::Classical(w) => w.begin(sample),
            Self::Optimal(o) => o.begin(sample),
        }
    }

    /// One sample after `dt` seconds; `ahead`: the drive's next samples at the optimal cueing's steps (preview),
    /// or none.
    pub fn step(
        &mut self,
        sample: &Telemetry<f64>,
        dt: f64,
        ahead: &[Telemetry<f64>],
    ) -> Result<[f64; 6], SampleError> {
        match self {
            Self::Classical(w) => w.step(sample, dt),
            Self::Optimal(o) => o.step(sample, dt, ahead),
        }
    }

    /// The current offset from neutral.
    pub fn offset(&self) -> [f64; 6] {
        match self {
            Self::Classical(w) => w.offset(),
            Self::Optimal(o) => o.offset(),
        }
    }

    /// Back to neutral: the next sample is a first one.
    pub fn reset(&mut self) {
        match self {
            Self::Classical(w) => w.reset(),
            Self::Optimal(o) => o.reset(),
        }
    }

    /// The optimal cueing's counts (none for the classical washout).
    pub fn counts(&self) -> Option<&Counts> {
        match self {
            Self::Classical(_) => None,
            Self::Optimal(o) => Some(o.counts()),
        }
    }

    /// The samples ahead the optimal cueing looks at, with a preview: how many and at which step (s).
    pub fn horizon(&self) -> Option<(usize, f64)> {
        match self {
            Self::Optimal(o) => Some((o.config().optimal.horizon as usize, o.config().optimal.step_s)),
            Self::Classical(_) => None,
        }
    }
}

/// The samples at `t + k h` for `k = 1..=steps` of rows sorted by time (`t, ax, ay, az, wx, wy, wz`): each the
/// last row at or before its time (the drive's end held).
pub fn ahead(rows: &[(usize, Vec<f64>)], t: f64, steps: usize, h: f64) -> Vec<Telemetry<f64>> {
    if rows.is_empty() {
        return Vec::new();
    }
    (1..=steps)
        .map(|k| {
            let at = t + k as f64 * h;
            let i = rows.partition_point(|(_, v)| v[0] <= at).saturating_sub(1);
            row_sample(&rows[i].1)
        })
        .collect()
}

/// A telemetry row's sample (`t, ax, ay, az, wx, wy, wz`: the values after the time).
pub fn row_sample(v: &[f64]) -> Telemetry<f64> {
    Telemetry {
        force: [v[1], v[2], v[3]],
        rate: [v[4], v[5], v[6]],
    }
}

/// A pause in a drive: more than a second between two rows (a game's menu, its pause). The washout rests through it
/// and starts again at neutral from the row after it, as the live stream glides to neutral while a game is silent.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Pause {
    /// The row after the pause (its line, or its packet in a capture).
    pub line: usize,
    /// How long the drive paused (s).
    pub seconds: f64,
}
