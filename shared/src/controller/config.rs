//! The controller's configuration: the platform, its drives, homing, inputs and timings; the trainer model's, a
//! rig file's, and the checks that decide whether a configuration can run.

#[cfg(doc)]
use super::Controller;
use crate::kinematics::presets::{self, Preset};
use crate::kinematics::{AxisKind, KinematicsError, Mechanism, Pose, RingPlatform};
use crate::kinematics::{GeometryError, RingGeometry};
use crate::model::{self, CARRIAGE_HOMING, LINEAR_HOMING, SHOULDER_HOMING};
use crate::motion::pulse::{PulseTiming, PulseTimingError, MAX_STEP_SLOTS, STEP_SLOT_NS};
use crate::motion::{AxisScale, PipelineConfig, SchedulerConfig};
use crate::protocol::{
    ConfigRefusal, Field, FieldName, HomingSettings, RigRecord, Settings, SettingsKind, SwitchSettings, RIG_NAME_LEN,
};
use crate::safety::debounce::InputConfig;
use crate::safety::homing::{HomingError, HomingPlan, RingHoming};
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
    /// Homing of every axis in its own units, as the homing section gives it (in motor steps:
    /// [`Self::homing`]).
    pub switches: HomingSettings,
    /// Input polarity and debouncing.
    pub inputs: InputConfig,
    /// Telemetry samples per second while a host is connected (0: none).
    pub telemetry_hz: u16,
    /// After a lost stream, how long without a frame from any host before the device powers down (ms).
    pub host_gone_ms: u16,
    /// The rig's name (UTF-8, zero-padded), as `device rig show` reports it.
    pub rig_name: [u8; RIG_NAME_LEN],
}

