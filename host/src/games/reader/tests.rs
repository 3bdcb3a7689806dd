use super::*;
use crate::games::packets;

/// An F1 24 motion packet at session time `t`, level, braking at 0.5 g.
fn f1(t: f32) -> Vec<u8> {
    packets::f1::packet(2024, 0, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -0.5, 0.0])
}

/// One 64-byte datagram of zeros (the size of a classic OutSim packet) before a stream of F1 packets: `auto` locks
/// onto F1 after five of them and reads every F1 packet; nothing is refused.
#[test]
fn a_stray_datagram_does_not_choose_the_format() {
    let mut r = Reader::new(TelemetryFormat::Auto, None);
    // Read as what it is (a classic OutSim packet at rest), and not locked onto.
    assert!(r.read(&[0; 64]).is_ok());
    assert_eq!(r.format(), TelemetryFormat::Auto);
    for k in 0..100 {
        let s = r
            .read(&f1(1.0 + k as f32 / 60.0))
            .unwrap_or_else(|e| panic!("F1 packet {k}: {e}"))
            .expect("a sample");
        // The arrival time for the first after the stray (another format's clock), the game's own after.
        assert_eq!(s.time.is_some(), k > 0, "{k}");
        assert!(s.telemetry.force[0] < -4.0, "{s:?}");
    }
    assert_eq!(r.format(), TelemetryFormat::Game(Format::F1));
    assert_eq!(
        r.locks(),
        [Lock {
            format: Some("f1"),
            datagram: 1 + u64::from(LOCK_AFTER)
        }]
    );
    assert!(r
        .news()
        .is_some_and(|n| n.contains("f1") && n.contains("datagrams 2-6")));
    assert_eq!(r.news(), None);
    // Offline, the capture's first run of five names the format.
    let mut all = vec![vec![0u8; 64]];
    all.extend((0..10).map(|k| f1(k as f32)));
    assert_eq!(detect(all.iter().map(Vec::as_slice), None), Some((Format::F1, 1)));
    assert_eq!(detect([&[0u8; 64][..], &[1, 2, 3]], None), Some((Format::Outsim, 0)));
    assert_eq!(detect([&b"1 2 3"[..]], None), None);
}

/// A locked format that refuses fifty datagrams in a row is dropped, and the new source's format is locked onto.
#[test]
fn a_locked_format_that_keeps_refusing_is_recognised_again() {
    let mut r = Reader::new(TelemetryFormat::Auto, None);
    for k in 0..10 {
        r.read(&f1(k as f32)).unwrap();
    }
    let outsim = packets::outsim::packet(0, [0.0; 3], [0.0; 3], [0.0; 3], false);
    for k in 0..UNLOCK_AFTER {
        assert!(r.read(&outsim).is_err(), "{k}");
    }
    assert_eq!(r.format(), TelemetryFormat::Auto);
    assert!(r.news().is_some_and(|n| n.contains("recognising the format again")), "");
    for _ in 0..LOCK_AFTER {
        r.read(&outsim).unwrap();
    }
    assert_eq!(r.format(), TelemetryFormat::Game(Format::Outsim));
    let formats: Vec<_> = r.locks().iter().map(|l| l.format).collect();
    assert_eq!(formats, [Some("f1"), None, Some("outsim")]);
    // Refusals not in a row keep the lock.
    for _ in 0..3 * UNLOCK_AFTER {
        assert!(r.read(&f1(0.0)).is_err());
        r.read(&outsim).unwrap();
    }
    assert_eq!(r.format(), TelemetryFormat::Game(Format::Outsim));
}

/// The `OutSim Opts` given read an `OutSimPack2` that its size alone does not place, in `auto` and named.
#[test]
fn outsim_opts_reach_the_decoder() {
    let bytes = packets::outsim2::packet(0xff, 2500, [0.0; 3], [0.0; 3], [0.0; 3]);
    let opts = Opts::parse_hex("ff").unwrap();
    for format in [TelemetryFormat::Auto, TelemetryFormat::Game(Format::Outsim2)] {
        assert!(Reader::new(format, None)
            .read(&bytes)
            .unwrap_err()
            .contains("--outsim-opts"));
        let mut r = Reader::new(format, Some(opts));
        let times: Vec<_> = (0..6).map(|_| r.read(&bytes).unwrap().map(|s| s.time)).collect();
        assert_eq!(times.last(), Some(&Some(Some(2.5))), "{format:?}");
    }
}

/// F1 sends its other packet types to the motion packet's port between its motion packets: `auto` still locks
/// onto F1 (they neither break its run nor count against the lock), reads every motion packet, and passes the
/// others over as nothing, not as errors.
#[test]
fn the_games_other_packets_are_skipped_not_refused() {
    let other = |id: u8, t: f32| {
        let mut p = packets::f1::packet(2024, id, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3]);
        p.truncate(700);
        p
    };
    let mut stream = Vec::new();
    for k in 0..(2 * UNLOCK_AFTER) {
        let t = k as f32 / 60.0;
        stream.extend([other(1, t), other(2, t), f1(t), other(6, t)]);
    }
    for format in [TelemetryFormat::Auto, TelemetryFormat::Game(Format::F1)] {
        let mut r = Reader::new(format, None);
        let read: Vec<_> = stream.iter().map(|p| r.read(p)).collect();
        assert!(read.iter().all(Result::is_ok), "{format:?}");
        assert_eq!(
            read.iter().flatten().flatten().count(),
            2 * UNLOCK_AFTER as usize,
            "{format:?}"
        );
        assert_eq!(r.format(), TelemetryFormat::Game(Format::F1), "{format:?}");
    }
    // Offline, the run of motion packets names F1 from the first of them.
    assert_eq!(detect(stream.iter().map(Vec::as_slice), None), Some((Format::F1, 2)));
}
