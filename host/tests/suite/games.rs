//! Every telemetry format end to end: a drive in a game's own packets, built field by field from the published
//! layouts (`crate::common::packets`, the bytes the decoders' unit tests read), sent over UDP to the real `ringpod stream
//! --sim --telemetry-udp` with `--telemetry-format NAME` and with `auto`. The stream homes, cues the drive in the
//! directions the washout gives it (the same as the `text` format's), counts every datagram, and counts a foreign
//! packet unreadable.

use crate::common::packets;
use std::time::{Duration, Instant};

/// Standard gravity, as the decoders take it.
const G: f32 = 9.80665;

/// A format and, for Forza, which of its packets.
#[derive(Debug, Clone, Copy)]
enum Game {
    Text,
    Outsim,
    Outsim2,
    Beamng,
    Codemasters,
    F1,
    ForzaSled,
    ForzaDash,
    Xplane,
}

const GAMES: [Game; 9] = [
    Game::Text,
    Game::Outsim,
    Game::Outsim2,
    Game::Beamng,
    Game::Codemasters,
    Game::F1,
    Game::ForzaSled,
    Game::ForzaDash,
    Game::Xplane,
];

impl Game {
    /// The `--telemetry-format` name.
    fn format(self) -> &'static str {
        match self {
            Game::Text => "text",
            Game::Outsim => "outsim",
            Game::Outsim2 => "outsim2",
            Game::Beamng => "beamng",
            Game::Codemasters => "codemasters",
            Game::F1 => "f1",
            Game::ForzaSled | Game::ForzaDash => "forza",
            Game::Xplane => "xplane",
        }
    }

    /// Whether its packets carry angular rates (Codemasters' extradata 3 and F1's motion packet do not).
    fn has_rates(self) -> bool {
        !matches!(self, Game::Codemasters | Game::F1)
    }

    /// The packet at `ms` of a car on a level road accelerating `forward` and `left` (m/s^2 in ringpod's axes,
    /// gravity not in it) and turning left at `yaw` rad/s, written in the game's own axes and units (each module of
    /// `host/src/games/` tabulates them).
    fn packet(self, ms: u32, forward: f32, left: f32, yaw: f32) -> Vec<u8> {
        let s = ms as f32 / 1000.0;
        match self {
            Game::Text => format!("{s} {forward} {left} {G} 0 0 {yaw}").into_bytes(),
            // World axes x right, y forward (heading 0), z up; the car's acceleration without gravity.
            Game::Outsim => packets::outsim::packet(ms, [0.0, 0.0, yaw], [0.0; 3], [-left, forward, 0.0], false),
            // OutSim Opts 1ff, every section: a size no other set has, read without `--outsim-opts`.
            Game::Outsim2 => packets::outsim2::packet(0x1ff, ms, [0.0, 0.0, yaw], [0.0; 3], [-left, forward, 0.0]),
            // Car axes x right, y forward, z up; yaw rate positive to the left; no time (the arrival time).
            Game::Beamng => packets::beamng::packet([-left, forward, 0.0], [0.0, 0.0, 1.0], [0.0; 3], [0.0, 0.0, yaw]),
            // g-forces lateral (left, as real recordings show) and longitudinal; level: right = world x, forward =
            // world z.
            Game::Codemasters => {
                packets::codemasters::packet(s, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], left / G, forward / G)
            }
            Game::F1 => packets::f1::packet(
                2024,
                0,
                3,
                s,
                [0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0],
                [left / G, forward / G, 0.0],
            ),
            // Car space X right, Y up, Z forward; a turn to the left is negative about Y (left-handed).
            Game::ForzaSled | Game::ForzaDash => {
                let size = match self {
                    Game::ForzaSled => packets::forza::SLED,
                    _ => packets::forza::DASH_FM2023,
                };
                packets::forza::packet(size, 1, ms, [-left, 0.0, forward], [0.0, -yaw, 0.0], [0.0; 3])
            }
            // g-loads normal, axial, side (right); R positive nose right.
            Game::Xplane => packets::xplane::packet(s, [1.0, forward / G, -left / G], [0.0, 0.0, -yaw], true),
        }
    }
}

/// The drive's packets, one every 10 ms: 0.6 s accelerating at 4 m/s^2, then 0.4 s of a left corner (4 m/s^2 to
/// the left, 0.4 rad/s).
const SAMPLES: u32 = 100;
/// The sample after which a foreign datagram is sent (it is datagram `FOREIGN_AFTER + 2`).
const FOREIGN_AFTER: u32 = 30;

