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

pub mod axes;
mod config;
pub mod filter;
mod live;
pub mod optimal;
pub mod perception;
pub mod schema;
pub mod smoothing;

pub use config::{ConfigError, Corner, CueConfig, Forward, YawMode, ROTATION_AXES, TILT_AXES, TRANSLATION_AXES};
use filter::{Biquad, Section};
pub use live::{Live, HANDOVER_S};
pub use optimal::{Algorithm, OptimalConfig};
pub use smoothing::{Smoother, Smoothing};

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

/// The largest specific force a sample may carry on an axis (m/s^2): a thousand g, beyond any vehicle's, a
/// crash's included. A larger one is a misread packet or a broken plugin; taken, it would fill every channel's
/// filters with a number that rings through them long after.
pub const MAX_FORCE: f64 = 1e4;

/// The largest angular rate a sample may carry (rad/s), on the same grounds: some 160 turns a second.
pub const MAX_RATE: f64 = 1e3;

/// Why a sample was not taken (the caller holds the last pose).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleError {
    /// A number is NaN or infinite.
    NonFinite,
    /// A number is beyond any vehicle's ([`MAX_FORCE`], [`MAX_RATE`]).
    Implausible,
    /// The interval is not positive, or longer than a second (a gap: the washout holds).
    Interval,
}

/// Whether a sample can be taken: every value finite and within any vehicle's.
pub fn check<T: Real>(sample: &Telemetry<T>) -> Result<(), SampleError> {
    if !sample.force.iter().chain(&sample.rate).all(|v| v.finite()) {
        return Err(SampleError::NonFinite);
    }
    let within = |v: &T, limit: f64| v.to_f64().abs() <= limit;
    if sample.force.iter().all(|v| within(v, MAX_FORCE)) && sample.rate.iter().all(|v| within(v, MAX_RATE)) {
        Ok(())
    } else {
        Err(SampleError::Implausible)
    }
}

impl core::fmt::Display for SampleError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::NonFinite => "a value is not finite",
            Self::Implausible => "a value is beyond any vehicle's (1000 g, or 1000 rad/s)",
            Self::Interval => "the interval is not after the last sample, or longer than a second",
        })
    }
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
    smoother: Smoother<T>,
    /// Whether a sample has been taken since the start (or the last reset).
    started: bool,
    /// The last raw sample taken.
    last: Option<Telemetry<T>>,
    translation: [Biquad<T>; 3],
    break_: [Biquad<T>; 3],
    /// Roll (from the lateral force, the `y` keys) and pitch (from the longitudinal force, the `x` keys).
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

/// Tilt channel `i` (0 roll, 1 pitch) cues the force on this vehicle axis, whose per-axis tilt keys it reads.
const TILT_FORCE_AXIS: [usize; 2] = [1, 0];

/// A (smoothed) sample's inputs to each filter.
struct Inputs<T> {
    translation: [T; 3],
    tilt: [T; 2],
    rotation: [T; 2],
    yaw: T,
}

/// The filters' sections of a configuration.
struct Sections<T> {
    translation: [Section<T>; 3],
    break_: [Section<T>; 3],
    tilt: [Section<T>; 2],
    rotation: [Section<T>; 2],
    yaw: Section<T>,
}

impl<T: Real> Sections<T> {
    fn of(config: &CueConfig) -> Self {
        let c = |x: Corner| (T::of(x.omega), T::of(x.zeta));
        Self {
            translation: core::array::from_fn(|i| {
                let (w, z) = c(config.translation_high_pass[i]);
                Section::high_pass_position(w, z)
            }),
            break_: core::array::from_fn(|i| Section::first_order_high_pass(T::of(config.translation_break[i]))),
            tilt: core::array::from_fn(|i| {
                let (w, z) = c(config.tilt_low_pass[TILT_FORCE_AXIS[i]]);
                Section::low_pass(w, z)
            }),
            rotation: core::array::from_fn(|i| {
                let (w, z) = c(config.rotation_high_pass[i]);
                Section::high_pass_angle(w, z)
            }),
            yaw: {
                let (w, z) = c(config.yaw_high_pass);
                Section::high_pass_angle(w, z)
            },
        }
    }
}

