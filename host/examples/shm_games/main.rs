//! `cargo run --example shm_games -- GAME [SECONDS]`: a stand-in for a game's shared memory, for trying `ringpod
//! stream --telemetry-shm GAME` on Windows (or under Wine) without the game. It creates the game's named mapping(s)
//! with `CreateFileMappingW`, as the game (or its plugin) does, and writes a drive into them in the publisher's layout at the game's rate:
//! at rest, accelerating, braking, a left turn, nose up, rolled right side down, a second each, then a pause of a
//! second and a half (the counter stands still: ringpod counts a stall), over and over for SECONDS (30 by default).
//!
//! An example of the host rather than a program of the test runners: it builds with the host's tests (`cargo test
//! --no-run` builds examples), and it writes through the host's own named-mapping writer (`src/vr/mapping.rs`).
//!
//! The offsets are written here from the publishers' structures (Kunos' `SPageFilePhysics`, iRacing's
//! `irsdk_defines.h`, the rF2SharedMemoryMapPlugin's `rF2State.h`, `SharedMemory.h` of AMS2, the scs-sdk-plugin's
//! `scs-telemetry-common.hpp`), independently of ringpod's decoders, with the senses ringpod's modules state
//! (published or assumed); ringpod should cue surge forwards when accelerating, sway left in the left turn.
//!
//! It prints `shm_games: ready` once the mappings exist. Under Wine, both programs must share one prefix (one
//! wineserver holds the named objects):
//!
//! ```sh
//! export WINEPREFIX=$PWD/target/wine WINEDEBUG=-all
//! wine target/x86_64-pc-windows-gnu/debug/examples/shm_games.exe acc 20 &
//! wine target/x86_64-pc-windows-gnu/debug/ringpod.exe stream --sim --telemetry-shm acc --report-json
//! ```

#[cfg(windows)]
mod writer;

#[cfg(windows)]
fn main() -> std::process::ExitCode {
    writer::main()
}

#[cfg(not(windows))]
fn main() -> std::process::ExitCode {
    eprintln!("shm_games creates Windows named file mappings: run it on Windows or under Wine");
    std::process::ExitCode::from(2)
}