/// What [`ControllerConfig::check`] found a configuration to be: its mechanism, its home pose (solved) and its
/// proven homing plan.
#[derive(Debug, Clone, Copy)]
pub struct Checked {
    /// The mechanism in `f32`, as the controller computes it.
    pub mechanism: RingPlatform<f32>,
    /// The home pose in `f32`.
    pub home_pose: Pose<f32>,
    /// The homing plan, its spacing proven.
    pub plan: HomingPlan,
}

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
    /// A field is out of its range.
    Value(Field),
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
            Self::Value(field) => ConfigRefusal::OutOfRange(*field),
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
    /// The step generator's slot grid for this configuration.
    pub fn pulse_timing(&self) -> Result<PulseTiming, PulseTimingError> {
        PulseTiming::new(&self.scheduler, STEP_SLOT_NS, MAX_STEP_SLOTS)
    }

    /// Every actuator's velocity limit within the step generator's rate at its steps per unit: the tracker never
    /// asks an axis for more steps a second than one per minimum step spacing.
    fn step_rates(&self) -> Result<(), ConfigError> {
        let most = self.top_step_rate();
        let limits = &self.pipeline.limits;
        match (0..6).find(|&a| limits.actuator_velocity[a] * self.scales[a].steps_per_unit > most) {
            Some(a) => Err(ConfigError::Value(Field::at(
                SettingsKind::Motion,
                a,
                FieldName::ActuatorVelocity,
            ))),
            None => Ok(()),
        }
    }

    /// The step generator's top rate (steps/s): one step per minimum step spacing.
    pub(super) fn top_step_rate(&self) -> f32 {
        1e9 / self.scheduler.min_spacing_ns.max(1) as f32
    }

    /// A fitted spare axis takes the pins of the supply senses and the USART1 link (the board has no other free
    /// pin): the supervisor must then sequence by timing alone.
    fn spare_pins(&self) -> Result<(), ConfigError> {
        let fitted = self.pipeline.spare.iter().position(|a| a.enabled);
        match fitted {
            Some(i) if self.supervisor.logic_sense || self.supervisor.power_sense => Err(ConfigError::Value(
                Field::at(SettingsKind::Spare, i, FieldName::Enabled),
            )),
            _ => Ok(()),
        }
    }

    /// Whether a controller can run this configuration (what [`Controller::new`] checks).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.check().map(|_| ())
    }

    /// Every check of the whole configuration, once, with what they compute and a controller needs: the step
    /// timing and its slot grid, the supervisor's delays, the home pose's solution, the homing plan's proof. The
    /// sections' own ranges were checked as they were applied ([`Self::apply`]).
    pub fn check(&self) -> Result<Checked, ConfigError> {
        let geometry = &self.geometry;
        if !self.scheduler.is_valid() || self.scheduler.period_ns != self.pipeline.tick_us.saturating_mul(1000) {
            return Err(ConfigError::Scheduler);
        }
        self.pulse_timing().map_err(ConfigError::StepTiming)?;
        self.step_rates()?;
        supervisor_fields(&self.supervisor)?;
        self.spare_pins()?;
        let mechanism = RingPlatform::<f32>::new(geometry);
        let home_pose = Pose::from_array(self.home).cast::<f32>();
        let home_q = mechanism.inverse(&home_pose).map_err(ConfigError::HomePose)?;
        let n = geometry.chains().len();
        let mut home_angles = [0.0; 6];
        for (i, a) in home_angles.iter_mut().enumerate().take(n) {
            *a = f64::from(home_q.0[i]);
        }
        let ring = RingHoming {
            carriages: n,
            home_angles,
            min_spacing: geometry.limits.carriage_spacing[0],
            steps_per_rad: self.scales[0].steps_per_turn as f64 / core::f64::consts::TAU,
        };
        let plan = HomingPlan::new(self.homing()?, &ring).map_err(ConfigError::Homing)?;
        Ok(Checked {
            mechanism,
            home_pose,
            plan,
        })
    }

    /// The 1:20 trainer model ([`crate::model`]) with the FL20 drives of FIRMWARE.md: the configuration the firmware
    /// compiles in and every rig starts from.
    pub fn trainer_model() -> Self {
        let mut config = Self {
            geometry: presets::TRAINER_MODEL,
            home: Preset::TrainerModel.home(),
            supervisor: SupervisorConfig::default(),
            pipeline: PipelineConfig::default(),
            scheduler: SchedulerConfig::default(),
            scales: model::SCALES,
            switches: model::HOMING,
            inputs: InputConfig::default(),
            telemetry_hz: model::TELEMETRY_HZ,
            host_gone_ms: crate::safety::HOST_GONE_MS,
            rig_name: [0; RIG_NAME_LEN],
        };
        config.rig_name = RigRecord::new(
            presets::TRAINER_MODEL.name,
            &config.geometry,
            config.home,
            config.machine(),
        )
        .name;
        config
    }

    /// The trainer model's drives, switches and timings on another ring platform (its own geometry and home
    /// pose): each carriage with the model's carriage drive and index-switch homing, each linear actuator with the
    /// model's lead screw and its lower end switch 1 mm below the stroke, each elbow chain's shoulder with
    /// [`AxisScale::MODEL_SHOULDER`] and an index flag at its home angle ([`model::SHOULDER_HOMING`]); linear
    /// actuators and shoulders home first, then every other carriage, then the rest (the homing plan's spacing
    /// proof decides whether that order is safe).
    pub fn for_rig(geometry: &RingGeometry, home: [f64; 6]) -> Result<Self, ConfigError> {
        Self::from_record(&Self::default_record(geometry.name, geometry, home))
    }

    /// The record [`Self::for_rig`] runs: `geometry` homed at `home` with the trainer model's machine sections.
    /// A home pose without a solution leaves the linear switches at the home pose (the record is then refused by
    /// its home-pose check).
    pub fn default_record(name: &str, geometry: &RingGeometry, home: [f64; 6]) -> RigRecord {
        let model = Self::trainer_model();
        let axes = geometry.axes();
        let solved = RingPlatform::<f64>::new(geometry)
            .inverse(&Pose::from_array(home))
            .map(|q| q.0)
            .ok();
        let q = solved.unwrap_or([0.0; 6]);
        let mut machine = model.machine();
        let carriages = axes.iter().filter(|k| **k == AxisKind::Ring).count();
        for (a, kind) in axes.iter().enumerate() {
            // A rig's fifth carriage turns like a carriage, a shoulder like a shoulder.
            (
                machine.motion.actuator_velocity[a],
                machine.motion.actuator_acceleration[a],
            ) = model::actuator_limits(*kind);
            if *kind == AxisKind::Ring {
                machine.axes[a].steps_per_unit = AxisScale::MODEL_CARRIAGE.steps_per_turn as f32;
                machine.homing.axes[a] = SwitchSettings {
                    search: solved.map_or(CARRIAGE_HOMING.search, |q| {
                        carriage_search(&q, a, carriages, geometry.limits.carriage_spacing[0])
                    }),
                    ..CARRIAGE_HOMING
                };
            } else if *kind == AxisKind::Angle {
                machine.axes[a].steps_per_unit = AxisScale::MODEL_SHOULDER.steps_per_turn as f32;
                machine.homing.axes[a] = SHOULDER_HOMING;
            } else {
                machine.axes[a].steps_per_unit = AxisScale::MODEL_LINEAR.steps_per_unit;
                let switch = geometry.limits.stroke[0] - 0.001 - q[a];
                machine.homing.axes[a] = SwitchSettings {
                    switch: switch as f32,
                    ..LINEAR_HOMING
                };
            }
        }
        let mut order = [0u8; 6];
        let linear_first = (0..6u8).filter(|&a| axes[usize::from(a)] != AxisKind::Ring);
        let even = (0..6u8).filter(|&a| axes[usize::from(a)] == AxisKind::Ring && a % 2 == 0);
        let odd = (0..6u8).filter(|&a| axes[usize::from(a)] == AxisKind::Ring && a % 2 == 1);
        for (slot, a) in order.iter_mut().zip(linear_first.chain(even).chain(odd)) {
            *slot = a;
        }
        machine.homing.order = order;
        RigRecord::new(name, geometry, home, machine)
    }

    /// A stored or loaded rig: its geometry and home pose, and its machine sections through the same checks as
    /// `SetSettings` of those sections; the sections a rig does not carry (stream, control) are the trainer
    /// model's.
    pub fn from_record(record: &RigRecord) -> Result<Self, ConfigError> {
        let geometry = record.geometry().map_err(ConfigError::Geometry)?;
        let mut config = Self {
            geometry,
            home: record.home,
            rig_name: record.name,
            ..Self::trainer_model()
        };
        let m = &record.machine;
        for section in [
            Settings::Axes(m.axes),
            Settings::Motion(m.motion),
            Settings::Inputs(m.inputs),
            Settings::Supervisor(m.supervisor),
            Settings::Homing(m.homing),
        ] {
            config.apply(&section)?;
        }
        config.validate()?;
        Ok(config)
    }

    /// The rig this configuration drives, as a record.
    pub fn rig(&self) -> RigRecord {
        RigRecord {
            name: self.rig_name,
            ..RigRecord::new("", &self.geometry, self.home, self.machine())
        }
    }
}

