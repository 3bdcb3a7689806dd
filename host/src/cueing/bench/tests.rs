use std::path::Path;

use super::*;

/// A short lap (12 s at 25 m/s: 300 m): braking at 3 s, a left corner from 6 to 10 s; `shift` moves the braking
/// (s), `scale` the forces. Rows `t, ax, ay, az, wx, wy, wz, lap_distance` from time `t0`.
fn lap(t0: f64, shift: f64, scale: f64, line: &mut usize) -> Rows {
    let ramp = |x: f64| (x.clamp(0.0, 1.0) * core::f64::consts::PI).cos() * -0.5 + 0.5;
    (0..1200)
        .map(|k| {
            let p = k as f64 * 0.01;
            let b = p - 3.0 - shift;
            let braking = -8.0 * ramp(b / 0.15) * ramp((1.5 - b) / 0.3);
            let corner = 8.0 * ramp((p - 6.0) / 0.8) * ramp((10.0 - p) / 0.8);
            *line += 1;
            let v = vec![
                t0 + p,
                braking * scale,
                corner * scale,
                ringpod_core::cueing::G,
                0.0,
                0.0,
                corner * scale / 25.0,
                25.0 * p,
            ];
            (*line, v)
        })
        .collect()
}

fn laps() -> Rows {
    let mut line = 1;
    let mut rows = lap(0.0, 0.0, 1.0, &mut line);
    rows.extend(lap(12.0, -0.2, 1.05, &mut line));
    rows.extend(lap(24.0, 0.2, 0.95, &mut line));
    rows
}

fn rig() -> Rig {
    let selected = Selected::of("trainer-model", None).unwrap();
    let AnyMechanism::Ring(mechanism) = selected.mechanism else {
        unreachable!("the trainer model is a ring platform")
    };
    let neutral = Pose::from_array(selected.home);
    Rig {
        envelope: crate::cueing::engine::envelope(&mechanism, &neutral).unwrap(),
        mechanism: *mechanism,
        neutral,
    }
}

#[test]
fn a_drive_is_scored_from_its_second_lap_where_its_lap_distance_wraps() {
    let rows = laps();
    assert_eq!(second_lap(&rows), 1200);
    let without: Rows = rows.iter().map(|(l, v)| (*l, v[..7].to_vec())).collect();
    assert_eq!(second_lap(&without), 0);
    let mut unknown = rows.clone();
    unknown.iter_mut().for_each(|(_, v)| v[7] = f64::NAN);
    assert_eq!(second_lap(&unknown), 0);
}

/// The optimal cueing with the lap preview on three laps: the laps found and kept, no departure on laps that only
/// differ by their braking points and forces, the motion not the live one's, and two runs the same bit for bit.
#[test]
fn the_lap_preview_cues_the_laps_after_the_first_and_repeats_bit_for_bit() {
    let rig = rig();
    let drives = [laps()];
    let from = [second_lap(&drives[0])];
    let mut config = crate::input::cueing::load_config(
        Some(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/drives/optimal-tilt.toml")),
        None,
    )
    .unwrap();
    config.optimal.budget_ms = 1000.0;
    let run = |preview| replay(&drives[0], config, &rig.mechanism, &rig.neutral, &rig.envelope, preview).unwrap();
    let (a, b, live) = (run(Preview::Lap), run(Preview::Lap), run(Preview::None));
    let poses =
        |r: &super::super::offline::Replay| -> Vec<[f64; 6]> { r.cued.iter().map(|c| c.pose.to_array()).collect() };
    assert!(poses(&a) == poses(&b), "two runs differ");
    assert!(poses(&a) != poses(&live), "the preview changed nothing");
    // The first lap is the same motion: nothing to preview from.
    assert!(poses(&a)[..1200] == poses(&live)[..1200]);
    let c = a.lap.unwrap();
    assert_eq!((c.laps, c.kept, c.departures, c.bad_distance), (2, 2, 0, 0), "{c:?}");
    assert!(c.previewed_s > 20.0, "{c:?}");
    let (e, _) = evaluate("lap", config, &drives, &from, &rig, Preview::Lap).unwrap();
    let (l, _) = evaluate("live", config, &drives, &from, &rig, Preview::None).unwrap();
    assert_eq!(e.total.samples, 2400);
    eprintln!(
        "lap preview {:.3} m/s^2 against live {:.3}",
        e.total.force_total(),
        l.total.force_total()
    );
}
