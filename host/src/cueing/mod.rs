//! How a game's telemetry becomes platform motion: the cueing between the games' readers ([`crate::games`]) and
//! the stream ([`crate::stream`]). The live engine a stream and the workbench run at every sample (the classical
//! washout of the core, or the optimal cueing's plan: [`engine`], [`optimal`], its reference from the laps before:
//! [`lap`], the games' lap positions as its distance: [`lap_track`]), retuned and restarted without a jump
//! ([`live`]); and the same engine offline, to tune it: a recorded drive cued to poses (`ringpod cue`: [`offline`],
//! from a packet capture: [`capture`]) and scored against another tuning and the floors (`cue --compare`: [`bench`]).

pub mod bench;
pub mod capture;
pub mod engine;
pub mod error;
pub mod lap;
pub mod lap_track;
pub mod live;
pub mod offline;
pub mod optimal;
