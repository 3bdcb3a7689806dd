//! The supervisor's states: what it is doing ([`State`]), which supplies a latched fault keeps ([`Supplies`]), where
//! the shutdown sequence is ([`Shutdown`]) and why a fault latched ([`FaultReason`]).

use core::fmt;

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
