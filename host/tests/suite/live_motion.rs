//! A live source's motion on the simulated platform: the pose the platform followed (from its counted steps, in the
//! run record) against the pose sent, over the whole session. Counting setpoints is not enough here: a platform that
//! stands still while every setpoint counts as applied must fail.

use std::time::{Duration, Instant};

use crate::common::spawn_live_stream;

/// A record's rows: device time, the commanded pose and the followed pose (the columns `cmd_*` and the pose).
fn rows(path: &std::path::Path) -> Vec<(f64, [f64; 6], [f64; 6], String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, cmd, pose, state) = (at("device_s"), at("cmd_x"), at("x"), at("state"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let six = |from: usize| std::array::from_fn(|i| f[from + i].parse::<f64>().unwrap());
            (f[t].parse().unwrap(), six(cmd), six(pose), f[state].to_owned())
        })
        .collect()
}

/// Sends `alpha(t)` as pose datagrams at 100 Hz for `seconds` to a `stream --udp` session, then lets it end.
fn roll_session(extra: &[&str], seconds: f64, alpha: impl Fn(f64) -> f64) -> Vec<(f64, [f64; 6], [f64; 6], String)> {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("live.csv");
    let record_arg = record.display().to_string();
    let args = [
        &["--udp", "127.0.0.1:0", "--udp-idle", "0.5", "--record", &record_arg][..],
        extra,
    ]
    .concat();
    let (child, _stderr, addr) = spawn_live_stream(&args);
    send_at_100_hz(&addr, seconds, |t| format!("0 0 0.227 {} 0 0", alpha(t)));
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    rows(&record)
}

/// The followed roll over the Running rows: its range, and the largest distance from the commanded roll of any row
/// within `lag` seconds before it (the trackers follow a setpoint over the next interval or two).
fn followed(rows: &[(f64, [f64; 6], [f64; 6], String)], lag: f64) -> (f64, f64) {
    let running: Vec<_> = rows.iter().filter(|r| r.3 == "Running").collect();
    assert!(running.len() > 300, "{} Running rows", running.len());
    let (lo, hi) = running
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), r| (lo.min(r.2[3]), hi.max(r.2[3])));
    let worst = running
        .iter()
        .map(|r| {
            running
                .iter()
                .filter(|c| c.0 <= r.0 && c.0 >= r.0 - lag)
                .map(|c| (c.1[3] - r.2[3]).abs())
                .fold(f64::MAX, f64::min)
        })
        .fold(0.0f64, f64::max);
    (hi - lo, worst)
}

fn sine(t: f64) -> f64 {
    0.05 * (2.0 * std::f64::consts::PI * 0.5 * t).sin()
}

/// A 0.05 rad roll sine at 100 datagrams/s for 6 s into a session with `extra` options: the platform rolls through
/// the whole sine (0.1 rad from side to side), within 5 mrad of a pose commanded in the 60 ms before, every row.
fn rolls_through_the_sine(extra: &[&str]) {
    let rows = roll_session(extra, 6.0, sine);
    let (range, worst) = followed(&rows, 0.06);
    assert!(
        range > 0.095,
        "the followed roll spans {range} rad of the 0.1 commanded"
    );
    assert!(
        worst < 0.005,
        "the followed roll is {worst} rad from what was commanded"
    );
}

/// The simulator in real time.
#[test]
fn a_live_session_moves_the_simulated_platform_in_real_time() {
    rolls_through_the_sine(&[]);
}

/// The simulator computing as fast as it can until the source is live (`--fast`).
#[test]
fn a_live_session_moves_the_simulated_platform_when_fast() {
    rolls_through_the_sine(&["--fast"]);
}

/// A free UDP port on loopback (bound and released: the stream binds it next).
fn free_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// A game that sends text telemetry at 100 Hz to `addr` from now for `seconds`: braking and accelerating at 6 m/s^2
/// in turn every 2 s, a sine of lateral force and of yaw rate (its own clock in the first column).
fn game(addr: String, seconds: f64) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        send_at_100_hz(&addr, seconds, |t| {
            let ax = if ((t / 2.0) as u32).is_multiple_of(2) {
                6.0
            } else {
                -6.0
            };
            format!("{t} {ax} {} 9.81 0 0 {}", 3.0 * t.sin(), 0.3 * t.sin())
        })
    })
}

/// Sends `datagram(t)` to `addr` 100 times a second for `seconds`, on the wall clock as a game sends: a late
/// datagram is not followed by a burst.
fn send_at_100_hz(addr: &str, seconds: f64, datagram: impl Fn(f64) -> String) {
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let start = Instant::now();
    let mut k = 0u32;
    loop {
        let t = start.elapsed().as_secs_f64();
        if t > seconds {
            return;
        }
        // A port nobody listens on yet (the game started first) refuses on some systems: sent all the same.
        let _ = socket.send_to(datagram(t).as_bytes(), addr);
        k += 1;
        let next = start + Duration::from_secs_f64(f64::from(k) * 0.01);
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
}

/// The game started first: it sends while the platform powers up and homes (about 9 s in real time). What it sent
/// meanwhile is dropped and counted, the cueing starts at neutral on the first sample after, and the session runs
/// without a refused setpoint: no row's commanded pose steps further than the limits allow in its 10 ms, and the
/// platform follows the braking and the accelerating.
#[test]
fn a_game_started_before_the_platform_homed_is_followed_from_neutral() {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("game-first.csv");
    let addr = format!("127.0.0.1:{}", free_port());
    let sender = game(addr.clone(), 14.0);
    std::thread::sleep(Duration::from_millis(500));
    let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["stream", "--sim", "--report-json", "--quiet", "--telemetry-udp", &addr])
        .args(["--telemetry-format", "text", "--udp-idle", "1", "--record"])
        .arg(&record)
        .output()
        .unwrap();
    sender.join().unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert!(out.status.success(), "{report}");
    assert_eq!(report["rejected"], serde_json::json!({}), "{report}");
    assert!(report["datagrams"]["before_ready"].as_u64().unwrap() > 100, "{report}");
    let rows = rows(&record);
    let running: Vec<_> = rows.iter().filter(|r| r.3 == "Running").collect();
    assert!(running.len() > 200, "{} Running rows", running.len());
    // Yaw follows the heading (a turn of up to 0.3 rad/s), pitch the braking: small steps from row to row.
    for w in running.windows(2) {
        let step = (0..6).map(|i| (w[1].1[i] - w[0].1[i]).abs()).fold(0.0, f64::max);
        assert!(step < 0.02, "a step of {step} between rows at {} s", w[1].0);
    }
    let pitch = running.iter().map(|r| r.2[4]);
    let (lo, hi) = pitch.fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    assert!(
        hi - lo > 0.01,
        "the platform pitched {} rad through braking and accelerating",
        hi - lo
    );
}
