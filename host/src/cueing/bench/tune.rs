//! `--tune`: the classical washout's best tuning for the bench's drives and envelope, so that the optimal cueing
//! is compared with the best the washout does, not with its defaults.
//!
//! A small coordinate search: for each parameter in [`KNOBS`] in turn, every factor of [`FACTORS`] times its
//! current value (within the key's range) is tried on every drive, and the best kept; two passes over the
//! list. The score is the bench's: the RMS perceived specific-force error over the three axes, with a false cue
//! costing as much as [`FALSE_CUE_COST`] of it (a tuning that wins on RMS by adding false cues is not better).

use ringpod_core::cueing::CueConfig;

use super::{evaluate, Rig, Rows};
use crate::cueing::offline::{CueError, Preview};

/// The factors tried on each parameter.
pub const FACTORS: [f64; 6] = [0.4, 0.6, 0.8, 1.25, 1.6, 2.5];
/// Passes over the parameters.
pub const PASSES: usize = 2;
/// What one false cue adds to the score (m/s^2 of RMS error).
pub const FALSE_CUE_COST: f64 = 0.01;

/// A parameter the search turns: its name and where it sits in the configuration (each axis turned together).
type Knob = (&'static str, fn(&mut CueConfig, f64));

/// The parameters searched: the scales, the corners, the tilt's limits.
pub const KNOBS: [Knob; 8] = [
    ("translation_scale", |c, f| {
        c.translation_scale = c.translation_scale.map(|v| v * f)
    }),
    ("translation_high_pass.omega", |c, f| {
        c.translation_high_pass.iter_mut().for_each(|k| k.omega *= f)
    }),
    ("translation_break", |c, f| {
        c.translation_break = c.translation_break.map(|v| v * f)
    }),
    ("tilt_scale", |c, f| c.tilt_scale = c.tilt_scale.map(|v| v * f)),
    ("tilt_low_pass.omega", |c, f| {
        c.tilt_low_pass.iter_mut().for_each(|k| k.omega *= f)
    }),
    ("tilt_limit_deg", |c, f| {
        c.tilt_limit_deg = c.tilt_limit_deg.map(|v| v * f)
    }),
    ("tilt_rate_deg", |c, f| c.tilt_rate_deg = c.tilt_rate_deg.map(|v| v * f)),
    ("rotation_scale", |c, f| {
        c.rotation_scale = c.rotation_scale.map(|v| v * f)
    }),
];

/// The score of a configuration on the drives (lower is better).
pub fn cost(config: CueConfig, drives: &[Rows], from: &[usize], rig: &Rig) -> Result<f64, CueError> {
    let (e, _) = evaluate("", config, drives, from, rig, Preview::None)?;
    Ok(e.total.force_total() + FALSE_CUE_COST * e.total.false_total() as f64)
}

/// The best configuration found from `start`.
pub fn tune(start: CueConfig, drives: &[Rows], from: &[usize], rig: &Rig) -> Result<CueConfig, CueError> {
    let mut best = start;
    let mut best_cost = cost(best, drives, from, rig)?;
    for _ in 0..PASSES {
        for (_, turn) in KNOBS {
            let mut pass_best = (best, best_cost);
            for f in FACTORS {
                let mut c = best;
                turn(&mut c, f);
                // Out of a key's range: not a tuning.
                if c.validate().is_err() {
                    continue;
                }
                let k = cost(c, drives, from, rig)?;
                if k < pass_best.1 {
                    pass_best = (c, k);
                }
            }
            (best, best_cost) = pass_best;
        }
    }
    Ok(best)
}
