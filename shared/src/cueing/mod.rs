//! Motion cueing: vehicle telemetry (specific force and angular rates) in, platform pose out, by the classical
//! washout algorithm (Reid and Nahon; Conrad and Schmidt).
//!
//! ```text
//! f (vehicle) --scale, limit--+--> high-pass 2nd order + 1/s^2 --> (3rd order: s/(s+wb)) ----> surge, sway, heave
//!                             |
//!                             +--> low-pass 2nd order --> asin(f/g) --> rate limit --------+--> roll, pitch
//! w_x, w_y --scale, limit-------> high-pass 2nd order + 1/s ------------------------------+
//! w_z -----scale, limit---------> 1/s within the yaw-rate limit (heading) | high-pass + 1/s ---> yaw
//! ```
//!
//! Onset cues come from translation and rotation, high-passed so that the platform returns to neutral; a
//! sustained force comes from tilting the platform so that gravity supplies it (tilt coordination), slowly
//! enough (below the perception threshold) not to be felt as a rotation. A ring platform turns without limit, so
//! the vehicle's heading can be followed one to one.
//!
//! Conventions: the vehicle frame is x forward, y left, z up; specific force in m/s^2 (a vehicle at rest reads
//! `+9.81` on z); rates in rad/s. A platform rolled by `alpha` delivers `g sin(alpha)` on its y axis, pitched by
//! `beta` it delivers `-g sin(beta)` on its x axis ([`delivered`]), so a sustained forward force pitches the nose
//! up (`beta < 0`) and a force to the left rolls the right side down (`alpha > 0`). Every filter is discretised by
//! Tustin at each sample's interval ([`filter`]). Generic over `f32`/`f64`, no allocation, no panics.

pub mod filter;

use filter::{Biquad, Section};

use crate::kinematics::Pose;
use crate::Real;

/// Standard gravity (m/s^2).
pub const G: f64 = 9.80665;

/// One telemetry sample: specific force and angular rates in the vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Telemetry<T> {
    /// Specific force `[x, y, z]` (m/s^2): x forward, y left, z up; `+9.81` on z at rest.
    pub force: [T; 3],
    /// Angular rates `[roll, pitch, yaw]` about x, y, z (rad/s).
    pub rate: [T; 3],
}

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
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CueConfig {
    /// Scale of the specific force into the translational channel, per vehicle axis (default 0.1, 0.1, 0.1).
    pub translation_scale: [f64; 3],
    /// Limit of the scaled specific force, per vehicle axis (m/s^2; default 6).
    pub translation_limit: [f64; 3],
    /// High-pass of the translational channel (default 4 rad/s, damping 1).
    pub translation_high_pass: Corner,
    /// Third-order break of the translational channel (rad/s), which brings a sustained force back to neutral;
    /// 0 keeps second order (default 1).
    pub translation_break: f64,
    /// Scale of the specific force into tilt coordination, x and y (default 0.6).
    pub tilt_scale: [f64; 2],
    /// Low-pass of tilt coordination (default 5 rad/s, damping 1).
    pub tilt_low_pass: Corner,
    /// Largest tilt angle (deg; default 15).
    pub tilt_limit_deg: f64,
    /// Tilt rate limit, below the perception threshold (deg/s; default 3).
    pub tilt_rate_deg: f64,
    /// Scale of the roll and pitch rates (default 0.5).
    pub rotation_scale: [f64; 2],
    /// Limit of the scaled roll and pitch rates (rad/s; default 1).
    pub rotation_limit: f64,
    /// High-pass of the roll and pitch rates (default 1 rad/s, damping 1).
    pub rotation_high_pass: Corner,
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
}

impl Default for CueConfig {
    fn default() -> Self {
        Self {
            translation_scale: [0.1; 3],
            translation_limit: [6.0; 3],
            translation_high_pass: Corner { omega: 4.0, zeta: 1.0 },
            translation_break: 1.0,
            tilt_scale: [0.6; 2],
            tilt_low_pass: Corner { omega: 5.0, zeta: 1.0 },
            tilt_limit_deg: 15.0,
            tilt_rate_deg: 3.0,
            rotation_scale: [0.5; 2],
            rotation_limit: 1.0,
            rotation_high_pass: Corner { omega: 1.0, zeta: 1.0 },
            yaw: YawMode::Heading,
            yaw_scale: 1.0,
            yaw_rate_limit: 1.9,
            yaw_high_pass: Corner { omega: 0.5, zeta: 1.0 },
            forward: Forward::PlusX,
        }
    }
}

/// A parameter out of its range: its key and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigError {
    /// The key, as in the TOML file.
    pub key: &'static str,
    /// What it must be.
    pub must: &'static str,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} must be {}", self.key, self.must)
    }
}