impl<T: Real> Washout<T> {
    /// A washout at neutral; the configuration must be valid.
    pub fn new(config: CueConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let s = Sections::<T>::of(&config);
        Ok(Self {
            config,
            smoother: Smoother::new(&config.smoothing),
            started: false,
            last: None,
            translation: s.translation.map(Biquad::new),
            break_: s.break_.map(Biquad::first_order),
            tilt_filter: s.tilt.map(Biquad::new),
            rotation: s.rotation.map(Biquad::new),
            yaw_filter: Biquad::new(s.yaw),
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

    /// The inputs of each filter for a (smoothed) sample: scaled and limited.
    fn inputs(&self, s: &Telemetry<T>) -> Inputs<T> {
        let cfg = &self.config;
        // Translation: the force the vehicle feels beyond gravity at rest.
        let rest = [T::zero(), T::zero(), T::of(G)];
        Inputs {
            translation: core::array::from_fn(|i| {
                clamp(
                    (s.force[i] - rest[i]) * T::of(cfg.translation_scale[i]),
                    T::of(cfg.translation_limit[i]),
                )
            }),
            tilt: core::array::from_fn(|i| {
                let a = TILT_FORCE_AXIS[i];
                s.force[a] * T::of(cfg.tilt_scale[a])
            }),
            rotation: core::array::from_fn(|i| {
                clamp(s.rate[i] * T::of(cfg.rotation_scale[i]), T::of(cfg.rotation_limit[i]))
            }),
            yaw: clamp(s.rate[2] * T::of(cfg.yaw_scale), T::of(cfg.yaw_rate_limit)),
        }
    }

    /// Takes the first sample of a stream (or the first after [`Washout::reset`]), which has no interval before
    /// it: the smoothing starts on it and every filter holds it as its last input, so that the next interval's
    /// input runs from this sample's value (not from zero, as if the vehicle had been at rest). No time passes:
    /// the offset is unchanged. A sample that is not finite, or beyond any vehicle's, is refused and changes
    /// nothing.
    pub fn begin(&mut self, sample: &Telemetry<T>) -> Result<[T; 6], SampleError> {
        check(sample)?;
        let s = self.smoother.begin(sample);
        self.started = true;
        self.last = Some(*sample);
        let u = self.inputs(&s);
        for (f, u) in self.translation.iter_mut().zip(u.translation) {
            f.begin(u);
        }
        for f in &mut self.break_ {
            f.begin(T::zero());
        }
        for (f, u) in self.tilt_filter.iter_mut().zip(u.tilt) {
            f.begin(u);
        }
        for (f, u) in self.rotation.iter_mut().zip(u.rotation) {
            f.begin(u);
        }
        self.yaw_filter.begin(u.yaw);
        Ok(self.offset())
    }

    /// Takes one sample covering `dt` seconds and returns the platform's offset from neutral: `[x, y, z, alpha,
    /// beta, gamma]` in platform axes. A refused sample changes nothing. A first sample taken here rather than by
    /// [`Washout::begin`] starts the smoothing on itself and reaches the filters as a step from rest.
    // One index runs through the parallel per-axis arrays of a channel (input, scale, limit, filter, output).
    #[allow(clippy::needless_range_loop)]
    pub fn step(&mut self, sample: &Telemetry<T>, dt: T) -> Result<[T; 6], SampleError> {
        check(sample)?;
        if !(dt.finite() && dt > T::zero() && dt <= T::one()) {
            return Err(SampleError::Interval);
        }
        let s = if self.started {
            self.smoother.step(sample, dt)
        } else {
            self.started = true;
            self.smoother.begin(sample)
        };
        self.last = Some(*sample);
        let cfg = self.config;
        let g = T::of(G);
        let u = self.inputs(&s);
        for i in 0..3 {
            let p = self.translation[i].step(u.translation[i], dt);
            self.channels.translation[i] = if cfg.translation_break[i] > 0.0 {
                self.break_[i].step(p, dt)
            } else {
                p
            };
        }
        // Tilt coordination: the sustained horizontal force as a tilt of gravity, slowly.
        for i in 0..2 {
            // Roll (index 0) comes from the lateral force (y), pitch (index 1) from the longitudinal (x).
            let a = TILT_FORCE_AXIS[i];
            let sin_limit = T::of(libm::sin(cfg.tilt_limit_deg[a].to_radians()));
            let max_step = T::of(cfg.tilt_rate_deg[a].to_radians()) * dt;
            let f = self.tilt_filter[i].step(u.tilt[i], dt);
            let s = clamp(f / g, sin_limit);
            // alpha = asin(f_y / g); beta = -asin(f_x / g).
            let want = if i == 0 { s.asin_() } else { -s.asin_() };
            let now = self.channels.tilt[i];
            self.channels.tilt[i] = now + clamp(want - now, max_step);
        }
        // Roll and pitch onsets.
        for i in 0..2 {
            self.channels.rotation[i] = self.rotation[i].step(u.rotation[i], dt);
        }
        // Yaw.
        self.channels.yaw = match cfg.yaw {
            YawMode::Heading => self.channels.yaw + u.yaw * dt,
            YawMode::Washout => self.yaw_filter.step(u.yaw, dt),
        };
        Ok(self.offset())
    }

    /// The same washout under another configuration from here on, its state carried: the channels (tilt, the
    /// heading), every filter's output and the output's rate (each filter retuned without a bump:
    /// [`Biquad::retune`]) and the smoothing, if it is the same (a new smoothing starts on the last sample). What
    /// the carried state cannot hide (a new scale, limit or `forward`) changes the offset from the next sample:
    /// [`Live`] blends that in over [`HANDOVER_S`].
    pub fn retuned(&self, config: CueConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let s = Sections::<T>::of(&config);
        let mut w = self.clone();
        w.config = config;
        for (f, s) in w.translation.iter_mut().zip(s.translation) {
            f.retune(s);
        }
        for i in 0..3 {
            if self.config.translation_break[i] > 0.0 {
                w.break_[i].retune(s.break_[i]);
            } else {
                // The break was not running: it starts passing the translation through as it stands.
                w.break_[i] = Biquad::first_order(s.break_[i]);
                w.break_[i].begin(self.channels.translation[i]);
            }
        }
        for (f, s) in w.tilt_filter.iter_mut().zip(s.tilt) {
            f.retune(s);
        }
        for (f, s) in w.rotation.iter_mut().zip(s.rotation) {
            f.retune(s);
        }
        w.yaw_filter.retune(s.yaw);
        if self.config.yaw == YawMode::Heading && config.yaw == YawMode::Washout {
            // From the heading where it stands, washed out from there.
            w.yaw_filter.set_output(self.channels.yaw, T::zero());
        }
        if config.smoothing != self.config.smoothing {
            w.smoother = Smoother::new(&config.smoothing);
            if let Some(last) = self.last {
                w.smoother.begin(&last);
            }
        }
        Ok(w)
    }

    /// The current offset from neutral in platform axes: `[x, y, z, alpha, beta, gamma]`.
    pub fn offset(&self) -> [T; 6] {
        let c = &self.channels;
        let (roll, pitch) = (c.tilt[0] + c.rotation[0], c.tilt[1] + c.rotation[1]);
        to_platform(self.config.forward, c.translation, roll, pitch, c.yaw)
    }

    /// Back to neutral (filters at rest, smoothing empty, yaw kept): the next sample is a first one.
    pub fn reset(&mut self) {
        let yaw = self.channels.yaw;
        for f in self.translation.iter_mut().chain(&mut self.break_) {
            f.reset();
        }
        for f in self.tilt_filter.iter_mut().chain(&mut self.rotation) {
            f.reset();
        }
        self.yaw_filter.reset();
        self.smoother = Smoother::new(&self.config.smoothing);
        self.started = false;
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

/// An offset in vehicle axes (translation, roll, pitch, yaw) as the platform's `[x, y, z, alpha, beta, gamma]`,
/// for the platform direction that faces the vehicle's forward.
pub fn to_platform<T: Real>(forward: Forward, translation: [T; 3], roll: T, pitch: T, yaw: T) -> [T; 6] {
    let [x, y, z] = translation;
    // Vehicle axes to platform axes: a quarter turn about z moves x to y (and roll to pitch) and y to -x.
    let (px, py, pa, pb) = match forward {
        Forward::PlusX => (x, y, roll, pitch),
        Forward::PlusY => (-y, x, -pitch, roll),
        Forward::MinusX => (-x, -y, -roll, -pitch),
        Forward::MinusY => (y, -x, pitch, -roll),
    };
    [px, py, z, pa, pb, yaw]
}

/// A pose: the neutral pose plus an offset (yaw added).
pub fn pose<T: Real>(neutral: &Pose<T>, offset: &[T; 6]) -> Pose<T> {
    let n = neutral.to_array();
    Pose::from_array(core::array::from_fn(|i| n[i] + offset[i]))
}
