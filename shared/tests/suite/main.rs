//! The core's integration tests, run on the host: the kinematics against the source's reference values, the
//! controller and its pipeline through requests, the step scheduler, the protocol and the settings store, with
//! properties over many random inputs. One module per subject.
//!
//! One test program, not one per file: the core and proptest are compiled and linked once, and the subjects' tests
//! run side by side in one process.

mod common;
// The latency example's measurement, held by `latency`'s test.
#[allow(dead_code)]
#[path = "../../examples/latency.rs"]
mod latency_example;

mod aux;
mod bootloader;
mod continuous_yaw;
mod cueing;
mod cueing_tuning;
mod dynamics;
mod elbow;
mod elbow_drive;
mod forward;
mod guard;
mod homing;
mod host_gone;
mod jog;
mod latency;
mod pass;
mod pipeline;
mod properties;
mod protocol;
mod pulse;
mod reference;
mod rig_record;
mod scheduler;
mod screws;
mod selfcheck;
mod settings;
mod source_numbers;
mod spare;
mod stability;
mod store;
mod structure;
mod supervisor;
mod telemetry;
mod tipping;
mod tool_loads;
mod unframe;
mod validation;
