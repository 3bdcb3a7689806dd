//! The washout's parameters ([`CueConfig`]): every key with its default and range, per axis where the axes differ,
//! checked as a whole ([`CueConfig::validate`]) with errors that name the key and the axis.

use super::axes;
use super::optimal::{Algorithm, OptimalConfig};
use super::smoothing::Smoothing;

/// Which platform direction faces the vehicle's forward.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Forward {
    /// The platform's +x (default).
    #[default]
    #[serde(rename = "+x")]
    PlusX,
    /// The platform's +y.
    #[serde(rename = "+y")]
    PlusY,
    /// The platform's -x.
    #[serde(rename = "-x")]
    MinusX,
    /// The platform's -y.
    #[serde(rename = "-y")]
    MinusY,
}

/// How the yaw channel follows the vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum YawMode {
    /// One to one with the vehicle's heading, continuous (a ring platform turns without limit), the rate within
    /// the yaw-rate limit (default).
    #[default]
    Heading,
    /// High-passed like roll and pitch: onset cues only, back to the neutral heading.
    Washout,
}

/// A second-order filter's corner (rad/s) and damping.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Corner {
    /// Natural frequency (rad/s).
    pub omega: f64,
    /// Damping ratio.
    pub zeta: f64,
}

/// The washout's parameters. Every field has a documented default (the trainer model, 1:20: a car's forces
/// scaled into +-50 mm and +-20 deg); a TOML file names only what it changes.
///
/// Per-axis keys take a list (translation: surge, sway, heave, the vehicle's x, y, z; tilt: x and y, the
/// longitudinal force's pitch and the lateral force's roll; rotation: roll, pitch) or one value for every axis, as
/// the files written before the axes were separate do ([`axes::one_or_each`]): such a file reads as it did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CueConfig {
    /// Scale of the specific force into the translational channel, per vehicle axis (default 0.1, 0.1, 0.1).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub translation_scale: [f64; 3],
    /// Limit of the scaled specific force, per vehicle axis (m/s^2; default 6).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub translation_limit: [f64; 3],
    /// High-pass of the translational channel, surge, sway, heave (default 4 rad/s, damping 1, each).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub translation_high_pass: [Corner; 3],
    /// Third-order break of the translational channel (rad/s), which brings a sustained force back to neutral,
    /// per vehicle axis; 0 keeps second order (default 1).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub translation_break: [f64; 3],
    /// Scale of the specific force into tilt coordination, x and y (default 0.6).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub tilt_scale: [f64; 2],
    /// Low-pass of tilt coordination, x and y (default 5 rad/s, damping 1).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub tilt_low_pass: [Corner; 2],
    /// Largest tilt angle, x (pitch) and y (roll) (deg; default 15).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub tilt_limit_deg: [f64; 2],
    /// Tilt rate limit, below the perception threshold, x and y (deg/s; default 3).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub tilt_rate_deg: [f64; 2],
    /// Scale of the roll and pitch rates (default 0.5).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub rotation_scale: [f64; 2],
    /// Limit of the scaled roll and pitch rates (rad/s; default 1).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub rotation_limit: [f64; 2],
    /// High-pass of the roll and pitch rates (default 1 rad/s, damping 1).
    #[serde(deserialize_with = "axes::one_or_each")]
    pub rotation_high_pass: [Corner; 2],
    /// How yaw follows (default heading, one to one).
    pub yaw: YawMode,
    /// Scale of the yaw rate (default 1).
    pub yaw_scale: f64,
    /// Yaw-rate limit (rad/s; default 1.9, the trainer model's).
    pub yaw_rate_limit: f64,
    /// High-pass of the yaw rate in washout mode (default 0.5 rad/s, damping 1).
    pub yaw_high_pass: Corner,
    /// Which platform direction faces the vehicle's forward (default +x).
    pub forward: Forward,
    /// Smoothing of the telemetry before the washout (default off).
    pub smoothing: Smoothing,
    /// Which cueing runs: the classical washout (default) or the optimal cueing (on the host).
    pub algorithm: Algorithm,
    /// The optimal cueing's parameters (`[optimal]`), read whichever algorithm runs.
    pub optimal: OptimalConfig,
}

impl Default for CueConfig {
    fn default() -> Self {
        Self {
            translation_scale: [0.1; 3],
            translation_limit: [6.0; 3],
            translation_high_pass: [Corner { omega: 4.0, zeta: 1.0 }; 3],
            translation_break: [1.0; 3],
            tilt_scale: [0.6; 2],
            tilt_low_pass: [Corner { omega: 5.0, zeta: 1.0 }; 2],
            tilt_limit_deg: [15.0; 2],
            tilt_rate_deg: [3.0; 2],
            rotation_scale: [0.5; 2],
            rotation_limit: [1.0; 2],
            rotation_high_pass: [Corner { omega: 1.0, zeta: 1.0 }; 2],
            yaw: YawMode::Heading,
            yaw_scale: 1.0,
            yaw_rate_limit: 1.9,
            yaw_high_pass: Corner { omega: 0.5, zeta: 1.0 },
            forward: Forward::PlusX,
            smoothing: Smoothing::Off,
            algorithm: Algorithm::Classical,
            optimal: OptimalConfig::default(),
        }
    }
}

