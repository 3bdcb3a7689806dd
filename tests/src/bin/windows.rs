//! `cargo run -p ringpod-tests --bin windows`: the Windows build of the host, tested on Linux under Wine.
//!
//! 1. The MinGW-w64 cross compiler and Wine (installed with apt-get when missing and allowed, as QEMU is), and the
//!    `x86_64-pc-windows-gnu` standard library (rustup).
//! 2. A cross-build of the host's test programs, with `ringpod.exe` and the examples (`cargo test --no-run`, the test
//!    profile made lighter: [`LIGHTER`]), at the lowest CPU priority (`nice -n 19`): it uses what the machine's other
//!    work leaves.
//! 3. Beside them, a test-only `bcryptprimitives.dll` built from `tests/windows/bcryptprimitives.c`: Rust's standard
//!    library imports `ProcessPrng` from it, which Wine 8 lacks.
//! 4. The host's tests under Wine, unit and integration, four at a time (`cargo test` with Wine as the target's runner): the
//!    integration tests start `ringpod.exe` as a user does; the ones that need a Unix facility (a pseudo-terminal,
//!    signals, FIFOs, inode numbers) are left out by `cfg(unix)` in their source. Then the README's main command,
//!    `ringpod.exe stream --sim --motion demo`, as a check.
//! 5. Each game of `--telemetry-shm` cued end to end: the example `shm_games.exe GAME` writes a drive into the
//!    game's named mappings in its publisher's layout while `ringpod.exe stream --sim --telemetry-shm GAME` reads it.
//!
//! Wine runs in its own prefix under the target folder, so that a developer's `~/.wine` is not touched. Cargo's own
//! `test result:` lines are passed through; the last line is the sum, `N passed, N failed`, and the exit status is 1
//! when anything failed.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

use ringpod_tests::priority::yielding;
use ringpod_tests::{setup, wine};

/// The Windows target the host is cross-built for.
const TARGET: &str = "x86_64-pc-windows-gnu";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

/// The folder of the cross-built debug programs, and of the test programs beside it.
fn debug_dir() -> PathBuf {
    target_dir().join(TARGET).join("debug")
}

fn ensure_target() -> Result<(), String> {
    let installed = Command::new("rustup")
        .current_dir(repo())
        .args(["target", "list", "--installed"])
        .output()
        .map_err(|e| format!("rustup: {e} (install the {TARGET} standard library the way the toolchain was)"))?;
    if String::from_utf8_lossy(&installed.stdout)
        .lines()
        .any(|l| l.trim() == TARGET)
    {
        return Ok(());
    }
    let command = format!("rustup target add {TARGET}");
    if !setup::may_install() {
        return Err(format!("the {TARGET} standard library is missing: run `{command}`"));
    }
    println!("== the {TARGET} standard library is missing: {command}");
    let ok = Command::new("rustup")
        .current_dir(repo())
        .args(["target", "add", TARGET])
        .status()
        .is_ok_and(|s| s.success());
    ok.then_some(())
        .ok_or_else(|| format!("`{command}` failed: run it by hand"))
}

/// The test profile, lighter for this build: optimised once (`opt-level` 1) and without line tables. The
/// cross-build took 4 min 8 s instead of 5 min 52 s on two idle cores, and every test under Wine still passed, the
/// host's in 231 s (their time is spent waiting on `ringpod.exe` in real time, not computing).
const LIGHTER: [&str; 3] = [
    "profile.test.opt-level = 1",
    "profile.test.package.\"*\".opt-level = 1",
    "profile.test.debug = false",
];

/// Cargo for the Windows target, with Wine as the runner of what it builds.
fn cargo(args: &[&str]) -> Command {
    // Cargo's own options go before a `--`: what follows it is the test programs' (`--exact NAME`), which refuse
    // `--target`.
    let (own, programs) = args.split_at(args.iter().position(|a| *a == "--").unwrap_or(args.len()));
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(repo())
        .args(own)
        .args(["--target", TARGET])
        // Wine runs what cargo runs, given as a configuration value and not as the environment variable
        // `CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUNNER`: the test programs inherit the environment, and assert_cmd
        // starts `ringpod.exe` through the runner that variable names, which inside Wine does not exist.
        .args(["--config", "target.x86_64-pc-windows-gnu.runner = \"wine\""])
        .args(LIGHTER.iter().flat_map(|kv| ["--config", kv]))
        .env("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER", "x86_64-w64-mingw32-gcc")
        .args(programs);
    wine_env(&mut c);
    c
}

