//! ringpod-core: the hardware-independent core of the ringpod motion controller.
//!
//! Everything that decides what the machine does lives here, as `no_std` code without allocation or
//! panics, so that the firmware, the host simulator and the QEMU tests run the very same logic.
//!
//! This release holds the kinematics of the three circular-guide mechanisms of `KINEMATICS.md`:
//! - [`kinematics::RingPlatform`]: carriages on a ring with rod chains and radial linear-actuator chains.
//!   The *trainer* (four chains, six actuators, the machine the firmware drives) and the *rotopod* (six rod
//!   chains) are two chain layouts of it.
//! - [`kinematics::ToolCarrier`]: the five-DOF parallel-serial tool carrier with two planar dyads.
//!
//! All math is generic over [`Real`] (`f32` on the MCU, `f64` for host analysis) and calls `libm`
//! explicitly, so that the same `f32` code gives the same bits on a PC and on a Cortex-M4F.

#![cfg_attr(not(test), no_std)]
#![warn(missing_docs)]
// No panics: no unwrap/expect/panic in the core. Array indexing stays: every loop runs to the chain count,
// which the validated geometry bounds by the arrays' length of six.
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod controller;
pub mod cueing;
pub mod kinematics;
pub mod model;
pub mod motion;
pub mod protocol;
mod real;
pub mod safety;
pub mod screws;
#[cfg(feature = "sim")]
pub mod selfcheck;
#[cfg(feature = "sim")]
pub mod sim;
pub mod store;
pub mod vehicle;

pub use real::Real;
