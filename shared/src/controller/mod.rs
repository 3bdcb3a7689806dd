//! The controller: protocol dispatch, supervisor, homing, motion pipeline and step scheduler wired together.
//!
//! This is the whole decision-making of the device. The firmware calls it from its tasks (frames from USB,
//! input levels from the switches, one [`Controller::tick`] per control period) and drives its pins from what it
//! returns; the host simulator and the tests call exactly the same code.

mod config;
mod dispatch;
mod homing;
mod sections;
mod settings;

/// The inputs the controller reads (they belong to the safety layer, which debounces them).
pub use crate::safety::Inputs;
pub use config::{Checked, ConfigError, ControllerConfig};
pub use sections::axis_scale;
pub use settings::Restart;

use crate::kinematics::{AxisKind, Mechanism, Pose, RingPlatform};
use crate::motion::jog::Jog;
use crate::motion::{AxisMove, Pipeline, PipelineEvent, StepConverter, StepScheduler, SPARE_AXES};
use crate::protocol::{DeviceMessage, Firmware, InputReport, Response, RigSource, Status, Telemetry, TelemetryFlags};
use crate::safety::homing::HomingPlan;
use crate::safety::{Command, Event, HostWatch, Motion, Outputs, State, Supervisor};
use homing::Homing;

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
    /// The stored configuration changed since the firmware last took it for storing.
    unsaved: bool,
    home_pose: Pose<f32>,
    supervisor: Supervisor,
    pipeline: Pipeline<RingPlatform<f32>>,
    scheduler: StepScheduler,
    /// The spare axes' steps, on the same timing as the platform's.
    spare_scheduler: StepScheduler<SPARE_AXES>,
    plan: HomingPlan,
    homing: Homing,
    connected: bool,
    /// Hellos accepted since start: a board with several links sends unsolicited messages to the latest.
    hellos: u32,
    inputs: Inputs,
    elapsed_us: u32,
    bad_frames: u32,
    tick_cost: u32,
    queue_depth: u16,
    idle_periods: u32,
    passed_periods: u32,
    pending_fault: bool,
    telemetry: TelemetryClock,
    /// Electrical input levels as the board sampled them, if it does.
    raw_inputs: Option<u16>,
    /// A commissioning move in progress, and whether its axis's home switch was active when it started.
    jog: Option<(Jog, bool)>,
    /// Where the running rig came from (the board says so at boot).
    rig_source: RigSource,
    /// The host asked for a restart, and into what.
    restart: Option<Restart>,
    /// The firmware it runs (the board says so at boot).
    firmware: Firmware,
    /// A homing since start set every axis's origin: the counted steps say where the axes are (whatever moved them
    /// since, a power-down, a jog or a fault, the motors did it step by step), so homing again can park first.
    origins: bool,
    /// The silence since a lost stream: a host gone that long powers the machine down (`safety::HostWatch`).
    host: HostWatch,
    /// The board drives the spare axes' STEP/DIR (see [`Controller::no_spare_outputs`]).
    spare_outputs: bool,
    /// The spare axes' pulses of the last tick, when either is fitted: kept here rather than in [`TickOutput`],
    /// whose every byte is copied on each tick's way out (a tick without spare axes pays nothing for them).
    spare_moves: Option<[AxisMove; SPARE_AXES]>,
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
        let Checked {
            mechanism,
            home_pose,
            plan,
        } = config.check()?;
        let converter = StepConverter::new(config.scales, mechanism.axes());
        let pipeline =
            Pipeline::new(mechanism, config.pipeline, converter, home_pose).map_err(ConfigError::HomePose)?;
        Ok(Self {
            config,
            saved: config,
            unsaved: false,
            home_pose,
            supervisor: Supervisor::new(config.supervisor),
            pipeline,
            scheduler: StepScheduler::new(config.scheduler, [0; 6]),
            spare_scheduler: StepScheduler::new(config.scheduler, [0; SPARE_AXES]),
            plan,
            homing: Homing::Idle,
            connected: false,
            hellos: 0,
            inputs: Inputs::default(),
            elapsed_us: 0,
            bad_frames: 0,
            tick_cost: 0,
            queue_depth: 0,
            idle_periods: 0,
            passed_periods: 0,
            pending_fault: false,
            telemetry: TelemetryClock::default(),
            raw_inputs: None,
            jog: None,
            rig_source: RigSource::Compiled,
            restart: None,
            firmware: Firmware::BUILT,
            origins: false,
            host: HostWatch::default(),
            spare_outputs: true,
            spare_moves: None,
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

    /// The board's step generator's counters, for the status: periods it played empty, and control periods
    /// passed (see [`Controller::pass`]).
    pub fn set_step_counters(&mut self, idle_periods: u32, passed_periods: u32) {
        self.idle_periods = idle_periods;
        self.passed_periods = passed_periods;
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
            self.homing = Homing::Idle;
            if !was_fault {
                self.pending_fault = true;
            }
        }
    }

    /// The electrical levels of the input pins as the board sampled them (before debouncing and polarity), for
    /// [`crate::protocol::HostMessage::GetInputs`].
    pub fn set_raw_inputs(&mut self, raw: u16) {
        self.raw_inputs = Some(raw);
    }

    /// Every input's level and state.
    pub fn input_report(&self) -> InputReport {
        let active = self.inputs.word();
        let polarity = self.config.inputs.active_low;
        InputReport {
            raw: self.raw_inputs.unwrap_or(active ^ polarity),
            sampled: self.raw_inputs.is_some(),
            active,
            active_low: polarity,
            debounce_ms: self.config.inputs.debounce_samples,
        }
    }

    /// New input levels: changes become supervisor events. A linear actuator's home end is also an end-of-travel
    /// limit outside homing; a carriage passes its index switch every turn and a shoulder its index flag, which is
    /// no fault.
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
        let homing_axis = self.homing.axis();
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

    /// How many hellos the controller has accepted since it started. A board serving the protocol on more than one
    /// link compares it before and after a frame to learn which link holds the connection: that link gets the
    /// unsolicited messages ([`Controller::unsolicited`]).
    pub fn hellos(&self) -> u32 {
        self.hellos
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
            inputs: self.inputs.word(),
            outputs: {
                let o = self.supervisor.outputs();
                u8::from(o.logic_relay) | u8::from(o.power_relay) << 1 | u8::from(o.driver_enable) << 2 | o.aux << 3
            },
        }
    }

    /// The status report.
    pub fn status(&self) -> Status {
        Status {
            state: self.supervisor.state(),
            homed: self.supervisor.homed(),
            aux: self.supervisor.aux(),
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
            idle_periods: self.idle_periods,
            passed_periods: self.passed_periods,
            spare_steps: self.spare_scheduler.position(),
        }
    }

    /// One control period.
    pub fn tick(&mut self) -> TickOutput {
        let tick_us = self.advance_clock();
        let position = self.scheduler.position();
        let outputs = self.supervisor.outputs();
        let targets = match outputs.motion {
            Motion::Stream => {
                let (targets, event) = self.pipeline.tick();
                match event {
                    Some(PipelineEvent::StreamLost) => self.stream_lost(),
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
        self.spare_moves = self.spare_tick(&outputs);
        TickOutput {
            moves: self.scheduler.plan(&targets),
            outputs,
        }
    }

    /// The spare axes' period: a stream's positions while the drivers are enabled; otherwise they stay at their
    /// counted steps, and the pipeline takes those as where they are (a fault or a disable stops them where the
    /// steps did, and the next stream starts there). Nothing when neither is fitted.
    fn spare_tick(&mut self, outputs: &Outputs) -> Option<[AxisMove; SPARE_AXES]> {
        if !self.pipeline.spare().any() {
            return None;
        }
        let targets = if outputs.driver_enable && outputs.motion == Motion::Stream {
            self.pipeline.spare_steps()
        } else {
            let at = self.spare_scheduler.position();
            self.pipeline.spare_at_steps(at);
            at
        };
        Some(self.spare_scheduler.plan(&targets))
    }

    /// The spare axes' pulses for the period the last [`Controller::tick`] planned (`None` when neither is fitted).
    pub fn spare_moves(&self) -> Option<[AxisMove; SPARE_AXES]> {
        self.spare_moves
    }

    /// The spare axes' counted steps.
    pub fn spare_steps(&self) -> [i64; SPARE_AXES] {
        self.spare_scheduler.position()
    }

    /// A control period that plans no motion, for a firmware whose step generator is already far enough ahead:
    /// after a hold-up of the control loop (a flash erase, a burst of link traffic) the periods it missed are
    /// caught up at once, while the step generator played them empty. Ticking them would queue their moves behind
    /// each other and every later period's behind those, for the rest of the session. A pass keeps the clocks
    /// (device time, the supervisor's timers, telemetry) as [`Controller::tick`] would, so a supply sequence or a
    /// power-down ends when it is due; motion is not advanced, because the motors did not move in the periods the
    /// hold-up cost: the pipeline, homing and jogging continue from where they were, one period later. Returns
    /// the outputs, which a timer may have changed.
    pub fn pass(&mut self) -> Outputs {
        self.advance_clock();
        // A stream's setpoints bound its hold-ups too (`Pipeline::pass`): a loop that stays behind still loses it.
        if self.supervisor.outputs().motion == Motion::Stream && self.pipeline.pass().is_some() {
            self.stream_lost();
        }
        self.supervisor.outputs()
    }

    /// Advances device time and the supervisor's timers by one period; returns the period (us).
    fn advance_clock(&mut self) -> u32 {
        let tick_us = self.pipeline.config().tick_us;
        self.telemetry_tick(tick_us);
        self.elapsed_us = self.elapsed_us.saturating_add(tick_us);
        if self.elapsed_us >= 1000 {
            let ms = self.elapsed_us / 1000;
            self.elapsed_us %= 1000;
            self.event(Event::Elapsed(ms));
            if self.host.elapse(ms, self.supervisor.state(), self.config.host_gone_ms) {
                // The host's STOP, given by the device: the drivers, the motor supply and the logic supply off in
                // the supervisor's order and delays.
                self.event(Event::Command(Command::Disable));
            }
        }
        tick_us
    }

    /// The stream's setpoints stopped: the platform brakes to rest, and a host silent from now on for the stream
    /// section's `host_gone_ms` is taken as gone.
    fn stream_lost(&mut self) {
        self.event(Event::StreamLost);
        if self.supervisor.state() == State::Stopping {
            self.host.lost();
        }
    }

    /// Milliseconds since a lost stream with no request from a host, while the device watches for one.
    pub fn host_silent_ms(&self) -> Option<u32> {
        self.host.silent_ms()
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
}