/// Wine in its own prefix, quiet, without the desktop integration a console program does not need.
fn wine_env(c: &mut Command) {
    c.env("WINEPREFIX", target_dir().join("wine"))
        .env("WINEDEBUG", "-all")
        .env(
            "WINEDLLOVERRIDES",
            "mscoree,mshtml,winemenubuilder.exe=;bcryptprimitives=n,b",
        )
        .env("WINEARCH", "win64");
}

/// The test-only DLL, built once and copied beside the programs and the test programs.
fn shim() -> Result<(), String> {
    let dll = debug_dir().join("bcryptprimitives.dll");
    let source = repo().join("tests/windows/bcryptprimitives.c");
    let status = Command::new("x86_64-w64-mingw32-gcc")
        .args(["-shared", "-O2", "-o"])
        .arg(&dll)
        .arg(&source)
        .arg("-ladvapi32")
        .status()
        .map_err(|e| format!("x86_64-w64-mingw32-gcc: {e}"))?;
    if !status.success() {
        return Err(format!("building {} failed ({status})", dll.display()));
    }
    for dir in ["deps", "examples"] {
        std::fs::copy(&dll, debug_dir().join(dir).join("bcryptprimitives.dll"))
            .map_err(|e| format!("copying the DLL beside the programs in {dir}: {e}"))?;
    }
    Ok(())
}

fn step(name: &str, run: impl FnOnce() -> Result<(), String>) -> Result<(), String> {
    println!("== {name}");
    let started = Instant::now();
    let result = run();
    println!("== {name}: {:.0} s", started.elapsed().as_secs_f64());
    result
}

fn status(mut c: Command, what: &str) -> Result<(), String> {
    let s = c.status().map_err(|e| format!("{what}: {e}"))?;
    s.success().then_some(()).ok_or_else(|| format!("{what} failed ({s})"))
}

/// The host's tests under Wine. A test that failed only because Wine did not start a process (see
/// [`ringpod_tests::wine`]) is run once more alone, and said; any other failure fails the step.
fn host_tests() -> Result<(), String> {
    let mut tests = cargo(&["test", "-p", "ringpod", "--no-fail-fast"]);
    ringpod_tests::priority::many_tests_at_once(&mut tests);
    let (passed, output) = tee(tests)?;
    if passed {
        return Ok(());
    }
    let failed = wine::failures(&output);
    let others: Vec<_> = failed.iter().filter(|f| !f.by_wine || f.program.is_empty()).collect();
    if failed.is_empty() || !others.is_empty() {
        let names: Vec<_> = others.iter().map(|f| f.name.as_str()).collect();
        return Err(format!("cargo test under Wine failed: {names:?}"));
    }
    for f in &failed {
        println!(
            "again: {} {}, which Wine failed by not starting a process (OS error 1359)",
            f.program.join(" "),
            f.name
        );
        let mut args = vec!["test", "-p", "ringpod"];
        args.extend(f.program.iter().map(String::as_str));
        args.extend(["--", "--exact", f.name.as_str()]);
        status(cargo(&args), &format!("{} run again", f.name))?;
    }
    println!(
        "{} test(s) failed by Wine's process creation passed when run again",
        failed.len()
    );
    Ok(())
}

/// Runs `c` with its output and errors printed as they come and kept, in order: (success, what it printed).
fn tee(mut c: Command) -> Result<(bool, String), String> {
    use std::io::{BufRead, BufReader};
    let (reader, writer) = std::io::pipe().map_err(|e| format!("a pipe: {e}"))?;
    let copy = writer.try_clone().map_err(|e| format!("a pipe: {e}"))?;
    let mut child = c
        .stdout(copy)
        .stderr(writer)
        .spawn()
        .map_err(|e| format!("cargo test: {e}"))?;
    drop(c); // the command keeps the pipe's write ends open: without them the reader sees the end
    let mut all = String::new();
    for line in BufReader::new(reader).lines() {
        let line = line.map_err(|e| format!("cargo test's output: {e}"))?;
        println!("{line}");
        all.push_str(&line);
        all.push('\n');
    }
    let status = child.wait().map_err(|e| format!("cargo test: {e}"))?;
    Ok((status.success(), all))
}

