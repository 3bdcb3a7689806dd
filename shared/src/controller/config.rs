//! The controller's configuration: the platform, its drives, homing, inputs and timings; the trainer model's, a
//! rig file's, and the checks that decide whether a configuration can run.

use super::Controller;
use crate::kinematics::presets::{self, Preset};
use crate::kinematics::{AxisKind, KinematicsError, Mechanism, Pose, RingPlatform};
use crate::kinematics::{GeometryError, RingGeometry};
use crate::motion::pulse::{PulseTiming, PulseTimingError};
use crate::motion::{AxisScale, FollowMode, PipelineConfig, SchedulerConfig};
use crate::protocol::{ConfigKey, ConfigRefusal, RigRecord, RIG_NAME_LEN};
use crate::safety::debounce::InputConfig;
use crate::safety::homing::{HomingConfig, HomingError};
use crate::safety::SupervisorConfig;

/// Everything the controller is configured with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerConfig {
    /// The platform it drives (a ring platform).
    pub geometry: RingGeometry,
    /// Where homing leaves the platform: `[x, y, z, alpha, beta, gamma]` (m, rad), inside every check.
    pub home: [f64; 6],
    /// Supply sequencing.
    pub supervisor: SupervisorConfig,
    /// Motion pipeline.
    pub pipeline: PipelineConfig,
    /// Step timing.
    pub scheduler: SchedulerConfig,
    /// Motor scale of every axis.
    pub scales: [AxisScale; 6],
    /// Homing of every axis.
    pub homing: HomingConfig,
    /// Input polarity and debouncing.
    pub inputs: InputConfig,
    /// Telemetry samples per second while a host is connected (0: none).
    pub telemetry_hz: u16,
    /// The rig's name (UTF-8, zero-padded), as `device rig show` reports it.
    pub rig_name: [u8; RIG_NAME_LEN],
}

/// Slot of the step generator (ns): the boards' timers emit one GPIO set/reset word per slot
/// ([`crate::motion::pulse`]). 2.5 us is the shortest STEP pulse of FIRMWARE.md.
pub const STEP_SLOT_NS: u32 = 2_500;
/// Longest step buffer a board holds (slots): one period of 2 ms at [`STEP_SLOT_NS`].
pub const MAX_STEP_SLOTS: usize = 800;

/// Why a configuration cannot run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigError {
    /// The preset is not a ring platform.
    NotARingPlatform,
    /// The geometry fails its checks (lengths, chains, joint limits).
    Geometry(GeometryError),
    /// The home pose has no IK solution.
    HomePose(KinematicsError),
    /// The homing plan is unsafe or inconsistent.
    Homing(HomingError),
    /// The step timing is inconsistent.
    Scheduler,
    /// The step generator's slot grid cannot render the step timing faithfully.
    StepTiming(PulseTimingError),
    /// A value is out of its key's range (or the key does not exist for this machine).
    Value,
}

impl ConfigError {
    /// The cause as the protocol names it.
    pub fn refusal(&self) -> ConfigRefusal {
        match self {
            Self::NotARingPlatform | Self::Geometry(_) => ConfigRefusal::Geometry,
            Self::HomePose(_) => ConfigRefusal::HomePose,
            Self::Homing(_) => ConfigRefusal::Homing,
            Self::Scheduler => ConfigRefusal::StepTiming,
            Self::StepTiming(_) => ConfigRefusal::PulseSlots,
            Self::Value => ConfigRefusal::OutOfRange,
        }
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::HomePose(e) => write!(f, "the home pose would have no solution: {e}"),
            Self::Homing(e) => write!(f, "the homing plan would not be safe: {e}"),
            Self::StepTiming(e) => write!(f, "step timing: {e}"),
            Self::Geometry(e) => write!(f, "the geometry is not a valid ring platform: {e}"),
            other => other.refusal().fmt(f),
        }
    }
}

