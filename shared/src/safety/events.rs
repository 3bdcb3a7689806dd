//! What the supervisor is told (an operator's commands, the machine's events) and why it may refuse a command.

use core::fmt;

/// What an operator asks of the supervisor: one type for the wire (`protocol::HostMessage::Command`) and
/// for the state machine ([`Event::Command`]), so the two cannot drift apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Bring up logic, then power.
    Enable,
    /// Shut down: drivers, power, then logic.
    Disable,
    /// Home the axes.
    Home,
    /// Start taking the pose stream.
    Start,
    /// Ramp to rest (or abort homing).
    Stop,
    /// Clear a latched fault.
    ClearFault,
    /// Switch an auxiliary output (test equipment: a spindle, a pump, a valve). On only when homed and holding or
    /// streaming (`Ready`, `Running`); off is always taken.
    Aux {
        /// Which output.
        output: Aux,
        /// `true`: on.
        on: bool,
    },
}

impl Command {
    /// Every command, in wire order (each auxiliary output on and off).
    pub const ALL: [Command; 10] = [
        Command::Enable,
        Command::Disable,
        Command::Home,
        Command::Start,
        Command::Stop,
        Command::ClearFault,
        Command::Aux {
            output: Aux::Aux1,
            on: true,
        },
        Command::Aux {
            output: Aux::Aux1,
            on: false,
        },
        Command::Aux {
            output: Aux::Aux2,
            on: true,
        },
        Command::Aux {
            output: Aux::Aux2,
            on: false,
        },
    ];
}

/// One of the two auxiliary outputs (chapter 5.3.2's control box: two 10 A relays for test equipment).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Aux {
    /// AUX1.
    Aux1,
    /// AUX2.
    Aux2,
}

impl Aux {
    /// Both, in order.
    pub const ALL: [Aux; 2] = [Aux::Aux1, Aux::Aux2];

    /// The output numbered `n` (1 or 2), as an operator names it.
    pub fn from_number(n: u8) -> Option<Aux> {
        match n {
            1 => Some(Aux::Aux1),
            2 => Some(Aux::Aux2),
            _ => None,
        }
    }

    /// Its bit in [`AuxLevels`] and in [`crate::safety::Outputs::aux`]: bit 0 AUX1, bit 1 AUX2.
    pub const fn bit(self) -> u8 {
        match self {
            Aux::Aux1 => 1,
            Aux::Aux2 => 2,
        }
    }
}

/// What a setpoint asks of the auxiliary outputs, one entry per output (AUX1, AUX2): `Some(level)` switches it when
/// the setpoint is taken, `None` leaves it as it is (a pose file without that column).
pub type AuxLevels = [Option<bool>; 2];

/// An event the supervisor reacts to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// An operator's command.
    Command(Command),
    /// Command: jog or buzz one axis (commissioning), from powered-and-settled or from Ready.
    Jog,
    /// The jog or buzz finished (or stopped at a switch).
    JogDone,
    /// LOGIC_OK input level.
    LogicOk(bool),
    /// POWER_OK input level.
    PowerOk(bool),
    /// E-stop chain: `true` = open (stop).
    EStop(bool),
    /// End-of-travel switch of an axis: `true` = tripped.
    Limit(u8, bool),
    /// The homing sequence finished.
    HomingDone,
    /// The homing sequence failed.
    HomingFailed,
    /// The stopping ramp reached rest.
    AtRest,
    /// No valid setpoint within the stream timeout.
    StreamLost,
    /// The motion pipeline could not keep the platform inside its workspace.
    MotionFault,
    /// Reported once at boot when the reset cause was the watchdog.
    WatchdogReset,
    /// Time passed (ms).
    Elapsed(u32),
}

/// Why a command was not carried out (the state is unchanged).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum Refusal {
    /// The command does not apply in the current state.
    WrongState,
    /// The e-stop chain is open.
    EStopOpen,
    /// An end-of-travel switch is tripped.
    LimitActive,
    /// A latched fault must be cleared first.
    Faulted,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::WrongState => "not possible in the current state",
            Self::EStopOpen => "e-stop is open",
            Self::LimitActive => "a limit switch is tripped",
            Self::Faulted => "a fault is latched: clear it first",
        })
    }
}