/// The README's main command under Wine: the demo followed to its end, exit 0.
fn main_command() -> Result<(), String> {
    let mut c = Command::new("wine");
    c.arg(debug_dir().join("ringpod.exe"))
        .args("stream --sim --motion demo --duration 2 --quiet --report-json".split(' '))
        .stderr(Stdio::inherit());
    wine_env(&mut c);
    let out = c.output().map_err(|e| format!("wine ringpod.exe: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("ringpod.exe printed no report ({e}): {text}"))?;
    println!(
        "ringpod.exe stream --sim --motion demo --duration 2: {} ({} of {} applied), exit {:?}",
        report["outcome"],
        report["setpoints_applied"],
        report["setpoints_sent"],
        out.status.code()
    );
    (out.status.success() && report["outcome"] == "followed")
        .then_some(())
        .ok_or_else(|| "the demo was not followed under Wine".into())
}

/// The games whose shared memory `--telemetry-shm` reads (`ringpod stream --help`), in two lanes that run side by
/// side: the games of one lane one after the other, since AC and ACC share their mappings' names, and so do rF2
/// and LMU.
const SHM_GAMES: [&[&str]; 2] = [&["ac", "acc", "ets2"], &["rf2", "lmu", "iracing", "ams2"]];
/// Seconds of each stand-in's drive: one cycle of it (6 s of motion, then its pause of 1.5 s), and a half second.
const DRIVE_S: &str = "8";
/// The reader ends this long after its last sample (once the drive is over): longer than the drive's pause.
const IDLE_S: &str = "3";

/// Each shared-memory game cued end to end under Wine: `shm_games.exe GAME` creates the game's named mappings in its
/// publisher's layout and writes a drive at the game's rate (with a pause), while `ringpod.exe stream --sim
/// --telemetry-shm GAME` reads them, cues them and streams to the simulated controller. Both run in one Wine prefix
/// (one wineserver holds the named objects). Each game: followed, every setpoint applied, more than a hundred new
/// samples taken (the drive runs at 50 Hz or more), none refused.
fn shared_memory_games() -> Result<(), String> {
    let failed: Vec<&str> = std::thread::scope(|s| {
        let lanes: Vec<_> = SHM_GAMES
            .map(|lane| {
                s.spawn(move || {
                    lane.iter()
                        .copied()
                        .filter(|game| cue_game(game).map_err(|e| println!("{game}: {e}")).is_err())
                        .collect::<Vec<_>>()
                })
            })
            .into_iter()
            .collect();
        lanes
            .into_iter()
            .flat_map(|lane| lane.join().unwrap_or_else(|_| vec!["a lane that panicked"]))
            .collect()
    });
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("not cued end to end: {failed:?}"))
    }
}

/// One game: its stand-in started and ready (its mappings created), then ringpod reading it until the drive is over.
fn cue_game(game: &str) -> Result<(), String> {
    let mut writer = Command::new("wine");
    writer
        .arg(debug_dir().join("examples").join("shm_games.exe"))
        .args([game, DRIVE_S])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    wine_env(&mut writer);
    let mut writer = writer.spawn().map_err(|e| format!("wine shm_games.exe: {e}"))?;
    // Wine takes a second or more to start a program: ringpod starts once the game's mappings are there.
    let mut lines = std::io::BufRead::lines(std::io::BufReader::new(writer.stdout.take().expect("piped")));
    if !lines.any(|l| l.is_ok_and(|l| l.ends_with("ready"))) {
        let _ = writer.kill();
        return Err(format!(
            "shm_games.exe ended without its mappings ({:?})",
            writer.wait()
        ));
    }
    let mut reader = Command::new("wine");
    reader
        .arg(debug_dir().join("ringpod.exe"))
        // `--fast`: the simulated controller homes at once rather than in the seconds a rig takes, during which
        // the drive would go on unread.
        .args("stream --sim --fast --quiet --report-json --telemetry-shm".split(' '))
        .arg(game)
        .args(["--udp-idle", IDLE_S])
        .stderr(Stdio::null());
    wine_env(&mut reader);
    let out = reader.output().map_err(|e| format!("wine ringpod.exe: {e}"))?;
    let wrote = lines.find_map(Result::ok).unwrap_or_default();
    let writer = writer.wait().map_err(|e| format!("shm_games.exe: {e}"))?;
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
    let counts = &report["datagrams"]["shared_memory"];
    println!(
        "{game}: exit {:?}, {}, {} of {} applied; {} samples, {} repeats, {} settling, {} torn, {} stalls, {} refused \
         ({wrote})",
        out.status.code(),
        report["outcome"],
        report["setpoints_applied"],
        report["setpoints_sent"],
        counts["samples"],
        counts["repeats"],
        counts["settling"],
        counts["torn"],
        counts["stalls"],
        counts["refused"]
    );
    let ok = out.status.success()
        && writer.success()
        && report["outcome"] == "followed"
        && report["setpoints_applied"] == report["setpoints_sent"]
        && counts["samples"].as_u64().unwrap_or(0) > 100
        && counts["refused"] == 0;
    ok.then_some(()).ok_or_else(|| "not cued end to end".into())
}

