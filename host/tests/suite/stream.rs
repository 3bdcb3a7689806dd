//! `ringpod stream` against the simulated controller: the same core as the firmware behind the real framed bytes.

#[cfg(unix)]
use crate::common::simulator::Simulator;
#[cfg(unix)]
use crate::common::spawn_sim_stream;
use crate::common::{numbers, spawn_live_stream};
use assert_cmd::Command;
#[cfg(unix)]
use nix::sys::signal::Signal;
use ringpod_core::kinematics::Pose;

fn stream(args: &[&str], csv: Option<&str>) -> (serde_json::Value, std::process::Output) {
    let dir = std::env::temp_dir().join(format!("ringpod-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut cmd = Command::cargo_bin("ringpod").unwrap();
    cmd.args(["stream", "--sim", "--fast", "--report-json", "--quiet"])
        .args(args);
    if let Some(text) = csv {
        let path = dir.join(format!("{}.csv", text.len()));
        std::fs::write(&path, text).unwrap();
        cmd.arg("--input").arg(&path);
    }
    let out = cmd.output().unwrap();
    let json =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    (json, out)
}

/// The steps of the model's axes at a pose, after homing (home pose = step 0 on every axis).
fn steps_at(pose: [f64; 6]) -> [i64; 6] {
    let (m, conv, home) = crate::common::trainer_homed();
    let mut q = home;
    q.inverse_near(&m, &Pose::from_array(pose).cast()).unwrap();
    conv.to_steps(&q)
}

/// `ringpod simulate --pty` (killed when dropped, with the tests' stream timeout) and its pseudo-terminal.
#[cfg(unix)]
fn simulator_on_a_pty() -> (Simulator, String) {
    simulator_on_a_pty_with(&[])
}

/// [`simulator_on_a_pty`] with further arguments to `simulate` (`--mechanism trainer-elbow`).
#[cfg(unix)]
fn simulator_on_a_pty_with(args: &[&str]) -> (Simulator, String) {
    let simulator = Simulator::start_with(args);
    let path = simulator.path.clone();
    (simulator, path)
}

/// The run ended with every axis within a step of the IK of the last pose the device applied.
fn assert_at_the_last_pose(report: &serde_json::Value) {
    let last: Vec<f64> = numbers(&report["last_applied_pose"]);
    let want = steps_at(last.try_into().unwrap());
    let got = numbers(&report["final_steps"]);
    for (g, w) in got.iter().zip(want) {
        assert!(
            (*g as i64 - w).abs() <= 1,
            "final steps {got:?}, IK of the last pose {want:?}"
        );
    }
}

#[test]
fn csv_stream_ends_at_the_ik_of_the_last_pose() {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..=400 {
        let t = k as f64 * 0.005;
        let s = (t * 1.5).sin();
        csv += &format!(
            "{t},{},{},{},{},{},{}\n",
            0.01 * s,
            -0.005 * s,
            0.227 + 0.01 * s,
            0.05 * s,
            -0.04 * s,
            0.3 * t
        );
    }
    let (report, out) = stream(&[], Some(&csv));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["setpoints_sent"], report["setpoints_applied"]);
    assert!(report["setpoints_applied"].as_u64().unwrap() >= 401);
    assert_eq!(report["counts_agree"], true);
    let last: Vec<f64> = numbers(&report["last_applied_pose"]);
    let want = steps_at(last.try_into().unwrap());
    let got: Vec<f64> = numbers(&report["final_steps"]);
    for (g, w) in got.iter().zip(want) {
        assert!(
            (*g as i64 - w).abs() <= 1,
            "final steps {got:?}, IK of the last pose {want:?}"
        );
    }
}

#[test]
fn bad_lines_are_reported_and_counts_add_up() {
    let csv = "t,x,y,z,alpha,beta,gamma\n\
               0.00,0,0,0.227,0,0,0\n\
               0.01,0,0,0.2271,0,0,0\n\
               0.02,0,0,not-a-number,0,0,0\n\
               0.03,0,0,0.2272\n\
               0.04,0,0,NaN,0,0,0\n\
               0.05,0,0,0.5,0,0,0\n\
               0.05,0,0,0.2273,0,0,0\n\
               0.06,0,0,0.2273,0,0,0\n";
    let (report, out) = stream(&[], Some(csv));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let errors = report["input_errors"].as_array().unwrap();
    let lines: Vec<u64> = errors.iter().map(|e| e["line"].as_u64().unwrap()).collect();
    assert_eq!(
        lines,
        [4, 5, 6, 8],
        "malformed number, short line, not finite, time not increasing"
    );
    assert!(stderr.contains("line 6: z = NaN is not a finite number"), "{stderr}");
    // 27 cm up in 10 ms: a gross jump; the host's limiting brought it inside, so it is not outside as well.
    assert!(stderr.contains("line 7: refused by the device: gross_jump"), "{stderr}");
    assert_eq!(
        report["rejected"],
        serde_json::json!({"gross_jump": 1}),
        "garbage is not sent"
    );
    // Every refusal with its line, in the report as on stderr.
    let refusals: Vec<(u64, String)> = report["refusals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["line"].as_u64().unwrap(), r["reason"].as_str().unwrap().to_owned()))
        .collect();
    assert_eq!(refusals, [(7, "gross_jump".into())]);
    let sent = report["setpoints_sent"].as_u64().unwrap();
    let applied = report["setpoints_applied"].as_u64().unwrap();
    let rejected: u64 = report["rejected"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(
        (sent, applied),
        (4, 3),
        "input setpoints only: lead-in and settle apart"
    );
    assert_eq!(sent, applied + rejected);
    assert_eq!(report["counts_agree"], true);
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["outcome"], "refused");
    assert_eq!(out.status.code(), Some(4), "device refusals outrank input errors");
}

#[test]
fn a_gap_in_the_stream_is_interpolated_and_a_long_one_rests() {
    // 0.39 s between two rows: interpolated every 10 ms (38 setpoints), the stream never stops; every pose is
    // applied.
    let csv = "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.01,0,0,0.2271,0,0,0\n0.4,0,0,0.2272,0,0,0\n0.41,0,0,0.2273,0,0,0\n";
    let (report, out) = stream(&[], Some(csv));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["restarts"], 0);
    assert!(
        (37..=39).contains(&report["interpolated_sent"].as_u64().unwrap()),
        "{report}"
    );
    assert_eq!(report["setpoints_applied"], 4);
    assert_eq!(report["rejected"], serde_json::json!({}));
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
}

/// The runs of the issue that found every stream stalling: each ends with every setpoint applied (limited where
/// needed), state Ready and exit 0.
#[test]
fn streams_beyond_the_envelope_and_the_limits_flow() {
    // The demo for 20 s (it left the workspace at 18.9 s before), and a combined motion whose every axis stays
    // inside the spec table while all move at once, yaw turning.
    let (demo, out) = stream(&["--motion", "demo", "--duration", "20", "--rate", "250"], None);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(demo["setpoints_applied"], demo["setpoints_sent"]);
    let mut combined = String::from("t,x,y,z,alpha,beta,gamma\n");
    let mut fast = combined.clone();
    for k in 0..=1200 {
        let t = f64::from(k) / 60.0;
        let r = 18f64.to_radians();
        combined += &format!(
            "{t},{},{},{},{},{},{}\n",
            0.045 * (0.9 * t).sin(),
            0.045 * (1.1 * t + 1.0).sin(),
            0.227 + 0.03 * (1.3 * t + 2.0).sin(),
            r * (0.8 * t + 0.5).sin(),
            r * (0.7 * t + 1.5).sin(),
            0.3 * t
        );
        // Surge peaking at 0.075 m/s, half again the 0.05 m/s limit.
        if k <= 600 {
            fast += &format!("{t},{},0,0.227,0,0,0\n", 0.03 * (2.5 * t).sin());
        }
    }
    for (name, csv, limited) in [("combined", &combined, true), ("fast", &fast, false)] {
        let (report, out) = stream(&[], Some(csv));
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(report["outcome"], "followed", "{name}");
        assert_eq!(report["state"], "Ready", "{name}");
        assert_eq!(report["setpoints_applied"], report["setpoints_sent"], "{name}");
        assert_eq!(report["counts_agree"], true, "{name}");
        let host_limited = report["limited"]["host"].as_u64().unwrap();
        assert_eq!(host_limited > 0, limited, "{name}: {}", report["limited"]);
        if limited {
            // The host limits with the device's margins: the device has (almost) nothing left to limit.
            assert!(
                report["limited"]["device"].as_u64().unwrap() * 100 <= host_limited,
                "{}",
                report["limited"]
            );
            assert!(report["limited"]["largest_mm"].as_f64().unwrap() > 1.0);
        }
    }
}

/// A stream that turns to garbage ends non-zero with the reason: the garbage is refused on the host, line by
/// line, and never sent.
#[test]
fn a_stream_that_turns_to_nan_ends_non_zero() {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..200 {
        let z = if k < 100 { "0.227" } else { "NaN" };
        csv += &format!("{},0,0,{z},0,0,0\n", f64::from(k) * 0.01);
    }
    let (report, out) = stream(&[], Some(&csv));
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["outcome"], "input_errors");
    assert_eq!(report["input_errors"].as_array().unwrap().len(), 100);
    assert_eq!(report["rejected"], serde_json::json!({}));
    assert_eq!(report["setpoints_applied"], 100);
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
}

