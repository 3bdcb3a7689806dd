use super::super::testing::{close, layout, Layout, Page, C, DRIVE};
use super::super::{decode as decode_game, Game, Unreadable};
use super::*;

/// `irsdk_header` and `irsdk_varHeader` as `irsdk_defines.h` declares them.
fn header_layout() -> Layout {
    use C::I32;
    layout(
        4,
        &[
            ("ver", I32, 1),
            ("status", I32, 1),
            ("tickRate", I32, 1),
            ("sessionInfoUpdate", I32, 1),
            ("sessionInfoLen", I32, 1),
            ("sessionInfoOffset", I32, 1),
            ("numVars", I32, 1),
            ("varHeaderOffset", I32, 1),
            ("numBuf", I32, 1),
            ("bufLen", I32, 1),
            ("pad", I32, 2),
            ("varBuf", I32, 4 * 4),
        ],
    )
}

fn var_header_layout() -> Layout {
    use C::{I32, I8};
    layout(
        4,
        &[
            ("type", I32, 1),
            ("offset", I32, 1),
            ("count", I32, 1),
            ("countAsTime", I8, 1),
            ("pad", I8, 3),
            ("name", I8, 32),
            ("desc", I8, 64),
            ("unit", I8, 32),
        ],
    )
}

/// One variable: its name, type (4 float, 5 double), count.
type Var = (&'static str, i32, i32);

/// The variables of the test's sim, a few that are not read among them (one whose name starts like one read).
const VARS: [Var; 10] = [
    ("SessionTime", 5, 1),
    ("Speed", 4, 1),
    ("LatAccel_ST", 4, 6),
    ("LongAccel", 4, 1),
    ("LatAccel", 4, 1),
    ("VertAccel", 4, 1),
    ("RollRate", 4, 1),
    ("PitchRate", 4, 1),
    ("YawRate", 4, 1),
    ("Gear", 2, 1),
];

/// A variable's offset in a buffer: in the order of `vars`, each after the last.
fn var_offsets(vars: &[Var]) -> Vec<usize> {
    let mut at = 0;
    vars.iter()
        .map(|(_, ty, n)| {
            let here = at;
            at += if *ty == 5 { 8 } else { 4 } * *n as usize;
            here
        })
        .collect()
}

const BUF_LEN: usize = 256;
const VAR_HEADERS: usize = 1024;
const BUFS: usize = 3;

/// The mapping with `vars`, three buffers with ticks `ticks`, and `values` (by name) in the buffer of the highest
/// tick; the others hold other values (what the sim wrote before).
fn mapping(vars: &[Var], ticks: [i32; BUFS], values: &[(&str, f64)], connected: bool) -> Vec<u8> {
    let (h, vh) = (header_layout(), var_header_layout());
    assert_eq!((h.size, vh.size), (HEADER, VAR_HEADER));
    let first_buf = VAR_HEADERS + vars.len() * vh.size;
    let mut p = Page::zeros(first_buf + BUFS * BUF_LEN);
    p.i32(h.at("ver"), 2)
        .i32(h.at("status"), i32::from(connected))
        .i32(h.at("tickRate"), 60)
        .i32(h.at("numVars"), vars.len() as i32)
        .i32(h.at("varHeaderOffset"), VAR_HEADERS as i32)
        .i32(h.at("numBuf"), BUFS as i32)
        .i32(h.at("bufLen"), BUF_LEN as i32);
    let offsets = var_offsets(vars);
    for (i, ((name, ty, n), off)) in vars.iter().zip(&offsets).enumerate() {
        let at = VAR_HEADERS + i * vh.size;
        p.i32(at + vh.at("type"), *ty)
            .i32(at + vh.at("offset"), *off as i32)
            .i32(at + vh.at("count"), *n)
            .put(at + vh.at("name"), name.as_bytes());
    }
    let latest = (0..BUFS).max_by_key(|i| ticks[*i]).unwrap();
    for (b, tick) in ticks.iter().enumerate() {
        let buf = first_buf + b * BUF_LEN;
        p.i32(h.at("varBuf") + 16 * b, *tick)
            .i32(h.at("varBuf") + 16 * b + 4, buf as i32);
        for ((name, ty, _), off) in vars.iter().zip(&offsets) {
            let v = values.iter().find(|(n, _)| n == name).map_or(0.0, |(_, v)| *v);
            let v = if b == latest { v } else { -99.0 };
            if *ty == 5 {
                p.f64s(buf + off, &[v]);
            } else if *ty == 4 {
                p.f32s(buf + off, &[v]);
            }
        }
    }
    p.0
}

#[test]
fn a_drive_decodes_from_the_latest_buffer_by_the_variables_names() {
    for (i, m) in DRIVE.iter().enumerate() {
        let f = m.force();
        let values = [
            ("SessionTime", 12.5 + i as f64),
            ("LongAccel", f[0]),
            ("LatAccel", f[1]),
            ("VertAccel", f[2]),
            ("RollRate", m.rate[0]),
            ("PitchRate", m.rate[1]),
            ("YawRate", m.rate[2]),
            ("LatAccel_ST", 55.0),
        ];
        let tick = 1000 + i as i32;
        // The latest buffer moves round the three.
        let mut ticks = [tick - 2, tick - 1, tick - 3];
        ticks.rotate_left(i % 3);
        let read = decode_game(Game::Iracing, &[mapping(&VARS, ticks, &values, true)])
            .unwrap_or_else(|e| panic!("{}: {e}", m.name));
        assert_eq!(read.tick, tick as u64 - 1);
        assert_eq!(read.sample.time, Some(12.5 + i as f64));
        assert!(close(read.sample.telemetry.force, f), "{}: {read:?}", m.name);
        assert!(close(read.sample.telemetry.rate, m.rate), "{}: {read:?}", m.name);
        let latest = ticks.iter().position(|t| *t == tick - 1).unwrap();
        assert_eq!(
            read.guard.at,
            48 + 16 * latest,
            "the tick re-read is the latest buffer's"
        );
    }
}

#[test]
fn a_missing_or_mistyped_variable_is_refused_by_name() {
    let without: Vec<Var> = VARS.iter().copied().filter(|v| v.0 != "YawRate").collect();
    let e = decode(&mapping(&without, [3, 2, 1], &[], true)).unwrap_err();
    assert!(matches!(e, Unreadable::Variable { name: "YawRate", .. }), "{e}");
    assert!(
        e.to_string().contains("YawRate is not among the variable headers"),
        "{e}"
    );
    let mut doubled = VARS;
    doubled[0].1 = 4;
    let e = decode(&mapping(&doubled, [3, 2, 1], &[], true)).unwrap_err();
    assert!(e.to_string().contains("SessionTime has type 4"), "{e}");
}

#[test]
fn a_disconnected_sim_or_a_garbage_header_is_refused() {
    let off = mapping(&VARS, [3, 2, 1], &[], false);
    assert!(matches!(decode(&off), Err(Unreadable::NoMotion { .. })));
    let good = mapping(&VARS, [3, 2, 1], &[], true);
    assert!(decode(&good).is_ok());
    for (at, v) in [(24, -1), (24, 1_000_000), (32, 5), (32, 0), (36, -7), (28, 1 << 30)] {
        let mut bad = good.clone();
        bad[at..at + 4].copy_from_slice(&i32::to_le_bytes(v));
        assert!(decode(&bad).is_err(), "{at}: {v}");
    }
    assert!(matches!(decode(&good[..HEADER - 1]), Err(Unreadable::Size { .. })));
    // The last buffer the latest: a snapshot one byte short of it is refused.
    let last = mapping(&VARS, [1, 2, 3], &[], true);
    assert!(decode(&last).is_ok());
    assert!(matches!(decode(&last[..last.len() - 1]), Err(Unreadable::Size { .. })));
}

/// `LapDistPct` gives the lap position; a sim without it still gives the motion, without a lap position.
#[test]
fn lap_dist_pct_is_the_lap_position_when_the_sim_has_it() {
    let with: Vec<Var> = VARS.iter().copied().chain([("LapDistPct", 4, 1)]).collect();
    for x in [0.0, 0.5, 0.875] {
        let read = decode(&mapping(&with, [3, 2, 1], &[("LapDistPct", x)], true)).unwrap();
        assert_eq!(read.sample.lap, Some(crate::games::LapPosition::Along(x)));
    }
    assert_eq!(decode(&mapping(&VARS, [3, 2, 1], &[], true)).unwrap().sample.lap, None);
    let mut doubled = with.clone();
    doubled[10].1 = 5;
    assert_eq!(
        decode(&mapping(&doubled, [3, 2, 1], &[], true)).unwrap().sample.lap,
        None,
        "of another type: not read"
    );
}
