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
//! Everything is built first; then the sections run as child processes of this runner (`--section NAME` runs one),
//! one per two cores at once. `--busy` runs the suite beside two spinning threads per core
//! (`ringpod_tests::busy`): the emulated controller keeps device time under `-icount` and its checks hold on a loaded
//! machine.
//!
//! `setup` installs what the suite needs first (the target's standard library, QEMU) or says how;
//! `cargo run -p ringpod-tests --bin qemu -- --preflight` runs only that, `-- --prepare` that and the builds (the
//! test command's, beside `cargo test`). `emulator` starts QEMU and the programs;
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
use ringpod_tests::sections;
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

    /// The runner's last line, and its exit status.
    fn end(self) -> ExitCode {
        println!("{} passed, {} failed", self.passed, self.failed);
        if self.failed == 0 {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        }
    }
}

/// A section of the suite: its checks, counted in the tally.
type Section = fn(&mut Tally);

/// The suite's sections, longest first (each starts its own QEMU).
const SECTIONS: [(&str, Section); 6] = [
    ("controller", controller_on_m4f),
    ("watchdog", watchdog_on_m4f),
    ("core", core_on_m4f),
    ("rig", rig_on_m4f),
    ("elbow", elbow_on_m4f),
    ("rotopod", rotopod_on_m4f),
];

enum Mode {
    Suite { busy: bool },
    Preflight,
    Prepare,
    Section(Section),
}

fn mode() -> Result<Mode, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        [] => Ok(Mode::Suite { busy: false }),
        ["--preflight"] => Ok(Mode::Preflight),
        ["--prepare"] => Ok(Mode::Prepare),
        ["--busy"] => Ok(Mode::Suite { busy: true }),
        ["--section", name] | ["--busy", "--section", name] => SECTIONS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, run)| Mode::Section(*run))
            .ok_or_else(|| format!("no section {name:?} (one of {:?})", SECTIONS.map(|(n, _)| n))),
        _ => Err(format!(
            "unknown arguments {args:?} (--preflight, --prepare, --busy, or --section NAME)"
        )),
    }
}

fn main() -> ExitCode {
    let busy = match mode() {
        Err(e) => {
            eprintln!("qemu: {e}");
            return ExitCode::from(2);
        }
        Ok(Mode::Section(run)) => {
            let mut t = Tally { passed: 0, failed: 0 };
            run(&mut t);
            return t.end();
        }
        Ok(Mode::Preflight) => return preflight_only(),
        Ok(Mode::Prepare) => {
            return match preflight().and_then(|()| controller::build_all()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("qemu: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Ok(Mode::Suite { busy }) => busy,
    };
    // Nothing is built before this passes: a missing piece is one line naming its command, not a compiler error.
    if let Err(e) = preflight() {
        eprintln!("qemu: {e}");
        println!("0 passed, 1 failed");
        return ExitCode::FAILURE;
    }
    // Everything is built first, so that the sections do not wait on one another's cargo.
    if let Err(e) = controller::build_all() {
        eprintln!("qemu: {e}");
        println!("0 passed, 1 failed");
        return ExitCode::FAILURE;
    }
    // `--busy`: the suite runs beside two spinning threads per core.
    let load = busy.then(|| {
        let load = Busy::start(2);
        println!("== beside {} busy threads (a loaded machine)", load.threads());
        load
    });
    // A streamed section keeps about a core busy (QEMU's CPU thread counts device time in instructions) and its CLI
    // answers in real time: one section per two cores, so that a section is never starved into a late answer (on
    // two cores the sections run one after the other).
    let jobs = std::thread::available_parallelism().map_or(1, |n| n.get() / 2).max(1);
    let names = SECTIONS.map(|(n, _)| n);
    let sections = sections::run(&names, if busy { &["--busy"] } else { &[] }, jobs);
    if let Some(load) = load {
        let average = load_average().map_or("unknown".into(), |l| format!("{l:.1}"));
        println!(
            "the suite ran beside {} busy threads; load average {average}",
            load.threads()
        );
    }
    Tally {
        passed: sections.passed,
        failed: sections.failed,
    }
    .end()
}

fn preflight_only() -> ExitCode {
    match preflight() {
        Ok(()) => {
            println!(
                "preflight: the {} standard library and qemu-system-arm are installed",
                setup::TARGET
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("qemu: {e}");
            println!("0 passed, 1 failed");
            ExitCode::FAILURE
        }
    }
}
