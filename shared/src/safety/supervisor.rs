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

use core::fmt;

use super::events::{Command, Event, Refusal};
use super::Inputs;

/// Supply sequencing and sensing. A rig file's `[supervisor]` section is this type, by its field names (an unknown
/// key is an error there; postcard, which has no names, is not affected).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupervisorConfig {
    /// The board has a LOGIC_OK input; without it, timing alone sequences.
    pub logic_sense: bool,
    /// The board has a POWER_OK input.
    pub power_sense: bool,
    /// Wait after the logic relay closes (and LOGIC_OK, if sensed) before the power relay may close (ms).
    pub logic_settle_ms: u32,
    /// Wait after the power relay closes (and POWER_OK, if sensed) before the drivers may be enabled (ms).
    pub power_settle_ms: u32,
    /// A sensed supply that is not up this long after its relay closed is a fault (ms).
    pub supply_timeout_ms: u32,
    /// Drivers disabled this long before the power relay opens on shutdown (ms).
    pub driver_off_ms: u32,
    /// Power supply discharge time before the logic relay opens on shutdown (ms).
    pub discharge_ms: u32,
}

impl Default for SupervisorConfig {
    fn default() -> Self {
        Self {
            logic_sense: true,
            power_sense: true,
            logic_settle_ms: 100,
            power_settle_ms: 200,
            supply_timeout_ms: 1000,
            driver_off_ms: 20,
            discharge_ms: 500,
        }
    }
}

impl SupervisorConfig {
    /// Longest delay a configuration may set (ms): a supply that takes longer to come up or discharge is not one
    /// this controller should sequence blind.
    pub const LONGEST_MS: u32 = 60_000;

    /// Every delay at most [`Self::LONGEST_MS`], and a sensed supply given time to come up.
    pub fn is_valid(&self) -> bool {
        let delays = [
            self.logic_settle_ms,
            self.power_settle_ms,
            self.supply_timeout_ms,
            self.driver_off_ms,
            self.discharge_ms,
        ];
        delays.iter().all(|d| *d <= Self::LONGEST_MS)
            && (self.supply_timeout_ms > 0 || !(self.logic_sense || self.power_sense))
    }

    fn timer_cap(&self) -> u32 {
        let longest = self
            .logic_settle_ms
            .max(self.power_settle_ms)
            .max(self.supply_timeout_ms);
        longest.max(self.driver_off_ms).max(self.discharge_ms).saturating_add(1)
    }
}

/// Why the supervisor latched a fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum FaultReason {
    /// The e-stop chain opened.
    EStop,
    /// An end-of-travel switch of this axis tripped.
    Limit(u8),
    /// LOGIC_OK dropped while logic was up.
    LogicLost,
    /// POWER_OK dropped while power was up.
    PowerLost,
    /// A sensed supply did not come up within the timeout.
    SupplyTimeout,
    /// Homing did not find a switch within its travel.
    HomingFailed,
    /// The independent watchdog reset the MCU.
    Watchdog,
    /// The motion pipeline could not keep the platform inside its workspace while stopping.
    MotionFault,
}

impl fmt::Display for FaultReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EStop => f.write_str("e-stop open"),
            Self::Limit(axis) => write!(f, "limit switch of axis {axis}"),
            Self::LogicLost => f.write_str("logic supply lost"),
            Self::PowerLost => f.write_str("power supply lost"),
            Self::SupplyTimeout => f.write_str("supply did not come up in time"),
            Self::HomingFailed => f.write_str("homing failed"),
            Self::Watchdog => f.write_str("watchdog reset"),
            Self::MotionFault => f.write_str("motion left the workspace"),
        }
    }
}

/// Which supplies a state keeps on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Supplies {
    /// Both relays open.
    None,
    /// Logic relay closed, power relay open.
    Logic,
    /// Both relays closed.
    Both,
}

/// Phase of the shutdown sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Shutdown {
    /// Drivers disabled, power still on.
    Drivers,
    /// Power relay open, waiting for the supply to discharge; logic still on.
    Discharge,
}