impl ControllerConfig {
    /// The 1:20 trainer model with the FL20 drives of FIRMWARE.md: carriages home in the order 1, 3, 2, 4 after the
    /// two linear actuators, searching up to 20 degrees of ring (linear actuators up to 40 mm); then the platform
    /// moves to the home pose under the normal limits.
    pub fn trainer_model() -> Self {
        let carriage = crate::safety::homing::AxisHoming {
            toward: 1,
            search_steps: 1_422, // 20 degrees at 25,600 steps per turn
            backoff_steps: 142,  // 2 degrees
            fast_rate: 4_000,
            slow_rate: 500,
            home_position: 0, // the index flags sit at the carriages' home-pose angles
        };
        let linear = crate::safety::homing::AxisHoming {
            toward: -1,
            search_steps: 64_000, // 40 mm at 1.6 M steps/m: the platform parks within 40 mm of the switches
            backoff_steps: 3_200, // 2 mm
            fast_rate: 32_000,
            slow_rate: 4_000,
            // The lower end switch is at 165 mm, below the 173 mm the spec ranges use and above the 160 mm stroke
            // minimum: 231.31 - 165 = 66.31 mm = 106,096 steps below the home-pose length. The platform parks low.
            home_position: -106_096,
        };
        Self {
            geometry: presets::TRAINER_MODEL,
            home: Preset::TrainerModel.home(),
            supervisor: SupervisorConfig::default(),
            pipeline: PipelineConfig::default(),
            scheduler: SchedulerConfig::default(),
            scales: [
                AxisScale::MODEL_CARRIAGE,
                AxisScale::MODEL_CARRIAGE,
                AxisScale::MODEL_CARRIAGE,
                AxisScale::MODEL_CARRIAGE,
                AxisScale::MODEL_LINEAR,
                AxisScale::MODEL_LINEAR,
            ],
            homing: HomingConfig {
                axes: [carriage, carriage, carriage, carriage, linear, linear],
                order: [4, 5, 0, 2, 1, 3],
            },
            inputs: InputConfig::default(),
            telemetry_hz: 100,
            rig_name: RigRecord::new(
                presets::TRAINER_MODEL.name,
                &presets::TRAINER_MODEL,
                Preset::TrainerModel.home(),
            )
            .name,
        }
    }

    /// The step generator's slot grid for this configuration.
    pub fn pulse_timing(&self) -> Result<PulseTiming, PulseTimingError> {
        PulseTiming::new(&self.scheduler, STEP_SLOT_NS, MAX_STEP_SLOTS)
    }

    /// Whether a controller can run this configuration (what [`Controller::new`] checks).
    pub fn validate(&self) -> Result<(), ConfigError> {
        Controller::new(*self).map(|_| ())
    }

    /// The value of a setting.
    pub fn get(&self, key: ConfigKey) -> Option<f32> {
        let c = &self.pipeline;
        Some(match key {
            ConfigKey::StreamTimeoutMs => c.stream_timeout_us as f32 / 1000.0,
            ConfigKey::PoseVelocity(a) => *c.limits.pose_velocity.get(usize::from(a))?,
            ConfigKey::PoseAcceleration(a) => *c.limits.pose_acceleration.get(usize::from(a))?,
            ConfigKey::GrossJumpMs => c.gross_jump_us as f32 / 1000.0,
            ConfigKey::FollowDirect => f32::from(u8::from(c.follow == FollowMode::Direct)),
            ConfigKey::EnvelopeMargin(i) => *c.margins.0.get(usize::from(i))?,
            ConfigKey::TickHz => 1e6 / c.tick_us as f32,
            ConfigKey::StepsPerUnit(a) => {
                let scale = self.scales.get(usize::from(a))?;
                match self.axis_kind(a)? {
                    AxisKind::Ring => scale.steps_per_turn as f32,
                    AxisKind::Linear | AxisKind::Angle => scale.steps_per_unit,
                }
            }
            ConfigKey::InputActiveLow => f32::from(self.inputs.active_low),
            ConfigKey::DebounceMs => f32::from(self.inputs.debounce_samples),
            ConfigKey::TelemetryHz => f32::from(self.telemetry_hz),
            ConfigKey::Reverse(a) => f32::from(u8::from(self.scales.get(usize::from(a))?.invert)),
        })
    }

    pub(super) fn axis_kind(&self, axis: u8) -> Option<AxisKind> {
        RingPlatform::<f32>::new(&self.geometry)
            .axes()
            .get(usize::from(axis))
            .copied()
    }

