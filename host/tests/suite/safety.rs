//! `ringpod stream` never moves the platform wrongly and never loses data: the input checked before anything
//! moves, garbage refused by one rule, gaps that keep the stream alive, outputs that fail without a panic and
//! files written whole.

use std::io::{BufRead, Read};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::spawn_live_stream;

fn bin() -> std::path::PathBuf {
    assert_cmd::cargo::cargo_bin("ringpod")
}

/// A folder of this test's own.
fn folder(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("ringpod-safety-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `stream --sim --fast --report-json --quiet ARGS`: the exit code, the report and stderr.
fn stream(args: &[&str]) -> (i32, serde_json::Value, String) {
    let out = Command::new(bin())
        .args(["stream", "--sim", "--fast", "--report-json", "--quiet"])
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let report = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {stderr}"));
    (out.status.code().unwrap_or(-1), report, stderr)
}

/// 200 rows at 100 Hz, a heave around the trainer model's home, with row `k` (0-based) replaced where given.
fn poses(replace: &[(usize, &str)]) -> String {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..200 {
        let t = k as f64 * 0.01;
        match replace.iter().find(|(at, _)| *at == k) {
            Some((_, row)) => csv += &format!("{t:.2},{row}\n"),
            None => csv += &format!("{t:.2},0,0,{:.5},0,0,0\n", 0.227 + 0.003 * (t * 3.0).sin()),
        }
    }
    csv
}

#[test]
fn an_input_without_a_pose_moves_nothing() {
    let dir = folder("empty");
    let empty = dir.join("empty.csv");
    std::fs::write(&empty, "t,x,y,z,alpha,beta,gamma\n").unwrap();
    let garbage = dir.join("garbage.csv");
    std::fs::write(
        &garbage,
        "t,x,y,z,alpha,beta,gamma\n0,nan,0,0.227,0,0,0\n1,0,0,inf,0,0,0\n",
    )
    .unwrap();
    for file in [&empty, &garbage] {
        let (code, report, stderr) = stream(&["--input", file.to_str().unwrap()]);
        assert_eq!(code, 3, "{stderr}");
        assert!(
            report["reason"].as_str().unwrap().starts_with("no pose in the input"),
            "{report}"
        );
        // The simulated controller starts Off: nothing powered up, homed or led in.
        assert_eq!(report["state"], "Off", "{report}");
        assert_eq!(report["lead_in_sent"], 0);
        assert_eq!(report["final_steps"], serde_json::json!([0, 0, 0, 0, 0, 0]));
    }
}

#[test]
fn a_stream_without_a_source_is_a_usage_error_naming_the_choices() {
    for args in [&["stream", "--sim", "--fast"][..], &["stream", "--port", "/dev/null"]] {
        let out = Command::new(bin()).args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        for choice in ["--input", "--motion", "--udp", "--telemetry-udp"] {
            assert!(stderr.contains(choice), "{args:?}: {stderr}");
        }
    }
    let help = Command::new(bin()).args(["stream", "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("there is no default"), "{help}");
}

#[test]
fn a_bad_first_row_is_refused_by_name_and_the_rest_followed() {
    let dir = folder("first");
    for (row, words) in [
        ("1000,0,0.227,0,0,0", "x = 1000 m is beyond"),
        ("1,0,0.227,0,0,0", "outside the envelope in x"),
        ("0,0,0.4,0,0,0", "outside the envelope in z"),
        ("inf,0,0.227,0,0,0", "x = inf is not a finite number"),
        ("nan,0,0.227,0,0,0", "x = NaN is not a finite number"),
    ] {
        let file = dir.join("first.csv");
        std::fs::write(&file, poses(&[(0, row)])).unwrap();
        for mode in [&[][..], &["--device-limits-only"]] {
            let started = Instant::now();
            let (code, report, stderr) = stream(&[&["--input", file.to_str().unwrap()][..], mode].concat());
            assert_eq!(code, 3, "{row} {mode:?}: {stderr}");
            assert_eq!(report["input_errors"][0]["line"], 2, "{row}: {report}");
            let reason = report["input_errors"][0]["reason"].as_str().unwrap();
            assert!(reason.contains(words), "{row}: {reason}");
            assert!(stderr.contains("line 2:"), "{row}: said on stderr: {stderr}");
            assert_eq!(
                report["setpoints_applied"], 199,
                "{row} {mode:?}: every other row followed: {report}"
            );
            assert_eq!(report["rejected"], serde_json::json!({}), "{row} {mode:?}");
            // The lead-in is bounded by the envelope: from home, a few hundred setpoints at most.
            assert!(
                report["lead_in_sent"].as_u64().unwrap() < 500,
                "{row} {mode:?}: {report}"
            );
            assert!(started.elapsed() < Duration::from_secs(30), "{row} {mode:?}");
        }
    }
}

#[test]
fn garbage_anywhere_in_a_file_is_refused_by_the_rule_of_every_source() {
    let dir = folder("garbage");
    for (row, words) in [
        ("1e308,0,0.227,0,0,0", "x = 1e308 is not a finite number"),
        ("0,-1e39,0.227,0,0,0", "y = -1e39 is not a finite number"),
        ("0,0,0.227,0,0,1e6", "gamma = 1e6 rad is beyond 10000 rad"),
        ("0,0,0.227,7,0,0", "alpha = 7 rad is beyond"),
        ("0,0,-500,0,0,0", "z = -500 m is beyond"),
    ] {
        let file = dir.join("mid.csv");
        std::fs::write(&file, poses(&[(100, row)])).unwrap();
        let (code, report, stderr) = stream(&["--input", file.to_str().unwrap()]);
        assert_eq!(code, 3, "{row}: {stderr}");
        assert_eq!(report["input_errors"][0]["line"], 102, "{row}: {report}");
        assert!(
            report["input_errors"][0]["reason"].as_str().unwrap().contains(words),
            "{report}"
        );
        assert_eq!(report["setpoints_applied"], 199, "{row}: {report}");
        assert_eq!(
            report["limited"]["largest_mm"].as_f64().unwrap(),
            0.0,
            "{row}: nothing taken as a pose"
        );
    }
    // The same numbers over UDP are refused the same way, and counted.
    let (child, _stderr, addr) = spawn_live_stream(&["--udp", "127.0.0.1:0", "--udp-idle", "0.5", "--fast"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    for text in [
        "0 0 0.227 0 0 0",
        "0 0 -500 0 0 0",
        "0 0 0.227 0 0 1e6",
        "0 0 0.228 0 0 0",
    ] {
        socket.send_to(text.as_bytes(), &addr).unwrap();
        std::thread::sleep(Duration::from_millis(30));
    }
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["datagrams"]["unreadable"], 2, "{report}");
    assert_eq!(report["setpoints_applied"], 2, "{report}");
    assert_eq!(out.status.code(), Some(3), "{report}");
}

/// The record's state column from the first `Running` row to the last: the stream never stopped in between.
fn stayed_running(record: &std::path::Path) -> bool {
    let text = std::fs::read_to_string(record).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let state = header.iter().position(|h| *h == "state").unwrap();
    let states: Vec<String> = lines.map(|l| l.split(',').nth(state).unwrap().to_owned()).collect();
    let first = states.iter().position(|s| s == "Running").unwrap();
    let last = states.iter().rposition(|s| s == "Running").unwrap();
    states[first..=last].iter().all(|s| s == "Running")
}

#[test]
fn a_gap_between_rows_is_interpolated_and_the_outputs_stay() {
    let dir = folder("gaps");
    // The README's auxiliary-output example: AUX1 on for a second, rows half a second apart.
    let cut = dir.join("cut.csv");
    std::fs::write(
        &cut,
        "t,x,y,z,alpha,beta,gamma,aux1,aux2\n0.00,0,0,0.227,0,0,0,0,0\n0.50,0,0,0.230,0,0,0,1,0\n\
         1.50,0,0,0.227,0,0,0,0,1\n",
    )
    .unwrap();
    let record = dir.join("cut-run.csv");
    let (code, report, stderr) = stream(&["--input", cut.to_str().unwrap(), "--record", record.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(report["restarts"], 0, "{report}");
    assert_eq!(report["counts_agree"], true);
    assert!(stayed_running(&record));
    let text = std::fs::read_to_string(&record).unwrap();
    let aux1: Vec<f64> = text
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(28) == Some("1"))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let on = aux1.last().unwrap() - aux1.first().unwrap();
    assert!((0.95..1.05).contains(&on), "AUX1 on for {on} s, the file says 1 s");
    // Gaps of 0.2, 1 and 5 s in a pose file: led in once, interpolated every 10 ms, never stopped.
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    let mut t = 0.0;
    for gap in [0.2, 1.0, 5.0, 0.01] {
        for _ in 0..10 {
            csv += &format!("{t:.3},0,0,{:.5},0,0,0\n", 0.227 + 0.002 * (t * 2.0f64).sin());
            t += 0.01;
        }
        t += gap;
    }
    let file = dir.join("gaps.csv");
    std::fs::write(&file, csv).unwrap();
    let record = dir.join("gaps-run.csv");
    let (code, report, stderr) = stream(&["--input", file.to_str().unwrap(), "--record", record.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(report["setpoints_applied"], 40, "{report}");
    // 0.21 s from row to row: 21 intervals of 10 ms, 20 setpoints between; 1.01 s: 100; 5.01 s: 500 (within the
    // rounding of the rows' times).
    let between = report["interpolated_sent"].as_u64().unwrap();
    assert!((617..=623).contains(&between), "{report}");
    assert_eq!(report["counts_agree"], true);
    assert!(stayed_running(&record));
}

#[test]
fn a_live_source_that_pauses_is_held() {
    let (child, _stderr, addr) = spawn_live_stream(&["--udp", "127.0.0.1:0", "--udp-idle", "6"]);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let send = |n: usize| {
        for k in 0..n {
            let z = 0.227 + 0.001 * (k as f64 * 0.1).sin();
            socket.send_to(format!("0 0 {z} 0 0 0").as_bytes(), &addr).unwrap();
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    send(10);
    for gap in [0.2, 1.0, 5.0] {
        std::thread::sleep(Duration::from_secs_f64(gap));
        send(10);
    }
    // Ended by --udp-idle (6 s), which is a pause too.
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(out.status.code(), Some(0), "{report}");
    assert_eq!(report["setpoints_applied"], 40, "{report}");
    assert_eq!(report["held_gaps"], 4, "three pauses and the idle end: {report}");
    let held = report["held_s"].as_f64().unwrap();
    // Each pause held from half the stream timeout (50 ms) on: 0.15 + 0.95 + 4.95 + 5.95 s, within the
    // machine's scheduling.
    assert!((11.0..12.6).contains(&held), "held {held} s: {report}");
    assert!(report["lead_in_sent"].as_u64().unwrap() > 0);
    assert_eq!(report["counts_agree"], true, "{report}");
    assert_eq!(report["rejected"], serde_json::json!({}), "{report}");
}

/// Reads the first line of a child's stderr, then closes it, as `2>&1 | head -1` does.
fn close_stderr_after_a_line(child: &mut std::process::Child) -> String {
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    line
}

#[test]
fn a_closed_stderr_ends_the_run_as_a_stop_does() {
    // A live source: the first line is the address; a datagram that cannot be read says so mid-motion.
    let (child, stderr, addr) = spawn_live_stream(&["--udp", "127.0.0.1:0", "--udp-idle", "1"]);
    drop(stderr);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    for _ in 0..20 {
        socket.send_to(b"0 0 0.23 0 0 0", &addr).unwrap();
        std::thread::sleep(Duration::from_millis(10));
    }
    socket.send_to(b"not a pose", &addr).unwrap();
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(out.status.code(), Some(141), "{report}");
    assert_eq!(report["outcome"], "output_failed", "{report}");
    assert_eq!(report["exit_code"], 141);
    assert_eq!(report["state"], "Ready", "brought to rest: {report}");
    assert_eq!(report["counts_agree"], true, "{report}");
    // A file whose rows the device refuses (a yaw jump every 50 rows), in real time: the refusals are said on
    // stderr while the platform moves.
    let dir = folder("pipe");
    let jumps: Vec<(usize, &str)> = (1..4).map(|k| (k * 50, "0,0,0.227,0,0,1.2")).collect();
    let file = dir.join("jumps.csv");
    std::fs::write(&file, poses(&jumps)).unwrap();
    let mut child = Command::new(bin())
        .args([
            "stream",
            "--sim",
            "--quiet",
            "--report-json",
            "--input",
            file.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = close_stderr_after_a_line(&mut child);
    assert!(first.contains("line 52: refused by the device"), "{first}");
    let mut stdout = String::new();
    child.stdout.take().unwrap().read_to_string(&mut stdout).unwrap();
    let status = child.wait().unwrap();
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(status.code(), Some(141), "{report}");
    assert_eq!(report["exit_code"], 141);
    assert_eq!(report["state"], "Ready", "{report}");
    assert!(
        report["setpoints_sent"].as_u64().unwrap() < 150,
        "ended at the write that failed: {report}"
    );
}

/// Runs `ringpod ARGS` with standard output on /dev/full.
fn to_dev_full(args: &[&str]) -> (Option<i32>, String) {
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let out = Command::new(bin()).args(args).stdout(full).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn output_that_cannot_be_written_is_a_failure_named() {
    for args in [
        &["presets", "--export", "trainer-model"][..],
        &["device", "rig", "show", "--sim"],
        &["ik", "--json", "--pose", "0,0,0.227,0,0,0"],
        &["presets"],
        &[
            "stream",
            "--sim",
            "--fast",
            "--motion",
            "heave",
            "--duration",
            "0.3",
            "--quiet",
            "--report-json",
        ],
    ] {
        let (code, stderr) = to_dev_full(args);
        assert_eq!(code, Some(141), "{args:?}: {stderr}");
        // The system's words for a full disk (Wine maps /dev/full to Windows' ERROR_DISK_FULL).
        let full = if cfg!(windows) {
            "standard output: Disk full"
        } else {
            "standard output: No space left on device"
        };
        assert!(stderr.contains(full), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// Runs `ringpod ARGS` allowed to write files of at most 1 KiB (`ulimit -f 2`, the signal for a larger file
/// ignored so that the write fails with EFBIG): a disk that fills up after the first kilobyte.
#[cfg(unix)]
fn with_small_files(dir: &std::path::Path, args: &str) -> (Option<i32>, String) {
    let out = Command::new("sh")
        .current_dir(dir)
        .arg("-c")
        .arg(format!("trap '' XFSZ; ulimit -f 2; exec {} {args}", bin().display()))
        .output()
        .unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
#[cfg(unix)]
fn files_are_written_whole_or_not_at_all() {
    let dir = folder("whole");
    for picture in ["x.svg", "x.png"] {
        std::fs::write(dir.join(picture), "before").unwrap();
        let (code, stderr) = with_small_files(&dir, &format!("draw --out {picture}"));
        assert_eq!(code, Some(1), "{picture}: {stderr}");
        assert!(stderr.contains("File too large"), "{picture}: {stderr}");
        assert_eq!(
            std::fs::read_to_string(dir.join(picture)).unwrap(),
            "before",
            "{picture}"
        );
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 2, "no temporary file left behind: {leftovers:?}");
    // A record that cannot be written: exit 7, and the report's exit code says the same.
    let out = Command::new("sh")
        .current_dir(&dir)
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 2; exec {} stream --sim --fast --quiet --report-json --motion heave \
             --duration 1 --record run.csv",
            bin().display()
        ))
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(out.status.code(), Some(7), "{report}");
    assert_eq!(report["exit_code"], 7, "{report}");
    assert_eq!(report["record"]["rows"], 0, "nothing put under its name: {report}");
    assert!(!dir.join("run.csv").exists());
    // A stream that never starts leaves an existing record as it was.
    std::fs::write(dir.join("keep.csv"), "precious").unwrap();
    std::fs::write(dir.join("empty.csv"), "t,x,y,z,alpha,beta,gamma\n").unwrap();
    let (code, _, _) = stream(&[
        "--input",
        dir.join("empty.csv").to_str().unwrap(),
        "--record",
        dir.join("keep.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 3);
    assert_eq!(std::fs::read_to_string(dir.join("keep.csv")).unwrap(), "precious");
}

#[test]
fn an_output_that_is_an_input_is_refused_before_anything_runs() {
    let dir = folder("same");
    let poses_csv = dir.join("p.csv");
    let text = poses(&[]);
    std::fs::write(&poses_csv, &text).unwrap();
    let spelled = dir.join(".").join("p.csv");
    let out = Command::new(bin())
        .args(["stream", "--sim", "--fast", "--quiet", "--input"])
        .arg(&poses_csv)
        .arg("--record")
        .arg(&spelled)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is also an input"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&poses_csv).unwrap(), text);
    let telemetry = dir.join("t.csv");
    let drive = "t,ax,ay,az,wx,wy,wz\n0,0,0,9.81,0,0,0\n0.01,0,0,9.81,0,0,0\n";
    std::fs::write(&telemetry, drive).unwrap();
    let out = Command::new(bin())
        .args(["cue", "--input"])
        .arg(&telemetry)
        .arg("--out")
        .arg(&telemetry)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&telemetry).unwrap(), drive);
}

/// A file of which every fifth row the device refuses (a yaw jump): the first refusals are said each on a line, the
/// rest counted in a line or two, and every one is in the report; the counts said add up to the report's.
#[test]
fn many_refusals_are_said_in_a_few_lines_and_all_reported() {
    let jumps: Vec<(usize, &str)> = (1..40).map(|k| (k * 5, "0,0,0.227,0,0,1.2")).collect();
    let file = folder("flood").join("jumps.csv");
    std::fs::write(&file, poses(&jumps)).unwrap();
    let (code, report, stderr) = stream(&["--input", file.to_str().unwrap()]);
    assert_ne!(code, 0, "{report}");
    let refusals = report["refusals"].as_array().unwrap().len();
    assert!(refusals >= 30, "{report}");
    let lines = stderr
        .lines()
        .filter(|l| l.contains(": refused by the device:"))
        .count();
    assert_eq!(lines, 10, "{stderr}");
    let counted: usize = stderr
        .lines()
        .filter(|l| l.contains("more setpoints refused by the device"))
        .map(|l| l.split_whitespace().next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(lines + counted, refusals, "{stderr}");
    assert!(stderr.lines().count() < 20, "{stderr}");
}