/// One session: the real binary, the drive sent in real time (each packet at its own time after the first, so
/// that a late one does not delay the rest), and `foreign` sent after sample 30; `more` arguments. Returns the exit
/// code, the report and stderr.
fn session(format: &str, game: Game, foreign: &[Vec<u8>], more: &[&str]) -> (Option<i32>, serde_json::Value, String) {
    use std::io::Read;
    let mut args = vec![
        "--fast",
        "--telemetry-udp",
        "127.0.0.1:0",
        "--telemetry-format",
        format,
        "--udp-idle",
        "0.4",
    ];
    args.extend_from_slice(more);
    let (child, mut stderr, addr) = crate::common::spawn_live_stream(&args);
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let start = Instant::now();
    for k in 0..SAMPLES {
        let (forward, left, yaw) = if k < 60 { (4.0, 0.0, 0.0) } else { (0.0, 4.0, 0.4) };
        let due = start + Duration::from_millis(10 * u64::from(k));
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        socket.send_to(&game.packet(10 * k, forward, left, yaw), &addr).unwrap();
        if k == FOREIGN_AFTER {
            for bytes in foreign {
                socket.send_to(bytes, &addr).unwrap();
            }
        }
    }
    let out = child.wait_with_output().unwrap();
    let mut said = String::new();
    stderr.read_to_string(&mut said).unwrap();
    let report = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{format} {game:?}: {e}: {said}"));
    (out.status.code(), report, said)
}

/// A JSON array of numbers.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    let all = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    all.iter().map(|n| n.as_f64().unwrap()).collect()
}

/// What every session of the drive must show: homed and at rest at the end, every readable datagram one setpoint
/// applied (received = applied + unreadable), the device's counts agreeing, and the last pose where the washout
/// takes the drive: forward and to the left (surge and sway), nose up (the acceleration's tilt), right side down
/// (the corner's tilt: the seat pushes the rider left), and turned left by the corner's 0.16 rad when the format
/// carries angular rates (not at all when it does not).
fn assert_cued(what: &str, game: Game, report: &serde_json::Value, unreadable: u64) {
    let n = |v: &serde_json::Value| v.as_u64().unwrap_or_else(|| panic!("{what}: {v} in {report}"));
    assert_eq!(report["state"], "Ready", "{what}: homed and at rest: {report}");
    assert!(n(&report["lead_in_sent"]) > 0, "{what}: led in from home: {report}");
    let d = &report["datagrams"];
    assert_eq!(n(&d["received"]), u64::from(SAMPLES) + unreadable, "{what}: {report}");
    assert_eq!(n(&d["unreadable"]), unreadable, "{what}: {report}");
    assert_eq!(
        n(&report["setpoints_applied"]),
        n(&d["received"]) - n(&d["unreadable"]),
        "{what}: {report}"
    );
    assert_eq!(
        report["setpoints_sent"], report["setpoints_applied"],
        "{what}: {report}"
    );
    assert_eq!(report["rejected"], serde_json::json!({}), "{what}: {report}");
    assert_eq!(report["counts_agree"], true, "{what}: {report}");
    assert!(
        report["datagrams"].get("optimal").is_none(),
        "{what}: the washout: {report}"
    );
    let last = numbers(&report["last_applied_pose"]);
    // Measured on the text drive (`ringpod cue`): x 3.2 mm, y 9.9 mm, alpha 0.021, beta -0.052 rad.
    assert!(last[0] > 0.001, "{what}: surges forward: {last:?}");
    assert!(last[1] > 0.004, "{what}: sways left: {last:?}");
    assert!(last[3] > 0.01, "{what}: right side down: {last:?}");
    assert!(last[4] < -0.03, "{what}: nose up: {last:?}");
    if game.has_rates() {
        // 40 samples at 0.4 rad/s: 0.16 rad. A late packet (a busy machine: seventeen sessions side by side, under
        // Wine on the Windows runner) costs the washout's rest that long, so the bound below is wide on that side.
        assert!(last[5] > 0.10 && last[5] < 0.19, "{what}: turned left: {last:?}");
    } else {
        assert_eq!(last[5], 0.0, "{what}: no rates, no turn: {last:?}");
    }
}