    /// The trainer model's drives, switches and timings on another ring platform (its own geometry and home
    /// pose): each carriage with the model's carriage drive and index-switch homing, each linear actuator with the
    /// model's lead screw and its lower end switch 1 mm below the stroke; linear actuators home first, then every
    /// other carriage, then the rest (the homing plan's spacing proof decides whether that order is safe).
    pub fn for_rig(geometry: &RingGeometry, home: [f64; 6]) -> Result<Self, ConfigError> {
        let model = Self::trainer_model();
        let m = RingPlatform::<f64>::new(geometry);
        let axes = m.axes();
        let q = m.inverse(&Pose::from_array(home)).map_err(ConfigError::HomePose)?;
        let [carriage, linear] = [model.homing.axes[0], model.homing.axes[4]];
        let mut config = Self {
            geometry: *geometry,
            home,
            rig_name: RigRecord::new(geometry.name, geometry, home).name,
            ..model
        };
        for (a, kind) in axes.iter().enumerate() {
            let ring = *kind == AxisKind::Ring;
            config.scales[a] = if ring {
                AxisScale::MODEL_CARRIAGE
            } else {
                AxisScale::MODEL_LINEAR
            };
            config.homing.axes[a] = if ring {
                carriage
            } else {
                let switch = geometry.limits.stroke[0] - 0.001;
                let steps = libm::round((switch - q.0[a]) * f64::from(AxisScale::MODEL_LINEAR.steps_per_unit));
                crate::safety::homing::AxisHoming {
                    home_position: steps as i64,
                    ..linear
                }
            };
        }
        let mut order = [0u8; 6];
        let linear_first = (0..6u8).filter(|&a| axes[usize::from(a)] != AxisKind::Ring);
        let even = (0..6u8).filter(|&a| axes[usize::from(a)] == AxisKind::Ring && a % 2 == 0);
        let odd = (0..6u8).filter(|&a| axes[usize::from(a)] == AxisKind::Ring && a % 2 == 1);
        for (slot, a) in order.iter_mut().zip(linear_first.chain(even).chain(odd)) {
            *slot = a;
        }
        config.homing.order = order;
        config.validate()?;
        Ok(config)
    }

    /// A stored or loaded rig: its geometry and home pose with the trainer model's switches and timings
    /// ([`Self::for_rig`]), then its axes, pose limits and inputs through the same checks as the settings of those
    /// names (so that steps per unit and direction scale and mirror the homing distances as a setting does).
    pub fn from_record(record: &RigRecord) -> Result<Self, ConfigError> {
        let geometry = record.geometry().map_err(ConfigError::Geometry)?;
        let mut config = Self::for_rig(&geometry, record.home)?;
        config.rig_name = record.name;
        let axes = RingPlatform::<f64>::new(&geometry).axes();
        for (a, (kind, scale)) in (0u8..).zip(axes.iter().zip(&record.scales)) {
            let per_unit = match kind {
                AxisKind::Ring => scale.steps_per_turn as f32,
                AxisKind::Linear | AxisKind::Angle => scale.steps_per_unit,
            };
            let i = usize::from(a);
            config.set(ConfigKey::StepsPerUnit(a), per_unit)?;
            config.set(ConfigKey::Reverse(a), f32::from(u8::from(scale.invert)))?;
            config.set(ConfigKey::PoseVelocity(a), record.pose_velocity[i])?;
            config.set(ConfigKey::PoseAcceleration(a), record.pose_acceleration[i])?;
        }
        config.set(ConfigKey::InputActiveLow, f32::from(record.inputs.active_low))?;
        config.set(ConfigKey::DebounceMs, f32::from(record.inputs.debounce_samples))?;
        config.supervisor = record.supervisor;
        config.validate()?;
        Ok(config)
    }

    /// The rig this configuration drives, as a record.
    pub fn rig(&self) -> RigRecord {
        RigRecord {
            name: self.rig_name,
            scales: self.scales,
            pose_velocity: self.pipeline.limits.pose_velocity,
            pose_acceleration: self.pipeline.limits.pose_acceleration,
            inputs: self.inputs,
            supervisor: self.supervisor,
            ..RigRecord::new("", &self.geometry, self.home)
        }
    }