/// Adversarial input: each ends with a clear error or a correct result, a report, and the right exit code.
#[test]
fn garbage_input_gets_a_clear_answer() {
    // A time of 1e308 is refused with its line, the rest is followed; no panic.
    let (report, out) = stream(
        &[],
        Some("t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n1e308,0,0,0.227,0,0,0\n"),
    );
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["input_errors"][0]["line"], 3);
    assert_eq!(report["setpoints_applied"], 1);
    // A gap of a million seconds under --fast ends (not one motion: the stream stops and the device rests; nothing
    // to compute for the rest of it).
    let (report, out) = stream(
        &[],
        Some("t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n1000000,0,0,0.228,0,0,0\n"),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        (report["restarts"].as_u64(), report["setpoints_applied"].as_u64()),
        (Some(1), Some(2))
    );
    // Columns by name, in any order; a wrong header is an error before anything moves.
    let (report, out) = stream(
        &[],
        Some("z,t,x,y,alpha,beta,gamma\n0.23,0,0,0,0,0,0\n0.231,0.01,0,0,0,0,0\n"),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!((report["last_applied_pose"][2].as_f64().unwrap() - 0.231).abs() < 1e-12);
    for (csv, why) in [
        ("t,x,y,z,roll,pitch,yaw\n0,0,0,0.227,0,0,0\n", "header"),
        ("0,0,0,0.227,0,0,0\n", "header"),
        ("", "no header"),
    ] {
        let dir = std::env::temp_dir().join(format!("ringpod-bad-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.csv");
        std::fs::write(&path, csv).unwrap();
        Command::cargo_bin("ringpod")
            .unwrap()
            .args(["stream", "--sim", "--fast", "--quiet", "--input"])
            .arg(&path)
            .assert()
            .code(1)
            .stderr(predicates::str::contains(why));
    }
    // Old Mac line ends (CR only) are lines.
    let (report, out) = stream(
        &[],
        Some("t,x,y,z,alpha,beta,gamma\r0,0,0,0.227,0,0,0\r0.01,0,0,0.2271,0,0,0\r"),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["setpoints_applied"], 2);
    // A header and nothing else: nothing was followed, and the exit code says so.
    let (report, out) = stream(&[], Some("t,x,y,z,alpha,beta,gamma\n"));
    assert_eq!(out.status.code(), Some(3));
    assert_eq!(report["reason"], "no pose in the input");
    // Options that are not numbers of the right size are errors before anything starts.
    for args in [
        &["--motion", "demo", "--duration", "inf"][..],
        &["--motion", "demo", "--duration", "NaN"],
        &["--motion", "demo", "--duration", "0"],
        &["--motion", "demo", "--rate", "0"],
        &["--udp", "127.0.0.1:0", "--udp-idle", "NaN"],
    ] {
        Command::cargo_bin("ringpod")
            .unwrap()
            .args(["stream", "--sim", "--fast", "--quiet"])
            .args(args)
            .assert()
            .code(1)
            .stderr(predicates::str::contains("must be a number"));
    }
}

/// A built-in motion of a very long duration is generated as it is sent, not built in memory first; Ctrl-C ends
/// it with a stop, a report, and an exit code that is not success.
#[test]
#[cfg(unix)]
fn long_motions_start_at_once_and_stop_on_ctrl_c() {
    let interrupt_after = |args: &[&str], ms: u64| {
        let child = spawn_sim_stream(args);
        std::thread::sleep(std::time::Duration::from_millis(ms));
        nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(child.id() as i32),
            nix::sys::signal::Signal::SIGINT,
        )
        .unwrap();
        let sent = std::time::Instant::now();
        let out = child.wait_with_output().unwrap();
        (out, sent.elapsed())
    };
    // In real time, Ctrl-C during homing aborts it at once (homing takes seconds).
    let (out, took) = interrupt_after(&["--motion", "demo"], 1000);
    assert_eq!(out.status.code(), Some(130));
    assert!(String::from_utf8_lossy(&out.stderr).contains("interrupted"));
    assert!(took < std::time::Duration::from_secs(2), "{took:?}");
    let (out, _) = interrupt_after(&["--fast", "--motion", "demo", "--duration", "1e8"], 1500);
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(out.status.code(), Some(130), "an interrupted run is not a success");
    assert_eq!(report["outcome"], "interrupted");
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
}