/// Each format named, and each game format picked by `auto`, drives the simulator end to end. With the format
/// named, a foreign datagram (the next game's packet of the same drive) is unreadable and said by exit code 3;
/// with `auto`, the format is named on stderr and the session ends with exit 0. The sessions run side by side.
#[test]
fn every_format_drives_the_stream_end_to_end() {
    std::thread::scope(|scope| {
        let mut runs = Vec::new();
        for (i, game) in GAMES.into_iter().enumerate() {
            let next = GAMES[(i + 1) % GAMES.len()];
            let foreign = next.packet(300, 4.0, 0.0, 0.0);
            runs.push(scope.spawn(move || {
                let what = format!("{game:?} as {}", game.format());
                let (code, report, said) = session(game.format(), game, &[foreign], &[]);
                assert_eq!(code, Some(3), "{what}: one unreadable datagram: {report} {said}");
                assert_eq!(report["outcome"], "input_errors", "{what}: {report}");
                assert_eq!(
                    report["input_errors"][0]["line"],
                    FOREIGN_AFTER + 2,
                    "{what}: the foreign datagram by number: {report}"
                );
                assert_cued(&what, game, &report, 1);
            }));
            if matches!(game, Game::Text) {
                continue;
            }
            runs.push(scope.spawn(move || {
                let what = format!("{game:?} as auto");
                let (code, report, said) = session("auto", game, &[], &[]);
                assert_eq!(code, Some(0), "{what}: {report} {said}");
                assert_eq!(report["outcome"], "followed", "{what}: {report}");
                let named = format!("telemetry: the datagrams are {} (", game.format());
                assert_eq!(said.matches(&named).count(), 1, "{what}: said once: {said}");
                assert_cued(&what, game, &report, 0);
            }));
        }
        for run in runs {
            if let Err(e) = run.join() {
                std::panic::resume_unwind(e);
            }
        }
    });
}

/// F1 sends its other packet types to the motion packet's port: live, one of each id (F1 24's, at their specified
/// sizes) among the drive is skipped and counted apart, no input error, exit 0, named and with `auto`.
#[test]
fn the_games_other_packets_are_skipped_live() {
    let others: Vec<Vec<u8>> = packets::f1::other_ids(2024)
        .iter()
        .map(|&(id, _)| packets::f1::other(2024, id, 0.3))
        .collect();
    for format in ["f1", "auto"] {
        let (code, report, said) = session(format, Game::F1, &others, &[]);
        assert_eq!(code, Some(0), "{format}: {report} {said}");
        let d = &report["datagrams"];
        assert_eq!(d["skipped"], others.len(), "{format}: {report}");
        assert_eq!(d["unreadable"], 0, "{format}: {report}");
        assert_eq!(d["received"], SAMPLES as usize + others.len(), "{format}: {report}");
        assert_eq!(report["setpoints_applied"], SAMPLES, "{format}: {report}");
    }
}

/// The optimal cueing live: the drive through `docs/drives/optimal.toml` (its 2 ms budget on whatever this
/// machine gives a test), every datagram one setpoint applied (none rejected: what leaves the coupled envelope
/// is limited on the host), the corner cued as the washout cues it, and its counts in the report adding up: one
/// sample planned per datagram after the first and per setpoint of the washout to neutral while the source
/// paused; a fallback is a sample, and each one took one to three axes off their own solve.
#[test]
fn the_optimal_cueing_runs_live() {
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/drives/optimal.toml");
    let (code, report, said) = session("outsim", Game::Outsim, &[], &["--cue-config", config]);
    assert_eq!(code, Some(0), "{report} {said}");
    assert_eq!(report["outcome"], "followed", "{report}");
    assert_eq!(report["state"], "Ready", "{report}");
    assert_eq!(report["setpoints_sent"], report["setpoints_applied"], "{report}");
    assert_eq!(report["rejected"], serde_json::json!({}), "{report}");
    let o = &report["datagrams"]["optimal"];
    let n = |k: &str| o[k].as_u64().unwrap_or_else(|| panic!("{k} in {report}"));
    let paused = report["washout_sent"].as_u64().unwrap();
    assert_eq!(n("samples"), u64::from(SAMPLES) - 1 + paused, "{report}");
    assert!(n("late") <= n("samples") && n("fallbacks") <= n("samples"), "{report}");
    let axes = n("followed_plan") + n("took_classical");
    assert!((n("fallbacks")..=3 * n("fallbacks")).contains(&axes), "{report}");
    let ms = numbers(&o["solve_ms"]);
    assert!(ms[0] > 0.0 && ms[0] <= ms[1] && ms[1] <= ms[2], "{report}");
    let last = numbers(&report["last_applied_pose"]);
    // The corner's force to the left: right side down; its turn to the left through the heading channel.
    assert!(last[3] > 0.005, "right side down: {last:?}");
    // As in `assert_cued`: 0.16 rad, less where a busy machine delays a packet.
    assert!(last[5] > 0.10 && last[5] < 0.19, "turned left: {last:?}");
}

/// `--telemetry-shm` off Windows: refused by name as a usage error (exit 2), before anything is opened; with the
/// other sources or options it does not go with, refused as well.
#[test]
fn shared_memory_is_refused_by_name_off_windows_and_with_other_sources() {
    use assert_cmd::Command;
    let ringpod = || Command::cargo_bin("ringpod").unwrap();
    if !cfg!(windows) {
        let out = ringpod()
            .args(["stream", "--sim", "--telemetry-shm", "iracing"])
            .assert()
            .code(2);
        let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
        assert!(err.contains("--telemetry-shm") && err.contains("Windows"), "{err}");
    }
    for other in [
        &["--telemetry-udp", "127.0.0.1:0"][..],
        &["--udp", "127.0.0.1:0"],
        &["--motion", "demo"],
        &["--udp-from", "127.0.0.1"],
        &["--outsim-opts", "ff"],
    ] {
        ringpod()
            .args(["stream", "--sim", "--telemetry-shm", "ac"])
            .args(other)
            .assert()
            .code(2);
    }
}

