//! Safety: the interlock supervisor (FIRMWARE.md "Safety supervisor") and the homing sequence.

pub mod debounce;
pub mod homing;
pub mod pins;
pub mod supervisor;

pub use homing::{HomingConfig, HomingPlan, HomingSequencer, HomingStep};
pub use supervisor::{Event, FaultReason, Motion, Outputs, Refusal, State, Supervisor, SupervisorConfig, Supplies};
