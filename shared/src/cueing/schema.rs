//! What each washout parameter is, for a person setting it: its channel, its unit, its range or its few values
//! ([`PARAMS`]). The workbench's Cueing panel is built from this list (served by `ringpod ui`), so that it groups
//! the keys by channel and gives each its unit; the host's tests check that every key of [`super::CueConfig`] has
//! an entry here and that each range is the one [`super::CueConfig::validate`] enforces.

use super::config::{ROTATION_AXES, TILT_AXES, TRANSLATION_AXES};

/// The values a parameter takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Values {
    /// Any number from the first to the second.
    Range(f64, f64),
    /// One of these words.
    Words(&'static [&'static str]),
    /// One of these (whole) numbers.
    Numbers(&'static [u16]),
}

/// One parameter of the washout: a key of the cueing file, or one number of a key's table (a corner's `omega`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// The key as the cueing file writes it, a table's key after a dot: `yaw_scale`, `tilt_low_pass.omega`,
    /// `smoothing.window`. A per-axis key is a list of one value per axis (`translation_scale` is
    /// `[surge, sway, heave]`); its axis index goes after the key's first part (in the `optimal` table, after
    /// its second: `optimal.force_weight` is the list).
    pub key: &'static str,
    /// What it is, in a few words, for a label.
    pub name: &'static str,
    /// The axes of a per-axis key, in its list's order (none for a single value).
    pub axes: &'static [&'static str],
    /// The channel each axis belongs to, in the same order; the channel of a single value alone.
    pub channels: &'static [&'static str],
    /// The unit ("" for a ratio or a choice).
    pub unit: &'static str,
    /// The values it takes.
    pub values: Values,
    /// Read only when another parameter has this value (`smoothing.window` with `smoothing.kind` `median`), and
    /// then given this value when it appears.
    pub only_with: Option<(&'static str, &'static str, f64)>,
}

/// The channels in the order a person reads them: the algorithm and its parameters, the three translations, the tilt that cues a sustained force,
/// the three rotations, then what applies to all.
pub const CHANNELS: [&str; 10] = [
    "algorithm",
    "surge",
    "sway",
    "heave",
    "tilt coordination",
    "roll",
    "pitch",
    "yaw",
    "platform",
    "input smoothing",
];

/// The translational channels, in the order of the per-axis keys.
const TRANSLATION: &[&str] = &TRANSLATION_AXES;
/// Tilt coordination's two axes: the longitudinal force cued by pitch, the lateral force by roll.
const TILT: &[&str] = &["tilt coordination", "tilt coordination"];
/// Its axes as a label says them.
const TILT_LABELS: &[&str] = &["x (pitch)", "y (roll)"];
/// The rotational channels, in the order of the per-axis keys.
const ROTATION: &[&str] = &ROTATION_AXES;

/// A corner's natural frequency and damping, as [`super::CueConfig::validate`] bounds them.
const OMEGA: Values = Values::Range(1e-3, 1e3);
const ZETA: Values = Values::Range(0.05, 10.0);

const fn param(
    key: &'static str,
    name: &'static str,
    (axes, channels): (&'static [&'static str], &'static [&'static str]),
    unit: &'static str,
    values: Values,
) -> Param {
    Param {
        key,
        name,
        axes,
        channels,
        unit,
        values,
        only_with: None,
    }
}

/// A single value's channel.
const fn one(channel: &'static [&'static str]) -> (&'static [&'static str], &'static [&'static str]) {
    (&[], channel)
}

