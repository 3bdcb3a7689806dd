//! Motion: setpoints and their answers (`setpoint`), their validation and interpolation (`pipeline`),
//! velocity/acceleration limits, IK per tick, conversion to motor steps, and the step scheduler that turns
//! per-period step targets into timed pulses.

pub mod envelope;
pub mod jog;
pub mod limits;
pub mod phase;
pub mod pipeline;
pub mod pulse;
pub mod scheduler;
pub mod setpoint;
pub mod spare;
pub mod steps;

pub use envelope::{EnvelopeMargins, Limited};
pub use limits::{AxisTracker, MotionLimits};
pub use pipeline::{FollowMode, Pipeline, PipelineConfig, PipelineEvent};
pub use scheduler::{AxisMove, Direction, SchedulerConfig, StepScheduler, StepTimes};
pub use setpoint::{Accepted, LimitCounters, LimitReport, RejectCounters, RejectReason, Setpoint};
pub use spare::{SpareAxes, SpareAxisSettings, SpareTargets, SPARE_AXES};
pub use steps::{actuators_at_steps, AxisScale, StepConverter};