/// How far carriage `a` searches for its index flag in a rig's default homing: the trainer model's 20 degrees, or
/// less where carriages sit close together at home (a rotopod's pairs), so that the homing plan's proof holds with
/// every other carriage first (each may travel its search distance toward a neighbour that has not homed yet, which
/// may travel its own): 45 % of the room beyond the minimum spacing to the nearer neighbour. The simulator parks
/// each carriage at most 7 degrees before its flag ([`crate::sim::parked`]); a search shorter than that is refused
/// by the plan's own check (the back-off) or fails homing, never moves blind.
fn carriage_search(q: &[f64; 6], a: usize, carriages: usize, min_spacing: f64) -> f32 {
    let gap = |from: usize, to: usize| crate::real::wrap_turn(q[to] - q[from]);
    let next = (a + 1) % carriages;
    let prev = (a + carriages - 1) % carriages;
    let room = gap(a, next).min(gap(prev, a)) - min_spacing;
    (CARRIAGE_HOMING.search as f64).min(0.45 * room).max(0.0) as f32
}

/// The supervisor's delays, each at most [`SupervisorConfig::LONGEST_MS`], and a supply timeout where a supply is
/// sensed: the first field that is not.
pub(super) fn supervisor_fields(s: &SupervisorConfig) -> Result<(), ConfigError> {
    let delays = [
        (s.logic_settle_ms, FieldName::LogicSettleMs),
        (s.power_settle_ms, FieldName::PowerSettleMs),
        (s.supply_timeout_ms, FieldName::SupplyTimeoutMs),
        (s.driver_off_ms, FieldName::DriverOffMs),
        (s.discharge_ms, FieldName::DischargeMs),
    ];
    let sensed_without_timeout = s.supply_timeout_ms == 0 && (s.logic_sense || s.power_sense);
    let bad = match delays.iter().find(|(ms, _)| *ms > SupervisorConfig::LONGEST_MS) {
        Some((_, name)) => Some(*name),
        None => sensed_without_timeout.then_some(FieldName::SupplyTimeoutMs),
    };
    match bad {
        Some(name) => Err(ConfigError::Value(Field::of(SettingsKind::Supervisor, name))),
        None => Ok(()),
    }
}
