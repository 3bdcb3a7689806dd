//! `ringpod stability`: chapter 5.2's vehicle stability tests computed, and run on the simulated trainer model with
//! the tip-over read from the run record.

use assert_cmd::Command;

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

fn json(args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let out = ringpod().arg("stability").args(args).arg("--json").output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    (
        out.status.code(),
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}")),
    )
}

/// A 1:20 model truck: track 0.1 m, wheelbase 0.17 m, centre of gravity 0.16 m up, 0.045 m ahead of the rear axle.
const TRUCK: [&str; 8] = [
    "--track",
    "0.1",
    "--wheelbase",
    "0.17",
    "--cg-height",
    "0.16",
    "--cg-from-rear",
    "0.045",
];

/// By hand: climbing `atan(0.045 / 0.16)` = 15.7086 deg, descending `atan(0.125 / 0.16)` = 37.9987 deg, on the slope
/// `atan(0.05 / 0.16)` = 17.3540 deg, the turn `sqrt(0.3125 g 2 m)` = 2.4758 m/s.
#[test]
fn a_rigid_truck_by_hand() {
    let (code, j) = json(&[&TRUCK[..], &["--turn-radius", "2"]].concat());
    assert_eq!(code, Some(0));
    let close = |key: &str, want: f64| {
        let got = j[key].as_f64().unwrap();
        assert!((got - want).abs() < 1e-4, "{key}: {got} vs {want}");
    };
    close("incline_deg", 15.708_6);
    close("decline_deg", 37.998_7);
    close("slope_deg", 17.354_0);
    close("roll_at_slope_deg", 0.0);
    close("rollover_g", 0.3125);
    close("critical_speed_m_s", 2.475_8);
    assert!(j["experiments"].as_array().unwrap().is_empty());
}

/// Each test run on the simulated platform: the record's followed tilt, read in this test independently (the first
/// row where `tan(tilt)` passes the rigid truck's threshold), is where the command says the truck tips, within the
/// 0.05 deg it allows; the platform ramps at the rate asked; the sprung truck tips earlier on the slope.
#[test]
fn experiments_show_the_tip_over_where_computed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().to_str().unwrap();
    let (code, j) = json(&[&TRUCK[..], &["--experiment", path, "--rate", "3"]].concat());
    assert_eq!(code, Some(0), "{j}");
    assert_eq!(j["agree"], true);
    let experiments = j["experiments"].as_array().unwrap();
    assert_eq!(experiments.len(), 3);
    for (e, column, threshold) in [
        (&experiments[0], "beta", 0.045 / 0.16),
        (&experiments[1], "alpha", 0.3125),
        (&experiments[2], "alpha", 0.3125),
    ] {
        let measured = e["measured_deg"].as_f64().unwrap();
        let computed = e["computed_deg"].as_f64().unwrap();
        assert!((measured - computed).abs() < 0.05, "{e}");
        assert!((computed - f64::atan(threshold).to_degrees()).abs() < 1e-9);
        let record = std::fs::read_to_string(e["record"].as_str().unwrap()).unwrap();
        let header: Vec<&str> = record.lines().next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let (t, tilt) = (col("device_s"), col(column));
        let rows: Vec<(f64, f64)> = record
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[t].parse().unwrap(), f64::abs(f[tilt].parse().unwrap()))
            })
            .collect();
        let first = rows
            .iter()
            .position(|r| r.1.tan() > threshold)
            .expect("the record never passes the threshold");
        let (before, after) = (rows[first - 1].1.to_degrees(), rows[first].1.to_degrees());
        assert!(
            before <= measured + 0.01 && measured <= after + 0.01,
            "{before} {measured} {after}"
        );
        // The platform's tilt rate there is the one asked (3 deg/s), from the followed rows a quarter second apart.
        let back = rows[..first].iter().rposition(|r| r.0 <= rows[first].0 - 0.25).unwrap();
        let rate = (rows[first].1 - rows[back].1).to_degrees() / (rows[first].0 - rows[back].0);
        assert!((rate - 3.0).abs() < 0.05, "{rate} deg/s");
        // The turn read as a speed: sqrt(g tan(theta) 1 m).
        if let Some(v) = e["speed_m_s"].as_f64() {
            assert!((v - (9.80665 * measured.to_radians().tan()).sqrt()).abs() < 1e-9);
        }
    }
    let sprung = ["--roll-stiffness", "2", "--mass", "0.5", "--roll-centre-height", "0.06"];
    let (code, j) = json(&[&TRUCK[..], &sprung, &["--experiment", path]].concat());
    assert_eq!(code, Some(0), "{j}");
    let slope = &j["experiments"][1];
    let measured = slope["measured_deg"].as_f64().unwrap();
    assert!(measured < 17.0 && (measured - j["slope_deg"].as_f64().unwrap()).abs() < 0.05);
    assert!((slope["roll_deg"].as_f64().unwrap() - j["roll_at_slope_deg"].as_f64().unwrap()).abs() < 0.05);
}

/// A vehicle beyond the platform's tilt is not shown tipping: exit 3, saying how far the platform went.
#[test]
fn beyond_the_platforms_tilt_it_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let out = ringpod()
        .args([
            "stability",
            "--track",
            "0.2",
            "--wheelbase",
            "0.3",
            "--cg-height",
            "0.1",
        ])
        .args(["--experiment", dir.path().to_str().unwrap(), "--rate", "20"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3));
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text.matches("NOT tipped: the platform followed up to").count(),
        3,
        "{text}"
    );
}

#[test]
fn bad_vehicles_are_refused() {
    // A vehicle that is fine, the first two entries replaced or more words added in each case.
    let fine = ["--track", "0.1", "--wheelbase", "0.3", "--cg-height", "0.1"];
    for (track, extra, says) in [
        ("-0.1", &[][..], "track is zero, negative"),
        ("NaN", &[], "track is not a finite number"),
        ("0.1", &["--cg-from-rear", "0.4"], "between the axles"),
        (
            "0.1",
            &[
                "--roll-stiffness",
                "0.01",
                "--mass",
                "1",
                "--roll-centre-height",
                "0.05",
            ],
            "rolls over on its springs",
        ),
        ("0.1", &["--turn-radius", "0"], "radius is zero, negative"),
        (
            "0.1",
            &["--experiment", "/nonexistent-x", "--rate", "0"],
            "must be above 0",
        ),
    ] {
        let mut args = fine.to_vec();
        args[1] = track;
        args.extend_from_slice(extra);
        let out = ringpod().arg("stability").args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(out.stdout.is_empty());
    }
    // A roll stiffness without its mass and roll centre is a usage error.
    let out = ringpod()
        .arg("stability")
        .args(fine)
        .args(["--roll-stiffness", "5"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}
