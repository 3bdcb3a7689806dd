//! The controller's firmware tasks on the emulated MCU, streamed through its UART as a board is over USB.

use std::process::{Command, Stdio};
use std::time::Duration;

use crate::emulator::start_or_fail;
use crate::host_cli::{ringpod, ringpod_json, send_garbage, write_beyond_envelope, write_input};
use crate::Tally;

/// Builds everything the suite runs: the host CLI and both Cortex-M4F programs.
pub(crate) fn build_all() -> Result<(), String> {
    ringpod_tests::cli::host()?;
    crate::emulator::build("ringpod-qemu")?;
    crate::emulator::build("ringpod-qemu-controller").map(|_| ())
}

/// The firmware's tasks on the emulated MCU, driven by the host CLI over the UART.
pub(crate) fn controller_on_m4f(t: &mut Tally) {
    println!("== the controller's firmware tasks on the emulated Cortex-M4F, over its UART");
    if ringpod_tests::cli::host().is_err() {
        t.check(false, "the host CLI builds");
        return;
    }
    // `estop-on-aux2`: AUX2's contact in the e-stop chain, for the auxiliary outputs' run at the end.
    let Some(emulated) = start_or_fail(t, &["estop-on-aux2"]) else {
        return;
    };
    let pty = emulated.pty.as_str();
    println!("controller on {pty}");
    csv_streams(t, pty);
    garbage_frame(t, pty);
    telemetry_rows(t, pty);
    stream_loss(t, pty);
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
    hold_up_mid_stream(t, &emulated);
    crate::aux::aux_on_m4f(t, &emulated);
    drop(emulated);
}

/// A pose file streamed into the emulated controller and the simulator, and one beyond the envelope and the
/// limits: the same ends.
fn csv_streams(t: &mut Tally, pty: &str) {
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
}

/// A corrupted frame: answered, counted, never executed.
fn garbage_frame(t: &mut Tally, pty: &str) {
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
}

/// A recorded run's telemetry rows, one every 10 ms of device time.
fn telemetry_rows(t: &mut Tally, pty: &str) {
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
}

/// `ringpod stream --port PTY --motion demo --duration SECONDS --quiet`, its input closed.
fn demo_stream(pty: &str, seconds: &str) -> Command {
    let mut c = Command::new(ringpod());
    c.args([
        "stream",
        "--port",
        pty,
        "--motion",
        "demo",
        "--duration",
        seconds,
        "--quiet",
    ])
    .stdin(Stdio::null());
    c
}

/// A host killed mid-stream: the controller brakes to rest by itself.
fn stream_loss(t: &mut Tally, pty: &str) {
    // Stream loss: the host dies mid-stream; the controller brakes to rest by itself.
    let streaming = demo_stream(pty, "30")
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
    // The stream timeout, then braking to rest, both in device time: under `-icount` on a busy machine the emulated
    // clock runs slower than the wall clock, so the check polls the device's state rather than sleeping a fixed
    // wall-clock time. The deadline only bounds a device that never brakes.
    let deadline = std::time::Instant::now() + Duration::from_secs(60);
    std::thread::sleep(Duration::from_millis(u64::from(crate::emulator::STREAM_TIMEOUT_MS)));
    let mut after = ringpod_json(&["device", "status", "--port", pty]);
    while std::time::Instant::now() < deadline && !after.as_ref().is_ok_and(|s| s["state"] == "Ready") {
        std::thread::sleep(Duration::from_millis(250));
        after = ringpod_json(&["device", "status", "--port", pty]);
    }
    t.check(
        after
            .as_ref()
            .is_ok_and(|s| s["state"] == "Ready" && s["applied"].as_u64().unwrap_or(0) > 0),
        "a host killed mid-stream leaves the platform braked to rest (Ready)",
    );
    if let Ok(s) = &after {
        println!("after the stream loss: state {}, steps {}", s["state"], s["steps"]);
    }
}

/// A hold-up of the emulator mid-stream (QEMU's process stopped for 0.05, 0.5 and 2 s, longer than the stream
/// timeout), as a busy test machine gives one: the stream goes on, every setpoint applied, no restart. Under
/// `-icount` device time stands still while QEMU is stopped, so the device sees no hold-up of its own (the periods it
/// passed are printed); the firmware's catch-up after a hold-up of device time is the core's and the simulator's
/// test (`Controller::pass`, `host/tests/suite/link.rs`).
fn hold_up_mid_stream(t: &mut Tally, emulated: &crate::emulator::Emulated) {
    let pty = emulated.pty.as_str();
    let passed = |s: &serde_json::Value| s["passed_periods"].as_u64().unwrap_or(0);
    for stall_ms in [50u64, 500, 2_000] {
        let before = ringpod_json(&["device", "status", "--port", pty])
            .map(|s| passed(&s))
            .unwrap_or(0);
        let streaming = demo_stream(pty, "6")
            .arg("--report-json")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn();
        let Ok(streaming) = streaming else {
            t.check(false, "a stream starts");
            return;
        };
        std::thread::sleep(Duration::from_secs(3));
        let held = emulated.hold_up(Duration::from_millis(stall_ms));
        let report = streaming
            .wait_with_output()
            .ok()
            .and_then(|o| serde_json::from_slice::<serde_json::Value>(&o.stdout).ok());
        let after = ringpod_json(&["device", "status", "--port", pty])
            .map(|s| passed(&s))
            .unwrap_or(0);
        if let Some(r) = &report {
            println!(
                "a hold-up of {stall_ms} ms: {}, {} of {} applied, {} restarts, {} periods passed",
                r["outcome"],
                r["setpoints_applied"],
                r["setpoints_sent"],
                r["restarts"],
                after.saturating_sub(before)
            );
        }
        t.check(
            held.is_ok()
                && report.is_some_and(|r| {
                    r["outcome"] == "followed" && r["restarts"] == 0 && r["setpoints_applied"] == r["setpoints_sent"]
                }),
            &format!("a stream goes on through a {stall_ms} ms hold-up of the emulator, every setpoint applied"),
        );
    }
}
