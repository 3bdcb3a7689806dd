//! The controller: protocol dispatch, supervisor, homing, motion pipeline and step scheduler wired together.
//!
//! This is the whole decision-making of the device. The firmware calls it from its tasks (frames from USB,
//! input levels from the switches, one [`Controller::tick`] per control period) and drives its pins from what it
//! returns; the host simulator and the tests call exactly the same code.

use crate::kinematics::presets::{self, Preset, PresetGeometry};
use crate::kinematics::RingGeometry;
use crate::kinematics::{AxisKind, KinematicsError, Mechanism, MultiTurn, Pose, RingPlatform};
use crate::motion::jog::Jog;
use crate::motion::pulse::{PulseTiming, PulseTimingError};
use crate::motion::{
    Accepted, AxisMove, AxisScale, FollowMode, Pipeline, PipelineConfig, PipelineEvent, SchedulerConfig, StepConverter,
    StepScheduler,
};
use crate::protocol::{
    self, ConfigKey, ConfigRefusal, DeviceMessage, HostMessage, InputReport, NackReason, Request, Response, Status,
    Telemetry, TelemetryFlags, PROTOCOL_VERSION,
};
use crate::safety::debounce::InputConfig;
use crate::safety::homing::{HomingConfig, HomingError, HomingPlan, RingHoming};
use crate::safety::{Event, HomingSequencer, HomingStep, Motion, Outputs, State, Supervisor, SupervisorConfig};

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
            Self::NotARingPlatform => ConfigRefusal::Geometry,
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
        })
    }

    fn axis_kind(&self, axis: u8) -> Option<AxisKind> {
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

/// Switch and supply levels, as read from the pins (after debouncing and polarity).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Inputs {
    /// E-stop chain open.
    pub estop_open: bool,
    /// Home switch of each axis (bit per axis): the carriage index switches and the linear actuators' home ends.
    pub home: u16,
    /// End-of-travel switch at the far end of each linear actuator (bit per axis).
    pub limits: u16,
    /// LOGIC_OK.
    pub logic_ok: bool,
    /// POWER_OK.
    pub power_ok: bool,
}

/// What the firmware does in one control period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickOutput {
    /// Pulses of each axis for this period.
    pub moves: [AxisMove; 6],
    /// Relays, driver enable.
    pub outputs: Outputs,
}

/// The controller.
pub struct Controller {
    /// The configuration running now.
    config: ControllerConfig,
    /// The configuration as stored: equal to `config` but for settings that take effect at the next start.
    saved: ControllerConfig,
    /// Settings changed since the firmware last took them for storing (bit per [`ConfigKey::code`]).
    unsaved: u64,
    home_pose: Pose<f32>,
    supervisor: Supervisor,
    pipeline: Pipeline<RingPlatform<f32>>,
    scheduler: StepScheduler,
    plan: HomingPlan,
    homing: Option<HomingSequencer>,
    homing_carry: i64,
    /// Homing found every switch; the platform is on its way to the home pose.
    returning_home: bool,
    /// Re-homing a homed machine: the platform is on its way to the parking pose near the switches first.
    parking: bool,
    connected: bool,
    inputs: Inputs,
    elapsed_us: u32,
    bad_frames: u32,
    tick_cost: u32,
    queue_depth: u16,
    pending_fault: bool,
    telemetry: TelemetryClock,
    /// Electrical input levels as the board sampled them, if it does.
    raw_inputs: Option<u16>,
    /// A commissioning move in progress, and whether its axis's home switch was active when it started.
    jog: Option<(Jog, bool)>,
}

/// When the next telemetry sample is due, and what the previous one counted (for its flags).
#[derive(Debug, Clone, Copy, Default)]
struct TelemetryClock {
    /// Device time (us).
    now_us: u64,
    /// Ticks since the last sample.
    ticks: u32,
    /// The host asked for telemetry on this connection.
    on: bool,
    due: bool,
    /// `(limited, refused, held)` at the last sample.
    counted: (u32, u32, u32),
}

