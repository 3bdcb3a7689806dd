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

/// QEMU's command line for an ELF on mps2-an386 with semihosting; `args` are the program's semihosting command line.
/// With `icount`, virtual time advances one nanosecond per instruction (the instruction counter of the cost table);
/// without, it follows the host's clock, which a controller streamed in real time needs.
fn qemu(elf: &Path, icount: bool, args: &[&str]) -> Command {
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
    .arg("-semihosting-config")
    .arg(
        args.iter()
            .fold("enable=on,target=native".to_string(), |c, a| c + ",arg=" + a),
    );
    if icount {
        c.args(["-icount", "shift=0"]);
    }
    c.arg("-kernel").arg(elf);
    c
}

/// Runs a program to its end (or the limit) and returns what it printed.
fn run_to_end(elf: &Path) -> Result<String, String> {
    let mut child = qemu(elf, true, &[])
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
    for (row, budget) in BUDGETS {
        match costs.iter().find(|(name, _)| name.contains(row)) {
            Some((_, n)) => t.check(
                *n <= budget,
                &format!("budget: {row} {n} instructions, at most {budget}"),
            ),
            None => t.check(false, &format!("budget: the row {row:?} was measured")),
        }
    }
    println!();
    println!("| operation (f32, trainer model) | instructions | at 96 MHz, 1 instruction a cycle | of its period |");
    println!("|---|---|---|---|");
    for (name, n) in &costs {
        // Rows at 2 kHz take a share of a 500 us period; everything else of the default 1 kHz.
        let period_us = if name.contains("2 kHz") { 500.0 } else { 1_000.0 };
        let us = *n as f64 / 96.0;
        println!("| {name} | {n} | {us:.1} us | {:.1} % |", us / period_us * 100.0);
    }
    if let Some(i) = iterations {
        println!("(FK: {:.2} Newton iterations per solve)", i as f64 / 100.0);
    }
    println!();
}

/// Instruction budgets of the control path on the M4F (issue "the control tick under 6 % of its period"): a row
/// whose name contains the key must not cost more. Counts under `-icount` are exact and repeatable for a given
/// build, so these hold or fail deterministically; they keep the tick from growing back unnoticed.
const BUDGETS: [(&str, u64); 5] = [
    ("control tick: pipeline", 6_000),
    ("control tick at 2 kHz", 6_000),
    ("IK + all", 4_000),
    ("setpoint frame", 8_000),
    ("FK", 20_000),
];

/// QEMU running the controller program, its UART on a pseudo-terminal.
struct Emulated {
    child: std::process::Child,
    pty: String,
    /// What the program prints over semihosting (and QEMU on its stderr), line by line.
    lines: std::sync::mpsc::Receiver<String>,
}

impl Emulated {
    /// Lines printed until one satisfies `done` (included), or an error with what came when `limit` passes first.
    fn wait_for(&self, limit: Duration, done: impl Fn(&str) -> bool) -> Result<Vec<String>, String> {
        let deadline = Instant::now() + limit;
        let mut seen = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    let last = done(&line);
                    seen.push(line);
                    if last {
                        return Ok(seen);
                    }
                }
                Err(_) => return Err(format!("waited {} s; printed: {seen:?}", limit.as_secs())),
            }
        }
    }

    /// Lines printed so far and not yet read.
    fn printed(&self) -> Vec<String> {
        self.lines.try_iter().collect()
    }
}

