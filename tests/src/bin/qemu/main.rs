//! `cargo run -p ringpod-tests --bin qemu`: builds the Cortex-M4F programs of `tests/qemu`, runs them in
//! `qemu-system-arm -machine mps2-an386` with a time limit, checks what they report, and prints
//! `N passed, N failed` as its last line (exit status 1 when anything failed).
//!
//! 1. `self_check`: the core's self-check on the emulated MCU: every check passes, and the digest of its output
//!    bits equals the digest the same code computes on this host (bit identity of the f32 math); the cost of the
//!    control path in instructions (`-icount shift=0`), printed as a table with the budget.
//! 2. `controller`: the controller's firmware tasks on the emulated MCU, streamed through its UART, and (`aux`)
//!    the auxiliary outputs switched by a pose file's column and `device aux`, dropped by an e-stop.
//! 3. `watchdog`: a stalled control loop reset by the watchdog. 4. `rig`: a rig of one's own loaded and run, and
//!    the elbow trainer's and the rotopod's rig files likewise.
//!
//! `--busy` builds everything first, then runs the suite beside two spinning threads per core (`ringpod_tests::busy`):
//! the emulated controller keeps device time under `-icount` and its checks hold on a loaded machine.
//!
//! `setup` installs what the suite needs first (the target's standard library, QEMU) or says how;
//! `cargo run -p ringpod-tests --bin qemu -- --preflight` runs only that. `emulator` starts QEMU and the programs;
//! `host_cli` drives the `ringpod` CLI against them.

mod aux;
mod controller;
mod emulator;
mod host_cli;
mod rig;
mod self_check;
mod watchdog;

use std::process::ExitCode;

use crate::controller::controller_on_m4f;
use crate::rig::{elbow_on_m4f, rig_on_m4f, rotopod_on_m4f};
use crate::self_check::core_on_m4f;
use crate::watchdog::watchdog_on_m4f;
use ringpod_tests::busy::{load_average, Busy};
use ringpod_tests::setup::{self, preflight};

pub(crate) struct Tally {
    passed: u32,
    failed: u32,
}

impl Tally {
    pub(crate) fn check(&mut self, ok: bool, what: &str) {
        println!("{} {what}", if ok { "PASS" } else { "FAIL" });
        if ok {
            self.passed += 1;
        } else {
            self.failed += 1;
        }
    }
}

fn main() -> ExitCode {
    let (only_preflight, busy) = match std::env::args().nth(1).as_deref() {
        None => (false, false),
        Some("--preflight") => (true, false),
        Some("--busy") => (false, true),
        Some(other) => {
            eprintln!("qemu: unknown argument {other:?} (--preflight, or --busy)");
            return ExitCode::from(2);
        }
    };
    // Nothing is built before this passes: a missing piece is one line naming its command, not a compiler error.
    if let Err(e) = preflight() {
        eprintln!("qemu: {e}");
        println!("0 passed, 1 failed");
        return ExitCode::FAILURE;
    }
    if only_preflight {
        println!(
            "preflight: the {} standard library and qemu-system-arm are installed",
            setup::TARGET
        );
        return ExitCode::SUCCESS;
    }
    let mut t = Tally { passed: 0, failed: 0 };
    // `--busy`: everything is built first, then the suite runs beside two spinning threads per core.
    let load = if busy {
        if let Err(e) = controller::build_all() {
            eprintln!("qemu: {e}");
            println!("0 passed, 1 failed");
            return ExitCode::FAILURE;
        }
        let load = Busy::start(2);
        println!("== beside {} busy threads (a loaded machine)", load.threads());
        Some(load)
    } else {
        None
    };
    core_on_m4f(&mut t);
    controller_on_m4f(&mut t);
    watchdog_on_m4f(&mut t);
    rig_on_m4f(&mut t);
    elbow_on_m4f(&mut t);
    rotopod_on_m4f(&mut t);
    if let Some(load) = load {
        let average = load_average().map_or("unknown".into(), |l| format!("{l:.1}"));
        println!(
            "the suite ran beside {} busy threads; load average {average}",
            load.threads()
        );
    }
    println!("{} passed, {} failed", t.passed, t.failed);
    if t.failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