/// A second stream to the same device: its counters are this run's, and it agrees with the device's. Garbage
/// on the line does not break the next request.
#[test]
#[cfg(unix)]
fn a_second_stream_to_the_same_device_agrees() {
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let (server, path) = simulator_on_a_pty();
    let file = std::env::temp_dir().join(format!("ringpod-twice-{}.csv", std::process::id()));
    std::fs::write(
        &file,
        "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.05,0.001,0,0.228,0,0,0\n",
    )
    .unwrap();
    for run in 0..2 {
        if run == 1 {
            // Line noise without a delimiter, as a loose connector makes.
            use std::io::Write;
            let mut port = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
            port.write_all(b"\x13\x37garbage").unwrap();
        }
        let out = std::process::Command::new(&exe)
            .args(["stream", "--port", &path, "--report-json", "--quiet", "--input"])
            .arg(&file)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "run {run}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["counts_agree"], true, "run {run}");
        assert_eq!(report["setpoints_applied"], 2, "run {run}");
    }
    drop(server);
}

/// Every built-in motion stays inside the envelope (nothing to limit) and the limits (nothing refused) for 120 s,
/// at every yaw it turns through.
#[test]
fn motions_stay_inside_the_envelope_and_the_limits() {
    for motion in ["demo", "heave", "yaw", "vibration"] {
        let (report, out) = stream(&["--motion", motion, "--duration", "120", "--rate", "100"], None);
        assert!(
            out.status.success(),
            "{motion}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(report["rejected"], serde_json::json!({}), "{motion}");
        assert_eq!(report["limited"]["host"], 0, "{motion}: {}", report["limited"]);
        assert_eq!(report["limited"]["device"], 0, "{motion}: {}", report["limited"]);
        assert_eq!(report["setpoints_applied"], 12_001, "{motion}");
        assert_eq!(report["state"], "Ready", "{motion}");
    }
}

#[test]
fn stream_needs_a_device() {
    Command::cargo_bin("ringpod")
        .unwrap()
        .args(["stream", "--motion", "demo"])
        .assert()
        .code(1);
}

/// `ringpod simulate --pty` serves the simulated controller on a pseudo-terminal; `stream --port` reaches it
/// through the real serial transport, in real time.
#[test]
#[cfg(unix)]
fn stream_through_a_pseudo_terminal() {
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let (server, path) = simulator_on_a_pty();
    assert!(path.starts_with("/dev/pts/"), "{path}");
    let csv =
        "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.05,0.001,0,0.228,0.01,0,0.05\n0.1,0.002,0,0.229,0.02,0,0.1\n";
    let file = std::env::temp_dir().join(format!("ringpod-pty-{}.csv", std::process::id()));
    std::fs::write(&file, csv).unwrap();
    let out = std::process::Command::new(&exe)
        .args(["stream", "--port", &path, "--report-json", "--quiet", "--input"])
        .arg(&file)
        .output()
        .unwrap();
    drop(server);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
    assert_at_the_last_pose(&report);
}

/// Starts `ringpod stream --udp 127.0.0.1:0 ARGS` and waits until it announces the address to send to.
fn spawn_udp_stream(
    args: &[&str],
) -> (
    std::process::Child,
    std::io::BufReader<std::process::ChildStderr>,
    String,
) {
    spawn_live_stream(&[&["--udp", "127.0.0.1:0"][..], args].concat())
}

/// Waits for a live stream to end: its output, its JSON report and what it said on stderr.
fn ended(
    child: std::process::Child,
    stderr: &mut std::io::BufReader<std::process::ChildStderr>,
) -> (std::process::Output, serde_json::Value, String) {
    let out = child.wait_with_output().unwrap();
    let mut said = String::new();
    let _ = std::io::Read::read_to_string(stderr, &mut said);
    let report = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}; status {:?}; {said}", out.status));
    (out, report, said)
}

