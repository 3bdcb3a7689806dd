//! Inputs from outside that must not hold a command or its memory: a flood of the largest unreadable datagrams,
//! a FIFO where a file is read (as `--input`, and as a watched `--cue-config` replaced while streaming).

use std::time::Duration;
#[cfg(unix)]
use std::time::Instant;

/// A directory of this run's own (the FIFO tests: Unix only).
#[cfg(unix)]
fn dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("ringpod-inputs-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// 1,500 datagrams of 65,507 bytes (the largest UDP payload over IPv4), none readable: every one is counted, by
/// kind, and the report and stderr keep the first few of each kind, cut to a line.
#[test]
fn a_flood_of_the_largest_unreadable_datagrams_keeps_bounded_memory() {
    use std::io::Read;
    let (child, mut stderr, addr) = crate::common::spawn_live_stream(&[
        "--fast",
        "--telemetry-udp",
        "127.0.0.1:0",
        "--telemetry-format",
        "text",
        "--udp-idle",
        "3",
    ]);
    let game = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let words = "x".repeat(65_507);
    let numbers = format!("1 2 3 {}", "4".repeat(65_500));
    for k in 0..1_500 {
        let payload = if k % 2 == 0 {
            words.as_bytes()
        } else {
            numbers.as_bytes()
        };
        game.send_to(payload, &addr).unwrap();
        if k % 20 == 0 {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    let mut err = String::new();
    stderr.read_to_string(&mut err).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.stdout.len() < 64 << 10, "report of {} bytes", out.stdout.len());
    assert!(err.len() < 64 << 10, "stderr of {} bytes", err.len());
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &report["datagrams"];
    let unreadable = d["unreadable"].as_u64().unwrap();
    assert!(unreadable > 100, "{d}");
    let by_kind: u64 = d["unreadable_by_kind"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(by_kind, unreadable, "{d}");
    let kept = report["input_errors"].as_array().unwrap();
    assert!(kept.len() <= 10, "{}", kept.len());
    assert!(
        kept.iter().all(|e| e["reason"].as_str().unwrap().len() <= 130),
        "{kept:?}"
    );
    assert!(err.contains("unreadable datagrams:"), "{err}");
    assert_eq!(out.status.code(), Some(3));
}

/// Runs `ringpod ARGS` and waits at most `within`, killing it after.
#[cfg(unix)]
fn within(args: &[&str], within: Duration) -> Option<std::process::Output> {
    let child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = nix::unistd::Pid::from_raw(child.id() as i32);
    let started = Instant::now();
    let waiter = std::thread::spawn(move || child.wait_with_output().unwrap());
    while !waiter.is_finished() {
        if started.elapsed() > within {
            let _ = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGKILL);
            let _ = waiter.join();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(waiter.join().unwrap())
}

/// A FIFO with no writer as `stream --input` or `cue --input`: refused at once, named, not waited on.
#[cfg(unix)]
#[test]
fn a_fifo_as_an_input_file_is_refused_at_once() {
    let fifo = dir("fifo").join("poses.csv");
    let _ = std::fs::remove_file(&fifo);
    nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
    let path = fifo.display().to_string();
    let out = dir("fifo").join("out.csv").display().to_string();
    for args in [
        vec!["stream", "--sim", "--fast", "--quiet", "--input", &path],
        vec!["cue", "--input", &path, "--out", &out],
        vec!["dynamics", "--file", &path],
    ] {
        let o = within(&args, Duration::from_secs(20)).unwrap_or_else(|| panic!("{args:?} waited on the FIFO"));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}");
        assert!(stderr.contains("FIFO") && stderr.contains(&path), "{stderr}");
    }
}

/// A watched `--cue-config` replaced by a FIFO while streaming: the change is not read (the running cueing stays),
/// the datagrams keep being cued, and SIGINT ends the stream.
#[cfg(unix)]
#[test]
fn a_cueing_file_replaced_by_a_fifo_does_not_stop_the_stream() {
    use std::io::Read;
    let d = dir("cue-fifo");
    let config = d.join("cue.toml");
    std::fs::write(&config, "").unwrap();
    let config_arg = config.display().to_string();
    let (child, mut stderr, addr) = crate::common::spawn_live_stream(&[
        "--telemetry-udp",
        "127.0.0.1:0",
        "--cue-config",
        &config_arg,
        "--udp-idle",
        "30",
    ]);
    let game = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let send = |from: u32, to: u32| {
        for k in from..to {
            let line = format!("{} 0 0 9.81 0 0 0", f64::from(k) / 100.0);
            game.send_to(line.as_bytes(), &addr).unwrap();
            std::thread::sleep(Duration::from_millis(10));
        }
    };
    send(0, 100);
    std::fs::remove_file(&config).unwrap();
    nix::unistd::mkfifo(&config, nix::sys::stat::Mode::S_IRWXU).unwrap();
    send(100, 250);
    let pid = nix::unistd::Pid::from_raw(child.id() as i32);
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGINT).unwrap();
    let started = Instant::now();
    let mut err = String::new();
    stderr.read_to_string(&mut err).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "SIGINT took {:?}",
        started.elapsed()
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["outcome"], "interrupted", "{report}");
    // Not read (a FIFO is no cueing file): ignored until the file is whole again, the running cueing kept.
    let d = &report["datagrams"];
    assert!(
        d["cue_refused"].as_u64().unwrap() + d["cue_ignored"].as_u64().unwrap() >= 1,
        "{report}"
    );
    assert_eq!(d["cue_reloads"], 0, "{report}");
    assert_eq!(report["datagrams"]["received"], 250, "{report}");
    assert!(err.contains("FIFO"), "{err}");
}