impl Drop for Emulated {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Builds and starts the controller program with `args`; a failure is reported and counted.
fn start_or_fail(t: &mut Tally, args: &[&str]) -> Option<Emulated> {
    match build("ringpod-qemu-controller").and_then(|elf| start_controller(&elf, args)) {
        Ok(e) => Some(e),
        Err(e) => {
            eprintln!("{e}");
            t.check(false, "the controller starts on the emulated Cortex-M4F");
            None
        }
    }
}

/// Starts the controller program with the semihosting command line `args` and waits for its pty and its `READY`.
fn start_controller(elf: &Path, args: &[&str]) -> Result<Emulated, String> {
    let mut child = qemu(elf, false, args)
        .args(["-serial", "pty"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e}"))?;
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    for stream in [
        child.stdout.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
        child.stderr.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
    ]
    .into_iter()
    .flatten()
    {
        let tx = tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stream).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
    }
    let mut emulated = Emulated {
        child,
        pty: String::new(),
        lines: rx,
    };
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut ready = false;
    while !ready || emulated.pty.is_empty() {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = emulated
            .lines
            .recv_timeout(left)
            .map_err(|_| "the controller did not come up in 30 s".to_string())?;
        if let Some(at) = line.find("/dev/pts/") {
            emulated.pty = line[at..].split_whitespace().next().unwrap_or("").to_string();
        }
        ready |= line.trim() == "READY";
        if line.starts_with("ERROR") {
            return Err(line);
        }
    }
    Ok(emulated)
}

fn ringpod() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../target"));
    target.join("release/ringpod")
}

/// Runs the CLI and parses the JSON it prints.
fn ringpod_json(args: &[&str]) -> Result<serde_json::Value, String> {
    let out = Command::new(ringpod())
        .args(args)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("ringpod: {e}"))?;
    if !out.status.success() {
        return Err(format!("ringpod {args:?}: {}", String::from_utf8_lossy(&out.stderr)));
    }
    serde_json::from_slice(&out.stdout).map_err(|e| format!("ringpod {args:?}: {e}"))
}

/// A 3 s input: 2 s of motion on every axis, then 1 s holding the last pose, so that both runs end at rest at the
/// same pose whatever their timing.
fn write_input(path: &Path) -> std::io::Result<()> {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..=300 {
        let t = f64::from(k) * 0.01;
        let u = t.min(2.0);
        csv += &format!(
            "{t:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}\n",
            0.01 * (2.0 * u).sin(),
            0.008 * (1.5 * u).sin(),
            0.227 + 0.006 * (2.5 * u).sin(),
            0.03 * u.sin(),
            0.04 * (2.0 * u).sin(),
            0.3 * u
        );
    }
    std::fs::write(path, csv)
}

/// A 6 s stream as simulator software sends it, beyond what the model can do: every axis at once up to 1.5 times
/// its spec range, surge at up to twice its speed limit, yaw turning, at 100 Hz; the excursion fades out over the
/// last 1.5 s and the input holds home for its last 0.5 s, so both runs end at rest at the same pose.
fn write_beyond_envelope(path: &Path) -> std::io::Result<()> {
    let mut csv = String::from(
        "t,x,y,z,alpha,beta,gamma
",
    );
    let r = ringpod_core::kinematics::presets::TRAINER_MODEL_RANGES;
    for k in 0..=600 {
        let t = f64::from(k) * 0.01;
        let fade = (t / 0.5).min(1.0) * ((5.5 - t) / 1.5).clamp(0.0, 1.0);
        let a = |i: usize| 1.5 * r[i] * fade;
        csv += &format!(
            "{t:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}
",
            a(0) * (1.3 * t).sin(),
            a(1) * (0.9 * t + 1.0).sin(),
            0.227 + a(2) * (1.1 * t + 2.0).sin(),
            a(3) * (0.8 * t + 0.5).sin(),
            a(4) * (0.7 * t + 1.5).sin(),
            0.4 * t.min(5.5)
        );
    }
    std::fs::write(path, csv)
}

/// Writes `garbage` to the device's pty and returns what it answers within half a second.
fn send_garbage(pty: &str, garbage: &[u8]) -> Result<Vec<u8>, String> {
    use std::io::Write;
    let status = Command::new("stty")
        .args(["-F", pty, "raw", "-echo", "min", "0", "time", "5"])
        .status()
        .map_err(|e| format!("stty: {e}"))?;
    if !status.success() {
        return Err("stty failed".into());
    }
    let mut port = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(pty)
        .map_err(|e| format!("{pty}: {e}"))?;
    // QEMU's pty backend notices an opened slave side by polling (about once a second) and drops what the guest
    // sends until then.
    std::thread::sleep(Duration::from_millis(1_500));
    port.write_all(garbage).map_err(|e| e.to_string())?;
    let mut answer = Vec::new();
    let mut buf = [0u8; 256];
    while let Ok(n) = port.read(&mut buf) {
        if n == 0 {
            break;
        }
        answer.extend_from_slice(&buf[..n]);
    }
    Ok(answer)
}

