use super::*;
use crate::games::packets;
use crate::input::capture::{spec, udp_packet};
use proptest::prelude::*;

const RAW: u32 = 101;

/// A raw-IP frame of `payload` from a game to port 4123.
fn frame(payload: &[u8]) -> Vec<u8> {
    udp_packet(
        "10.0.0.2:5000".parse().unwrap(),
        "10.0.0.1:4123".parse().unwrap(),
        payload,
    )
}

/// Text telemetry (a format without its own time) whose capture times go backwards: the datagram is named, the
/// others cued, nothing panics.
#[test]
fn capture_times_that_go_backwards_are_input_errors() {
    let line = |s: &str| frame(s.as_bytes());
    let frames = [
        (2_000_000, line("0 0 9.8 0 0 0")),
        (1_000_000, line("0 0 9.8 0 0 0")),
        (2_500_000, line("0 0 9.8 0 0 0")),
        (2_400_000, line("0 0 9.8 0 0 0")),
    ];
    let (rows, errors, summary) = rows(&spec::pcap(false, RAW, &frames), TelemetryFormat::Text, None, None).unwrap();
    assert_eq!(rows.iter().map(|r| r.0).collect::<Vec<_>>(), [1, 3]);
    assert_eq!((errors[0].line, errors[1].line), (2, 4), "{errors:?}");
    assert!(errors[0].reason.contains("before the first"), "{errors:?}");
    assert!(errors[1].reason.contains("not after the last"), "{errors:?}");
    assert_eq!(summary.datagrams, 4);
}

/// A stray 64-byte datagram before F1's: the capture is read as F1 from packet 2, only the stray refused.
#[test]
fn auto_reads_a_capture_in_its_first_run_of_one_format() {
    let mut frames = vec![(0, frame(&[0; 64]))];
    for k in 0..20u64 {
        let f1 = packets::f1::packet(2024, 0, 3, k as f32 / 20.0, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3]);
        frames.push((k * 50_000, frame(&f1)));
    }
    let (rows, errors, summary) = rows(&spec::pcap(true, RAW, &frames), TelemetryFormat::Auto, None, None).unwrap();
    assert_eq!((rows.len(), errors.len()), (20, 1), "{errors:?}");
    assert_eq!(errors[0].line, 1);
    assert_eq!(summary.telemetry_format, "f1");
    assert_eq!(summary.recognised_from_packet, Some(2));
}

/// The captures the fuzz run mutates: pcap in both byte orders, pcapng with time options, on three link types,
/// holding game packets and text, and a telemetry CSV.
fn bases() -> Vec<Vec<u8>> {
    let outsim = packets::outsim::packet(10, [0.0; 3], [0.0; 3], [0.0, -3.0, 0.0], false);
    let text = b"1.5 0 0 9.8 0 0 0".to_vec();
    let frames: Vec<(u64, Vec<u8>)> = (0..4u64)
        .map(|k| (1_000 * k, frame(if k % 2 == 0 { &outsim } else { &text })))
        .collect();
    let loop_frames: Vec<(u64, Vec<u8>)> = frames
        .iter()
        .map(|(t, f)| (*t, spec::loopback_frame(spec::LINKTYPE_NULL, false, false, f)))
        .collect();
    vec![
        spec::pcap(false, RAW, &frames),
        spec::pcap(true, spec::LINKTYPE_NULL, &loop_frames),
        spec::pcapng(false, RAW, Some(9), Some(1 << 33), &frames),
        spec::pcapng(true, spec::LINKTYPE_NULL, Some(0x86), None, &loop_frames),
        b"t,ax,ay,az,wx,wy,wz\n0,0,0,9.8,0,0,0\n0.01,1,0,9.8,0,0,0.1\n".to_vec(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// Mutated captures and files (bytes overwritten, with the large and small values that move lengths, times and
    /// offsets, then cut anywhere): each is read or refused without a panic, and what is kept is bounded by the
    /// file (no more datagrams, payload bytes, rows, errors or skip reasons than it has room for, no reason longer
    /// than a line).
    #[test]
    fn mutated_captures_never_panic_and_stay_bounded(
        base in 0usize..5,
        edits in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(vec![0u8, 1, 0x7f, 0x80, 0xfe, 0xff]), any::<u8>(), any::<bool>()), 1..8),
        cut in any::<prop::sample::Index>(),
        format in prop::sample::select(vec![TelemetryFormat::Auto, TelemetryFormat::Text, TelemetryFormat::Game(crate::games::Format::Outsim)]),
    ) {
        let mut bytes = bases().swap_remove(base);
        for (at, special, random, use_special) in edits {
            let i = at.index(bytes.len());
            bytes[i] = if use_special { special } else { random };
        }
        let len = bytes.len();
        for bytes in [&bytes[..], &bytes[..cut.index(len + 1)]] {
            if let Ok(cap) = capture::read(bytes) {
                prop_assert!(cap.datagrams.len() <= bytes.len() / 16);
                prop_assert!(cap.datagrams.iter().map(|d| d.payload.len()).sum::<usize>() <= bytes.len());
                prop_assert!(cap.skipped.len() <= cap.packets.max(1));
            }
            if let Ok((rows, errors, summary)) = rows(bytes, format, None, None) {
                prop_assert!(rows.len() + errors.len() <= summary.packets + 1);
                prop_assert!(errors.iter().all(|e| e.reason.len() <= 300), "{errors:?}");
            }
            if let Ok(text) = std::str::from_utf8(bytes) {
                if let Ok((rows, errors)) = crate::input::table::read(text, &crate::cueing::offline::TELEMETRY_COLUMNS) {
                    prop_assert!(rows.len() + errors.len() <= text.lines().count());
                }
            }
        }
    }
}

