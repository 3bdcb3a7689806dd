//! `cargo run --bin all`: the README's test command. Every test of the project, the emulators'
//! and the browser's runs and the Windows build under Wine, arranged so that two cores are both at work:
//!
//! 1. `cargo test --no-run`: the workspace's test programs, built with both cores. Its `ringpod` (the test profile:
//!    optimised, with debug assertions) is the CLI the QEMU suite, the rehost run and the browser tests drive, named
//!    to them in `RINGPOD_CLI`: no second, release, build of the host.
//! 2. `cargo test`, four tests at a time: most of its time is the host's tests waiting on a child `ringpod` in real
//!    time (its suite spends 14 s of CPU in 74 s). Beside it, at the lowest CPU priority (`nice -n 19`: they take
//!    what the tests leave and never starve their answers), two lanes start: the runners' preparation, one runner
//!    after the other (`--prepare`: the QEMU programs; the firmware as flashed and the emulator's venv; Chromium),
//!    and the Windows runner, in a target folder of its own (`target/windows`: a cross-build holds the build
//!    folder's lock for minutes), whose cross-build runs niced and whose programs then run under Wine; its output is
//!    written to `target/windows-runner.log` as it comes and printed whole at the end.
//! 3. Once `cargo test` is over: the QEMU suite, the rehost run and the browser tests, one after the other, each
//!    keeping about one core busy and waiting on real time, each once its preparation is over (the rehost run's
//!    and the browser's go on beside the QEMU suite), beside the Windows lane.
//!
//! Each part runs whatever the others gave. The last lines name each part with its result and time, and the exit
//! status is 1 when any part failed. On a system other than Linux only `cargo test` runs: the emulators, the
//! browser tests and Wine are Linux tools (the book's Tests chapter).

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use ringpod_tests::priority::yielding;

/// A part of the run: what it was, whether it passed, how long it took.
struct Part {
    name: String,
    passed: bool,
    took: Duration,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(repo());
    c
}

/// A runner of this crate, beside this program.
fn runner(name: &str) -> Command {
    let exe = std::env::current_exe().map_or_else(|_| PathBuf::from(name), |me| me.with_file_name(name));
    let mut c = Command::new(exe);
    c.current_dir(repo());
    c
}

/// A runner that drives the CLI: `cli`, when the test programs' build gave one, named to it in `RINGPOD_CLI`.
fn driving(name: &str, cli: Option<&Path>) -> Command {
    let mut c = runner(name);
    if let Some(cli) = cli {
        c.env(ringpod_tests::cli::CLI_VAR, cli);
    }
    c
}

/// Prints the file `log` line by line, each after `indent`.
fn print_log(log: &Path, indent: &str) {
    match std::fs::File::open(log) {
        Ok(f) => BufReader::new(f)
            .lines()
            .map_while(Result::ok)
            .for_each(|l| println!("{indent}{l}")),
        Err(e) => println!("{indent}{}: {e}", log.display()),
    }
}

/// Runs `c` with its output as it comes.
fn part(name: &str, mut c: Command) -> Part {
    println!("== {name}");
    let start = Instant::now();
    let passed = c.status().is_ok_and(|s| s.success());
    Part {
        name: name.into(),
        passed,
        took: start.elapsed(),
    }
}

/// The Windows runner in its own target folder, its output to `log` (its cross-build yields the CPU to lane one).
fn windows_lane(log: &Path) -> Result<Child, String> {
    let target = target_dir().join("windows");
    std::fs::create_dir_all(&target).map_err(|e| format!("{}: {e}", target.display()))?;
    let out = std::fs::File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let err = out.try_clone().map_err(|e| format!("{}: {e}", log.display()))?;
    runner("windows")
        .env("CARGO_TARGET_DIR", &target)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .spawn()
        .map_err(|e| format!("the Windows runner: {e}"))
}

