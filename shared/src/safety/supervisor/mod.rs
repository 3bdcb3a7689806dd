//! The interlock state machine. Its [`Outputs`] are the only way anything energises: the firmware drives the
//! relays and the driver enable from them and nothing else, and the motion pipeline moves only when they allow it.
//!
//! States (FIRMWARE.md): `Off -> LogicOn (logic relay on, settle / LOGIC_OK) -> PowerOn (power relay on, settle /
//! POWER_OK) -> Homing -> Ready -> Running`, `Stopping` (ramp to rest), `Fault` (latched, with a reason), and the
//! shutdown sequence `ShuttingDown(Drivers)` (drivers disabled) -> `ShuttingDown(Discharge)` (power relay off) ->
//! `Off` (logic relay off).
//!
//! Invariants that hold after every transition (checked by exhaustive enumeration in the tests):
//! power never on without logic on and settled; logic never off while power is on (power goes off first); the
//! drivers are enabled only with power on and no fault; an e-stop or end-of-travel switch with power on lands in
//! `Fault` in the same step; a fault is left only by `ClearFault`; no stream motion before homing; an auxiliary
//! output is on only in `Ready`, `Running` or `Stopping` (so off in every fault, e-stop, disable and power-down),
//! switched on only by its command, and off after a stream loss.
//!
//! The auxiliary outputs (AUX1, AUX2: chapter 5.3.2's relays for a spindle, a pump, a valve) are test equipment
//! that works on the moving platform: they may be switched on only where the machine is homed and holding or
//! streaming, and leaving those states for anything else (homing again, a jog, a disable, a fault) switches them
//! off. A stream loss switches them off too: the host that switched them is gone, and equipment should not run
//! unattended while the platform brakes.
//!
//! Time is milliseconds spent in the current state, advanced by [`Event::Elapsed`] and saturating just past the
//! longest configured delay, which keeps the state space finite and enumerable.
//!
//! The files, one job each: `state` (the states and fault reasons), `config` (the delays and what is sensed),
//! `outputs` (each state's outputs, and the transitions that switch them), `commands` (which command is taken
//! where) and `timers` (what time moves on); this file holds the machine and routes each event.

mod commands;
mod config;
mod outputs;
mod state;
mod timers;

pub use config::SupervisorConfig;
pub use outputs::{Motion, Outputs};
pub use state::{FaultReason, Shutdown, State, Supplies};

use super::events::{Command, Event, Refusal};
use super::Inputs;

/// The interlock state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Supervisor {
    config: SupervisorConfig,
    state: State,
    timer_ms: u32,
    homed: bool,
    /// The levels its events reported.
    inputs: Inputs,
    /// The auxiliary outputs that are on (`Aux::bit`).
    aux: u8,
}

impl Supervisor {
    /// Starts in `Off` with every output off.
    pub fn new(config: SupervisorConfig) -> Self {
        Self {
            config,
            state: State::Off,
            timer_ms: 0,
            homed: false,
            inputs: Inputs::default(),
            aux: 0,
        }
    }

    /// A supervisor as its telemetry reports it: in `state` with these debounced inputs. Asked what it
    /// [`permits`](Self::permits), it answers as the device's own would (a host shows why a button is disabled;
    /// no decision depends on which auxiliary outputs are on).
    pub fn as_reported(config: SupervisorConfig, state: State, inputs: Inputs) -> Self {
        Self {
            config,
            state,
            timer_ms: 0,
            homed: state == State::Ready,
            inputs,
            aux: 0,
        }
    }

    /// Whether a command (or a jog) would be taken now, and if not why: the decision [`handle`](Self::handle)
    /// makes, on a copy, so nothing changes. Events that are not commands always apply.
    pub fn permits(&self, command: Event) -> Result<(), Refusal> {
        let mut probe = *self;
        match command {
            Event::Command(_) | Event::Jog => probe.command(command),
            _ => Ok(()),
        }
    }

    /// Current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// Whether the axes are homed.
    pub fn homed(&self) -> bool {
        self.homed
    }

    /// The input levels its events reported.
    pub fn inputs(&self) -> Inputs {
        self.inputs
    }

    /// The configuration.
    pub fn config(&self) -> &SupervisorConfig {
        &self.config
    }

    fn is_fault(&self) -> bool {
        matches!(self.state, State::Fault(..))
    }

    /// Reacts to one event. Commands that do not apply return a [`Refusal`] and change nothing; inputs and time
    /// always apply.
    pub fn handle(&mut self, event: Event) -> Result<(), Refusal> {
        let powered = self.outputs().power_relay;
        match event {
            Event::EStop(open) => {
                self.inputs.estop_open = open;
                if open && self.state != State::Off && !self.is_fault() {
                    self.fault(FaultReason::EStop);
                }
            }
            Event::Limit(axis, active) => {
                let bit = 1u16.checked_shl(u32::from(axis)).unwrap_or(0);
                if active {
                    self.inputs.limits |= bit;
                } else {
                    self.inputs.limits &= !bit;
                }
                if active && powered && !self.is_fault() {
                    self.fault(FaultReason::Limit(axis));
                }
            }
            Event::LogicOk(ok) => {
                self.inputs.logic_ok = ok;
                let logic_up = !matches!(self.state, State::Off | State::LogicOn) && self.outputs().logic_relay;
                if !ok && self.config.logic_sense && logic_up && !self.is_fault() {
                    self.fault(FaultReason::LogicLost);
                }
            }
            Event::PowerOk(ok) => {
                self.inputs.power_ok = ok;
                let power_up = powered && !matches!(self.state, State::PowerOn { settled: false });
                if !ok && self.config.power_sense && power_up && !self.is_fault() {
                    self.fault(FaultReason::PowerLost);
                }
            }
            Event::WatchdogReset => {
                if !self.is_fault() {
                    self.fault(FaultReason::Watchdog);
                }
            }
            Event::JogDone => {
                if self.state == State::Jogging {
                    self.go(State::PowerOn { settled: true });
                }
            }
            Event::MotionFault => {
                if matches!(
                    self.state,
                    State::Running | State::Stopping | State::Homing | State::Jogging
                ) {
                    self.fault(FaultReason::MotionFault);
                }
            }
            Event::Elapsed(ms) => self.elapse(ms),
            Event::HomingDone => {
                if self.state == State::Homing {
                    self.homed = true;
                    self.go(State::Ready);
                }
            }
            Event::HomingFailed => {
                if self.state == State::Homing {
                    self.fault(FaultReason::HomingFailed);
                }
            }
            Event::AtRest => {
                if self.state == State::Stopping {
                    self.go(State::Ready);
                }
            }
            Event::StreamLost => {
                if self.state == State::Running {
                    self.aux = 0;
                    self.go(State::Stopping);
                }
            }
            Event::Command(Command::Enable)
            | Event::Command(Command::Disable)
            | Event::Command(Command::Home)
            | Event::Command(Command::Start)
            | Event::Command(Command::Stop)
            | Event::Command(Command::ClearFault)
            | Event::Command(Command::Aux { .. })
            | Event::Jog => return self.command(event),
        }
        Ok(())
    }
}