impl Controller {
    /// A controller in `Off`, axes at step position zero.
    pub fn new(config: ControllerConfig) -> Result<Self, ConfigError> {
        let geometry = &config.geometry;
        if !config.scheduler.is_valid() || config.scheduler.period_ns != config.pipeline.tick_us.saturating_mul(1000) {
            return Err(ConfigError::Scheduler);
        }
        config.pulse_timing().map_err(ConfigError::StepTiming)?;
        let mechanism = RingPlatform::<f32>::new(geometry);
        let home_pose = Pose::from_array(config.home).cast::<f32>();
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
            steps_per_rad: config.scales[0].steps_per_turn as f64 / core::f64::consts::TAU,
        };
        let plan = HomingPlan::new(config.homing, &ring).map_err(ConfigError::Homing)?;
        let converter = StepConverter::new(config.scales, mechanism.axes());
        let pipeline =
            Pipeline::new(mechanism, config.pipeline, converter, home_pose).map_err(ConfigError::HomePose)?;
        Ok(Self {
            config,
            saved: config,
            unsaved: 0,
            home_pose,
            supervisor: Supervisor::new(config.supervisor),
            pipeline,
            scheduler: StepScheduler::new(config.scheduler, [0; 6]),
            plan,
            homing: None,
            homing_carry: 0,
            returning_home: false,
            parking: false,
            connected: false,
            inputs: Inputs::default(),
            elapsed_us: 0,
            bad_frames: 0,
            tick_cost: 0,
            queue_depth: 0,
            pending_fault: false,
            telemetry: TelemetryClock::default(),
            raw_inputs: None,
            jog: None,
        })
    }

    /// The supervisor (state, outputs).
    pub fn supervisor(&self) -> &Supervisor {
        &self.supervisor
    }

    /// The motion pipeline.
    pub fn pipeline(&self) -> &Pipeline<RingPlatform<f32>> {
        &self.pipeline
    }

    /// Step position of every axis (what has been scheduled).
    pub fn steps(&self) -> [i64; 6] {
        self.scheduler.position()
    }

    /// The firmware reports the cost of its last tick and its step-queue depth for the status.
    pub fn set_platform_stats(&mut self, tick_cost: u32, queue_depth: u16) {
        self.tick_cost = tick_cost;
        self.queue_depth = queue_depth;
    }

    /// Reports a watchdog reset (once, at boot).
    pub fn watchdog_reset(&mut self) {
        self.event(Event::WatchdogReset);
    }

    /// The step generator could not keep its output buffer ahead of the hardware: steps may have been played out
    /// of order, so the position is no longer known. Latches a motion fault (drivers off, homing needed).
    pub fn step_generator_fault(&mut self) {
        self.event(Event::MotionFault);
    }

    fn event(&mut self, e: Event) {
        let was_fault = matches!(self.supervisor.state(), State::Fault(..));
        // Inputs and time always apply; refusals only concern commands.
        let _ = self.supervisor.handle(e);
        self.after_transition(was_fault);
    }

    fn after_transition(&mut self, was_fault: bool) {
        if self.supervisor.state() != State::Jogging {
            self.jog = None;
        }
        if matches!(self.supervisor.state(), State::Fault(..)) {
            self.pipeline.halt();
            self.homing = None;
            self.returning_home = false;
            self.parking = false;
            if !was_fault {
                self.pending_fault = true;
            }
        }
    }

    /// The electrical levels of the input pins as the board sampled them (before debouncing and polarity), for
    /// [`HostMessage::GetInputs`].
    pub fn set_raw_inputs(&mut self, raw: u16) {
        self.raw_inputs = Some(raw);
    }

    /// Every input's level and state.
    pub fn input_report(&self) -> InputReport {
        let active = crate::safety::debounce::from_inputs(&self.inputs);
        let polarity = self.config.inputs.active_low;
        InputReport {
            raw: self.raw_inputs.unwrap_or(active ^ polarity),
            sampled: self.raw_inputs.is_some(),
            active,
            active_low: polarity,
            debounce_ms: self.config.inputs.debounce_samples,
        }
    }

    /// New input levels: changes become supervisor events. A linear actuator's home end is also an
    /// end-of-travel limit outside homing; a carriage passes its index switch every turn, which is no fault.
    pub fn set_inputs(&mut self, inputs: Inputs) {
        let old = self.inputs;
        self.inputs = inputs;
        if inputs.estop_open != old.estop_open {
            self.event(Event::EStop(inputs.estop_open));
        }
        if inputs.logic_ok != old.logic_ok {
            self.event(Event::LogicOk(inputs.logic_ok));
        }
        if inputs.power_ok != old.power_ok {
            self.event(Event::PowerOk(inputs.power_ok));
        }
        let homing_axis = self.homing.as_ref().and_then(|h| h.current_axis());
        let axes = self.pipeline.mechanism().axes();
        let limit_bits = |i: &Inputs| {
            let mut bits = i.limits;
            for (a, kind) in axes.iter().enumerate() {
                if *kind == AxisKind::Linear && homing_axis != Some(a as u8) {
                    bits |= i.home & (1 << a);
                }
            }
            bits
        };
        let (was, now) = (limit_bits(&old), limit_bits(&inputs));
        for a in 0..6u8 {
            let bit = 1u16 << a;
            if (was ^ now) & bit != 0 {
                self.event(Event::Limit(a, now & bit != 0));
            }
        }
    }

    /// Handles one request; always exactly one response.
    pub fn handle(&mut self, request: &Request) -> Response {
        let body = match request.body {
            HostMessage::Hello { version } => {
                if version == PROTOCOL_VERSION {
                    self.connected = true;
                    self.telemetry.on = false;
                    DeviceMessage::Hello {
                        version: PROTOCOL_VERSION,
                        preset: Preset::ALL
                            .into_iter()
                            .find(|p| matches!(p.geometry(), PresetGeometry::Ring(g) if *g == self.config.geometry)),
                        axes: self.pipeline.mechanism().axes(),
                    }
                } else {
                    self.connected = false;
                    DeviceMessage::Nack(NackReason::VersionMismatch {
                        device: PROTOCOL_VERSION,
                    })
                }
            }
            _ if !self.connected => DeviceMessage::Nack(NackReason::NotConnected),
            HostMessage::Setpoint(sp) => match self.pipeline.submit(&sp) {
                Ok(Accepted::Applied) => DeviceMessage::Ack,
                Ok(Accepted::Limited(report)) => DeviceMessage::Limited(report),
                Err(reason) => DeviceMessage::Nack(NackReason::Rejected(reason)),
            },
            HostMessage::GetStatus => DeviceMessage::Status(self.status()),
            HostMessage::GetInputs => DeviceMessage::Inputs(self.input_report()),
            HostMessage::Jog { axis, steps } => self.start_jog(axis, Some(steps)),
            HostMessage::Buzz { axis } => self.start_jog(axis, None),
            HostMessage::Telemetry(on) => {
                self.telemetry.on = on;
                self.telemetry.ticks = 0;
                DeviceMessage::Ack
            }
            HostMessage::GetConfig(key) => match self.get_config(key) {
                Some(v) => DeviceMessage::Config(key, v),
                None => DeviceMessage::Nack(NackReason::BadConfig(ConfigRefusal::OutOfRange)),
            },
            HostMessage::SetConfig(key, value) => match self.set_config(key, value) {
                Ok(()) => DeviceMessage::Ack,
                Err(r) => DeviceMessage::Nack(r),
            },
            HostMessage::Enable => self.command(Event::Enable),
            HostMessage::Disable => self.command(Event::Disable),
            HostMessage::Home => self.command(Event::Home),
            HostMessage::Start => self.command(Event::Start),
            HostMessage::Stop => self.command(Event::Stop),
            HostMessage::ClearFault => self.command(Event::ClearFault),
        };
        Response { id: request.id, body }
    }

    /// Starts a jog (`Some(steps)`) or a buzz (`None`) of `axis`, if the supervisor allows it.
    fn start_jog(&mut self, axis: u8, steps: Option<i32>) -> DeviceMessage {
        let a = usize::from(axis);
        let (Some(homing), Some(kind)) = (
            self.config.homing.axes.get(a).copied(),
            self.pipeline.mechanism().axes().get(a).copied(),
        ) else {
            return DeviceMessage::Nack(NackReason::OutOfRange);
        };
        // A carriage moves at most its homing back-off unhomed or not (never far enough to reach a neighbour on
        // the ring); a linear actuator at most the travel its homing searches blind.
        let longest = match kind {
            AxisKind::Ring => homing.backoff_steps,
            AxisKind::Linear | AxisKind::Angle => homing.search_steps,
        };
        if steps.is_some_and(|s| s == 0 || s.unsigned_abs() > longest) {
            return DeviceMessage::Nack(NackReason::OutOfRange);
        }
        let answer = self.command(Event::Jog);
        if answer != DeviceMessage::Ack {
            return answer;
        }
        let from = self.scheduler.position()[a];
        let jog = match steps {
            Some(s) => Jog::one_leg(a, from, s, homing.slow_rate),
            None => {
                let amplitude = i32::try_from((homing.backoff_steps / 2).max(1)).unwrap_or(i32::MAX);
                Jog::buzz(a, from, amplitude, homing.fast_rate)
            }
        };
        self.jog = Some((jog, self.inputs.home & (1 << a) != 0));
        answer
    }

    /// One tick of a jog: the axis a step further, the others where they are; done at the end of the last leg or
    /// when the axis's home switch closes.
    fn jog_tick(&mut self, position: [i64; 6], tick_us: u32) -> [i64; 6] {
        let Some((jog, home_at_start)) = self.jog.as_mut() else {
            self.event(Event::JogDone);
            return position;
        };
        let a = jog.axis;
        let home_now = self.inputs.home & (1 << a) != 0;
        let next = if home_now && !*home_at_start {
            None
        } else {
            jog.next(position[a], tick_us)
        };
        match next {
            Some(p) => {
                let mut targets = position;
                targets[a] = p;
                targets
            }
            None => {
                self.jog = None;
                self.event(Event::JogDone);
                position
            }
        }
    }

    fn command(&mut self, e: Event) -> DeviceMessage {
        let was_fault = matches!(self.supervisor.state(), State::Fault(..));
        let was_homed = self.supervisor.homed() && self.supervisor.state() == State::Ready;
        let result = self.supervisor.handle(e);
        self.after_transition(was_fault);
        if let Err(r) = result {
            return DeviceMessage::Nack(NackReason::Refused(r));
        }
        match e {
            Event::Home => {
                self.homing_carry = 0;
                self.returning_home = false;
                // A homed machine knows where its switches are: it first moves, under the normal limits and
                // checks, to where the first homing started (each axis a little before its switch), so that
                // every search is as short as the first one was. The home pose is often further from a linear
                // actuator's end switch than its search travel.
                self.parking = was_homed
                    && self
                        .parking_pose()
                        .is_ok_and(|pose| self.pipeline.move_to(pose).is_ok());
                self.homing = (!self.parking).then(|| HomingSequencer::new(self.plan, &self.scheduler.position()));
            }
            Event::Start => self.pipeline.start(),
            Event::Stop => {
                self.pipeline.stop();
                if self.homing.take().is_some() || self.returning_home || self.parking {
                    self.pipeline.halt();
                    self.returning_home = false;
                    self.parking = false;
                }
            }
            _ => {}
        }
        DeviceMessage::Ack
    }

    /// Decodes a frame, handles it and encodes the response into `out`; returns the response length. A frame that
    /// does not decode is counted and answered with a `Malformed` nack (id 0): it is never executed.
    pub fn handle_frame(&mut self, frame: &[u8], out: &mut [u8]) -> usize {
        let response = match protocol::decode::<Request>(frame) {
            Ok(request) => self.handle(&request),
            Err(_) => {
                self.bad_frames = self.bad_frames.saturating_add(1);
                Response {
                    id: 0,
                    body: DeviceMessage::Nack(NackReason::Malformed),
                }
            }
        };
        protocol::encode(&response, out).unwrap_or(0)
    }

    /// An unsolicited message to send, if one is pending: a newly latched fault first, then a telemetry sample
    /// when one is due.
    pub fn unsolicited(&mut self) -> Option<Response> {
        if self.pending_fault {
            self.pending_fault = false;
            if let State::Fault(reason, _) = self.supervisor.state() {
                return Some(Response {
                    id: 0,
                    body: DeviceMessage::Fault(reason),
                });
            }
        }
        if !self.telemetry.due {
            return None;
        }
        self.telemetry.due = false;
        Some(Response {
            id: 0,
            body: DeviceMessage::Telemetry(self.telemetry_sample()),
        })
    }

    /// One telemetry sample; its flags say what happened since the previous one.
    pub fn telemetry_sample(&mut self) -> Telemetry {
        let limited = self.pipeline.limited().count;
        let refused = self.pipeline.rejected().total();
        let held = self.pipeline.held();
        let (l0, r0, h0) = self.telemetry.counted;
        self.telemetry.counted = (limited, refused, held);
        let flag = |changed: bool, bit: u8| if changed { bit } else { 0 };
        let flags = flag(limited != l0, TelemetryFlags::LIMITED)
            | flag(refused != r0, TelemetryFlags::REFUSED)
            | flag(held != h0, TelemetryFlags::HELD);
        Telemetry {
            time_us: self.telemetry.now_us,
            state: self.supervisor.state(),
            pose: self.pipeline.pose(),
            target: self.pipeline.target(),
            steps: self.scheduler.position(),
            flags,
            applied: self.pipeline.applied(),
            limited,
            refused,
            tick_cost: self.tick_cost,
            inputs: crate::safety::debounce::from_inputs(&self.inputs),
            outputs: {
                let o = self.supervisor.outputs();
                u8::from(o.logic_relay) | u8::from(o.power_relay) << 1 | u8::from(o.driver_enable) << 2
            },
        }
    }

    /// The status report.
    pub fn status(&self) -> Status {
        Status {
            state: self.supervisor.state(),
            homed: self.supervisor.homed(),
            steps: self.scheduler.position(),
            pose: self.pipeline.pose(),
            target: self.pipeline.target(),
            applied: self.pipeline.applied(),
            limited: *self.pipeline.limited(),
            rejected: *self.pipeline.rejected(),
            held: self.pipeline.held(),
            carried: self.scheduler.carried(),
            bad_frames: self.bad_frames,
            tick_cost: self.tick_cost,
            queue_depth: self.queue_depth,
        }
    }

    /// The configuration running now.
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// The configuration as stored (what the next start runs).
    pub fn saved_config(&self) -> &ControllerConfig {
        &self.saved
    }

    /// A setting changed over the protocol that the firmware has not stored yet, with its value; each change is
    /// handed out once. Nothing is lost: a key changed twice before it is taken is stored once, with its last value.
    ///
    /// Only while the power relay and the drivers are off: writing flash can stall the CPU (a sector erase on an
    /// STM32F4 for up to 2 s), which must never happen while anything could move.
    pub fn take_unsaved(&mut self) -> Option<(ConfigKey, f32)> {
        let o = self.supervisor.outputs();
        if o.power_relay || o.driver_enable {
            return None;
        }
        while self.unsaved != 0 {
            let code = self.unsaved.trailing_zeros();
            self.unsaved &= !(1u64 << code);
            if let Some(key) = ConfigKey::from_code(code as u8) {
                if let Some(value) = self.saved.get(key) {
                    return Some((key, value));
                }
            }
        }
        None
    }

    /// Whether settings wait to be stored.
    pub fn has_unsaved(&self) -> bool {
        self.unsaved != 0
    }

    fn get_config(&self, key: ConfigKey) -> Option<f32> {
        self.saved.get(key)
    }

    fn set_config(&mut self, key: ConfigKey, value: f32) -> Result<(), NackReason> {
        if !matches!(self.supervisor.outputs().motion, Motion::None) {
            return Err(NackReason::Refused(crate::safety::Refusal::WrongState));
        }
        let mut saved = self.saved;
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
        saved.set(key, value).map_err(refused)?;
        saved.validate().map_err(refused)?;
        if key.is_live() {
            let mut live = self.config;
            live.set(key, value).map_err(refused)?;
            self.config = live;
            self.pipeline.set_config(live.pipeline);
        }
        self.saved = saved;
        self.unsaved |= 1u64 << key.code();
        Ok(())
    }

    /// One control period.
    pub fn tick(&mut self) -> TickOutput {
        let tick_us = self.pipeline.config().tick_us;
        self.telemetry_tick(tick_us);
        self.elapsed_us = self.elapsed_us.saturating_add(tick_us);
        if self.elapsed_us >= 1000 {
            let ms = self.elapsed_us / 1000;
            self.elapsed_us %= 1000;
            self.event(Event::Elapsed(ms));
        }
        let position = self.scheduler.position();
        let outputs = self.supervisor.outputs();
        let targets = match outputs.motion {
            Motion::Stream => {
                let (targets, event) = self.pipeline.tick();
                match event {
                    Some(PipelineEvent::StreamLost) => self.event(Event::StreamLost),
                    Some(PipelineEvent::AtRest) => self.event(Event::AtRest),
                    Some(PipelineEvent::MotionFault) => self.event(Event::MotionFault),
                    None => {}
                }
                if self.supervisor.outputs().motion == Motion::Stream {
                    targets
                } else {
                    position
                }
            }
            Motion::Homing => self.homing_tick(position, tick_us),
            Motion::Jog => self.jog_tick(position, tick_us),
            Motion::None => position,
        };
        let outputs = self.supervisor.outputs();
        let targets = if outputs.driver_enable {
            targets
        } else {
            self.scheduler.position()
        };
        TickOutput {
            moves: self.scheduler.plan(&targets),
            outputs,
        }
    }

    /// Advances device time; a telemetry sample falls due every `tick rate / telemetry rate` ticks while the
    /// connected host asks for telemetry.
    fn telemetry_tick(&mut self, tick_us: u32) {
        let t = &mut self.telemetry;
        t.now_us = t.now_us.wrapping_add(u64::from(tick_us));
        let hz = u32::from(self.config.telemetry_hz);
        if hz == 0 || !self.connected || !t.on {
            t.ticks = 0;
            return;
        }
        t.ticks += 1;
        let every = (1_000_000 / tick_us.max(1) / hz).max(1);
        if t.ticks >= every {
            t.ticks = 0;
            t.due = true;
        }
    }

    /// After homing each axis's origin is known: step 0 is its value at the home pose, and its switch is at step
    /// `home_position`. Sets the converter's origins and finds the platform's pose at the axes' current positions
    /// by forward kinematics.
    fn pose_after_homing(&mut self) -> Result<Pose<f32>, KinematicsError> {
        let mechanism = *self.pipeline.mechanism();
        let home = MultiTurn::new(mechanism.inverse(&self.home_pose)?);
        let converter = self.pipeline.converter_mut();
        for a in 0..6 {
            converter.set_home(a, &home, 0);
        }
        self.pose_at_steps(&self.scheduler.position())
    }

    /// Where re-homing starts: every axis two back-off distances before its switch (homed coordinates), found
    /// by forward kinematics.
    fn parking_pose(&self) -> Result<Pose<f32>, KinematicsError> {
        let axes = &self.config.homing.axes;
        let steps = core::array::from_fn(|a| {
            let h = &axes[a];
            h.home_position - i64::from(h.toward) * 2 * i64::from(h.backoff_steps)
        });
        self.pose_at_steps(&steps)
    }

    /// The pose at motor step positions in homed coordinates (step 0 of each axis at the home pose).
    fn pose_at_steps(&self, position: &[i64; 6]) -> Result<Pose<f32>, KinematicsError> {
        let mechanism = *self.pipeline.mechanism();
        let home = MultiTurn::new(mechanism.inverse(&self.home_pose)?);
        let axes = mechanism.axes();
        let q = crate::kinematics::Actuators(core::array::from_fn(|a| {
            let scale = &self.config.scales[a];
            let per_unit = scale.per_unit(axes[a]) * if scale.invert { -1.0 } else { 1.0 };
            home.within.0[a] + position[a] as f32 / per_unit
        }));
        let options = crate::kinematics::NewtonOptions::default();
        Ok(mechanism.forward(&q, &self.home_pose, &options)?.pose)
    }

    fn homing_tick(&mut self, position: [i64; 6], tick_us: u32) -> [i64; 6] {
        if self.parking {
            let (targets, event) = self.pipeline.tick();
            match event {
                Some(PipelineEvent::AtRest) => {
                    self.parking = false;
                    self.homing = Some(HomingSequencer::new(self.plan, &targets));
                }
                Some(PipelineEvent::MotionFault) => self.event(Event::MotionFault),
                _ => {}
            }
            return targets;
        }
        if self.returning_home {
            let (targets, event) = self.pipeline.tick();
            match event {
                Some(PipelineEvent::AtRest) => {
                    self.returning_home = false;
                    self.event(Event::HomingDone);
                }
                Some(PipelineEvent::MotionFault) => self.event(Event::MotionFault),
                _ => {}
            }
            return targets;
        }
        let Some(homing) = self.homing.as_mut() else {
            return position;
        };
        match homing.update(&position, self.inputs.home) {
            HomingStep::Move { axis, rate } => {
                // Steps this period at `rate`, the fraction carried so that the average rate is exact.
                let total = i64::from(rate) * i64::from(tick_us) + self.homing_carry;
                let steps = total / 1_000_000;
                self.homing_carry = total % 1_000_000;
                let mut t = position;
                t[usize::from(axis % 6)] += steps;
                t
            }
            HomingStep::Homed { axis, .. } => {
                // The switch defines this axis's origin: here it is at step `home_position`.
                let a = usize::from(axis % 6);
                let mut p = position;
                p[a] = self.config.homing.axes[a].home_position;
                self.scheduler.set_position(p);
                self.homing_carry = 0;
                p
            }
            HomingStep::Done => {
                self.homing = None;
                let started = self
                    .pose_after_homing()
                    .ok()
                    .and_then(|pose| self.pipeline.reset(pose).ok());
                if started.is_some() && self.pipeline.move_to(self.home_pose).is_ok() {
                    self.returning_home = true;
                } else {
                    self.event(Event::HomingFailed);
                }
                self.scheduler.position()
            }
            HomingStep::Failed(_) => {
                self.homing = None;
                self.event(Event::HomingFailed);
                position
            }
        }
    }
}
