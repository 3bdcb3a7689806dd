//! The host's integration tests: `ringpod` run as a user runs it (the CLI, its streams into the simulated
//! controller, the games' telemetry, the workbench's server), one module per subject.
//!
//! One test program, not one per file: the host and its dependencies are linked once (on Linux and in the
//! Windows cross-build), and the tests of every subject run side by side in one process, where most of them wait
//! on a child `ringpod` in real time.

mod common;

mod adversary;
mod aux;
mod capture;
mod cli;
mod dynamics;
mod followed;
mod front_ends;
mod games;
mod inputs;
mod line_endings;
mod link;
mod live_motion;
mod lost;
mod motion_compensation;
mod outputs;
mod safety;
mod signals;
mod spare;
mod stability;
mod stall;
mod stream;
mod tcp;
mod ui;
mod versions;
