//! The link to a board as the operating system shows it, against `ringpod simulate --pty`: a hold-up of the
//! device is not a lost link, a client that stops reading does not kill the device, and another process that
//! reads the same port never leaves the host blocked or deaf to signals.
#![cfg(unix)]

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::simulator::Simulator;

/// Time from `stream`'s start to streaming on the simulator: power-up and homing take about 9 s of real time.
const HOMED_AFTER: Duration = Duration::from_secs(12);

fn ringpod() -> Command {
    Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
}

fn signal(pid: u32, signal: nix::sys::signal::Signal) {
    nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid as i32), signal).unwrap();
}

/// `ringpod stream --port PORT --motion demo --duration SECONDS --quiet`.
fn demo_stream(port: &str, seconds: &str) -> Command {
    let mut c = ringpod();
    c.args([
        "stream",
        "--port",
        port,
        "--motion",
        "demo",
        "--duration",
        seconds,
        "--quiet",
    ]);
    c
}

/// Waits for `child` to end, up to `limit`; `None` while it still runs.
fn wait_at_most(child: &mut std::process::Child, limit: Duration) -> Option<std::process::ExitStatus> {
    let deadline = Instant::now() + limit;
    while Instant::now() < deadline {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
}

/// A stream through which the simulator is stopped (`kill -STOP`) for `stall`, mid-stream: the report and the
/// device's counters.
fn stream_through_a_stall(stall: Duration) -> (serde_json::Value, serde_json::Value) {
    let sim = Simulator::start();
    // The simulator, the host and this test share the machine's cores: a host descheduled for longer than the
    // default timeout (100 ms) is, to the device, a host that is gone. On a test run's busiest minutes (eight
    // tests at a time beside the Windows runner's build) a process waits up to 0.9 s for a core, measured; a
    // timeout of 1 s outlasts that and is still half the longest hold-up below, which the simulator must pass.
    let (code, _, err) = sim.ringpod(&["device", "config", "set", "stream.timeout_ms", "1000"]);
    assert_eq!(code, Some(0), "{err}");
    let stream = ringpod()
        .args(["stream", "--port", &sim.path, "--motion", "demo", "--duration", "8"])
        .args(["--quiet", "--report-json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(HOMED_AFTER);
    signal(sim.child.id(), nix::sys::signal::Signal::SIGSTOP);
    std::thread::sleep(stall);
    signal(sim.child.id(), nix::sys::signal::Signal::SIGCONT);
    let out = stream.wait_with_output().unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(
        out.status.code(),
        Some(0),
        "a stall of {stall:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (report, sim.status())
}

/// A device held up for 0.05 to 2 s (here the simulator's process stopped; on a board a flash erase) is not a
/// lost link: the periods the hold-up cost are passed, the setpoints that arrived meanwhile are read, and the
/// stream goes on without a restart, every setpoint applied.
#[test]
fn a_live_stream_survives_a_hold_up_of_the_device() {
    // One after the other: three simulators and streams at once were, with the other tests, more than two cores
    // could serve without holding a process up longer than the hold-ups themselves.
    for ms in [50u64, 500, 2000] {
        let (report, status) = stream_through_a_stall(Duration::from_millis(ms));
        assert_eq!(report["outcome"], "followed", "a stall of {ms} ms: {report}");
        assert_eq!(report["restarts"], 0, "a stall of {ms} ms: {report}");
        assert_eq!(report["setpoints_applied"], report["setpoints_sent"], "{report}");
        // The hold-up's periods were passed (all but the catch-up the simulator ticks), not ticked in a burst; a
        // busy machine's own hold-ups add theirs.
        let passed = status["passed_periods"].as_u64().unwrap();
        assert!(passed + 20 >= ms, "a stall of {ms} ms passed {passed} periods");
    }
}

/// A recorder suspended and then killed while telemetry flows: the simulator keeps serving (its bytes for the
/// client that does not read are bounded, the oldest frames dropped), and the next client finds it as it was.
#[test]
fn the_simulator_keeps_serving_when_a_client_stops_reading() {
    let sim = Simulator::start();
    let record = std::env::temp_dir().join(format!("ringpod-link-record-{}.csv", std::process::id()));
    let mut recorder = demo_stream(&sim.path, "60")
        .arg("--record")
        .arg(&record)
        .arg("--record-hz")
        .arg("1000")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(HOMED_AFTER);
    signal(recorder.id(), nix::sys::signal::Signal::SIGSTOP);
    std::thread::sleep(Duration::from_secs(6));
    let _ = recorder.kill();
    let _ = recorder.wait();
    let _ = std::fs::remove_file(&record);
    // The device's stream timeout brakes the platform; the simulator is still there to say so.
    std::thread::sleep(Duration::from_secs(1));
    assert!(
        sim.child_running(),
        "the simulator ended when its client stopped reading"
    );
    let status = sim.status();
    assert_eq!(status["state"], "Ready", "{status}");
    assert!(status["homed"] == true, "{status}");
}

/// Another process that opens the same port and takes bytes (`cat PORT`) makes the host lose answers, but never
/// blocks it: the stream ends by itself or on SIGTERM, within a bounded time, with an exit code.
#[test]
fn a_port_drained_by_another_reader_never_blocks_the_host() {
    let sim = Simulator::start();
    let mut stream = demo_stream(&sim.path, "30")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(HOMED_AFTER);
    for _ in 0..8 {
        let _ = Command::new("timeout")
            .args(["0.3", "cat", &sim.path])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
    }
    if stream.try_wait().unwrap().is_none() {
        signal(stream.id(), nix::sys::signal::Signal::SIGTERM);
    }
    let status = wait_at_most(&mut stream, Duration::from_secs(15));
    if status.is_none() {
        let _ = stream.kill();
    }
    let status = status.expect("the stream ended within 15 s of SIGTERM");
    assert!(status.code().is_some_and(|c| c != 0), "{status:?}");
}