impl CueConfig {
    /// Checks every parameter; the error names the first key out of range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let err = |key, must| Err(ConfigError { key, must });
        let in_range = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        let corner_ok = |c: &Corner| in_range(c.omega, 1e-3, 1e3) && in_range(c.zeta, 0.05, 10.0);
        if !self.translation_scale.iter().all(|v| in_range(*v, 0.0, 10.0)) {
            return err("translation_scale", "three numbers from 0 to 10");
        }
        if !self.translation_limit.iter().all(|v| in_range(*v, 0.0, 100.0)) {
            return err("translation_limit", "three numbers from 0 to 100 m/s^2");
        }
        if !corner_ok(&self.translation_high_pass) {
            return err("translation_high_pass", "omega 0.001-1000 rad/s, zeta 0.05-10");
        }
        if !in_range(self.translation_break, 0.0, 1e3) {
            return err("translation_break", "0 (second order) to 1000 rad/s");
        }
        if !self.tilt_scale.iter().all(|v| in_range(*v, 0.0, 10.0)) {
            return err("tilt_scale", "two numbers from 0 to 10");
        }
        if !corner_ok(&self.tilt_low_pass) {
            return err("tilt_low_pass", "omega 0.001-1000 rad/s, zeta 0.05-10");
        }
        if !in_range(self.tilt_limit_deg, 0.0, 45.0) {
            return err("tilt_limit_deg", "0 to 45 deg");
        }
        if !in_range(self.tilt_rate_deg, 0.0, 90.0) {
            return err("tilt_rate_deg", "0 to 90 deg/s");
        }
        if !self.rotation_scale.iter().all(|v| in_range(*v, 0.0, 10.0)) {
            return err("rotation_scale", "two numbers from 0 to 10");
        }
        if !in_range(self.rotation_limit, 0.0, 100.0) {
            return err("rotation_limit", "0 to 100 rad/s");
        }
        if !corner_ok(&self.rotation_high_pass) {
            return err("rotation_high_pass", "omega 0.001-1000 rad/s, zeta 0.05-10");
        }
        if !in_range(self.yaw_scale, 0.0, 10.0) {
            return err("yaw_scale", "0 to 10");
        }
        if !in_range(self.yaw_rate_limit, 0.0, 100.0) {
            return err("yaw_rate_limit", "0 to 100 rad/s");
        }
        if !corner_ok(&self.yaw_high_pass) {
            return err("yaw_high_pass", "omega 0.001-1000 rad/s, zeta 0.05-10");
        }
        Ok(())
    }
}

/// Why a sample was not taken (the caller holds the last pose).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleError {
    /// A number is NaN or infinite.
    NonFinite,
    /// The interval is not positive, or longer than a second (a gap: the washout holds).
    Interval,
}

/// The washout's channels, in vehicle axes, before they are turned to the platform's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Channels<T> {
    /// Surge, sway, heave (m), vehicle axes.
    pub translation: [T; 3],
    /// Tilt-coordination roll and pitch (rad).
    pub tilt: [T; 2],
    /// High-passed roll and pitch (rad).
    pub rotation: [T; 2],
    /// Yaw (rad, unbounded).
    pub yaw: T,
}

/// The classical washout, one instance per stream.
#[derive(Debug, Clone)]
pub struct Washout<T: Real> {
    config: CueConfig,
    translation: [Biquad<T>; 3],
    break_: [Biquad<T>; 3],
    tilt_filter: [Biquad<T>; 2],
    rotation: [Biquad<T>; 2],
    yaw_filter: Biquad<T>,
    channels: Channels<T>,
}

fn clamp<T: Real>(v: T, limit: T) -> T {
    if v > limit {
        limit
    } else if v < -limit {
        -limit
    } else {
        v
    }
}

