//! Safety: the interlock supervisor (FIRMWARE.md "Safety supervisor"), the homing sequence and the rule for a host
//! gone long after its stream was lost.

pub mod debounce;
mod events;
pub mod homing;
mod host_gone;
pub mod pins;
pub mod supervisor;

pub use events::{Aux, AuxLevels, Command, Event, Refusal};
pub use homing::{HomingConfig, HomingPlan, HomingSequencer, HomingStep};
pub use host_gone::{HostWatch, HOST_GONE_MS};
pub use supervisor::{FaultReason, Motion, Outputs, State, Supervisor, SupervisorConfig, Supplies};

/// Switch and supply levels, as read from the pins (after debouncing and polarity). The supervisor keeps the
/// ones its events report (its `home` stays clear: homing reads the switches, the interlocks do not).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
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