/// A lap of 200 m at 40 m/s (5 s) as F1 sends it at 30 Hz: each frame's motion packet, then its lap data packet
/// (the player in slot 4 at the lap distance); braking at 8 m/s^2 from 30 m to 60 m, a left corner at 10 m/s^2
/// from 80 m to 120 m, a right one at 8 from 150 m to 170 m, accelerating at 3 elsewhere.
fn f1_lap_frame(k: u32) -> [Vec<u8>; 2] {
    let t = k as f32 / 30.0;
    let s = (40.0 * t) % 200.0;
    let (long, lat) = match s {
        s if (30.0..60.0).contains(&s) => (-8.0, 0.0),
        s if (80.0..120.0).contains(&s) => (0.0, 10.0),
        s if (150.0..170.0).contains(&s) => (0.0, -8.0),
        _ => (3.0, 0.0),
    };
    let level = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    [
        packets::f1::packet(2024, 0, 4, t, level.0, level.1, [lat / G, long / G, 0.0]),
        packets::f1::lap_data(2024, 4, t, s),
    ]
}

/// Three laps of F1 packets over UDP to `stream --sim --telemetry-udp --telemetry-format f1` with the optimal
/// cueing, the lap preview on (the default) and off, side by side, each frame at its own time: with it, the report
/// counts two laps completed and kept, the third matched to an earlier one with the preview's whole share, and
/// the last pose differs from the one without (the stream times the samples by the game's session time, so each
/// run's motion does not depend on when the datagrams arrive); without it there is no preview in the report.
#[test]
fn a_multi_lap_f1_drive_engages_the_lap_preview_live() {
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/drives/optimal.toml");
    let run = |preview: &'static str| {
        use std::io::Read;
        let args = [
            "--fast",
            "--telemetry-udp",
            "127.0.0.1:0",
            "--telemetry-format",
            "f1",
            // Long enough that a stream starved of the processor for a moment on a busy machine (the optimal
            // cueing of a debug build, two sessions side by side) does not take it for the end of the drive.
            "--udp-idle",
            "3",
            "--cue-config",
            config,
            "--lap-preview",
            preview,
        ];
        let (child, mut stderr, addr) = crate::common::spawn_live_stream(&args);
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        let start = Instant::now();
        for k in 0..450u32 {
            let due = start + Duration::from_micros(33_333 * u64::from(k));
            std::thread::sleep(due.saturating_duration_since(Instant::now()));
            for bytes in f1_lap_frame(k) {
                socket.send_to(&bytes, &addr).unwrap();
            }
        }
        let out = child.wait_with_output().unwrap();
        let mut said = String::new();
        stderr.read_to_string(&mut said).unwrap();
        let report: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{preview}: {e}: {said}"));
        (out.status.code(), report, said)
    };
    let (on, off) = std::thread::scope(|s| {
        let on = s.spawn(|| run("on"));
        let off = s.spawn(|| run("off"));
        (on.join().unwrap(), off.join().unwrap())
    });
    for (code, report, said) in [&on, &off] {
        assert_eq!(*code, Some(0), "{report} {said}");
        assert_eq!(
            report["setpoints_applied"].as_u64(),
            Some(450),
            "one pose per motion packet: {report}"
        );
    }
    let lap = &on.1["datagrams"]["lap_preview"];
    let n = |k: &str| lap[k].as_u64().unwrap_or_else(|| panic!("{k} in {lap}"));
    assert_eq!(
        (n("laps"), n("kept"), n("departures"), n("bad_distance")),
        (2, 2, 0, 0),
        "{lap}"
    );
    assert!(
        lap["previewed_s"].as_f64().unwrap() > 8.0,
        "previewed most of laps 2 and 3: {lap}"
    );
    assert_eq!(lap["state"]["lap"], 2, "{lap}");
    assert!(lap["state"]["matched"].is_u64(), "{lap}");
    assert_eq!(lap["state"]["confidence"], 1.0, "{lap}");
    assert!(on.2.contains("lap preview: 2 laps (2 kept as references)"), "{}", on.2);
    assert!(off.1["datagrams"].get("lap_preview").is_none(), "{}", off.1);
    let (a, b) = (
        numbers(&on.1["last_applied_pose"]),
        numbers(&off.1["last_applied_pose"]),
    );
    assert!(
        a.iter().zip(&b).any(|(x, y)| (x - y).abs() > 1e-4),
        "the preview moves the platform otherwise: {a:?} against {b:?}"
    );
}