/// Supervisor state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum State {
    /// Everything off.
    Off,
    /// Logic relay closed, waiting for it to settle.
    LogicOn,
    /// Power relay closed; `settled` once POWER_OK (if sensed) and the settle time are there. Not homed.
    PowerOn {
        /// Power is up and settled: homing may start.
        settled: bool,
    },
    /// Drivers enabled, the homing sequence moves the axes.
    Homing,
    /// Homed, drivers enabled and holding, no stream.
    Ready,
    /// Streaming poses.
    Running,
    /// Commissioning: one axis jogs or buzzes, the others hold (drivers enabled). Homing is void afterwards.
    Jogging,
    /// Ramping to rest (stop command or stream loss).
    Stopping,
    /// Latched fault; the supplies it keeps.
    Fault(FaultReason, Supplies),
    /// Shutdown sequence.
    ShuttingDown(Shutdown),
}

/// What the supervisor lets the motion pipeline do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Motion {
    /// Nothing moves.
    None,
    /// Only the homing sequence moves axes.
    Homing,
    /// The pose stream (and its stopping ramp) moves the platform.
    Stream,
    /// One axis jogs or buzzes (commissioning).
    Jog,
}

/// The supervisor's outputs: relays, driver enable, and what may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Outputs {
    /// LOGIC_EN relay.
    pub logic_relay: bool,
    /// POWER_EN relay.
    pub power_relay: bool,
    /// Stepper driver enable.
    pub driver_enable: bool,
    /// What may move.
    pub motion: Motion,
    /// The auxiliary outputs: bit 0 AUX1, bit 1 AUX2 (`Aux::bit`).
    pub aux: u8,
}

impl Outputs {
    /// Everything off.
    pub const OFF: Outputs = Outputs {
        logic_relay: false,
        power_relay: false,
        driver_enable: false,
        motion: Motion::None,
        aux: 0,
    };
}