    /// Changes a setting after checking its range; the whole configuration is checked by [`Self::validate`].
    /// Changing an axis's steps per unit scales its homing distances and rates with it, so that they stay the
    /// same physical lengths and speeds.
    pub fn set(&mut self, key: ConfigKey, value: f32) -> Result<(), ConfigError> {
        if !value.is_finite() || value < 0.0 {
            return Err(ConfigError::Value);
        }
        let integer = value == libm::floorf(value);
        let c = &mut self.pipeline;
        match key {
            ConfigKey::StreamTimeoutMs if (1.0..=10_000.0).contains(&value) => {
                c.stream_timeout_us = (value * 1000.0) as u32
            }
            ConfigKey::PoseVelocity(a) if value > 0.0 => {
                *c.limits
                    .pose_velocity
                    .get_mut(usize::from(a))
                    .ok_or(ConfigError::Value)? = value
            }
            ConfigKey::PoseAcceleration(a) if value > 0.0 => {
                *c.limits
                    .pose_acceleration
                    .get_mut(usize::from(a))
                    .ok_or(ConfigError::Value)? = value
            }
            ConfigKey::GrossJumpMs if (10.0..=10_000.0).contains(&value) => c.gross_jump_us = (value * 1000.0) as u32,
            ConfigKey::FollowDirect if value == 0.0 || value == 1.0 => {
                c.follow = if value == 1.0 {
                    FollowMode::Direct
                } else {
                    FollowMode::Interpolate
                }
            }
            // No margin may take more than a tenth of the check's natural scale (0.1 m, 0.1 rad, 0.1 of the index).
            ConfigKey::EnvelopeMargin(i) if value <= 0.1 => {
                *c.margins.0.get_mut(usize::from(i)).ok_or(ConfigError::Value)? = value
            }
            ConfigKey::TickHz if value == 500.0 || value == 1000.0 || value == 2000.0 => {
                let tick_us = (1e6 / value) as u32;
                c.tick_us = tick_us;
                self.scheduler.period_ns = tick_us * 1000;
            }
            ConfigKey::Reverse(a) if value == 0.0 || value == 1.0 => {
                let i = usize::from(a);
                let (Some(scale), Some(h)) = (self.scales.get_mut(i), self.homing.axes.get_mut(i)) else {
                    return Err(ConfigError::Value);
                };
                let reverse = value == 1.0;
                if scale.invert != reverse {
                    // Homing works in motor steps: the switch is now the other way, at the mirrored position.
                    scale.invert = reverse;
                    h.toward = -h.toward;
                    h.home_position = -h.home_position;
                }
            }
            ConfigKey::StepsPerUnit(a) if integer && (1.0..=16_777_216.0).contains(&value) => {
                let kind = self.axis_kind(a).ok_or(ConfigError::Value)?;
                let i = usize::from(a);
                let scale = &mut self.scales[i];
                let old = f64::from(scale.per_unit(kind));
                match kind {
                    AxisKind::Ring => {
                        scale.steps_per_turn = value as i64;
                        scale.steps_per_unit = value / core::f32::consts::TAU;
                    }
                    AxisKind::Linear | AxisKind::Angle => scale.steps_per_unit = value,
                }
                let ratio = f64::from(scale.per_unit(kind)) / old;
                let h = &mut self.homing.axes[i];
                let steps = |v: i64| libm::round(v as f64 * ratio) as i64;
                let rate = |v: u32| libm::round(f64::from(v) * ratio).clamp(1.0, f64::from(u32::MAX)) as u32;
                h.search_steps = rate(h.search_steps);
                h.backoff_steps = rate(h.backoff_steps);
                h.home_position = steps(h.home_position);
                h.fast_rate = rate(h.fast_rate);
                h.slow_rate = rate(h.slow_rate);
            }
            ConfigKey::InputActiveLow if integer && value <= f32::from(u16::MAX) => {
                self.inputs.active_low = value as u16
            }
            ConfigKey::DebounceMs if integer && (1.0..=50.0).contains(&value) => {
                self.inputs.debounce_samples = value as u8
            }
            ConfigKey::TelemetryHz if integer && value <= 2000.0 => self.telemetry_hz = value as u16,
            _ => return Err(ConfigError::Value),
        }
        Ok(())
    }
}