/// Every washout parameter, in the order of [`super::CueConfig`]'s fields.
pub const PARAMS: &[Param] = &[
    param(
        "translation_scale",
        "scale",
        (TRANSLATION, TRANSLATION),
        "",
        Values::Range(0.0, 10.0),
    ),
    param(
        "translation_limit",
        "force limit",
        (TRANSLATION, TRANSLATION),
        "m/s²",
        Values::Range(0.0, 100.0),
    ),
    param(
        "translation_high_pass.omega",
        "high-pass corner",
        (TRANSLATION, TRANSLATION),
        "rad/s",
        OMEGA,
    ),
    param(
        "translation_high_pass.zeta",
        "high-pass damping",
        (TRANSLATION, TRANSLATION),
        "",
        ZETA,
    ),
    param(
        "translation_break",
        "third-order break (0: off)",
        (TRANSLATION, TRANSLATION),
        "rad/s",
        Values::Range(0.0, 1e3),
    ),
    param("tilt_scale", "scale", (TILT_LABELS, TILT), "", Values::Range(0.0, 10.0)),
    param(
        "tilt_low_pass.omega",
        "low-pass corner",
        (TILT_LABELS, TILT),
        "rad/s",
        OMEGA,
    ),
    param("tilt_low_pass.zeta", "low-pass damping", (TILT_LABELS, TILT), "", ZETA),
    param(
        "tilt_limit_deg",
        "tilt limit",
        (TILT_LABELS, TILT),
        "deg",
        Values::Range(0.0, 45.0),
    ),
    param(
        "tilt_rate_deg",
        "tilt rate limit",
        (TILT_LABELS, TILT),
        "deg/s",
        Values::Range(0.0, 90.0),
    ),
    param(
        "rotation_scale",
        "rate scale",
        (ROTATION, ROTATION),
        "",
        Values::Range(0.0, 10.0),
    ),
    param(
        "rotation_limit",
        "rate limit",
        (ROTATION, ROTATION),
        "rad/s",
        Values::Range(0.0, 100.0),
    ),
    param(
        "rotation_high_pass.omega",
        "high-pass corner",
        (ROTATION, ROTATION),
        "rad/s",
        OMEGA,
    ),
    param(
        "rotation_high_pass.zeta",
        "high-pass damping",
        (ROTATION, ROTATION),
        "",
        ZETA,
    ),
    param(
        "yaw",
        "follows",
        one(&["yaw"]),
        "",
        Values::Words(&["heading", "washout"]),
    ),
    param("yaw_scale", "rate scale", one(&["yaw"]), "", Values::Range(0.0, 10.0)),
    param(
        "yaw_rate_limit",
        "rate limit",
        one(&["yaw"]),
        "rad/s",
        Values::Range(0.0, 100.0),
    ),
    param(
        "yaw_high_pass.omega",
        "high-pass corner (washout)",
        one(&["yaw"]),
        "rad/s",
        OMEGA,
    ),
    param(
        "yaw_high_pass.zeta",
        "high-pass damping (washout)",
        one(&["yaw"]),
        "",
        ZETA,
    ),
    param(
        "forward",
        "vehicle forward is",
        one(&["platform"]),
        "",
        Values::Words(&["+x", "+y", "-x", "-y"]),
    ),
    param(
        "smoothing.kind",
        "kind",
        one(&["input smoothing"]),
        "",
        Values::Words(&["off", "median", "low_pass"]),
    ),
    Param {
        only_with: Some(("smoothing.kind", "median", 5.0)),
        ..param(
            "smoothing.window",
            "median window",
            one(&["input smoothing"]),
            "samples",
            Values::Numbers(&[3, 5, 7, 9, 11, 13, 15]),
        )
    },
    Param {
        only_with: Some(("smoothing.kind", "low_pass", 8.0)),
        ..param(
            "smoothing.corner_hz",
            "low-pass corner",
            one(&["input smoothing"]),
            "Hz",
            Values::Range(0.01, 1000.0),
        )
    },
    Param {
        only_with: Some(("smoothing.kind", "low_pass", 2.0)),
        ..param(
            "smoothing.order",
            "low-pass order",
            one(&["input smoothing"]),
            "",
            Values::Numbers(&[1, 2]),
        )
    },
    param(
        "algorithm",
        "cueing",
        one(&["algorithm"]),
        "",
        Values::Words(&["classical", "optimal"]),
    ),
    param(
        "optimal.horizon",
        "optimal: horizon",
        one(&["algorithm"]),
        "steps",
        Values::Numbers(&[4, 6, 8, 10, 12, 16, 20, 30, 40, 60]),
    ),
    param(
        "optimal.step_s",
        "optimal: step",
        one(&["algorithm"]),
        "s",
        Values::Range(0.005, 0.5),
    ),
    param(
        "optimal.force_weight",
        "optimal: perceived force weight",
        (TRANSLATION, TRANSLATION),
        "",
        WEIGHT,
    ),
    param(
        "optimal.rotation_weight",
        "optimal: perceived rate weight",
        (ROTATION, ROTATION),
        "",
        WEIGHT,
    ),
    param(
        "optimal.position_weight",
        "optimal: return to neutral",
        (TRANSLATION, TRANSLATION),
        "",
        WEIGHT,
    ),
    param(
        "optimal.velocity_weight",
        "optimal: velocity weight",
        (TRANSLATION, TRANSLATION),
        "",
        WEIGHT,
    ),
    param(
        "optimal.tilt_weight",
        "optimal: tilt return to neutral",
        (TILT_LABELS, TILT),
        "",
        WEIGHT,
    ),
    param(
        "optimal.tilt_loss_weight",
        "optimal: the tilt's loss of vertical force",
        one(&["tilt coordination"]),
        "",
        WEIGHT,
    ),
    param(
        "optimal.plan_weight",
        "optimal: the tilt's plan kept from sample to sample",
        one(&["tilt coordination"]),
        "",
        WEIGHT,
    ),
    param(
        "optimal.acceleration_weight",
        "optimal: acceleration effort",
        (TRANSLATION, TRANSLATION),
        "",
        EFFORT,
    ),
    param(
        "optimal.rate_weight",
        "optimal: rate effort",
        (TILT_LABELS, TILT),
        "",
        EFFORT,
    ),
    param(
        "optimal.max_velocity",
        "optimal: velocity limit",
        (TRANSLATION, TRANSLATION),
        "m/s",
        Values::Range(1e-6, 10.0),
    ),
    param(
        "optimal.max_acceleration",
        "optimal: acceleration limit",
        (TRANSLATION, TRANSLATION),
        "m/s²",
        Values::Range(1e-6, 100.0),
    ),
    param(
        "optimal.max_rate_deg",
        "optimal: rate limit",
        (TILT_LABELS, TILT),
        "deg/s",
        Values::Range(1e-6, 720.0),
    ),
    param(
        "optimal.envelope_share",
        "optimal: share of the envelope",
        one(&["platform"]),
        "",
        Values::Range(0.05, 1.0),
    ),
    param(
        "optimal.tilt_share",
        "optimal: share of the tilt range",
        one(&["platform"]),
        "",
        Values::Range(0.05, 1.0),
    ),
    param(
        "optimal.budget_ms",
        "optimal: solve time counted late after",
        one(&["algorithm"]),
        "ms",
        Values::Range(0.01, 1000.0),
    ),
    param(
        "optimal.iterations",
        "optimal: solver iterations",
        one(&["algorithm"]),
        "",
        Values::Numbers(&[1, 5, 10, 15, 20, 30, 40, 60, 100, 200]),
    ),
];

/// A weight of the optimal cueing's cost, as [`super::OptimalConfig::validate`] bounds it.
const WEIGHT: Values = Values::Range(0.0, 1e6);
/// An effort weight: above zero (it keeps the programme strictly convex).
const EFFORT: Values = Values::Range(1e-9, 1e6);

// Each per-axis key has a channel per axis: the lists agree with the core's axis names.
const _: () = assert!(TRANSLATION.len() == TRANSLATION_AXES.len() && TILT.len() == TILT_AXES.len());