fn main() -> ExitCode {
    if let Some(other) = std::env::args().nth(1) {
        eprintln!("all: unknown argument {other:?} (it takes none)");
        return ExitCode::from(2);
    }
    let mut parts = Vec::new();
    if !cfg!(target_os = "linux") {
        let mut test = cargo();
        test.args(["test", "--no-fail-fast"]);
        parts.push(part("cargo test", test));
        println!("the QEMU suite, the rehost run, the browser tests and the Windows build under Wine run on Linux");
        return summary(&parts);
    }
    let (built, cli) = test_programs();
    let mut runners = cargo();
    // Without `-p`: the workspace's features, as `cargo test` and this program were built with, so that no
    // dependency is built twice.
    runners.args(["build"]).args(RUNNERS.iter().flat_map(|r| ["--bin", r]));
    let runners = part("the runners (cargo build --bin qemu ...)", runners);
    let ready = built.passed && runners.passed;
    parts.extend([built, runners]);
    if !ready {
        return summary(&parts);
    }
    let prepared = preparation(cli.clone());
    let log = target_dir().join("windows-runner.log");
    let started = Instant::now();
    let mut windows = windows_lane(&log);
    match &windows {
        Ok(_) => println!(
            "== the Windows runner, beside the rest: its output at the end ({})",
            log.display()
        ),
        Err(e) => println!("FAIL {e}"),
    }
    let mut test = cargo();
    test.args(["test", "--no-fail-fast"]);
    ringpod_tests::priority::many_tests_at_once(&mut test);
    parts.push(part("cargo test", test));
    for name in LANE_ONE {
        // The preparations end in this order; a failed one leaves the runner to build and say why itself.
        if let Ok(ready) = prepared.recv() {
            parts.push(ready);
        }
        parts.push(part(&format!("the {name} runner"), driving(name, cli.as_deref())));
    }
    let passed = windows
        .as_mut()
        .map_err(|e| e.clone())
        .and_then(|child| child.wait().map_err(|e| format!("the Windows runner: {e}")))
        .is_ok_and(|s| s.success());
    println!("== the Windows runner's output");
    print_log(&log, "");
    parts.push(Part {
        name: "the windows runner (beside)".into(),
        passed,
        took: started.elapsed(),
    });
    summary(&parts)
}

/// The runners this program starts.
const RUNNERS: [&str; 4] = ["qemu", "rehost", "browser", "windows"];

/// The runners after `cargo test`, in their order.
const LANE_ONE: [&str; 3] = ["qemu", "rehost", "browser"];

/// The runners' `--prepare`, in [`LANE_ONE`]'s order, one after the other at the lowest CPU priority on a thread;
/// each one's part is sent as it ends. Their output goes to `target/prepare-NAME.log`, printed (indented: its counts
/// are not the runners') only when it failed.
fn preparation(cli: Option<PathBuf>) -> std::sync::mpsc::Receiver<Part> {
    let (parts, ready) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for name in LANE_ONE {
            let start = Instant::now();
            let log = target_dir().join(format!("prepare-{name}.log"));
            let mut c = driving(name, cli.as_deref());
            c.arg("--prepare");
            let mut niced = yielding(&c);
            let passed = std::fs::File::create(&log)
                .and_then(|out| Ok((out.try_clone()?, out)))
                .is_ok_and(|(out, err)| {
                    niced.stdin(Stdio::null()).stdout(out).stderr(err);
                    niced.status().is_ok_and(|s| s.success())
                });
            let part = format!("the {name} runner's preparation (niced)");
            if !passed {
                println!("== {part} failed: {}", log.display());
                print_log(&log, "    ");
            }
            let sent = parts.send(Part {
                name: part,
                passed,
                took: start.elapsed(),
            });
            if sent.is_err() {
                return;
            }
        }
    });
    ready
}

/// `cargo test --no-run`, its messages read for the `ringpod` it built (the runners' CLI), its diagnostics and
/// progress printed as they come.
fn test_programs() -> (Part, Option<PathBuf>) {
    let name = "the test programs (cargo test --no-run)";
    println!("== {name}");
    let start = Instant::now();
    let out = cargo()
        .args(["test", "--no-run", "--message-format=json-render-diagnostics"])
        .stderr(Stdio::inherit())
        .output();
    let (passed, cli) = match out {
        Ok(out) => (
            out.status.success(),
            ringpod_tests::cli::executable(&out.stdout, "ringpod"),
        ),
        Err(e) => {
            println!("cargo test --no-run: {e}");
            (false, None)
        }
    };
    let part = Part {
        name: name.into(),
        passed,
        took: start.elapsed(),
    };
    (part, cli)
}

/// The parts with their results and times; the exit status.
fn summary(parts: &[Part]) -> ExitCode {
    println!("== the test command");
    for p in parts {
        println!(
            "{:<52} {} in {:.0} s",
            p.name,
            if p.passed { "passed" } else { "FAILED" },
            p.took.as_secs_f64()
        );
    }
    let _ = std::io::stdout().flush();
    if parts.iter().all(|p| p.passed) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