/// The names of the translational axes, in the order of the per-axis keys.
pub const TRANSLATION_AXES: [&str; 3] = ["surge", "sway", "heave"];
/// The names of the tilt axes (the force they cue), in the order of the per-axis keys.
pub const TILT_AXES: [&str; 2] = ["x", "y"];
/// The names of the rotational axes, in the order of the per-axis keys.
pub const ROTATION_AXES: [&str; 2] = ["roll", "pitch"];

/// A parameter out of its range: its key, the axis of a per-axis key, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigError {
    /// The key, as in the TOML file.
    pub key: &'static str,
    /// The axis, for a per-axis key (`surge`, `sway`, `heave`; `x`, `y`; `roll`, `pitch`).
    pub axis: Option<&'static str>,
    /// What it must be.
    pub must: &'static str,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.axis {
            Some(axis) => write!(f, "{} ({axis}) must be {}", self.key, self.must),
            None => write!(f, "{} must be {}", self.key, self.must),
        }
    }
}

impl CueConfig {
    /// Checks every parameter; the error names the first key out of range (and its axis).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let err = |key, must| Err(ConfigError { key, axis: None, must });
        let in_range = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        let corner_ok = |c: &Corner| in_range(c.omega, 1e-3, 1e3) && in_range(c.zeta, 0.05, 10.0);
        const CORNER: &str = "omega 0.001-1000 rad/s, zeta 0.05-10";
        // The first axis of a per-axis key that fails.
        fn each<const N: usize, V>(
            key: &'static str,
            names: [&'static str; N],
            values: &[V; N],
            ok: impl Fn(&V) -> bool,
            must: &'static str,
        ) -> Result<(), ConfigError> {
            match values.iter().position(|v| !ok(v)) {
                Some(i) => Err(ConfigError {
                    key,
                    axis: Some(names[i]),
                    must,
                }),
                None => Ok(()),
            }
        }
        let (t, l, r) = (TRANSLATION_AXES, TILT_AXES, ROTATION_AXES);
        each(
            "translation_scale",
            t,
            &self.translation_scale,
            |v| in_range(*v, 0.0, 10.0),
            "0 to 10",
        )?;
        each(
            "translation_limit",
            t,
            &self.translation_limit,
            |v| in_range(*v, 0.0, 100.0),
            "0 to 100 m/s^2",
        )?;
        each(
            "translation_high_pass",
            t,
            &self.translation_high_pass,
            corner_ok,
            CORNER,
        )?;
        each(
            "translation_break",
            t,
            &self.translation_break,
            |v| in_range(*v, 0.0, 1e3),
            "0 (second order) to 1000 rad/s",
        )?;
        each(
            "tilt_scale",
            l,
            &self.tilt_scale,
            |v| in_range(*v, 0.0, 10.0),
            "0 to 10",
        )?;
        each("tilt_low_pass", l, &self.tilt_low_pass, corner_ok, CORNER)?;
        each(
            "tilt_limit_deg",
            l,
            &self.tilt_limit_deg,
            |v| in_range(*v, 0.0, 45.0),
            "0 to 45 deg",
        )?;
        each(
            "tilt_rate_deg",
            l,
            &self.tilt_rate_deg,
            |v| in_range(*v, 0.0, 90.0),
            "0 to 90 deg/s",
        )?;
        each(
            "rotation_scale",
            r,
            &self.rotation_scale,
            |v| in_range(*v, 0.0, 10.0),
            "0 to 10",
        )?;
        each(
            "rotation_limit",
            r,
            &self.rotation_limit,
            |v| in_range(*v, 0.0, 100.0),
            "0 to 100 rad/s",
        )?;
        each("rotation_high_pass", r, &self.rotation_high_pass, corner_ok, CORNER)?;
        if !in_range(self.yaw_scale, 0.0, 10.0) {
            return err("yaw_scale", "0 to 10");
        }
        if !in_range(self.yaw_rate_limit, 0.0, 100.0) {
            return err("yaw_rate_limit", "0 to 100 rad/s");
        }
        if !corner_ok(&self.yaw_high_pass) {
            return err("yaw_high_pass", CORNER);
        }
        self.smoothing.check().or_else(|(key, must)| err(key, must))?;
        self.optimal.validate().or_else(|(key, must)| err(key, must))
    }
}