/// The firmware's tasks on the emulated MCU, driven by the host CLI over the UART.
fn controller_on_m4f(t: &mut Tally) {
    println!("== the controller's firmware tasks on the emulated Cortex-M4F, over its UART");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let cli = Command::new(&cargo)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .args(["build", "--release", "-p", "ringpod"])
        .status();
    if !cli.is_ok_and(|s| s.success()) {
        t.check(false, "the host CLI builds");
        return;
    }
    let Some(emulated) = start_or_fail(t, &[]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    println!("controller on {pty}");
    let input = std::env::temp_dir().join(format!("ringpod-qemu-{}.csv", std::process::id()));
    if write_input(&input).is_err() {
        t.check(false, "the input file is written");
        return;
    }
    let file = input.to_string_lossy().to_string();
    let emu = ringpod_json(&["stream", "--port", pty, "--input", &file, "--quiet", "--report-json"]);
    let sim = ringpod_json(&[
        "stream",
        "--sim",
        "--fast",
        "--input",
        &file,
        "--quiet",
        "--report-json",
    ]);
    let _ = std::fs::remove_file(&input);
    match (&emu, &sim) {
        (Ok(e), Ok(s)) => {
            println!(
                "emulated: final steps {}, simulator: {}",
                e["final_steps"], s["final_steps"]
            );
            t.check(
                e["state"] == "Ready" && e["counts_agree"] == true && e["rejected"] == serde_json::json!({}),
                "stream a CSV: homed, every setpoint applied, back at rest, the counts add up",
            );
            t.check(
                e["final_steps"] == s["final_steps"] && e["setpoints_applied"] == s["setpoints_applied"],
                "the emulated controller ends at the host simulator's step positions",
            );
        }
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("{e}");
            t.check(false, "stream a CSV into the emulated controller and the simulator");
        }
    }

    // Beyond the envelope and the limits, limited by the device itself (no host limiting): every setpoint
    // applied, many limited on the M4F, none refused, and the same end as the simulator's.
    let beyond = std::env::temp_dir().join(format!("ringpod-qemu-beyond-{}.csv", std::process::id()));
    if write_beyond_envelope(&beyond).is_err() {
        t.check(false, "the input file is written");
        return;
    }
    let file = beyond.to_string_lossy().to_string();
    let args = ["--input", &file, "--device-limits-only", "--quiet", "--report-json"];
    let emu = ringpod_json(&[&["stream", "--port", pty][..], &args].concat());
    let sim = ringpod_json(&[&["stream", "--sim", "--fast"][..], &args].concat());
    let _ = std::fs::remove_file(&beyond);
    match (&emu, &sim) {
        (Ok(e), Ok(s)) => {
            println!(
                "beyond the envelope: {} of {} limited on the emulated device, final steps {} (simulator {})",
                e["limited"]["device"], e["setpoints_sent"], e["final_steps"], s["final_steps"]
            );
            t.check(
                e["outcome"] == "followed"
                    && e["state"] == "Ready"
                    && e["counts_agree"] == true
                    && e["rejected"] == serde_json::json!({})
                    && e["limited"]["device"].as_u64().unwrap_or(0) > 50,
                "a stream beyond the envelope and the limits flows: every setpoint applied, limited on the M4F",
            );
            t.check(
                e["final_steps"] == s["final_steps"] && e["limited"]["device"] == s["limited"]["device"],
                "the emulated controller limits as the host simulator does and ends at its step positions",
            );
        }
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("{e}");
            t.check(
                false,
                "stream beyond the envelope into the emulated controller and the simulator",
            );
        }
    }

    // A frame of garbage: answered with a Malformed nack (id 0), counted, never executed.
    let garbage = [0x05, 0x11, 0x22, 0x33, 0x44, 0x55, 0x00];
    let malformed = send_garbage(pty, &garbage).ok().and_then(|bytes| {
        let frame = bytes.split(|b| *b == 0).next()?.to_vec();
        ringpod_core::protocol::decode::<ringpod_core::protocol::Response>(&frame).ok()
    });
    t.check(
        malformed.is_some_and(|r| {
            r.id == 0
                && r.body == ringpod_core::protocol::DeviceMessage::Nack(ringpod_core::protocol::NackReason::Malformed)
        }),
        "a corrupted frame is answered with a Malformed nack",
    );
    let status = ringpod_json(&["device", "status", "--port", pty]);
    t.check(
        status
            .as_ref()
            .is_ok_and(|s| s["bad_frames"] == 1 && s["state"] == "Ready"),
        "the device counted the bad frame and moved nothing",
    );

    // Telemetry from the M4F: a recorded run has a row every 10 ms of device time.
    let record = std::env::temp_dir().join(format!("ringpod-qemu-record-{}.csv", std::process::id()));
    let recorded = ringpod_json(&[
        "stream",
        "--port",
        pty,
        "--motion",
        "demo",
        "--duration",
        "2",
        "--quiet",
        "--report-json",
        "--record",
        &record.to_string_lossy(),
    ]);
    let rows = std::fs::read_to_string(&record).unwrap_or_default();
    let _ = std::fs::remove_file(&record);
    let device_s: Vec<f64> = rows
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(1)?.parse().ok())
        .collect();
    println!(
        "recorded from the emulated controller: {} telemetry rows over {:.2} s of device time",
        device_s.len(),
        device_s.last().unwrap_or(&0.0) - device_s.first().unwrap_or(&0.0)
    );
    t.check(
        recorded
            .is_ok_and(|r| r["outcome"] == "followed" && r["record"]["rows"].as_u64() == Some(device_s.len() as u64))
            && device_s.len() > 200
            && device_s.windows(2).all(|w| (w[1] - w[0] - 0.01).abs() < 1e-9),
        "the emulated controller sends telemetry: a recorded run has a row every 10 ms of device time",
    );

    // Stream loss: the host dies mid-stream; the controller brakes to rest by itself.
    let streaming = Command::new(ringpod())
        .args([
            "stream",
            "--port",
            pty,
            "--motion",
            "demo",
            "--duration",
            "30",
            "--quiet",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
    let Ok(mut streaming) = streaming else {
        t.check(false, "a stream starts");
        return;
    };
    std::thread::sleep(Duration::from_secs(4));
    let _ = streaming.kill();
    let _ = streaming.wait();
    std::thread::sleep(Duration::from_millis(1_500));
    let after = ringpod_json(&["device", "status", "--port", pty]);
    t.check(
        after
            .as_ref()
            .is_ok_and(|s| s["state"] == "Ready" && s["applied"].as_u64().unwrap_or(0) > 0),
        "a host killed mid-stream leaves the platform braked to rest (Ready)",
    );
    if let Ok(s) = &after {
        println!("after the stream loss: state {}, steps {}", s["state"], s["steps"]);
    }

    // The plant moved only by the STEP edges of the step generator's words: they kept the drivers' timing, and no
    // step came while the drivers were disabled (the board module prints the first of either).
    let problems: Vec<String> = emulated
        .printed()
        .into_iter()
        .filter(|l| l.starts_with("TIMING") || l.starts_with("DISABLED") || l.starts_with("ERROR"))
        .collect();
    for p in &problems {
        eprintln!("qemu: {p}");
    }
    t.check(
        problems.is_empty(),
        "every run above moved the plant by its STEP edges only, within the drivers' timing, drivers enabled",
    );
    drop(emulated);
}

/// Runs the CLI; its exit status and what it printed on stdout.
fn ringpod_text(args: &[&str]) -> (bool, String) {
    Command::new(ringpod())
        .args(args)
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .map(|o| (o.status.success(), String::from_utf8_lossy(&o.stdout).into_owned()))
        .unwrap_or((false, String::new()))
}

/// The watchdog: the control loop hangs once the platform is homed (the program's `stall-when-homed`); the CMSDK
/// watchdog resets the emulated MCU, which comes back with its supplies off, the `Watchdog` fault latched, homing
/// lost and the setting stored before the reset restored from its flash; cleared, it powers and homes again.
fn watchdog_on_m4f(t: &mut Tally) {
    println!("== the watchdog on the emulated Cortex-M4F: a stalled control loop");
    let Some(emulated) = start_or_fail(t, &["stall-when-homed"]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    let port = ["--port", pty];
    let stored = ringpod_text(&[&["device", "config", "set", "stream.telemetry_hz", "50"][..], &port].concat()).0;
    // The settings task stores a change within 100 ms while the supplies are off.
    std::thread::sleep(Duration::from_millis(500));
    let enabled = ringpod_text(&[&["device", "enable"][..], &port].concat()).0;
    // Homing ends in the stall: the command gets no answer and fails.
    let _ = ringpod_text(&[&["device", "home"][..], &port].concat());
    let reset = emulated.wait_for(Duration::from_secs(20), |l| l.trim() == "READY");
    println!("printed over the stall: {reset:?}");
    let lines = reset.unwrap_or_default();
    t.check(
        stored && enabled && lines.iter().any(|l| l == "STALL") && lines.iter().any(|l| l == "RESET watchdog"),
        "a control loop stalled with the platform homed is reset by the watchdog",
    );
    let status = ringpod_json(&[&["device", "status"][..], &port].concat());
    let (_, inputs) = ringpod_text(&[&["device", "inputs"][..], &port].concat());
    let sense_off = ["LOGIC_OK", "POWER_OK"].iter().all(|name| {
        inputs
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().last())
            == Some("-")
    });
    if let Ok(s) = &status {
        println!("after the reset: state {}, homed {}", s["state"], s["homed"]);
    }
    t.check(
        status
            .as_ref()
            .is_ok_and(|s| s["state"] == serde_json::json!({"Fault": ["Watchdog", "None"]}) && s["homed"] == false)
            && sense_off,
        "it comes back with the Watchdog fault reported, both supplies off (sensed), homing lost",
    );
    let setting = ringpod_json(&[&["device", "config", "get", "stream.telemetry_hz"][..], &port].concat());
    t.check(
        setting.is_ok_and(|s| s["value"] == 50) && lines.iter().any(|l| l.starts_with("SETTINGS 2 restored")),
        "the setting stored before the reset is restored from flash by the settings task",
    );
    let cleared = ringpod_text(&[&["device", "clear"][..], &port].concat()).0
        && ringpod_text(&[&["device", "enable"][..], &port].concat()).0
        && ringpod_text(&[&["device", "home"][..], &port].concat()).0;
    let again = ringpod_json(&[&["device", "status"][..], &port].concat());
    t.check(
        cleared && again.is_ok_and(|s| s["state"] == "Ready" && s["homed"] == true),
        "cleared, it powers up and homes again (no second stall: the last reset was the watchdog's)",
    );
    drop(emulated);
}

/// A rig no preset describes, on the device: loaded over the UART (checked by the M4F), stored in its flash,
/// restored at the restart the host asks for, shown back as a rig file, and driven end to end: a CSV streamed into
/// it ends at exactly the steps the host simulator reaches with `--geometry` of the same file.
fn rig_on_m4f(t: &mut Tally) {
    println!("== a rig of its own on the emulated Cortex-M4F: load, restart, stream");
    let dir = std::env::temp_dir().join(format!("ringpod-qemu-rig-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let (rig, input) = (dir.join("wider.toml"), dir.join("input.csv"));
    let (exported, model) = ringpod_text(&["presets", "--export", "trainer-model"]);
    let wider = model
        .replace("name = \"trainer-model\"", "name = \"wider-ring\"")
        .replace("ring_radius = 0.286", "ring_radius = 0.3")
        .replace("rod_length = 0.312", "rod_length = 0.325");
    if !exported || wider == model || std::fs::write(&rig, wider).is_err() || write_input(&input).is_err() {
        t.check(false, "the rig file and the input are written");
        return;
    }
    let Some(emulated) = start_or_fail(t, &[]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    let (rig_file, input_file) = (rig.to_string_lossy().to_string(), input.to_string_lossy().to_string());
    let loaded = ringpod_text(&["device", "rig", "load", &rig_file, "--port", pty]).0;
    let (restarted, said) = ringpod_text(&["device", "restart", "--port", pty]);
    let printed = emulated.wait_for(Duration::from_secs(10), |l| l.trim() == "READY");
    println!("restart: {} / {printed:?}", said.trim());
    let (_, shown) = ringpod_text(&["device", "rig", "show", "--port", pty]);
    t.check(
        loaded
            && restarted
            && said.contains("running wider-ring (stored)")
            && printed.is_ok_and(|l| l.iter().any(|l| l == "RIG wider-ring (Stored)"))
            && shown.contains("name = \"wider-ring\"")
            && shown.contains("ring_radius = 0.3\n")
            && shown.contains("rod_length = 0.325\n"),
        "a rig file loaded into the emulated controller is stored and runs after a restart",
    );
    let args = ["--input", &input_file, "--quiet", "--report-json"];
    let emu = ringpod_json(&[&["stream", "--port", pty][..], &args].concat());
    let sim = ringpod_json(&[&["stream", "--sim", "--fast", "--geometry", &rig_file][..], &args].concat());
    let model = ringpod_json(&[&["stream", "--sim", "--fast"][..], &args].concat());
    let _ = std::fs::remove_dir_all(&dir);
    match (&emu, &sim, &model) {
        (Ok(e), Ok(s), Ok(m)) => {
            println!(
                "wider ring: emulated final steps {}, simulator {}, the trainer model {}",
                e["final_steps"], s["final_steps"], m["final_steps"]
            );
            t.check(
                e["state"] == "Ready"
                    && e["counts_agree"] == true
                    && e["final_steps"] == s["final_steps"]
                    && e["final_steps"] != m["final_steps"],
                "the emulated controller drives the stored rig to the simulator's steps for it (not the model's)",
            );
        }
        _ => {
            eprintln!("{emu:?} {sim:?} {model:?}");
            t.check(false, "stream into the emulated controller's rig and the simulator's");
        }
    }
    drop(emulated);
}

/// Makes sure `qemu-system-arm` is there: on a fresh Debian or Ubuntu machine it installs it (as root, or through
/// `sudo` without a password), as the README's test command promises; otherwise it says what to install.
fn ensure_qemu() -> Result<(), String> {
    let present = || {
        Command::new("qemu-system-arm")
            .arg("--version")
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if present() {
        return Ok(());
    }
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let sudo = !root
        && Command::new("sudo")
            .args(["-n", "true"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
    let apt = Command::new("apt-get")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok();
    let help = "qemu-system-arm is missing: install it (Debian and Ubuntu: apt-get install qemu-system-arm)";
    if !apt || !(root || sudo) {
        return Err(help.into());
    }
    println!("== qemu-system-arm is missing: installing it with apt-get");
    let apt_get = |args: &[&str]| {
        let mut c = if root {
            Command::new("apt-get")
        } else {
            Command::new("sudo")
        };
        if !root {
            c.arg("apt-get");
        }
        c.args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .status()
            .is_ok_and(|s| s.success())
    };
    if apt_get(&["update"]) && apt_get(&["install", "-y", "qemu-system-arm"]) && present() {
        Ok(())
    } else {
        Err(help.into())
    }
}

fn main() -> ExitCode {
    if let Err(e) = ensure_qemu() {
        eprintln!("{e}");
        println!("0 passed, 1 failed");
        return ExitCode::FAILURE;
    }
    let mut t = Tally { passed: 0, failed: 0 };
    core_on_m4f(&mut t);
    controller_on_m4f(&mut t);
    watchdog_on_m4f(&mut t);
    rig_on_m4f(&mut t);
    println!("{} passed, {} failed", t.passed, t.failed);
    if t.failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