/// F1's other packet `id` (session, lap data, car telemetry, ...) at session time `t`: the header as the game writes
/// it, then `len` bytes in all.
fn f1_other(id: u8, t: f32, len: usize) -> Vec<u8> {
    let mut p = packets::f1::packet(2024, id, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3]);
    p.resize(len, 0);
    p
}

/// A session's capture as F1 sends it to one port: each frame's motion packet among its session, lap data,
/// event, participants, car telemetry, car status and extended motion packets. Every motion packet is cued, the
/// others are skipped and counted, no input error, in `auto` and named.
#[test]
fn a_real_f1_session_cues_every_motion_packet_and_skips_the_others() {
    // F1 24's sizes of packets 1, 2, 3, 4, 6, 7 and 13.
    let others = [
        (1u8, 753),
        (2, 1285),
        (3, 45),
        (4, 1350),
        (6, 1352),
        (7, 1239),
        (13, 237),
    ];
    let mut frames = Vec::new();
    for k in 0..30u64 {
        let t = k as f32 / 20.0;
        for (id, len) in others.iter().take(1 + k as usize % others.len()) {
            frames.push((k * 50_000, frame(&f1_other(*id, t, *len))));
        }
        let motion = packets::f1::packet(2024, 0, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -0.5, 0.0]);
        frames.push((k * 50_000 + 1_000, frame(&motion)));
    }
    let pcap = spec::pcap(false, RAW, &frames);
    for format in [TelemetryFormat::Auto, TelemetryFormat::Game(crate::games::Format::F1)] {
        let (rows, errors, summary) = rows(&pcap, format, None, None).unwrap();
        assert!(errors.is_empty(), "{format:?}: {errors:?}");
        assert_eq!(rows.len(), 30, "{format:?}");
        assert!(rows.iter().all(|r| r.1[1] < -4.0), "braking in every row");
        assert_eq!(summary.datagrams, frames.len());
        assert_eq!(
            summary.skipped.get(GAME_PACKETS),
            Some(&(frames.len() - 30)),
            "{:?}",
            summary.skipped
        );
        assert_eq!(summary.telemetry_format, "f1");
    }
}

/// A motion packet while spectating (player car index 255) is refused by name, with what to do.
#[test]
fn an_f1_motion_packet_while_spectating_is_refused_by_name() {
    let mut spectating = packets::f1::packet(2024, 0, 3, 1.0, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3]);
    spectating[27] = crate::games::f1::SPECTATING;
    let pcap = spec::pcap(false, RAW, &[(0, frame(&spectating))]);
    let (rows, errors, _) = rows(&pcap, TelemetryFormat::Game(crate::games::Format::F1), None, None).unwrap();
    assert!(rows.is_empty());
    assert!(errors[0].reason.contains("spectating"), "{errors:?}");
}

/// Four 10 s laps of F1 at 20 Hz, each frame's lap data packet before its motion packet, braking over the same
/// stretch of every lap: each row carries the player's lap distance as its eighth value (wrapping at the line),
/// and the lap preview fed with the rows keeps the laps and matches the last to an earlier one.
#[test]
fn an_f1_captures_lap_distance_reaches_the_lap_preview() {
    const FRAMES: u64 = 200;
    const LAP_M: f32 = 600.0;
    let along = |k: u64| (k % FRAMES) as f32 * LAP_M / FRAMES as f32;
    let mut frames = Vec::new();
    for k in 0..4 * FRAMES {
        let t = k as f32 / 20.0;
        frames.push((k * 50_000, frame(&packets::f1::lap_data(2024, 3, t, along(k)))));
        let braking = if (40..80).contains(&(k % FRAMES)) { -0.6 } else { 0.1 };
        let motion = packets::f1::packet(2024, 0, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, braking, 0.0]);
        frames.push((k * 50_000 + 1_000, frame(&motion)));
    }
    let (rows, errors, _) = rows(&spec::pcap(false, RAW, &frames), TelemetryFormat::Auto, None, None).unwrap();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(rows.len() as u64, 4 * FRAMES);
    for (k, (_, row)) in rows.iter().enumerate() {
        assert_eq!(row.len(), 8, "row {k}: {row:?}");
        assert!((row[7] - f64::from(along(k as u64))).abs() < 1e-3, "row {k}: {row:?}");
    }
    let mut preview = crate::cueing::lap::LapPreview::new(crate::cueing::lap::Settings::default());
    for (_, r) in &rows {
        let sample = ringpod_core::cueing::Telemetry {
            force: [r[1], r[2], r[3]],
            rate: [r[4], r[5], r[6]],
        };
        preview.observe(r[0], r[7], &sample);
    }
    let counts = preview.counts();
    let state = counts.state.unwrap();
    assert!(counts.laps >= 3 && counts.kept >= 2, "{counts:?}");
    assert_eq!((counts.departures, counts.bad_distance), (0, 0), "{counts:?}");
    assert!(state.matched.is_some() && state.confidence > 0.5, "{counts:?}");
}