/// Poses from UDP datagrams, as motion-simulator software sends them.
#[test]
fn stream_from_udp_datagrams() {
    let (child, _stderr, addr) = spawn_udp_stream(&["--fast", "--udp-idle", "0.3", "--degrees"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    for k in 0..=50 {
        let z = 0.227 + 0.0002 * f64::from(k);
        socket
            .send_to(format!("0 0 {z} 0 {} 1", 0.05 * f64::from(k)).as_bytes(), &addr)
            .unwrap();
        if k == 20 {
            socket.send_to(b"0 0 nonsense", &addr).unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["rejected"], serde_json::json!({}), "{report}");
    assert_eq!(report["input_errors"].as_array().unwrap().len(), 1);
    let last: Vec<f64> = numbers(&report["last_applied_pose"]);
    assert!(
        (last[2] - 0.237).abs() < 1e-9 && (last[4] - 2.5f64.to_radians()).abs() < 1e-9,
        "{last:?}"
    );
    let want = steps_at(last.try_into().unwrap());
    for (g, w) in numbers(&report["final_steps"]).iter().zip(want) {
        assert!((*g as i64 - w).abs() <= 1);
    }
}

/// Ctrl-C (SIGINT) or SIGTERM in the middle of a stream ends it with a stop and a wait for rest, still reports, and
/// exits with 128 + the signal (130, 143) as a shell or a service manager expects.
#[test]
#[cfg(unix)]
fn a_signal_stops_and_reports() {
    for (signal, code) in [(Signal::SIGINT, 130), (Signal::SIGTERM, 143)] {
        // UDP source: the stream is then certainly running (it announces itself) when the signal comes.
        let (child, mut stderr, addr) = spawn_udp_stream(&["--udp-idle", "60"]);
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        for k in 0..20 {
            socket
                .send_to(format!("0 0 {} 0 0 0", 0.227 + 0.0001 * f64::from(k)).as_bytes(), &addr)
                .unwrap();
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        nix::sys::signal::kill(nix::unistd::Pid::from_raw(child.id() as i32), signal).unwrap();
        let out = child.wait_with_output().unwrap();
        let mut rest = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut rest);
        let report: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{e}; status {:?}; stderr: {rest}", out.status));
        assert_eq!(report["state"], "Ready", "stopped and at rest");
        assert!(report["setpoints_applied"].as_u64().unwrap() >= 1);
        assert_eq!(report["counts_agree"], true);
        assert_eq!(report["outcome"], "interrupted");
        assert_eq!(out.status.code(), Some(code), "{signal}: {rest}");
        assert!(rest.contains("interrupted by"), "{rest}");
    }
}

/// `simulate --pty` started the way a script starts it (`ringpod simulate --pty &`, where the shell sets SIGINT to
/// ignored): SIGINT and SIGTERM still stop it, and it exits with 128 + the signal, closing its pseudo-terminal.
#[test]
#[cfg(unix)]
fn the_simulator_stops_on_sigint_and_sigterm_even_started_with_sigint_ignored() {
    use std::io::BufRead;
    use std::os::unix::process::CommandExt;
    for (signal, code) in [(Signal::SIGINT, 130), (Signal::SIGTERM, 143)] {
        let mut command = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"));
        command
            .args(["simulate", "--pty"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        // SAFETY: between fork and exec only `signal`, which is async-signal-safe, runs.
        unsafe {
            command.pre_exec(|| {
                nix::sys::signal::signal(Signal::SIGINT, nix::sys::signal::SigHandler::SigIgn)
                    .map(|_| ())
                    .map_err(std::io::Error::from)
            });
        }
        let mut server = command.spawn().unwrap();
        let mut path = String::new();
        std::io::BufReader::new(server.stdout.take().unwrap())
            .read_line(&mut path)
            .unwrap();
        assert!(path.starts_with("/dev/pts/"), "{path}");
        nix::sys::signal::kill(nix::unistd::Pid::from_raw(server.id() as i32), signal).unwrap();
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
        let status = loop {
            if let Some(status) = server.try_wait().unwrap() {
                break status;
            }
            if std::time::Instant::now() > deadline {
                let _ = server.kill();
                panic!("the simulator still runs 10 s after {signal}");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert_eq!(status.code(), Some(code), "{signal}");
        let mut said = String::new();
        let _ = std::io::Read::read_to_string(&mut server.stderr.take().unwrap(), &mut said);
        assert!(said.contains("simulator stopped by"), "{said}");
    }
}

/// Class (adversary): a live source's garbage is unreadable, never sent, and never ends the session. A pose
/// datagram that is not finite (NaN, infinity, 1e400, a yaw of 1e300 that f32 makes infinite), one of 65,000 digits,
/// a telemetry datagram whose time is NaN or 1e300 or whose force is 1e30, and three seconds of nothing but garbage after a good start
/// (longer than the stream timeout): every later good datagram is applied, the garbage is counted by number, and
/// the exit code says input was unreadable (3).
#[test]
fn a_live_sources_garbage_is_unreadable_and_the_session_goes_on() {
    let sleep = |ms| std::thread::sleep(std::time::Duration::from_millis(ms));
    let long_number = "1".repeat(65_000);
    // Poses: garbage first, then good datagrams, then a long spell of garbage only, then good ones again.
    let (child, mut stderr, addr) = spawn_udp_stream(&["--udp-idle", "4"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let garbage = [
        "nan 0 0.227 0 0 0".to_string(),
        "0 inf 0.227 0 0 0".into(),
        "0 0 1e400 0 0 0".into(),
        "0 0 0.227 0 0 1e300".into(),
        format!("0 0 0.227 0 0 {long_number}"),
    ];
    for g in &garbage {
        socket.send_to(g.as_bytes(), &addr).unwrap();
    }
    let good = |k: u32| format!("0 0 {} 0 0 0", 0.227 + 0.0001 * f64::from(k % 10));
    for k in 0..20 {
        socket.send_to(good(k).as_bytes(), &addr).unwrap();
        sleep(10);
    }
    // 3 s of garbage every 10 ms: the device's stream timeout passes, the platform rests, the session goes on.
    for _ in 0..300 {
        socket.send_to(b"garbage", &addr).unwrap();
        sleep(10);
    }
    for k in 0..20 {
        socket.send_to(good(k).as_bytes(), &addr).unwrap();
        sleep(10);
    }
    let (out, report, said) = ended(child, &mut stderr);
    assert_eq!(out.status.code(), Some(3), "{said}");
    assert_eq!(report["datagrams"]["unreadable"], 305, "{said}");
    assert_eq!(report["setpoints_applied"], report["setpoints_sent"], "{said}");
    assert!(
        report["rejected"].as_object().unwrap().is_empty(),
        "nothing refused: {said}"
    );
    // The spell of garbage is a pause of the source: its last pose held, the stream alive.
    assert!(report["held_gaps"].as_u64().unwrap() >= 1, "{said}");
    assert!(report["lead_in_sent"].as_u64().unwrap() > 0);
    assert!(said.contains("datagram 1: value 1 is not a finite number"), "{said}");
    assert!(said.contains("datagram 4: value 6 is not a finite number"), "{said}");

    // Telemetry whose first time is garbage: the samples after it are cued.
    let (child, mut stderr, addr) = spawn_live_stream(&["--telemetry-udp", "127.0.0.1:0", "--udp-idle", "0.5"]);
    // The last is finite but beyond any vehicle's (a misread packet): refused as well.
    for first in [
        "nan 0 0 9.81 0 0 0",
        "1e300 0 0 9.81 0 0 0",
        "0.0 nan 0 9.81 0 0 0",
        "0.0 1e30 0 9.81 0 0 0",
    ] {
        socket.send_to(first.as_bytes(), &addr).unwrap();
    }
    for k in 0..50 {
        let t = f64::from(k) * 0.01;
        socket
            .send_to(format!("{t} 0.5 0 9.81 0 0 0").as_bytes(), &addr)
            .unwrap();
        sleep(10);
    }
    let (out, report, said) = ended(child, &mut stderr);
    assert_eq!(out.status.code(), Some(3), "{said}");
    assert_eq!(report["datagrams"]["unreadable"], 4, "{said}");
    assert!(said.contains("beyond any vehicle's"), "{said}");
    assert!(report["setpoints_applied"].as_u64().unwrap() >= 50, "{said}");
    assert!(report["rejected"].as_object().unwrap().is_empty(), "{said}");
}

/// A live session as a user has it: ringpod starts first, the game later; the game pauses (a menu) longer than
/// the stream timeout and resumes. The platform waits, leads in, holds the last pose through the pause: every
/// datagram is applied. Datagrams of any size are read whole; other senders are ignored with `--udp-from`.
#[test]
fn a_live_session_starts_late_pauses_and_resumes() {
    let (child, _stderr, addr) = spawn_udp_stream(&["--udp-idle", "0.4", "--udp-from", "127.0.0.1"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let stranger = std::net::UdpSocket::bind("127.0.0.2:0").unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let mut k = 0;
    for burst in 0..2 {
        for _ in 0..30 {
            k += 1;
            let z = 0.227 + 0.0001 * f64::from(k);
            let mut text = format!("0.001 0 {z} 0 0 {}", 0.01 * f64::from(k));
            if k == 5 {
                // Padded past the 512 bytes a datagram was once cut at.
                text += &" ".repeat(2000);
            }
            socket.send_to(text.as_bytes(), &addr).unwrap();
            // Under Wine a datagram sent from a socket bound to 127.0.0.2 arrives from 127.0.0.1: the other sender
            // is a Linux check.
            if k == 10 && cfg!(unix) {
                stranger.send_to(b"0 0 0.3 0 0 0", &addr).unwrap();
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        if burst == 0 {
            std::thread::sleep(std::time::Duration::from_millis(300));
        }
    }
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(out.status.code(), Some(0), "{report}");
    assert_eq!(report["outcome"], "followed");
    assert_eq!(report["setpoints_applied"], 60, "{report}");
    assert_eq!(report["rejected"], serde_json::json!({}));
    assert_eq!(report["datagrams"]["received"], 60);
    assert_eq!(report["datagrams"]["other_senders"], u64::from(cfg!(unix)));
    // The pause and the idle end: both held, the stream never stopped; led in once.
    assert_eq!(report["held_gaps"], 2, "{report}");
    assert_eq!(report["restarts"], 0);
    assert_eq!(report["counts_agree"], true);
    assert_at_the_last_pose(&report);
}

/// The link dies mid-stream (the board unplugged; here the simulator's process killed): the run ends with a
/// report that says so and exit code 6.
#[test]
#[cfg(unix)]
fn a_lost_link_ends_with_a_report() {
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let (server, path) = simulator_on_a_pty();
    let mut child = std::process::Command::new(&exe)
        .args([
            "stream",
            "--port",
            &path,
            "--motion",
            "demo",
            "--duration",
            "60",
            "--report-json",
            "--quiet",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    // Homing in real time takes about 9 s; then it streams.
    std::thread::sleep(std::time::Duration::from_secs(11));
    drop(server);
    let out = child.wait_with_output().unwrap();
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut stderr, &mut rest);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {rest}"));
    assert_eq!(out.status.code(), Some(6), "{report}");
    assert_eq!(report["outcome"], "transport_lost");
    assert!(report["setpoints_applied"].as_u64().unwrap() > 0, "{report}");
    assert!(rest.contains("ringpod:"), "{rest}");
}

/// Vehicle telemetry over UDP, cued live: braking then a left-hand corner, as text datagrams at 100 Hz. Every
/// sample is applied, the platform ends pitched and turned as the washout says, and bad datagrams are reported.
#[test]
fn telemetry_over_udp_is_cued_live() {
    let (child, _stderr, addr) = spawn_live_stream(&["--telemetry-udp", "127.0.0.1:0", "--fast", "--udp-idle", "0.3"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let g = 9.80665;
    for k in 0..150 {
        let t = f64::from(k) * 0.01;
        let (ax, ay, wz) = if k < 80 { (-6.0, 0.0, 0.0) } else { (0.0, 4.0, 0.4) };
        socket
            .send_to(format!("{t} {ax} {ay} {g} 0 0 {wz}").as_bytes(), &addr)
            .unwrap();
        if k == 40 {
            socket.send_to(b"not telemetry", &addr).unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(out.status.code(), Some(3), "one unreadable datagram: {report}");
    assert_eq!(report["setpoints_applied"], 150, "{report}");
    assert_eq!(report["rejected"], serde_json::json!({}));
    assert_eq!(report["datagrams"]["unreadable"], 1);
    let last = numbers(&report["last_applied_pose"]);
    // 0.7 s of the corner at 0.4 rad/s of heading; the braking's nose-down pitch not yet washed back.
    assert!((last[5] - 0.28).abs() < 1e-6, "{last:?}");
    assert!(last[4] > 0.0, "{last:?}");
    // The source stopped: the platform washed out toward neutral (the heading kept) until the session ended.
    assert!(report["washout_sent"].as_u64().unwrap() > 10, "{report}");
    assert_eq!(report["state"], "Ready");
}

/// `device jog` of an elbow chain's shoulder takes degrees, as a carriage's: 2 degrees of its 64,000 steps per turn
/// are 356 steps.
#[test]
#[cfg(unix)]
fn device_jog_turns_a_shoulder_by_degrees() {
    let (server, path) = simulator_on_a_pty_with(&["--mechanism", "trainer-elbow"]);
    let device = |words: &[&str]| {
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .arg("device")
            .args(words)
            .args(["--port", &path])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr),
        )
    };
    assert_eq!(device(&["enable"]).0, Some(0));
    std::thread::sleep(std::time::Duration::from_millis(600));
    let (code, said) = device(&["jog", "6", "2"]);
    assert!(
        code == Some(0) && said.contains("jogged 2 deg (356 steps): moved 356 steps"),
        "{said}"
    );
    drop(server);
}

/// Commissioning over the serial transport: `device jog` is refused unpowered; powered, a linear actuator jogs
/// 2 mm (3,200 steps) and comes back; a buzz ends where it began; a missing axis is a usage error.
#[test]
#[cfg(unix)]
fn device_jog_and_buzz_move_one_axis_over_a_pty() {
    let (server, path) = simulator_on_a_pty();
    let device = |words: &[&str]| {
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .arg("device")
            .args(words)
            .args(["--port", &path])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr),
        )
    };
    let (code, said) = device(&["jog", "5", "-2"]);
    assert_eq!(code, Some(1), "{said}");
    assert!(said.contains("not possible in the current state"), "{said}");
    assert_eq!(device(&["enable"]).0, Some(0));
    std::thread::sleep(std::time::Duration::from_millis(600));
    let (code, said) = device(&["jog", "5", "-2"]);
    assert_eq!(code, Some(0), "{said}");
    assert!(said.contains("jogged -2 mm (-3200 steps): moved -3200 steps"), "{said}");
    let (code, said) = device(&["jog", "5", "2"]);
    assert!(code == Some(0) && said.contains("moved 3200 steps, now at 0"), "{said}");
    let (code, said) = device(&["buzz", "1"]);
    assert!(code == Some(0) && said.contains("buzzed: moved 0 steps"), "{said}");
    let (code, said) = device(&["jog", "7", "1"]);
    assert!(code == Some(1) && said.contains("usage"), "{said}");
    let (code, said) = device(&["jog", "1", "30"]);
    assert!(
        code == Some(1) && said.contains("further than a jog goes"),
        "a carriage jogs at most its back-off: {said}"
    );
    drop(server);
}

/// The trainer model's rig file (`presets --export`) on a wider ring with longer rods: no preset describes it.
fn wider_ring() -> String {
    let exported = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    let rig = String::from_utf8(exported.stdout)
        .unwrap()
        .replace("name = \"trainer-model\"", "name = \"wider-ring\"")
        .replace("ring_radius = 0.286", "ring_radius = 0.3")
        .replace("rod_length = 0.312", "rod_length = 0.325");
    assert!(rig.contains("ring_radius = 0.3\n") && rig.contains("rod_length = 0.325\n"));
    rig
}

/// `stream --sim --geometry`: the simulated controller drives a rig no preset describes (a wider ring, longer
/// rods), homes it with the plan built for it, follows the whole stream with the counts agreeing, and ends at other
/// step positions than the trainer model does for the same motion.
#[test]
fn a_rig_of_ones_own_streams_on_the_simulator() {
    let dir = std::env::temp_dir().join(format!("ringpod-own-rig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rig = wider_ring();
    let file = dir.join("wider.toml");
    std::fs::write(&file, rig).unwrap();
    // A 4 s demo motion on the simulator, with further arguments.
    let demo = |extra: &[&str]| {
        std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["stream", "--sim", "--fast", "--quiet", "--report-json"])
            .args(["--motion", "demo", "--duration", "4"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = demo(&["--geometry", file.to_str().unwrap()]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(said.contains("a geometry of its own"), "{said}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["outcome"], "followed");
    assert_eq!(report["counts_agree"], true);
    // The trainer model's own stream of the same motion ends elsewhere: the rig's geometry was driven.
    let model = demo(&[]);
    let model: serde_json::Value = serde_json::from_slice(&model.stdout).unwrap();
    assert_ne!(report["final_steps"], model["final_steps"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The elbow trainer (ch. 5.1 fig. 5.2 arms with rotary shoulders in place of the linear actuators) homes and
/// follows a demo on the simulator, as a preset and as its exported rig file: every setpoint applied, the counts
/// agreeing, no fault (the shoulders pass their index flags at home without tripping anything), and the shoulders'
/// motors turned.
#[test]
fn the_elbow_trainer_streams_on_the_simulator() {
    let dir = std::env::temp_dir().join(format!("ringpod-elbow-rig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exported = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["presets", "--export", "trainer-elbow"])
        .output()
        .unwrap();
    assert!(exported.status.success());
    let file = dir.join("elbow.toml");
    std::fs::write(&file, exported.stdout).unwrap();
    let demo = |extra: &[&str]| {
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["stream", "--sim", "--fast", "--quiet", "--report-json"])
            .args(["--motion", "demo", "--duration", "6"])
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["outcome"], "followed", "{report}");
        assert_eq!(report["state"], "Ready");
        assert_eq!(report["setpoints_applied"], report["setpoints_sent"]);
        assert_eq!(report["counts_agree"], true);
        assert_eq!(
            report["faults"].as_array().map(Vec::len),
            Some(0),
            "{}",
            report["faults"]
        );
        report
    };
    let preset = demo(&["--mechanism", "trainer-elbow"]);
    let rig = demo(&["--geometry", file.to_str().unwrap()]);
    assert_eq!(preset["final_steps"], rig["final_steps"]);
    let model = demo(&[]);
    assert_ne!(preset["final_steps"], model["final_steps"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `cue --geometry` and `stream --check-loads --geometry` work on the rig given, not on the trainer model: the cues
/// centre on its home pose (another height) and the drive margins are those of its geometry, so both answers differ
/// from the trainer model's for the same input.
#[test]
fn cue_and_check_loads_take_the_platform_of_the_rig() {
    let dir = std::env::temp_dir().join(format!("ringpod-rig-cue-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("wider.toml");
    // A wider ring with longer rods, homed 1 cm higher: no preset describes it.
    let rig = wider_ring().replacen("0.227", "0.237", 1);
    std::fs::write(&file, &rig).unwrap();
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let run = |args: &[&str]| std::process::Command::new(&exe).args(args).output().unwrap();
    let mut drive = String::from("t,ax,ay,az,wx,wy,wz\n");
    for k in 0..200 {
        drive += &format!("{},2.0,0,9.81,0,0,0.3\n", f64::from(k) * 0.01);
    }
    let input = dir.join("drive.csv");
    std::fs::write(&input, drive).unwrap();
    let cue = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let o = run(&[
            &[
                "cue",
                "--input",
                input.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            extra,
        ]
        .concat());
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(out).unwrap()
    };
    let model = cue("model.csv", &[]);
    let own = cue("own.csv", &["--geometry", file.to_str().unwrap()]);
    let z_at_start = |csv: &str| -> f64 { csv.lines().nth(1).unwrap().split(',').nth(3).unwrap().parse().unwrap() };
    assert!((z_at_start(&model) - 0.227).abs() < 1e-9, "{model:.200}");
    assert!((z_at_start(&own) - 0.237).abs() < 1e-9, "the rig's neutral: {own:.200}");
    // The drive margins of a yaw motion on each platform (the rig file carries the model's drives).
    let loads = |extra: &[&str]| {
        let o = run(&[
            &[
                "stream",
                "--sim",
                "--fast",
                "--quiet",
                "--motion",
                "yaw",
                "--duration",
                "2",
            ][..],
            &["--check-loads", "--mass", "0.02"],
            extra,
        ]
        .concat());
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let on_model = loads(&[]);
    let on_rig = loads(&["--geometry", file.to_str().unwrap()]);
    assert!(
        on_model.contains("keeps up") && on_rig.contains("keeps up"),
        "{on_model}\n{on_rig}"
    );
    assert_ne!(on_model, on_rig, "the margins are the rig's");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A rig on the device: loaded into the simulator over its pseudo-terminal (checked there), stored in its flash,
/// running after `device restart`, and shown back as a rig file that describes the same machine to the last bit
/// (IK through the shown file equals IK through the loaded one); `simulate --geometry` starts with a rig.
#[test]
#[cfg(unix)]
fn a_rig_loaded_into_the_device_runs_after_a_restart_and_shows_back() {
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let run = |args: &[&str]| std::process::Command::new(&exe).args(args).output().unwrap();
    let dir = std::env::temp_dir().join(format!("ringpod-device-rig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let wider = wider_ring();
    // With the controller sections too: a reversed motor, other pose limits, other input wiring.
    let mut axes = String::new();
    for (steps, reverse) in [
        (25_600, false),
        (25_600, true),
        (25_600, false),
        (25_600, false),
        (1_600_000, false),
        (1_600_000, false),
    ] {
        axes += &format!("\n[[axes]]\nsteps_per_unit = {steps}\nreverse = {reverse}\n");
    }
    let wider = wider
        + &axes
        + "\n[motion]\npose_velocity = [0.04, 0.04, 0.04, 1.0, 1.0, 1.5]\npose_acceleration = [1, 1, 1, 20, 20, 20]\n"
        + "\n[inputs]\nactive_low = [\"home1\", \"home2\", \"home3\", \"home4\", \"end5\", \"end6\"]\ndebounce_ms = 4\n";
    let file = dir.join("wider.toml");
    std::fs::write(&file, wider).unwrap();
    let file = file.to_str().unwrap();
    let (server, pty) = simulator_on_a_pty();
    let port = ["--port", pty.as_str()];

    let loaded = run(&[&["device", "rig", "load", file][..], &port].concat());
    assert!(loaded.status.success(), "{}", String::from_utf8_lossy(&loaded.stderr));
    let status = run(&[&["device", "status"][..], &port].concat());
    let status: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
    assert_eq!(
        status["rig"],
        serde_json::json!({ "name": "trainer-model", "source": "compiled in", "pending": true })
    );
    let before = String::from_utf8(run(&[&["device", "rig", "show"][..], &port].concat()).stdout).unwrap();
    assert!(
        before.starts_with("# running on the device: trainer-model (compiled in)\n# another rig is stored"),
        "{before}"
    );
    let restarted = run(&[&["device", "restart"][..], &port].concat());
    assert_eq!(
        String::from_utf8_lossy(&restarted.stdout).trim(),
        "restarted: running wider-ring (stored)"
    );
    let status = run(&[&["device", "status"][..], &port].concat());
    let status: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
    assert_eq!(
        status["rig"],
        serde_json::json!({ "name": "wider-ring", "source": "stored", "pending": false })
    );
    let shown = run(&[&["device", "rig", "show"][..], &port].concat());
    let shown = String::from_utf8(shown.stdout).unwrap();
    assert!(
        shown.starts_with("# running on the device: wider-ring (stored)\n"),
        "{shown}"
    );
    assert!(
        shown.contains("reverse = true") && shown.contains("debounce_ms = 4"),
        "{shown}"
    );
    assert!(
        shown.contains("pose_velocity = [0.04, 0.04, 0.04, 1.0, 1.0, 1.5]"),
        "{shown}"
    );
    let config = run(&[&["device", "config", "get", "axes.1.reverse"][..], &port].concat());
    assert!(String::from_utf8_lossy(&config.stdout).contains("\"value\": true"));
    // Loading refuses while powered.
    assert!(run(&[&["device", "enable"][..], &port].concat()).status.success());
    let refused = run(&[&["device", "rig", "load", file][..], &port].concat());
    assert_eq!(refused.status.code(), Some(1));
    drop(server);

    let back = dir.join("shown.toml");
    std::fs::write(&back, &shown).unwrap();
    let back = back.to_str().unwrap();
    assert!(run(&["rig", "check", back])
        .status
        .code()
        .is_some_and(|c| c == 0 || c == 3));
    let pose = "--pose=0.01,-0.005,0.23,0.03,-0.02,0.4";
    let ik = |geometry: &str| run(&["ik", "--geometry", geometry, pose]).stdout;
    assert!(!ik(file).is_empty());
    assert_eq!(ik(back), ik(file), "the shown rig is the loaded one, bit for bit");

    // The simulator can also start with a rig.
    let (server, path) = simulator_on_a_pty_with(&["--geometry", file]);
    let shown = run(&["device", "rig", "show", "--port", &path]);
    drop(server);
    let shown = String::from_utf8(shown.stdout).unwrap();
    assert!(shown.contains("ring_radius = 0.3\n"), "{shown}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A record's device times and states.
#[cfg(unix)]
fn record_rows(path: &std::path::Path) -> Vec<(f64, String)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[1].parse().unwrap(), f[20].to_owned())
        })
        .collect()
}

/// Rows a second of device time, and the device time of the first `Running` row.
#[cfg(unix)]
fn rate_and_start(rows: &[(f64, String)]) -> (f64, f64) {
    let span = rows[rows.len() - 1].0 - rows[0].0;
    let start = rows.iter().find(|(_, s)| s == "Running").unwrap().0;
    ((rows.len() - 1) as f64 / span, start)
}

/// `stream --record-hz 1000`: a row every millisecond of device time (the default: every 10 ms), and chapter 5.2's
/// 18.8 Hz heave at 0.008 m/s read back from it by `plot --derivatives` over a 5 ms window at 0.008 m/s times the
/// window's stated attenuation `1 - (pi w f)^2 / 10` (0.9913), within 1 %; a 100 Hz record cannot (5 samples a
/// period). Over a board's link (the simulator on a pty) a record at 200 Hz, and the device's own rate set back
/// afterwards.
#[test]
#[cfg(unix)]
fn a_record_at_the_control_rate_reads_the_18_8_hz_experiment() {
    let dir = std::env::temp_dir().join(format!("ringpod-1khz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sine = [
        "--motion",
        "sine",
        "--axis",
        "z",
        "--frequency",
        "18.8",
        "--velocity-amplitude",
        "0.008",
    ];
    let run = |record: &std::path::Path, extra: &[&str]| {
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["stream", "--sim", "--fast", "--quiet", "--duration", "4"])
            .args(sine)
            .arg("--record")
            .arg(record)
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stderr).unwrap()
    };
    let fast = dir.join("1khz.csv");
    let said = run(&fast, &["--record-hz", "1000"]);
    assert!(said.contains(" at 1000 Hz (0 dropped)"), "{said}");
    assert!(
        said.contains("velocity 0.008000 m/s") && said.contains("(as asked"),
        "{said}"
    );
    let rows = record_rows(&fast);
    let (rate, start) = rate_and_start(&rows);
    assert!((rate - 1000.0).abs() < 0.5, "{rate} rows a second");
    // Consecutive rows one tick apart, every one.
    assert!(rows.windows(2).all(|w| ((w[1].0 - w[0].0) - 0.001).abs() < 1e-6));
    let slow = dir.join("100hz.csv");
    run(&slow, &[]);
    let (rate, _) = rate_and_start(&record_rows(&slow));
    assert!((rate - 100.0).abs() < 0.5, "{rate} rows a second by default");
    // The full amplitude: 1 s after the ease-in, 1 s before the ease-out. A row every tick shows the seat (the
    // counted steps' pose) following the sine: 68 um of amplitude, which a carriage step moves by about 40 um in
    // heave, so the seat's heave is the sine to within a carriage step at every tick, and spans the sine's range to
    // within one. (Its 5 ms derivatives are the steps', not the sine's: `plot --derivatives` reads the seat.)
    let text = std::fs::read_to_string(&fast).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (t, z, cmd_z) = (col("device_s"), col("z"), col("cmd_z"));
    let window: Vec<(f64, f64)> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| {
            let at: f64 = f[t].parse().unwrap();
            at >= start + 1.2 && at <= start + 2.8
        })
        .map(|f| (f[z].parse().unwrap(), f[cmd_z].parse().unwrap()))
        .collect();
    assert!(window.len() > 1_500, "{} rows in the window", window.len());
    let worst = window.iter().map(|(z, c)| (z - c).abs()).fold(0.0, f64::max);
    assert!(worst < 60e-6, "the seat is {worst} m from the sine at a tick");
    let span = |v: &mut dyn Iterator<Item = f64>| {
        let v: Vec<f64> = v.collect();
        v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
    };
    let (seat, asked) = (
        span(&mut window.iter().map(|w| w.0)),
        span(&mut window.iter().map(|w| w.1)),
    );
    assert!(
        (seat - asked).abs() < 40e-6,
        "the seat spans {seat} m, the sine {asked} m"
    );
    assert!(
        (asked / (2.0 * 0.008 / (std::f64::consts::TAU * 18.8)) - 1.0).abs() < 0.01,
        "{asked}"
    );

    // On a board's link: the rate is the device's setting, set for the run and back after it.
    let (_simulator, path) = simulator_on_a_pty();
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let on_port = dir.join("port.csv");
    let out = std::process::Command::new(&exe)
        .args([
            "stream",
            "--port",
            &path,
            "--quiet",
            "--motion",
            "heave",
            "--duration",
            "0.3",
        ])
        .arg("--record")
        .arg(&on_port)
        .args(["--record-hz", "200"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (rate, _) = rate_and_start(&record_rows(&on_port));
    assert!((rate - 200.0).abs() < 0.5, "{rate} rows a second");
    let config = std::process::Command::new(&exe)
        .args(["device", "config", "get", "stream.telemetry_hz", "--port", &path])
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&config.stdout).contains("\"value\": 100"),
        "{}",
        String::from_utf8_lossy(&config.stdout)
    );
    // Without --record it is refused; beyond 2000 Hz too.
    for extra in [
        &["--record-hz", "1000"][..],
        &["--record", "x.csv", "--record-hz", "5000"],
    ] {
        let out = std::process::Command::new(&exe)
            .args(["stream", "--sim", "--fast", "--quiet", "--motion", "heave"])
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
    }
}