/// The states an auxiliary output may stay on in: homed, drivers enabled, holding, streaming or braking.
fn keeps_aux(state: State) -> bool {
    matches!(state, State::Ready | State::Running | State::Stopping)
}

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

    /// Outputs of the current state.
    pub fn outputs(&self) -> Outputs {
        let (logic, power, enable, motion) = match self.state {
            State::Off => (false, false, false, Motion::None),
            State::LogicOn => (true, false, false, Motion::None),
            State::PowerOn { .. } | State::ShuttingDown(Shutdown::Drivers) => (true, true, false, Motion::None),
            State::Homing => (true, true, true, Motion::Homing),
            State::Jogging => (true, true, true, Motion::Jog),
            State::Ready => (true, true, true, Motion::None),
            State::Running | State::Stopping => (true, true, true, Motion::Stream),
            State::Fault(_, supplies) => (
                supplies != Supplies::None,
                supplies == Supplies::Both,
                false,
                Motion::None,
            ),
            State::ShuttingDown(Shutdown::Discharge) => (true, false, false, Motion::None),
        };
        Outputs {
            logic_relay: logic,
            power_relay: power,
            driver_enable: enable,
            motion,
            aux: self.aux,
        }
    }

    /// Which auxiliary outputs are on (`Aux::bit`).
    pub fn aux(&self) -> u8 {
        self.aux
    }

    fn go(&mut self, state: State) {
        if state != self.state {
            self.state = state;
            self.timer_ms = 0;
        }
        // The one place a state changes: whatever leads out of the states that keep them, the outputs go off.
        if !keeps_aux(state) {
            self.aux = 0;
        }
    }

    /// Latches a fault, keeping only the supplies that are safe to keep for that reason.
    fn fault(&mut self, reason: FaultReason) {
        let out = self.outputs();
        let supplies = match reason {
            // Losing the e-stop chain, a supply or the MCU's health removes power; logic stays as it was.
            FaultReason::EStop
            | FaultReason::LogicLost
            | FaultReason::PowerLost
            | FaultReason::SupplyTimeout
            | FaultReason::Watchdog => {
                if out.logic_relay {
                    Supplies::Logic
                } else {
                    Supplies::None
                }
            }
            // Motion faults keep the supplies: the drivers are disabled, nothing else needs to drop.
            FaultReason::Limit(_) | FaultReason::HomingFailed | FaultReason::MotionFault => {
                match (out.logic_relay, out.power_relay) {
                    (true, true) => Supplies::Both,
                    (true, false) => Supplies::Logic,
                    _ => Supplies::None,
                }
            }
        };
        self.homed = false;
        self.go(State::Fault(reason, supplies));
    }

    /// What a command that may move something (homing, a jog, clearing a fault) needs: the e-stop chain closed and
    /// no end switch made.
    fn may_move(&self) -> Result<(), Refusal> {
        if self.inputs.estop_open {
            return Err(Refusal::EStopOpen);
        }
        if self.inputs.limits != 0 {
            return Err(Refusal::LimitActive);
        }
        Ok(())
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

    fn command(&mut self, command: Event) -> Result<(), Refusal> {
        // Switching an output off is always safe, and always taken (where it is off already, nothing changes).
        if let Event::Command(Command::Aux { output, on: false }) = command {
            self.aux &= !output.bit();
            return Ok(());
        }
        if self.is_fault() && command != Event::Command(Command::ClearFault) {
            return Err(Refusal::Faulted);
        }
        match (command, self.state) {
            (Event::Command(Command::Enable), State::Off) => {
                if self.inputs.estop_open {
                    return Err(Refusal::EStopOpen);
                }
                self.go(State::LogicOn);
            }
            (Event::Command(Command::Disable), State::LogicOn | State::PowerOn { .. } | State::Ready) => {
                // Without drive current the steppers hold nothing: the axes may be moved by hand or by gravity,
                // so the positions homing found are no longer known.
                self.homed = false;
                self.go(State::ShuttingDown(Shutdown::Drivers));
            }
            (Event::Command(Command::Home), State::PowerOn { settled: true } | State::Ready) => {
                self.may_move()?;
                self.homed = false;
                self.go(State::Homing);
            }
            (Event::Jog, State::PowerOn { settled: true } | State::Ready) => {
                self.may_move()?;
                // One axis moves away from the pose homing left: the platform must be homed again to stream.
                self.homed = false;
                self.go(State::Jogging);
            }
            (Event::Command(Command::Stop), State::Jogging) => self.go(State::PowerOn { settled: true }),
            (Event::Command(Command::Start), State::Ready) => self.go(State::Running),
            (Event::Command(Command::Aux { output, .. }), State::Ready | State::Running) => self.aux |= output.bit(),
            (Event::Command(Command::Stop), State::Running) => self.go(State::Stopping),
            (Event::Command(Command::Stop), State::Homing) => {
                self.homed = false;
                self.go(State::PowerOn { settled: true });
            }
            (Event::Command(Command::ClearFault), State::Fault(_, supplies)) => {
                self.may_move()?;
                self.go(match supplies {
                    Supplies::Both => State::PowerOn { settled: true },
                    // Logic is kept, power is off: the way back up is the normal Enable sequence from Off, and
                    // Off opens the logic relay, which is allowed because power is already off.
                    Supplies::Logic | Supplies::None => State::Off,
                });
            }
            _ => return Err(Refusal::WrongState),
        }
        Ok(())
    }

    fn elapse(&mut self, ms: u32) {
        self.timer_ms = self.timer_ms.saturating_add(ms).min(self.config.timer_cap());
        let c = self.config;
        let t = self.timer_ms;
        match self.state {
            State::LogicOn => {
                let up = self.inputs.logic_ok || !c.logic_sense;
                if up && t >= c.logic_settle_ms {
                    self.go(State::PowerOn { settled: false });
                } else if !up && t >= c.supply_timeout_ms {
                    self.fault(FaultReason::SupplyTimeout);
                }
            }
            State::PowerOn { settled: false } => {
                let up = self.inputs.power_ok || !c.power_sense;
                if up && t >= c.power_settle_ms {
                    self.go(State::PowerOn { settled: true });
                } else if !up && t >= c.supply_timeout_ms {
                    self.fault(FaultReason::SupplyTimeout);
                }
            }
            State::ShuttingDown(Shutdown::Drivers) if t >= c.driver_off_ms => {
                self.go(State::ShuttingDown(Shutdown::Discharge));
            }
            State::ShuttingDown(Shutdown::Discharge) if t >= c.discharge_ms => self.go(State::Off),
            _ => {}
        }
    }
}
