//! End-to-end testing of ringpod without hardware: the controller core with a simulated plant ([`plant`]) and
//! data-driven scenarios ([`scenario`], files under `tests/scenarios/`).

pub mod busy;
pub mod cli;
pub mod emulator;
pub mod priority;
pub mod scenario;
pub mod sections;
pub mod setup;
pub mod wine;

/// The simulated plant lives in the core, where the host's simulator uses it too.
pub use ringpod_core::sim as plant;