impl<T: Real> Washout<T> {
    /// A washout at neutral; the configuration must be valid.
    pub fn new(config: CueConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let c = |x: Corner| (T::of(x.omega), T::of(x.zeta));
        let (tw, tz) = c(config.translation_high_pass);
        let (lw, lz) = c(config.tilt_low_pass);
        let (rw, rz) = c(config.rotation_high_pass);
        let (yw, yz) = c(config.yaw_high_pass);
        Ok(Self {
            config,
            translation: [Biquad::new(Section::high_pass_position(tw, tz)); 3],
            break_: [Biquad::first_order(Section::first_order_high_pass(T::of(config.translation_break))); 3],
            tilt_filter: [Biquad::new(Section::low_pass(lw, lz)); 2],
            rotation: [Biquad::new(Section::high_pass_angle(rw, rz)); 2],
            yaw_filter: Biquad::new(Section::high_pass_angle(yw, yz)),
            channels: Channels::default(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CueConfig {
        &self.config
    }

    /// The channels after the last sample.
    pub fn channels(&self) -> &Channels<T> {
        &self.channels
    }

    /// Takes one sample covering `dt` seconds and returns the platform's offset from neutral: `[x, y, z, alpha,
    /// beta, gamma]` in platform axes. A refused sample changes nothing.
    // One index runs through the parallel per-axis arrays of a channel (input, scale, limit, filter, output).
    #[allow(clippy::needless_range_loop)]
    pub fn step(&mut self, sample: &Telemetry<T>, dt: T) -> Result<[T; 6], SampleError> {
        if !(sample.force.iter().chain(&sample.rate).all(|v| v.finite()) && dt.finite()) {
            return Err(SampleError::NonFinite);
        }
        if !(dt > T::zero() && dt <= T::one()) {
            return Err(SampleError::Interval);
        }
        let cfg = self.config;
        let g = T::of(G);
        // Translation: the force the vehicle feels beyond gravity at rest, scaled, limited, washed out.
        let rest = [T::zero(), T::zero(), g];
        for i in 0..3 {
            let f = clamp(
                (sample.force[i] - rest[i]) * T::of(cfg.translation_scale[i]),
                T::of(cfg.translation_limit[i]),
            );
            let p = self.translation[i].step(f, dt);
            self.channels.translation[i] = if cfg.translation_break > 0.0 {
                self.break_[i].step(p, dt)
            } else {
                p
            };
        }
        // Tilt coordination: the sustained horizontal force as a tilt of gravity, slowly.
        let sin_limit = T::of(libm::sin(cfg.tilt_limit_deg.to_radians()));
        let max_step = T::of(cfg.tilt_rate_deg.to_radians()) * dt;
        for (i, force_axis) in [(0, 1), (1, 0)] {
            // Roll (index 0) comes from the lateral force (y), pitch (index 1) from the longitudinal (x).
            let f = self.tilt_filter[i].step(sample.force[force_axis] * T::of(cfg.tilt_scale[force_axis]), dt);
            let s = clamp(f / g, sin_limit);
            // alpha = asin(f_y / g); beta = -asin(f_x / g).
            let want = if i == 0 { s.asin_() } else { -s.asin_() };
            let now = self.channels.tilt[i];
            self.channels.tilt[i] = now + clamp(want - now, max_step);
        }
        // Roll and pitch onsets.
        for i in 0..2 {
            let w = clamp(sample.rate[i] * T::of(cfg.rotation_scale[i]), T::of(cfg.rotation_limit));
            self.channels.rotation[i] = self.rotation[i].step(w, dt);
        }
        // Yaw.
        let w = clamp(sample.rate[2] * T::of(cfg.yaw_scale), T::of(cfg.yaw_rate_limit));
        self.channels.yaw = match cfg.yaw {
            YawMode::Heading => self.channels.yaw + w * dt,
            YawMode::Washout => self.yaw_filter.step(w, dt),
        };
        Ok(self.offset())
    }

    /// The current offset from neutral in platform axes: `[x, y, z, alpha, beta, gamma]`.
    pub fn offset(&self) -> [T; 6] {
        let c = &self.channels;
        let (x, y) = (c.translation[0], c.translation[1]);
        let (roll, pitch) = (c.tilt[0] + c.rotation[0], c.tilt[1] + c.rotation[1]);
        // Vehicle axes to platform axes: a quarter turn about z moves x to y (and roll to pitch) and y to -x.
        let (px, py, pa, pb) = match self.config.forward {
            Forward::PlusX => (x, y, roll, pitch),
            Forward::PlusY => (-y, x, -pitch, roll),
            Forward::MinusX => (-x, -y, -roll, -pitch),
            Forward::MinusY => (y, -x, pitch, -roll),
        };
        [px, py, c.translation[2], pa, pb, c.yaw]
    }

    /// Back to neutral (filters at rest, yaw kept).
    pub fn reset(&mut self) {
        let yaw = self.channels.yaw;
        for f in self.translation.iter_mut().chain(&mut self.break_) {
            f.reset();
        }
        for f in self.tilt_filter.iter_mut().chain(&mut self.rotation) {
            f.reset();
        }
        self.yaw_filter.reset();
        self.channels = Channels {
            yaw,
            ..Channels::default()
        };
    }
}

/// The specific force a platform delivers to a rider, in platform axes (m/s^2): its translational acceleration
/// `accel` (m/s^2, base axes) minus gravity seen in its tilted frame, for roll `alpha` and pitch `beta` (small
/// yaw-free model, as the washout uses). At rest and level: `[0, 0, g]`.
pub fn delivered<T: Real>(accel: [T; 3], alpha: T, beta: T) -> [T; 3] {
    let g = T::of(G);
    [
        accel[0] - g * beta.sin_(),
        accel[1] + g * alpha.sin_() * beta.cos_(),
        accel[2] + g * alpha.cos_() * beta.cos_(),
    ]
}

/// A pose: the neutral pose plus an offset (yaw added).
pub fn pose<T: Real>(neutral: &Pose<T>, offset: &[T; 6]) -> Pose<T> {
    let n = neutral.to_array();
    Pose::from_array(core::array::from_fn(|i| n[i] + offset[i]))
}
