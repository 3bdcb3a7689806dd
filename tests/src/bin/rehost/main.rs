//! `cargo run -p ringpod-tests --bin rehost`: the firmware ELF, exactly as flashed, run on Qiling's
//! stm32f411 model with the harness's peripheral models (`tests/rehost`, see its README).
//!
//! 1. The `thumbv7em-none-eabihf` standard library (the preflight the QEMU runner uses), then
//!    `cargo build -p ringpod-firmware --target thumbv7em-none-eabihf --profile firmware`.
//!    Then the host CLI, the release build the README's main command makes (`ringpod_tests::cli`), which run.py
//!    drives over ptys bridged to the emulated USART1 and to the USB host on the emulated OTG FS core.
//! 2. A Python venv in `target/rehost-venv` with the pinned emulator (`tests/rehost/requirements.txt`), made again
//!    whenever that file changes.
//! 3. The firmware's flash against its budget (`size`), counted as one check.
//! 4. The models' unit tests (`python -m unittest`), counted as one check, then `tests/rehost/run.py`, whose checks
//!    print `PASS`/`FAIL` lines. The last line is the sum, `N passed, N failed`; the exit status is 1 when anything
//!    failed.
//!
//! `--prepare`: step 1 and the venv only (the test command's, beside `cargo test`).
//! Other arguments go to run.py (`-- --until serial-status` stops after that check; `-- --help` lists them).
//! `-- --mutants [NAME...]`: instead, the firmware faults of `tests/rehost/mutants.toml`, each built from a copy of
//! the sources and run up to the check meant to catch it (`mutants`).

mod mutants;
mod prepare;
mod size;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, ExitCode};

use prepare::{build_firmware, repo, run_py, venv};
use ringpod_tests::cli;
use ringpod_tests::setup;

/// The models' unit tests: Ok(number of tests) when all passed.
fn unit_tests(python: &Path) -> Result<u32, String> {
    let out = Command::new(python)
        .current_dir(repo().join("tests/rehost"))
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .args(["-m", "unittest", "discover", "-s", "tests", "-t", "."])
        .output()
        .map_err(|e| format!("python -m unittest: {e}"))?;
    let report = String::from_utf8_lossy(&out.stderr);
    let ran = report
        .lines()
        .find_map(|l| l.strip_prefix("Ran ")?.split_whitespace().next()?.parse().ok())
        .unwrap_or(0);
    if out.status.success() && ran > 0 {
        Ok(ran)
    } else {
        eprintln!("{report}");
        Err(format!(
            "{ran} tests ran, not all passed (python -m unittest, output above)"
        ))
    }
}

/// `N passed, M failed` alone on a line.
fn tally(line: &str) -> Option<(u32, u32)> {
    let (passed, failed) = line.trim().split_once(" passed, ")?;
    Some((passed.parse().ok()?, failed.strip_suffix(" failed")?.parse().ok()?))
}

/// run.py, its lines passed through as they come, except its count, which is returned.
fn checks(python: &Path, elf: &Path, cli: &Path, args: &[String]) -> Result<(u32, u32, bool), String> {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut child = run_py(python, elf, cli, &args)?;
    let mut count = None;
    if let Some(out) = child.stdout.take() {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            match tally(&line) {
                Some(c) => count = Some(c),
                None => println!("{line}"),
            }
        }
    }
    let ok = child.wait().is_ok_and(|s| s.success());
    let (passed, failed) = count.ok_or("run.py ended without its `N passed, N failed` line")?;
    Ok((passed, failed, ok))
}

fn main() -> ExitCode {
    let prepared = setup::ensure_target()
        .and_then(|()| build_firmware())
        .and_then(|elf| Ok((elf, cli::host()?, venv()?)));
    let (elf, cli, python) = match prepared {
        Ok(p) => p,
        Err(e) => {
            eprintln!("rehost: {e}");
            println!("0 passed, 1 failed");
            return ExitCode::FAILURE;
        }
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args == ["--prepare"] {
        return ExitCode::SUCCESS;
    }
    if args.first().is_some_and(|a| a == "--mutants") {
        return mutants::run(&python, &cli, &args[1..]);
    }
    let (mut passed, mut failed) = (0, 0);
    match size::measure(&elf) {
        Ok(m) if m.flash <= size::FLASH_BUDGET => {
            println!(
                "PASS firmware-size: flash {} B (budget {} B), RAM {} B",
                m.flash,
                size::FLASH_BUDGET,
                m.ram
            );
            passed += 1;
        }
        Ok(m) => {
            println!(
                "FAIL firmware-size: flash {} B, over its budget of {} B (RAM {} B)",
                m.flash,
                size::FLASH_BUDGET,
                m.ram
            );
            failed += 1;
        }
        Err(e) => {
            println!("FAIL firmware-size: {e}");
            failed += 1;
        }
    }
    match unit_tests(&python) {
        Ok(n) => {
            println!("PASS model-unit-tests: {n} tests of tests/rehost/models (python -m unittest)");
            passed += 1;
        }
        Err(e) => {
            println!("FAIL model-unit-tests: {e}");
            failed += 1;
        }
    }
    let mut ok = failed == 0;
    match checks(&python, &elf, &cli, &args) {
        Ok((p, f, exited_ok)) => {
            passed += p;
            failed += f;
            ok &= exited_ok && f == 0;
        }
        Err(e) => {
            println!("FAIL run.py: {e}");
            failed += 1;
            ok = false;
        }
    }
    println!("{passed} passed, {failed} failed");
    if ok && failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