fn main() -> ExitCode {
    if let Some(other) = std::env::args().nth(1) {
        eprintln!("windows: unknown argument {other:?} (it takes none)");
        return ExitCode::from(2);
    }
    let mut failed = 0u32;
    let mut passed = 0u32;
    let prepared = step("MinGW-w64 and Wine", setup::ensure_windows)
        .and_then(|()| step("the Windows target", ensure_target))
        .and_then(|()| {
            step("cross-build (debug)", || {
                // The test programs, and with them `ringpod.exe` (the integration tests start it) and the examples
                // (`shm_games.exe`, the games' stand-in): one build, no second one of the host with other features.
                status(
                    yielding(&cargo(&["test", "-p", "ringpod", "--no-run"])),
                    "cargo test --no-run",
                )
            })
        })
        .and_then(|()| step("the ProcessPrng DLL", shim));
    if let Err(e) = prepared {
        println!("FAIL {e}");
        println!("0 passed, 1 failed");
        return ExitCode::FAILURE;
    }
    // The test programs print their own `test result:` lines (summed by .ci/run); here each is a check.
    let checks = [
        (
            "the host's tests under Wine",
            step("the host's tests under Wine", host_tests),
        ),
        (
            "the main command under Wine",
            step("the main command under Wine", main_command),
        ),
        (
            "the shared-memory games under Wine",
            step("the shared-memory games under Wine", shared_memory_games),
        ),
    ];
    for (name, result) in checks {
        match result {
            Ok(()) => {
                passed += 1;
                println!("PASS {name}");
            }
            Err(e) => {
                failed += 1;
                println!("FAIL {name}: {e}");
            }
        }
    }
    println!("{passed} passed, {failed} failed");
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tee_keeps_output_and_errors_in_order_and_the_status() {
        let mut c = Command::new("sh");
        c.args(["-c", "echo one; echo two >&2; echo three; exit 3"]);
        assert_eq!(tee(c).unwrap(), (false, "one\ntwo\nthree\n".to_owned()));
        let mut ok = Command::new("sh");
        ok.args(["-c", "true"]);
        assert_eq!(tee(ok).unwrap(), (true, String::new()));
    }

    /// A test run again alone: its `--exact NAME` reaches the test program, cargo's target and runner stay cargo's.
    #[test]
    fn a_test_run_again_gets_its_name_and_cargo_its_target() {
        let c = cargo(&["test", "-p", "ringpod", "--test", "cli", "--", "--exact", "a::b"]);
        let args: Vec<_> = c.get_args().map(|a| a.to_string_lossy().into_owned()).collect();
        let at = |word: &str| args.iter().position(|a| a == word).unwrap();
        assert!(at("--target") < at("--") && at("--config") < at("--"), "{args:?}");
        assert_eq!(&args[at("--")..], ["--", "--exact", "a::b"], "{args:?}");
        // Without a `--`, everything is cargo's.
        let c = cargo(&["build", "-p", "ringpod"]);
        assert_eq!(c.get_args().next().unwrap(), "build");
        assert!(c.get_args().any(|a| a == "--target"));
    }
}
