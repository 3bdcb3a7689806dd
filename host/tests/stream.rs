//! `ringpod stream` against the simulated controller: the same core as the firmware behind the real framed bytes.

use assert_cmd::Command;
use ringpod_core::kinematics::{presets, Mechanism, MultiTurn, Pose, RingPlatform};
use ringpod_core::motion::{AxisScale, StepConverter};

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
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let c = AxisScale::MODEL_CARRIAGE;
    let l = AxisScale::MODEL_LINEAR;
    let mut conv = StepConverter::new([c, c, c, c, l, l], m.axes());
    let home = MultiTurn::new(
        m.inverse(&Pose::from_array(presets::Preset::TrainerModel.home()).cast())
            .unwrap(),
    );
    for a in 0..6 {
        conv.set_home(a, &home, 0);
    }
    let mut q = home;
    q.inverse_near(&m, &Pose::from_array(pose).cast()).unwrap();
    conv.to_steps(&q)
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
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
    assert_eq!(lines, [4, 5, 8], "malformed number, short line, time not increasing");
    assert!(
        stderr.contains("line 6: rejected by the device: non_finite"),
        "{stderr}"
    );
    assert!(stderr.contains("line 7: rejected by the device: too_fast"), "{stderr}");
    assert_eq!(report["rejected"]["non_finite"], 1);
    assert_eq!(report["rejected"]["too_fast"], 1);
    let sent = report["setpoints_sent"].as_u64().unwrap();
    let applied = report["setpoints_applied"].as_u64().unwrap();
    let rejected: u64 = report["rejected"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(sent, applied + rejected);
    assert_eq!(report["counts_agree"], true);
    assert_eq!(report["state"], "Ready");
}

#[test]
fn a_gap_in_the_stream_ends_at_rest() {
    // 0.3 s without setpoints: the device brakes to rest, then refuses the rest until started again.
    let csv = "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.01,0,0,0.2271,0,0,0\n0.4,0,0,0.2272,0,0,0\n0.41,0,0,0.2273,0,0,0\n";
    let (report, _) = stream(&[], Some(csv));
    assert_eq!(report["rejected"]["not_streaming"], 2);
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
}

#[test]
fn motions_stay_inside_the_limits() {
    for motion in ["demo", "heave", "yaw", "vibration"] {
        let (report, out) = stream(&["--motion", motion, "--duration", "3", "--rate", "500"], None);
        assert!(
            out.status.success(),
            "{motion}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(report["rejected"], serde_json::json!({}), "{motion}");
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
fn stream_through_a_pseudo_terminal() {
    use std::io::BufRead;
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let mut server = std::process::Command::new(&exe)
        .args(["simulate", "--pty"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut path = String::new();
    std::io::BufReader::new(server.stdout.take().unwrap())
        .read_line(&mut path)
        .unwrap();
    let path = path.trim().to_owned();
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
    let _ = server.kill();
    let _ = server.wait();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["state"], "Ready");
    assert_eq!(report["counts_agree"], true);
    let last: Vec<f64> = numbers(&report["last_applied_pose"]);
    let want = steps_at(last.try_into().unwrap());
    for (g, w) in numbers(&report["final_steps"]).iter().zip(want) {
        assert!(
            (*g as i64 - w).abs() <= 1,
            "final steps vs IK of the last pose: {g} {w}"
        );
    }
}

/// Starts `ringpod stream --udp 127.0.0.1:0 ARGS` and waits until it announces the address to send to.
fn spawn_udp_stream(
    args: &[&str],
) -> (
    std::process::Child,
    std::io::BufReader<std::process::ChildStderr>,
    String,
) {
    use std::io::BufRead;
    let exe = assert_cmd::cargo::cargo_bin("ringpod");
    let mut child = std::process::Command::new(&exe)
        .args(["stream", "--sim", "--udp", "127.0.0.1:0", "--report-json", "--quiet"])
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    while !line.contains("send datagrams to") {
        line.clear();
        assert!(
            stderr.read_line(&mut line).unwrap() > 0,
            "the stream announces its address"
        );
    }
    let addr = line.trim().rsplit(' ').next().unwrap().to_owned();
    (child, stderr, addr)
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

/// Ctrl-C (SIGINT) in the middle of a stream ends it with a stop and a wait for rest, and still reports.
#[test]
fn ctrl_c_stops_and_reports() {
    // UDP source: the stream is then certainly running (it announces itself) when the signal comes.
    let (child, mut stderr, addr) = spawn_udp_stream(&["--udp-idle", "60"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    for k in 0..20 {
        socket
            .send_to(format!("0 0 {} 0 0 0", 0.227 + 0.0001 * f64::from(k)).as_bytes(), &addr)
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .unwrap();
    let out = child.wait_with_output().unwrap();
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut stderr, &mut rest);
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}; status {:?}; stderr: {rest}", out.status));
    assert_eq!(report["state"], "Ready", "stopped and at rest");
    assert!(report["setpoints_applied"].as_u64().unwrap() >= 1);
    assert_eq!(report["counts_agree"], true);
}
