//! The `ringpod` command line, run as a user runs it.

use assert_cmd::Command;
use predicates::prelude::*;

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = ringpod().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn ik_json_reproduces_the_reference() {
    let v = json(&["ik", "--mechanism", "trainer-ch5", "--pose=0.1,0,1,0,0,0", "--json"]);
    let want = [
        -1.920367228,
        -1.226396755,
        1.067953116,
        1.993650253,
        1.230749913,
        1.284901817,
    ];
    let got: Vec<f64> = v["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-8, "{g} vs {w}");
    }
    assert_eq!(v["axes"][4], "s3");
    assert_eq!(v["checks"].as_array().unwrap().len(), 6);
}

#[test]
fn ik_degrees_in_and_out() {
    let rad = json(&[
        "ik",
        "--pose=0,0,0.95,0.05235987756,0.03490658504,3.490658504",
        "-m",
        "trainer-ch5",
        "--json",
    ]);
    let deg = json(&[
        "ik",
        "--pose=0,0,0.95,3,2,200",
        "-m",
        "trainer-ch5",
        "--json",
        "--degrees",
    ]);
    for i in 0..4 {
        let (r, d) = (
            rad["actuators"][i].as_f64().unwrap(),
            deg["actuators"][i].as_f64().unwrap(),
        );
        assert!((r.to_degrees() - d).abs() < 1e-6);
    }
    assert_eq!(deg["units"][0], "deg");
}

#[test]
fn ik_reports_failing_checks_but_exits_zero() {
    // trainer-ch5 at home: carriage gaps of 134 degrees exceed the source's 120.
    ringpod()
        .args(["ik", "-m", "trainer-ch5"])
        .assert()
        .success()
        .stdout(predicate::str::contains("FAIL carriage-spacing"));
}

#[test]
fn check_exit_codes() {
    ringpod()
        .args(["check"])
        .assert()
        .code(0)
        .stdout(predicate::str::contains("inside the workspace"));
    ringpod().args(["check", "-m", "trainer-ch5"]).assert().code(3);
    ringpod()
        .args(["check", "-m", "trainer-ch5", "--pose=0,0,1,0,-5,0", "--degrees"])
        .assert()
        .code(1)
        .stderr(
            predicate::str::contains("unreachable: chain 2").and(predicate::str::contains("outside the reach limits")),
        );
}

#[test]
fn no_solution_is_an_error() {
    ringpod()
        .args(["ik", "-m", "rotopod-ch4", "--pose=0,0,0.99,0,0,0"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("unreachable"));
    ringpod()
        .args(["ik", "-m", "tool5-ex", "--pose=0,0,0.4,0,0,0.1"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("cannot move"));
}

#[test]
fn fk_inverts_ik() {
    let pose = [0.02, -0.01, 0.24, 0.1, -0.05, 2.5];
    let pose_arg = format!("--pose={}", pose.map(|v| v.to_string()).join(","));
    let ik = json(&["ik", &pose_arg, "--json"]);
    let q: Vec<String> = ik["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| format!("{:.17}", v.as_f64().unwrap()))
        .collect();
    let fk = json(&[
        "fk",
        &format!("--actuators={}", q.join(",")),
        "--guess=0.02,-0.01,0.24,0.1,-0.05,2.5",
        "--json",
    ]);
    for (i, want) in pose.iter().enumerate() {
        assert!((fk["pose"][i].as_f64().unwrap() - want).abs() < 1e-9);
    }
}

#[test]
fn bad_input_is_rejected_with_a_message() {
    ringpod()
        .args(["ik", "-m", "nope"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("unknown mechanism"));
    ringpod()
        .args(["ik", "--pose=1,2,3"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("expected 6 numbers"));
    ringpod()
        .args(["ik", "--pose=0,0,NaN,0,0,0"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("not a finite number"));
    ringpod()
        .args(["fk", "--actuators=a,b"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("--actuators"));
    ringpod()
        .args(["fk", "--actuators=0,0,0,0,0,0", "--max-iterations=3"])
        .assert()
        .code(1);
}

#[test]
fn presets_lists_every_geometry() {
    let v = json(&["presets", "--json"]);
    let names: Vec<&str> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "trainer-model",
            "trainer-elbow",
            "trainer-ch5",
            "rotopod-ch4",
            "tool5-ex",
            "trainer-ch3",
            "trainer-ch4"
        ]
    );
}

#[test]
fn loads_scale_with_the_mass_and_mirror_at_home() {
    let one = json(&["loads", "--mass", "1", "--json"]);
    let two = json(&["loads", "--mass", "2", "--json"]);
    for i in 0..6 {
        let (a, b) = (one["drives"][i].as_f64().unwrap(), two["drives"][i].as_f64().unwrap());
        assert!(
            (2.0 * a - b).abs() < 1e-9 * b.abs().max(1.0),
            "statics are linear in the load"
        );
    }
    // The model is symmetric about the YZ plane: mirrored carriages carry opposite torques at home.
    let d = |i: usize| one["drives"][i].as_f64().unwrap();
    assert!((d(0) + d(1)).abs() < 1e-9 && (d(2) + d(3)).abs() < 1e-9 && (d(4) - d(5)).abs() < 1e-9);
    assert_eq!(one["units"][0], "N m");
    ringpod()
        .args(["loads", "--mass", "1", "-m", "tool5-ex"])
        .assert()
        .code(1);
    ringpod().args(["loads", "--mass=-1"]).assert().code(1);
}

#[test]
fn workspace_scan_draws_and_reports() {
    let dir = std::env::temp_dir().join(format!("ringpod-ws-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("ws.png");
    let out = ringpod()
        .args(["workspace", "--cells", "40", "--quiet", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("7380 of 7380 poses inside: all inside"), "{text}");
    assert!(text.contains("m^3"), "{text}");
    assert_eq!(&std::fs::read(&png).unwrap()[..4], b"\x89PNG");
    let svg = dir.join("ws.svg");
    ringpod()
        .args(["workspace", "--section", "xz", "--cells", "20", "--quiet", "--out"])
        .arg(&svg)
        .assert()
        .success();
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    ringpod()
        .args(["workspace", "--section", "rotations", "--z", "0.2", "--out"])
        .arg(dir.join("x.png"))
        .assert()
        .code(1);
}

/// The tool carrier's workspace: the same scan gives the same counts, its x range at home is the carriage's stroke,
/// and the pose the source solves is inside while one past the stroke is not.
#[test]
fn tool_carrier_workspace_is_reproducible_and_bounded_by_its_stroke() {
    let dir = std::env::temp_dir().join(format!("ringpod-tool-ws-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |section: &str| {
        let out = ringpod()
            .args([
                "workspace",
                "-m",
                "tool5-ex",
                "--section",
                section,
                "--cells",
                "40",
                "--quiet",
                "--out",
            ])
            .arg(dir.join(format!("{section}.svg")))
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let rotations = run("rotations");
    assert_eq!(rotations, run("rotations"));
    let count = |text: &str| -> usize {
        let (_, after) = text.split_once("cells): ").unwrap();
        after.split(' ').next().unwrap().parse().unwrap()
    };
    // Some but not all of the tilts: the dyads give out at large roll.
    let inside = count(&rotations);
    assert!(inside > 400 && inside < 1600, "{rotations}");
    assert!(
        rotations.contains("x at home within [-0.4999, 0.4999] m"),
        "{rotations}"
    );
    assert!(rotations.contains("q1 in [-0.5, 0.5] m"), "{rotations}");
    let xy = run("xy");
    assert!(count(&xy) > 0, "{xy}");
    assert!(std::fs::read_to_string(dir.join("xy.svg")).unwrap().contains("<svg"));
    // The source's third example is inside; 0.55 m along x (or 0.45 m tilted 30 deg) is past the stroke.
    ringpod()
        .args([
            "check",
            "-m",
            "tool5-ex",
            "--degrees",
            "--pose=0,0,0.4,15.2167,25.3333,0",
        ])
        .assert()
        .code(0);
    for pose in ["--pose=0.55,0,0.4,0,0,0", "--pose=0.45,0,0.4,0,30,0"] {
        ringpod()
            .args(["check", "-m", "tool5-ex", "--degrees", pose])
            .assert()
            .code(3)
            .stdout(predicate::str::contains("FAIL reach"));
    }
    ringpod()
        .args(["workspace", "-m", "tool5-ex", "--cells", "5", "--out"])
        .arg(dir.join("x.svg"))
        .assert()
        .code(1);
}

/// `ik --branch`: the four assemblies of the tool carrier's dyads at the source's third example, each the source's
/// `q2` / `q2'` and `q4` / `q4'`; each closes back to the pose by `fk`, and the branches differ.
#[test]
fn tool_carrier_branches_round_trip_and_differ() {
    let pose = "--pose=0,0,0.4,15.2167,25.3333,0";
    let all = json(&["ik", "-m", "tool5-ex", "--degrees", pose, "--branch", "all", "--json"]);
    let rows = all["assemblies"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    let q = |row: &serde_json::Value| -> Vec<f64> {
        row["actuators"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    // The source's minutes: q2 65 deg 01' or 134 deg 08', q4 34 deg 22' or 169 deg 22'.
    let want = [
        (65.026, 34.359),
        (65.026, 169.341),
        (134.131, 34.359),
        (134.131, 169.341),
    ];
    for (row, (q2, q4)) in rows.iter().zip(want) {
        let q = q(row);
        assert!((q[1] - q2).abs() < 2e-3 && (q[3] - q4).abs() < 2e-3, "{row}");
        assert_eq!(row["all_pass"], true);
        let actuators: Vec<String> = q.iter().map(|v| format!("{v:.9}")).collect();
        let fk = json(&[
            "fk",
            "-m",
            "tool5-ex",
            "--degrees",
            &format!("--actuators={}", actuators.join(",")),
            "--guess=0.01,0.01,0.41,14,24,0",
            &format!(
                "--branch={}",
                row["branches"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|b| b.as_str().unwrap())
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            "--json",
        ]);
        let got: Vec<f64> = fk["pose"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        for (g, w) in got.iter().zip([0.0, 0.0, 0.4, 15.2167, 25.3333, 0.0]) {
            assert!((g - w).abs() < 1e-6, "{row}: fk {got:?}");
        }
    }
    assert_ne!(q(&rows[0]), q(&rows[3]));
    // One assembly by name, the same as its row of `all`.
    let one = json(&[
        "ik",
        "-m",
        "tool5-ex",
        "--degrees",
        pose,
        "--branch",
        "plus,minus",
        "--json",
    ]);
    assert_eq!(one["branches"], serde_json::json!(["plus", "minus"]));
    let got: Vec<f64> = one["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(got, q(&rows[2]));
    // The default is the preset's (minus, minus).
    let default = json(&["ik", "-m", "tool5-ex", "--degrees", pose, "--json"]);
    assert_eq!(default["branches"], serde_json::json!(["minus", "minus"]));
    ringpod().args(["ik", "--branch", "plus"]).assert().code(1);
    ringpod()
        .args(["ik", "-m", "tool5-ex", "--branch", "up"])
        .assert()
        .code(2);
    ringpod()
        .args(["ik", "-m", "tool5-ex", "--branch", "plus,minus,plus"])
        .assert()
        .code(2);
    // FK on the preset's assembly refuses actuators of another one, and answers for one assembly only.
    let other: Vec<String> = q(&rows[3]).iter().map(|v| format!("{v:.9}")).collect();
    ringpod()
        .args(["fk", "-m", "tool5-ex", "--degrees", "--guess=0,0,0.4,15,25,0"])
        .arg(format!("--actuators={}", other.join(",")))
        .assert()
        .code(1)
        .stderr(predicate::str::contains("other branches"));
    ringpod()
        .args(["fk", "-m", "tool5-ex", "--actuators=0,1,1,1,0,1", "--branch", "all"])
        .assert()
        .code(1);
}

#[test]
fn device_config_reads_writes_and_refuses() {
    // Every section is listed with its values, by the rig file's names.
    let all = json(&["device", "config", "--sim"]);
    assert_eq!(all["control"]["tick_hz"], 1000);
    assert_eq!(all["axes"][0]["steps_per_unit"], 25_600.0);
    assert_eq!(all["axes"][4]["steps_per_unit"], 1_600_000.0);
    assert_eq!(all["axes"][0]["reverse"], false);
    assert_eq!(all["stream"]["telemetry_hz"], 100);
    assert_eq!(all["stream"]["margins"][0], 0.002);
    assert_eq!(all["stream"]["gross_jump_ms"], 500);
    assert_eq!(all["stream"]["follow"], "interpolate");
    assert_eq!(all["homing"]["order"], serde_json::json!([4, 5, 0, 2, 1, 3]));
    assert_eq!(all["homing"]["axes"][4]["toward"], "minus");
    assert!(all["inputs"]["active_low"]
        .as_array()
        .unwrap()
        .contains(&serde_json::json!("home1")));
    assert_eq!(all["pending"], serde_json::json!([]));
    // A set answers with the section read back from the device; a next-start section says it is not live, and
    // pending until the next start.
    let set = json(&["device", "config", "set", "motion.pose_velocity.2", "0.02", "--sim"]);
    assert_eq!(set["value"]["pose_velocity"][2], 0.02);
    assert_eq!(
        (set["live"].as_bool(), set["pending"].as_bool()),
        (Some(true), Some(false))
    );
    let tick = json(&["device", "config", "set", "control.tick_hz", "2000", "--sim"]);
    assert_eq!(
        (
            tick["value"]["tick_hz"].as_u64(),
            tick["live"].as_bool(),
            tick["pending"].as_bool()
        ),
        (Some(2000), Some(false), Some(true))
    );
    let follow = json(&["device", "config", "set", "stream.follow", "direct", "--sim"]);
    assert_eq!(follow["value"]["follow"], "direct");
    let one = json(&["device", "config", "get", "axes.1.reverse", "--sim"]);
    assert_eq!(one["value"], false);
    // Out of range, unknown, malformed, or extra words: an error, exit 1.
    for args in [
        &["device", "config", "set", "control.tick_hz", "1500", "--sim"][..],
        &["device", "config", "set", "inputs.debounce_ms", "0", "--sim"],
        &["device", "config", "set", "inputs.active_low", "[\"home7\"]", "--sim"],
        &["device", "config", "get", "no-such-section", "--sim"],
        &["device", "config", "get", "stream.no_such_key", "--sim"],
        &["device", "config", "set", "stream.gross_jump_ms", "lots", "--sim"],
        &["device", "config", "set", "stream.follow", "sideways", "--sim"],
        &["device", "config", "set", "stream.margins.0", "0.5", "--sim"],
        &["device", "config", "set", "homing.order", "[0, 0, 1, 2, 3, 4]", "--sim"],
        &["device", "config", "set", "stream", "1", "--sim"],
        &["device", "config", "fetch", "control.tick_hz", "--sim"],
        &["device", "status", "control", "--sim"],
    ] {
        ringpod().args(args).assert().code(1);
    }
    ringpod()
        .args(["device", "config", "set", "control.tick_hz", "1500", "--sim"])
        .assert()
        .stderr(predicates::str::contains("BadConfig"));
}

/// A drive (accelerating, braking, a long corner, bumps) as telemetry.
fn drive_csv(rows: &mut dyn FnMut(f64, &mut [f64; 6])) -> String {
    let g = 9.80665;
    let mut csv = String::from("t,ax,ay,az,wx,wy,wz\n");
    for k in 0..=2000 {
        let t = f64::from(k) / 100.0;
        let mut v = [0.0, 0.0, g, 0.0, 0.0, 0.0];
        if (2.0..5.0).contains(&t) {
            v[0] = 3.0;
        }
        if (8.0..10.0).contains(&t) {
            v[0] = -6.0;
        }
        if (10.0..16.0).contains(&t) {
            v[1] = 4.0;
            v[5] = 0.4;
        }
        if (17.0..18.0).contains(&t) {
            v[2] = g + 2.0 * (std::f64::consts::TAU * 8.0 * t).sin();
        }
        rows(t, &mut v);
        csv += &format!("{t},{},{},{},{},{},{}\n", v[0], v[1], v[2], v[3], v[4], v[5]);
    }
    csv
}

#[test]
fn cue_turns_a_drive_into_poses_that_stream_without_refusals() {
    let dir = std::env::temp_dir().join(format!("ringpod-cue-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("drive.csv");
    std::fs::write(&input, drive_csv(&mut |_, _| {})).unwrap();
    let (poses, plot) = (dir.join("poses.csv"), dir.join("cue.svg"));
    let summary = json(&[
        "cue",
        "--json",
        "--input",
        input.to_str().unwrap(),
        "--out",
        poses.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(
        (summary["rows"].as_u64(), summary["poses"].as_u64()),
        (Some(2001), Some(2001))
    );
    assert_eq!(summary["input_errors"], serde_json::json!([]));
    let svg = std::fs::read_to_string(&plot).unwrap();
    for label in [
        "longitudinal specific force",
        "platform delivers",
        "time (s)",
        "m/s^2",
        "vehicle yaw rate",
    ] {
        assert!(svg.contains(label), "{label}");
    }
    // The corner's heading: 6 s at 0.4 rad/s.
    let last = std::fs::read_to_string(&poses).unwrap();
    let yaw: f64 = last
        .lines()
        .last()
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((yaw - 2.4).abs() < 1e-6, "{yaw}");
    let out = ringpod()
        .args(["stream", "--sim", "--fast", "--quiet", "--report-json", "--input"])
        .arg(&poses)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["setpoints_applied"], 2001);
    assert_eq!(report["rejected"], serde_json::json!({}));
    assert_eq!(report["limited"]["device"], 0);
}

#[test]
fn cue_reports_bad_rows_and_refuses_bad_parameters_by_name() {
    let dir = std::env::temp_dir().join(format!("ringpod-cue-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("drive.csv");
    // A NaN at 3 s (the platform holds: an input error), and a 2 s pause after 12 s (the washout rests through it
    // and starts again at neutral: reported, not an error).
    let csv = drive_csv(&mut |t, v| {
        if (t - 3.0).abs() < 1e-9 {
            v[0] = f64::NAN;
        }
    });
    let csv: String = csv
        .lines()
        .filter(|l| {
            let t: f64 = l.split(',').next().unwrap().parse().unwrap_or(-1.0);
            !(12.0 < t && t < 14.0)
        })
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&input, csv).unwrap();
    let poses = dir.join("poses.csv");
    let out = ringpod()
        .args(["cue", "--json", "--input"])
        .arg(&input)
        .arg("--out")
        .arg(&poses)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let errors = summary["input_errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0]["line"], 302, "the row of t = 3 s");
    assert!(errors[0]["reason"].as_str().unwrap().contains("not finite"));
    let pauses = summary["pauses"].as_array().unwrap();
    assert_eq!(pauses.len(), 1, "{summary}");
    assert_eq!(pauses[0]["line"], 1203, "the row of t = 14 s, after the rows it lacks");
    assert!((pauses[0]["seconds"].as_f64().unwrap() - 2.0).abs() < 1e-6, "{summary}");
    for (toml, key) in [
        ("tilt_rate_deg = -3.0\n", "tilt_rate_deg"),
        ("tilt_rate = 3.0\n", "tilt_rate"),
        (
            "translation_high_pass = { omega = 0.0, zeta = 1.0 }\n",
            "translation_high_pass",
        ),
        ("forward = \"up\"\n", "forward"),
    ] {
        let config = dir.join("cue.toml");
        std::fs::write(&config, toml).unwrap();
        ringpod()
            .args(["cue", "--input"])
            .arg(&input)
            .arg("--out")
            .arg(&poses)
            .arg("--config")
            .arg(&config)
            .assert()
            .code(1)
            .stderr(predicates::str::contains(key));
    }
}

/// A rig no preset describes (the model with a 2 % larger ring and a 1 % longer rod), from a rig file: `rig check`
/// accepts it, `ik`, `fk` (no guess), `check` and `workspace` drive it, and its IK differs from the preset's.
#[test]
fn a_rig_file_drives_the_kinematics_commands() {
    let dir = std::env::temp_dir().join(format!("ringpod-rig-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exported = ringpod()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    assert!(exported.status.success());
    let text = String::from_utf8(exported.stdout).unwrap();
    assert!(text.contains("ring_radius = 0.286"), "{text}");
    let own = text
        .replace("name = \"trainer-model\"", "name = \"my-rig\"")
        .replace("ring_radius = 0.286", "ring_radius = 0.29172")
        .replace("rod_length = 0.312", "rod_length = 0.31512");
    let rig = dir.join("my-rig.toml");
    std::fs::write(&rig, own).unwrap();
    let rig = rig.to_str().unwrap();
    ringpod().args(["rig", "check", rig]).assert().success().stdout(
        predicate::str::contains("my-rig: analysable: yes")
            .and(predicate::str::contains("drivable: yes"))
            .and(predicate::str::contains("surge")),
    );
    let pose = "--pose=0.02,-0.01,0.23,0.05,-0.04,1.2";
    let ours = json(&["ik", "--geometry", rig, pose, "--json"]);
    let preset = json(&["ik", pose, "--json"]);
    assert_eq!(ours["mechanism"], "my-rig");
    assert_ne!(ours["actuators"], preset["actuators"]);
    let q: Vec<String> = ours["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.to_string())
        .collect();
    let fk = json(&[
        "fk",
        "--geometry",
        rig,
        &format!("--actuators={}", q.join(",")),
        "--json",
    ]);
    let want = [0.02, -0.01, 0.23, 0.05, -0.04, 1.2];
    for (g, w) in fk["pose"].as_array().unwrap().iter().zip(want) {
        assert!((g.as_f64().unwrap() - w).abs() < 1e-6, "{fk}");
    }
    ringpod().args(["check", "--geometry", rig, pose]).assert().code(0);
    ringpod()
        .args(["check", "--geometry", rig, "--pose=0,-0.1,0.227,0,0,0"])
        .assert()
        .code(3);
    let svg = dir.join("w.svg");
    ringpod()
        .args([
            "workspace",
            "--geometry",
            rig,
            "--cells",
            "40",
            "--quiet",
            "--out",
            svg.to_str().unwrap(),
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("my-rig spec ranges"));
    // A broken file says which key and why.
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        text.replace("kind = \"radial\"\n", "kind = \"radial\"\nbranch = \"plus\"\n"),
    )
    .unwrap();
    ringpod()
        .args(["ik", "--geometry", bad.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains(
            "chains[2].branch: only rod chains have a branch",
        ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `loads --input`: along a motion the peak demand of each axis; for a motion that stands still it is the statics,
/// and moving costs more than standing; a pose with no solution is reported with its line (exit 3).
#[test]
fn loads_along_a_motion_report_the_peak_demand() {
    let dir = std::env::temp_dir().join(format!("ringpod-demand-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let still = dir.join("still.csv");
    let mut text = String::from("t,x,y,z,alpha,beta,gamma\n");
    for i in 0..20 {
        text += &format!("{},0.01,-0.02,0.23,0.1,-0.05,0.7\n", f64::from(i) * 0.01);
    }
    std::fs::write(&still, &text).unwrap();
    let at_rest = json(&["loads", "--pose=0.01,-0.02,0.23,0.1,-0.05,0.7", "--mass", "2", "--json"]);
    // 2 kg is more than the model's FL20s hold even at rest: exit 3, with the report.
    let with_code = |args: &[&str], code: i32| -> serde_json::Value {
        let out = ringpod().args(args).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(code),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let along = with_code(
        &["loads", "--input", still.to_str().unwrap(), "--mass", "2", "--json"],
        3,
    );
    for k in 0..6 {
        let (a, b) = (
            along["peak_demand"][k].as_f64().unwrap(),
            at_rest["drives"][k].as_f64().unwrap(),
        );
        assert!((a - b.abs()).abs() < 1e-9, "axis {k}: {a} vs {b}");
    }
    // The same poses fast (2 Hz heave, 0.8 g at the extremes, yawing 1.9 rad/s) and a hundred times slower.
    let write = |path: &std::path::Path, slow: f64| {
        let mut text = String::from("t,x,y,z,alpha,beta,gamma\n");
        for i in 0..1000 {
            let t = f64::from(i) * 0.002;
            let z = 0.227 + 0.02 * (std::f64::consts::TAU * 2.0 * t).sin();
            text += &format!("{},0,0,{z},0,0,{}\n", t * slow, 1.9 * t);
        }
        std::fs::write(path, &text).unwrap();
        text
    };
    let (moving, slowly) = (dir.join("moving.csv"), dir.join("slowly.csv"));
    let mut text = write(&moving, 1.0);
    write(&slowly, 100.0);
    // The model's FL20s cannot carry 2 kg this fast: the command says so with exit 3, and still reports.
    let fast = with_code(
        &[
            "loads",
            "--input",
            moving.to_str().unwrap(),
            "--mass",
            "2",
            "--inertia=0.02,0.02,0.04",
            "--json",
        ],
        3,
    );
    let slow = with_code(
        &[
            "loads",
            "--input",
            slowly.to_str().unwrap(),
            "--mass",
            "2",
            "--inertia=0.02,0.02,0.04",
            "--json",
        ],
        3,
    );
    assert_eq!(fast["drives_keep_up"], false);
    for k in 0..6 {
        let d = &fast["drives"][k];
        let (margin, demand, available) = (
            d["margin"].as_f64().unwrap(),
            d["demand"].as_f64().unwrap(),
            d["available"].as_f64().unwrap(),
        );
        assert!((margin - available / demand).abs() < 1e-12, "{d}");
        assert!(margin < 1.0 && d["rows_over"].as_u64().unwrap() > 0, "{d}");
    }
    // 2 mm per turn at 0.25 m/s (the heave's peak speed) is 7,500 rpm: beyond the motor's curve, nothing left.
    assert_eq!(fast["drives"][4]["available"].as_f64(), Some(0.0));
    let peak = |v: &serde_json::Value, k: usize| v["peak_demand"][k].as_f64().unwrap();
    assert!((0..6).all(|k| peak(&fast, k) >= peak(&slow, k)), "{fast} vs {slow}");
    assert!(
        (0..6).any(|k| peak(&fast, k) > 1.3 * peak(&slow, k)),
        "{fast} vs {slow}"
    );
    text += "2.0,0,0,0.9,0,0,3.8\n";
    std::fs::write(&moving, &text).unwrap();
    ringpod()
        .args(["loads", "--input", moving.to_str().unwrap(), "--mass", "2"])
        .assert()
        .code(3)
        .stdout(predicate::str::contains("line 1002"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A light payload moved gently keeps every FL20 inside its curve (exit 0); a rig file's own drives replace the
/// preset's, and a rig without drives reports no margin.
#[test]
fn loads_set_the_motion_against_the_drives_of_the_rig() {
    let dir = std::env::temp_dir().join(format!("ringpod-drives-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gentle = dir.join("gentle.csv");
    let mut text = String::from("t,x,y,z,alpha,beta,gamma\n");
    for i in 0..500 {
        let t = f64::from(i) * 0.01;
        let z = 0.227 + 0.01 * (std::f64::consts::TAU * 0.2 * t).sin();
        text += &format!("{t},0,0,{z},0,0,{}\n", 0.3 * t);
    }
    std::fs::write(&gentle, &text).unwrap();
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = ["loads", "--input", gentle.to_str().unwrap(), "--mass", "0.05", "--json"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let preset = json(&args(&[]).iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(preset["drives_keep_up"], true, "{preset}");
    assert!((0..6).all(|k| preset["drives"][k]["margin"].as_f64().unwrap() >= 1.0));
    // The same rig as a file, its drives halved: the margins halve (the demand is the same).
    let exported = ringpod()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    let rig = String::from_utf8(exported.stdout).unwrap();
    assert!(rig.contains("[[drives]]"), "{rig}");
    let halved = rig.replace("efficiency = 0.9", "efficiency = 0.45");
    let file = dir.join("rig.toml");
    std::fs::write(&file, &halved).unwrap();
    let out = ringpod()
        .args(args(&["--geometry", file.to_str().unwrap()]))
        .output()
        .unwrap();
    let own: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for k in 0..4 {
        let (a, b) = (
            preset["drives"][k]["margin"].as_f64().unwrap(),
            own["drives"][k]["margin"].as_f64().unwrap(),
        );
        assert!((b - a / 2.0).abs() < 1e-9 * a, "axis {k}: {a} vs {b}");
    }
    // Without [[drives]]: peak demand only, no margin, exit 0.
    let start = halved.find("[[drives]]").unwrap();
    std::fs::write(&file, &halved[..start]).unwrap();
    let bare = json(
        &args(&["--geometry", file.to_str().unwrap()])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!((0..6).all(|k| bare["drives"][k].is_null()), "{bare}");
    // A drive that names a missing axis is refused with its key.
    std::fs::write(&file, halved.replacen("axes = [5, 6]", "axes = [5, 7]", 1)).unwrap();
    ringpod()
        .args(args(&["--geometry", file.to_str().unwrap()]))
        .assert()
        .code(1)
        .stderr(predicate::str::contains("drives[1].axes"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `stream --check-loads` predicts the drive demand before moving: a payload the FL20s cannot carry through the
/// yaw motion is not streamed (exit 1) and the report says which axes and from when; a light one streams.
#[test]
fn stream_check_loads_refuses_a_motion_the_motors_cannot_carry() {
    let run = |mass: &str| {
        ringpod()
            .args([
                "stream",
                "--sim",
                "--fast",
                "--motion",
                "yaw",
                "--duration",
                "3",
                "--quiet",
            ])
            .args(["--check-loads", "--mass", mass, "--report-json"])
            .output()
            .unwrap()
    };
    let heavy = run("0.5");
    let said = String::from_utf8_lossy(&heavy.stderr);
    assert_eq!(heavy.status.code(), Some(1), "{said}");
    assert!(heavy.stdout.is_empty(), "a refused stream sends nothing");
    for axis in 1..=4 {
        assert!(
            said.contains(&format!("axis {axis}: over its drive from t = 0.000 s")),
            "{said}"
        );
    }
    assert!(said.contains("not streamed"), "{said}");
    let light = run("0.02");
    let said = String::from_utf8_lossy(&light.stderr);
    assert_eq!(light.status.code(), Some(0), "{said}");
    assert_eq!(said.matches("keeps up").count(), 6, "{said}");
    let report: serde_json::Value = serde_json::from_slice(&light.stdout).unwrap();
    assert_eq!(report["setpoints_sent"], 3001);
    // --mass belongs to --check-loads, and --check-loads needs it.
    ringpod().args(["stream", "--sim", "--check-loads"]).assert().code(2);
}

/// `reactions`: a downward load at the tool of the tool carrier at its home pose is carried half by each frame
/// pivot, the X carriage carries the X force; ring platforms are pointed to `loads`; a bad wrench is refused.
#[test]
fn reactions_share_a_tool_load_between_the_pivots() {
    let v = json(&[
        "reactions",
        "-m",
        "tool5-ex",
        "--pose=0,0,0.4,0,0,0",
        "--wrench=7,0,-100,0,0,0",
        "--json",
    ]);
    let f = |k: usize, i: usize| v["pivot_forces"][k][i].as_f64().unwrap();
    assert!((f(0, 2) + f(1, 2) - 100.0).abs() < 1e-9, "{v}");
    assert!((f(0, 2) - f(1, 2)).abs() < 1e-9, "{v}");
    assert!((v["drives"][0].as_f64().unwrap() + 7.0).abs() < 1e-9, "{v}");
    assert_eq!(v["drive_names"][4], "q5 pitch");
    ringpod()
        .args(["reactions", "--wrench=0,0,-1,0,0,0"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("ringpod loads"));
    ringpod()
        .args(["reactions", "-m", "tool5-ex", "--wrench=0,0,nan,0,0,0"])
        .assert()
        .code(1);
    ringpod()
        .args([
            "reactions",
            "-m",
            "tool5-ex",
            "--pose=0,0,0.4,0,0,0.2",
            "--wrench=0,0,-1,0,0,0",
        ])
        .assert()
        .code(1);
}

/// `stream --record` writes a row per telemetry sample (every 10 ms of device time), the commanded and followed
/// poses agree at rest, limits show as flags; `plot` draws the record; an unwritable record fails the stream
/// before it starts.
#[test]
fn a_recorded_run_has_a_row_every_10_ms_and_plots() {
    let dir = std::env::temp_dir().join(format!("ringpod-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Heave beyond the model's 40 mm: limited.
    let input = dir.join("poses.csv");
    let mut text = String::from("t,x,y,z,alpha,beta,gamma\n");
    for i in 0..=300 {
        let t = f64::from(i) * 0.01;
        text += &format!(
            "{t},0,0,{},0,0,0\n",
            0.227 + 0.08 * (std::f64::consts::PI * t / 3.0).sin()
        );
    }
    std::fs::write(&input, text).unwrap();
    let record = dir.join("run.csv");
    let out = ringpod()
        .args([
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--report-json",
            "--device-limits-only",
        ])
        .args(["--input", input.to_str().unwrap(), "--record", record.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = std::fs::read_to_string(&record).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 30, "28 columns and aux1, aux2");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(report["record"]["rows"].as_u64(), Some(rows.len() as u64));
    assert_eq!(report["record"]["dropped"], 0);
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let device: Vec<f64> = rows.iter().map(|r| r[col("device_s")].parse().unwrap()).collect();
    assert!(
        device.windows(2).all(|w| (w[1] - w[0] - 0.01).abs() < 1e-9),
        "a row every 10 ms"
    );
    let states: Vec<&str> = rows.iter().map(|r| r[col("state")]).collect();
    for s in ["LogicOn", "Homing", "Ready", "Running"] {
        assert!(states.contains(&s), "{s} missing");
    }
    let limited = rows.iter().filter(|r| r[col("limited")] == "1").count();
    assert!(limited > 0, "the heave crest was limited: flags show it");
    let last = rows.last().unwrap();
    assert_eq!(last[col("limited_total")], report["limited"]["device"].to_string());
    let png = dir.join("run.png");
    ringpod()
        .args(["plot", record.to_str().unwrap(), "--out", png.to_str().unwrap()])
        .assert()
        .success()
        .stdout(predicate::str::contains("limited stretches"));
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    ringpod()
        .args(["plot", input.to_str().unwrap(), "--out", png.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("no column"));
    ringpod()
        .args([
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--motion",
            "demo",
            "--duration",
            "1",
        ])
        .args(["--record", dir.join("no/such/dir/run.csv").to_str().unwrap()])
        .assert()
        .code(1);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `monitor` on a pseudo-terminal: it takes the terminal (alternate screen), draws the simulated controller's
/// telemetry (state Off, the supplies, every axis), and gives the terminal back when it ends.
#[test]
#[cfg(unix)]
fn monitor_draws_the_device_on_a_pseudo_terminal() {
    use std::io::Read;
    use std::os::fd::AsFd;
    let pty = nix::pty::openpty(
        Some(&nix::pty::Winsize {
            ws_row: 30,
            ws_col: 110,
            ws_xpixel: 0,
            ws_ypixel: 0,
        }),
        None,
    )
    .unwrap();
    let tty = || std::process::Stdio::from(pty.slave.as_fd().try_clone_to_owned().unwrap());
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["monitor", "--sim", "--frames", "12"])
        .stdin(tty())
        .stdout(tty())
        .stderr(tty())
        .spawn()
        .unwrap();
    // Read the screen while the monitor runs (a full pty buffer would block it).
    let mut master = std::fs::File::from(pty.master);
    let reader = std::thread::spawn(move || {
        let mut screen = Vec::new();
        let mut buf = [0u8; 4096];
        while let Ok(n) = master.read(&mut buf) {
            if n == 0 {
                break;
            }
            screen.extend_from_slice(&buf[..n]);
            if screen.windows(8).any(|w| w == b"\x1b[?1049l") {
                break; // left the alternate screen: done
            }
        }
        String::from_utf8_lossy(&screen).into_owned()
    });
    let status = child.wait().unwrap();
    drop(pty.slave);
    let screen = reader.join().unwrap();
    assert!(status.success(), "{screen}");
    assert!(screen.contains("\x1b[?1049h"), "the monitor takes the alternate screen");
    assert!(screen.contains("\x1b[?1049l"), "and gives it back");
    // The terminal gets the words with cursor moves between them.
    for want in [
        "ringpod",
        "monitor:",
        " Off ",
        "LOGIC_EN",
        "POWER_OK",
        "switches",
        "telemetry",
        "received",
    ] {
        assert!(screen.contains(want), "{want:?} not drawn: {screen}");
    }
}

/// `device inputs` lists every input with its pin level, polarity and state.
#[test]
fn device_inputs_lists_every_input() {
    let out = ringpod().args(["device", "inputs", "--sim"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 16, "{text}");
    for name in ["e-stop", "home 1", "home 6", "end 6", "LOGIC_OK", "POWER_OK"] {
        assert!(text.contains(name), "{name} missing: {text}");
    }
    ringpod()
        .args(["device", "status", "--watch", "--sim"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("--watch is for `device inputs`"));
}

/// `device inputs --watch | head -1`: the reader goes away while no input changes and nothing is printed; the
/// watch notices the closed pipe anyway and ends within a second or two with the closed output's exit (141).
#[test]
#[cfg(unix)]
fn device_inputs_watch_ends_when_its_reader_goes_away_while_nothing_changes() {
    use std::io::BufRead;
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["device", "inputs", "--watch", "--sim"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = std::io::BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    assert!(!line.is_empty(), "the table's first line");
    drop(stdout);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the watch still runs 5 s after its reader went away");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut said = String::new();
    let _ = std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut said);
    assert_eq!(status.code(), Some(141), "{said}");
    assert!(said.contains("standard output: Broken pipe"), "{said}");
}

/// Numbers a user gave come back in messages at a bounded width: 1e-300 as `1e-300`, never as 300 digits.
#[test]
fn messages_show_tiny_and_huge_numbers_at_a_bounded_width() {
    let picture = std::env::temp_dir().join(format!("ringpod-width-{}.png", std::process::id()));
    let picture = picture.to_str().unwrap();
    let rig = std::env::temp_dir().join(format!("ringpod-width-{}.toml", std::process::id()));
    let exported = ringpod()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    let text = String::from_utf8(exported.stdout).unwrap();
    let tiny = text
        .lines()
        .map(|l| {
            if l.starts_with("ring_radius =") {
                "ring_radius = 1e-300"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&rig, tiny).unwrap();
    let rig = rig.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["rig", "check", rig], "ring radius 1e-300 m"),
        (&["gram", "--step", "1e-300", "--out", picture], "--step 1e-300: "),
        (&["device", "jog", "1", "1e-300", "--sim"], "1e-300 deg is 0 steps"),
        (&["device", "jog", "1", "1e300", "--sim"], "1e300 deg is out of range"),
        (&["loads", "--mass", "1e-300"], "holding 1e-300 kg"),
        (
            &[
                "stream",
                "--sim",
                "--fast",
                "--motion",
                "sine",
                "--axis",
                "z",
                "--frequency",
                "1e-308",
                "--amplitude",
                "0.01",
                "--duration",
                "0.05",
            ],
            "sine on z at 1e-308 Hz",
        ),
    ];
    for (args, want) in cases {
        let out = ringpod().args(args).output().unwrap();
        let said = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        assert!(said.contains(want), "{args:?}: {said}");
        assert!(said.lines().all(|l| l.len() < 250), "{args:?}: {said}");
    }
}

/// A jog of nothing (0, or a distance under one motor step) is refused as such, naming one step's distance, not
/// called further than a jog goes: a jog checks a motor's direction and scale, and a move of no step checks neither.
#[test]
fn a_jog_of_no_step_says_so() {
    for distance in ["0", "-0", "0.00001"] {
        let out = ringpod()
            .args(["device", "jog", "1", distance, "--sim"])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{said}");
        assert!(
            said.contains("deg is 0 steps: a jog moves at least one step ("),
            "{said}"
        );
        assert!(!said.contains("further"), "{said}");
    }
}

/// An option that only one kind of source reads is refused with the others, by clap (exit 2, naming both), rather
/// than accepted and doing nothing: a file has no --duration, --rate, sine or telemetry options, a built-in motion
/// no --degrees, --udp-idle or --mass check from a live source; the simulator's options are not the board's.
#[test]
fn options_that_would_do_nothing_are_refused_naming_both() {
    let file = std::env::temp_dir().join(format!("ringpod-unused-{}.csv", std::process::id()));
    std::fs::write(&file, "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n").unwrap();
    let file = file.to_str().unwrap();
    fn stream<'a>(source: &[&'a str], option: &[&'a str]) -> Vec<&'a str> {
        let mut args = vec!["stream", "--sim", "--fast", "--quiet"];
        args.extend(source);
        args.extend(option);
        args
    }
    let input = ["--input", file];
    let motion = ["--motion", "heave"];
    let udp = ["--udp", "127.0.0.1:0"];
    let telemetry = ["--telemetry-udp", "127.0.0.1:0"];
    let cases: Vec<(Vec<&str>, [&str; 2])> = vec![
        (stream(&input, &["--duration", "5"]), ["--input", "--duration"]),
        (stream(&input, &["--rate", "10"]), ["--input", "--rate"]),
        (stream(&input, &["--profile", "wet"]), ["--input", "--profile"]),
        (stream(&input, &["--axis", "z"]), ["--input", "--axis"]),
        (stream(&input, &["--frequency", "1"]), ["--input", "--frequency"]),
        (stream(&input, &["--amplitude", "0.01"]), ["--input", "--amplitude"]),
        (
            stream(&input, &["--velocity-amplitude", "0.01"]),
            ["--input", "--velocity-amplitude"],
        ),
        (stream(&input, &["--udp-idle", "3"]), ["--input", "--udp-idle"]),
        (
            stream(&input, &["--telemetry-format", "beamng"]),
            ["--input", "--telemetry-format"],
        ),
        (stream(&motion, &["--degrees"]), ["--motion", "--degrees"]),
        (
            stream(&motion, &["--outsim-opts", "1ff"]),
            ["--motion", "--outsim-opts"],
        ),
        (stream(&motion, &["--udp-idle", "3"]), ["--motion", "--udp-idle"]),
        (stream(&udp, &["--duration", "5"]), ["--udp", "--duration"]),
        (
            stream(&udp, &["--telemetry-format", "beamng"]),
            ["--udp", "--telemetry-format"],
        ),
        (stream(&udp, &["--mass", "5"]), ["--udp", "--mass"]),
        (stream(&telemetry, &["--degrees"]), ["--telemetry-udp", "--degrees"]),
        (stream(&telemetry, &["--rate", "10"]), ["--telemetry-udp", "--rate"]),
        (
            vec!["stream", "--port", "/dev/null", "--fast", "--motion", "heave"],
            ["--port", "--fast"],
        ),
        (
            vec![
                "stream",
                "--port",
                "/dev/null",
                "--mechanism",
                "trainer-model",
                "--motion",
                "heave",
            ],
            ["--port", "--mechanism"],
        ),
        (
            vec![
                "loads",
                "--mass",
                "5",
                "--pose",
                "0,0,0.227,0,0,0",
                "--inertia",
                "1,1,1",
            ],
            ["--pose", "--inertia"],
        ),
    ];
    for (args, [a, b]) in cases {
        let out = ringpod().args(&args).output().unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {said}");
        assert!(
            said.contains("cannot be used with") && said.contains(&format!("'{a}")) && said.contains(&format!("'{b}")),
            "{args:?}: {said}"
        );
    }
}

/// `rates`: the velocity problem against finite differences of IK (actuator rates for pose rates) and of FK (pose
/// rates for actuator rates), on the trainer model, the rotopod and chapter 5's trainer; the angular velocity of
/// a pure yaw rate is that rate about z.
#[test]
fn rates_agree_with_finite_differences_of_ik_and_fk() {
    let six =
        |v: &serde_json::Value| -> Vec<f64> { v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect() };
    let list = |v: &[f64]| v.iter().map(|x| format!("{x:.12}")).collect::<Vec<_>>().join(",");
    let h = 1e-6;
    for (mechanism, pose, rates) in [
        (
            "trainer-model",
            [0.01, -0.02, 0.23, 0.05, -0.04, 0.7],
            [0.02, -0.01, 0.015, 0.1, -0.2, 0.5],
        ),
        (
            "rotopod-ch4",
            [0.05, 0.02, 0.7, 0.03, 0.02, 0.1],
            [0.1, 0.05, -0.02, 0.2, 0.1, -0.3],
        ),
        (
            "trainer-ch5",
            [0.1, 0.0, 1.0, 0.0, 0.0, 0.0],
            [0.1, 0.05, 0.05, 0.02, 0.1, 0.2],
        ),
    ] {
        let at = |s: f64| -> Vec<f64> {
            let p: Vec<f64> = pose.iter().zip(rates).map(|(p, r)| p + s * r).collect();
            six(&json(&[
                "ik",
                "--mechanism",
                mechanism,
                &format!("--pose={}", list(&p)),
                "--json",
            ])["actuators"])
        };
        let (plus, minus) = (at(h), at(-h));
        let got = json(&[
            "rates",
            "--mechanism",
            mechanism,
            &format!("--pose={}", list(&pose)),
            &format!("--pose-rates={}", list(&rates)),
            "--json",
        ]);
        let qd = six(&got["actuator_rates"]);
        for i in 0..6 {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (qd[i] - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                "{mechanism} q{}: {} vs {fd}",
                i + 1,
                qd[i]
            );
        }
        assert!(got["condition_a"].as_f64().unwrap() >= 1.0 && got["condition_b"].as_f64().unwrap() >= 1.0);
        // Back: the actuator rates give the pose rates, and FK along them moves the pose by them.
        let back = json(&[
            "rates",
            "--mechanism",
            mechanism,
            &format!("--pose={}", list(&pose)),
            &format!("--actuator-rates={}", list(&qd)),
            "--json",
        ]);
        let pd = six(&back["pose_rates"]);
        let q = at(0.0);
        let fk = |s: f64| -> Vec<f64> {
            let a: Vec<f64> = q.iter().zip(&qd).map(|(q, r)| q + s * r).collect();
            six(&json(&[
                "fk",
                "--mechanism",
                mechanism,
                &format!("--actuators={}", list(&a)),
                &format!("--guess={}", list(&pose)),
                "--anywhere",
                "--json",
            ])["pose"])
        };
        let (plus, minus) = (fk(h), fk(-h));
        for i in 0..6 {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            assert!((pd[i] - rates[i]).abs() < 1e-6, "{mechanism} round trip {i}: {pd:?}");
            assert!(
                (pd[i] - fd).abs() < 1e-4 * (1.0 + fd.abs()),
                "{mechanism} FK {i}: {} vs {fd}",
                pd[i]
            );
        }
    }
    let yaw = json(&["rates", "--pose-rates=0,0,0,0,0,0.5", "--json"]);
    assert_eq!(six(&yaw["angular_velocity"]), [0.0, 0.0, 0.5]);
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn structure_prints_the_sources_chain_determinants() {
    for (chain, published, unit) in [
        ("fig5.1", -0.2, -0.2),
        ("fig5.1-singular", 0.0, 0.0),
        ("fig5.2", -0.25, -0.25),
        ("fig5.3", 0.625, 0.559017),
    ] {
        let v = json(&["structure", "--chain", chain, "--json"]);
        let c = &v["chains"][0];
        let det = c["determinant"].as_f64().unwrap();
        assert!((det - published).abs() < 1e-9, "{chain}: {det}");
        assert!((c["determinant_unit"].as_f64().unwrap() - unit).abs() < 1e-6, "{chain}");
        assert_eq!(v["published"].as_f64().unwrap(), published);
        assert_eq!(v["mobility"]["w"], 6, "{chain}: one open chain of six freedoms");
        assert_eq!(c["unit_screws"].as_array().unwrap().len(), 6);
        assert!(v["determinant"].is_null(), "one chain has no mechanism determinant");
    }
    let text = ringpod().args(["structure", "--chain", "fig5.1"]).output().unwrap();
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("determinant -0.200000"), "{text}");
    assert!(text.contains("the source prints -0.2"), "{text}");
}

/// The trainer of chapter 5: W = 6 (8 without the pins), four chains of six unit screws, every transmitted wrench
/// reciprocal to its chain's unactuated joints, the rods' lines through the carriages IK places, and the wrench
/// determinant -8.065 (the source's -3.945 has a sign typo in row 4; corrected, its rounded matrix gives -8.04).
#[test]
fn structure_of_the_trainer_agrees_with_the_source_and_ik() {
    let pose = "--pose=0.1,-0.05,1,0.05,-0.03,0.4";
    let v = json(&["structure", "--mechanism", "trainer-ch5", pose, "--json"]);
    assert_eq!(v["mobility"]["w"], 6);
    assert_eq!(v["mobility"]["without_pins"], 8);
    assert_eq!(v["mobility"]["moving_links"], 11);
    let chains = v["chains"].as_array().unwrap();
    assert_eq!(chains.len(), 4);
    let q = numbers(&json(&["ik", "--mechanism", "trainer-ch5", pose, "--json"])["actuators"]);
    for (i, c) in chains.iter().enumerate() {
        let screws: Vec<Vec<f64>> = c["unit_screws"].as_array().unwrap().iter().map(numbers).collect();
        let driven: Vec<bool> = c["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().ends_with('*'))
            .collect();
        assert_eq!(screws.len(), 6);
        for w in c["wrenches"].as_array().unwrap().iter().map(numbers) {
            for (t, d) in screws.iter().zip(&driven) {
                let work: f64 = (0..3).map(|k| t[k] * w[k + 3] + t[k + 3] * w[k]).sum();
                if !d {
                    assert!(work.abs() < 1e-9, "chain {i}: {work}");
                }
            }
        }
        // The carriage of IK: B = 3 (cos q, sin q, 0). A rod chain's wrench is a line through B.
        if i < 2 {
            let w = numbers(&c["wrenches"][0]);
            let b = [3.0 * q[i].cos(), 3.0 * q[i].sin(), 0.0];
            let m = [
                b[1] * w[2] - b[2] * w[1],
                b[2] * w[0] - b[0] * w[2],
                b[0] * w[1] - b[1] * w[0],
            ];
            for k in 0..3 {
                assert!((m[k] - w[k + 3]).abs() < 1e-9, "chain {i}: {w:?} not through {b:?}");
            }
        }
    }
    let home = json(&[
        "structure",
        "--mechanism",
        "trainer-ch5",
        "--pose=0,0,1,0,0,0",
        "--json",
    ]);
    let det = home["determinant"].as_f64().unwrap();
    assert!((det + 8.064855).abs() < 1e-5, "{det}");
    for preset in ["trainer-model", "rotopod-ch4", "tool5-ex"] {
        let v = json(&["structure", "--mechanism", preset, "--json"]);
        assert!(v["determinant"].as_f64().unwrap().abs() > 1e-6, "{preset}");
        let w = if preset == "tool5-ex" { 5 } else { 6 };
        assert_eq!(v["mobility"]["w"], w, "{preset}");
    }
}

#[test]
fn structure_refuses_bad_input_in_one_line() {
    for args in [
        &["structure", "--mechanism", "trainer-ch5", "--pose=0,0,5,0,0,0"][..],
        &["structure", "--mechanism", "nothing"][..],
        &["structure", "--pose=0,0,nan,0,0,0"][..],
    ] {
        let out = ringpod().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ringpod: "), "{err}");
    }
    ringpod()
        .args(["structure", "--chain", "fig5.9"])
        .assert()
        .failure()
        .stderr(predicate::str::contains("possible values"));
}

/// A run record with the 28 columns of `stream --record`, the followed pose `pose(t)` every `dt` seconds.
fn synthetic_record(path: &std::path::Path, seconds: f64, dt: f64, pose: impl Fn(f64) -> [f64; 6]) {
    let mut text = String::from(
        "host_s,device_s,cmd_x,cmd_y,cmd_z,cmd_alpha,cmd_beta,cmd_gamma,x,y,z,alpha,beta,gamma,steps_1,steps_2,\
         steps_3,steps_4,steps_5,steps_6,state,limited,refused,held,applied,limited_total,refused_total,tick_cost\n",
    );
    for i in 0..=(seconds / dt).round() as usize {
        let t = i as f64 * dt;
        let p = pose(t).map(|v| v.to_string()).join(",");
        text += &format!("{t},{t},{p},{p},0,0,0,0,0,0,Running,0,0,0,{i},0,0,0\n");
    }
    std::fs::write(path, text).unwrap();
}

/// The peak |velocity| and |acceleration| `plot --derivatives` prints for an axis.
fn peaks(summary: &str, axis: &str) -> (f64, f64) {
    let line = summary.lines().find(|l| l.starts_with(axis)).unwrap();
    let words: Vec<&str> = line[axis.len()..].split_whitespace().collect();
    (words[0].parse().unwrap(), words[2].parse().unwrap())
}

/// `plot --derivatives` reads a 2 Hz, 10 mm heave's velocity (0.1257 m/s) and acceleration (1.579 m/s^2) from a
/// 100 Hz record within 1 %, the other axes at rest; a yaw at 1.9 rad/s as 1.9 rad/s; a real run's heave motion
/// at its 31.4 mm/s.
#[test]
fn plot_derivatives_reads_velocity_and_acceleration_from_a_record() {
    let dir = std::env::temp_dir().join(format!("ringpod-derivatives-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let w = std::f64::consts::TAU * 2.0;
    let record = dir.join("sine.csv");
    synthetic_record(&record, 3.0, 0.01, |t| {
        [0.0, 0.0, 0.227 + 0.01 * (w * t).sin(), 0.0, 0.0, 1.9 * t]
    });
    let svg = dir.join("sine.svg");
    let out = ringpod()
        .args([
            "plot",
            record.to_str().unwrap(),
            "--derivatives",
            "--out",
            svg.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary = String::from_utf8(out.stdout).unwrap();
    let (v, a) = peaks(&summary, "heave z");
    assert!((v / (0.01 * w) - 1.0).abs() < 0.01, "{v}\n{summary}");
    assert!((a / (0.01 * w * w) - 1.0).abs() < 0.01, "{a}\n{summary}");
    assert_eq!(peaks(&summary, "surge x"), (0.0, 0.0));
    let (yaw_rate, yaw_acceleration) = peaks(&summary, "yaw gamma");
    assert!((yaw_rate - 1.9).abs() < 1e-6 && yaw_acceleration < 1e-6, "{summary}");
    let picture = std::fs::read_to_string(&svg).unwrap();
    for label in ["velocity: translation", "acceleration: rotation", "heave z", "m/s^2"] {
        assert!(picture.contains(label), "{label} not in the picture");
    }
    // A real run: the simulated controller following the 10 mm, 0.5 Hz heave motion.
    let run = dir.join("run.csv");
    ringpod()
        .args([
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--motion",
            "heave",
            "--duration",
            "6",
        ])
        .args(["--record", run.to_str().unwrap()])
        .assert()
        .success();
    let out = ringpod()
        .args([
            "plot",
            run.to_str().unwrap(),
            "--derivatives",
            "--out",
            svg.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let summary = String::from_utf8(out.stdout).unwrap();
    let (v, _) = peaks(&summary, "heave z");
    assert!((v / (0.01 * std::f64::consts::PI) - 1.0).abs() < 0.05, "{v}\n{summary}");
    // Bad windows: one line, exit 1.
    for window in ["0", "-1", "nan"] {
        let out = ringpod()
            .args([
                "plot",
                record.to_str().unwrap(),
                "--derivatives",
                "--out",
                svg.to_str().unwrap(),
            ])
            .arg(format!("--window={window}"))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{window}");
        assert_eq!(String::from_utf8(out.stderr).unwrap().lines().count(), 1);
    }
    // A stretch of it: a quarter period around the heave's zero crossing at 1 s holds its peak velocity, the
    // stretch around its crest at 1.125 s does not; an empty span or one outside the record is refused.
    let stretch = |from: &str, to: &str| {
        ringpod()
            .args([
                "plot",
                record.to_str().unwrap(),
                "--derivatives",
                "--out",
                svg.to_str().unwrap(),
            ])
            .args(["--from", from, "--to", to])
            .output()
            .unwrap()
    };
    let crossing = String::from_utf8(stretch("0.95", "1.05").stdout).unwrap();
    assert!(
        crossing.contains("drawn and measured from 0.950 to 1.050 s (11 samples)"),
        "{crossing}"
    );
    let (v, _) = peaks(&crossing, "heave z");
    assert!((v / (0.01 * w) - 1.0).abs() < 0.01, "{crossing}");
    let crest = String::from_utf8(stretch("1.11", "1.14").stdout).unwrap();
    let (v, _) = peaks(&crest, "heave z");
    assert!(v < 0.2 * 0.01 * w, "{crest}");
    for (from, to) in [("2", "1"), ("10", "20"), ("nan", "1")] {
        assert_eq!(stretch(from, to).status.code(), Some(1), "{from} {to}");
    }
}

/// `plot --derivatives` of a record too short for a derivative says so of the record when no span was asked
/// (no `--from`/`--to` it was not given), and names only the span's ends that were given when one was.
#[test]
fn plot_derivatives_names_only_the_options_given() {
    let dir = std::env::temp_dir().join(format!("ringpod-short-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let record = dir.join("one.csv");
    let header = "host_s,device_s,cmd_x,cmd_y,cmd_z,cmd_alpha,cmd_beta,cmd_gamma,x,y,z,alpha,beta,gamma,steps_1,\
                  steps_2,steps_3,steps_4,steps_5,steps_6,state,limited,refused,held,applied,limited_total,\
                  refused_total,tick_cost,aux1,aux2";
    let row = "0.066,0.010,0,0,0.227,0,0,0,0,0,0.227,0,0,0,0,0,0,0,0,0,LogicOn,0,0,0,0,0,0,821,0,0";
    std::fs::write(&record, format!("{header}\n{row}\n")).unwrap();
    let plot = |span: &[&str]| {
        let out = ringpod()
            .arg("plot")
            .arg(&record)
            .args(["--derivatives", "--out"])
            .arg(dir.join("d.svg"))
            .args(span)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        String::from_utf8(out.stderr).unwrap()
    };
    let said = plot(&[]);
    assert!(
        said.contains("one.csv: 1 sample: a derivative needs at least 2"),
        "{said}"
    );
    assert!(!said.contains("--from") && !said.contains("--to"), "{said}");
    let said = plot(&["--from", "3"]);
    assert!(said.contains("--from 3: 0 of the record's samples"), "{said}");
    assert!(!said.contains("--to"), "{said}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `stream --motion sine`: chapter 5.2's 18.8 Hz at 0.008 m/s and 25 Hz at 0.001 m/s run as asked (inside the
/// model's 1 m/s^2); a velocity amplitude beyond the acceleration limit is cut to it, saying by how much; a 1 Hz
/// sine's record reads its velocity amplitude back through `plot --derivatives`.
#[test]
fn sine_experiments_run_as_asked_or_say_how_they_were_limited() {
    let sine = |axis: &str, hz: &str, amplitude: &[&str], seconds: &str, extra: &[&str]| {
        let out = ringpod()
            .args([
                "stream",
                "--sim",
                "--fast",
                "--quiet",
                "--motion",
                "sine",
                "--axis",
                axis,
                "--frequency",
                hz,
            ])
            .args(amplitude)
            .args(["--duration", seconds])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stderr).unwrap()
    };
    let said = sine("z", "18.8", &["--velocity-amplitude", "0.008"], "1", &[]);
    // 0.008 / (2 pi 18.8) = 6.773e-5 m, 0.008 * 2 pi 18.8 = 0.945 m/s^2.
    assert!(said.contains("amplitude 6.7726e-5 m"), "{said}");
    assert!(said.contains("acceleration 0.944991 m/s^2 (as asked"), "{said}");
    let said = sine("z", "25", &["--velocity-amplitude", "0.001"], "1", &[]);
    assert!(
        said.contains("velocity 0.001000 m/s, acceleration 0.157080 m/s^2 (as asked"),
        "{said}"
    );
    let said = sine("z", "18.8", &["--velocity-amplitude", "0.02"], "1", &[]);
    // 1 / (0.02 * 2 pi 18.8) = 42.3 % of the amplitude asked.
    assert!(
        said.contains("limited to 42.3 % of the amplitude asked, 1.6931e-4 m, by the acceleration limit of 1 m/s^2"),
        "{said}"
    );
    let said = sine("x", "0.5", &["--amplitude", "0.05"], "1", &[]);
    assert!(said.contains("by the velocity limit of 0.05 m/s"), "{said}");
    // Read back: a 1 Hz pitch at 0.3 rad/s (0.0477 rad).
    let dir = std::env::temp_dir().join(format!("ringpod-sine-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (record, png) = (dir.join("pitch.csv"), dir.join("pitch.png"));
    sine(
        "pitch",
        "1",
        &["--velocity-amplitude", "0.3"],
        "8",
        &["--record", record.to_str().unwrap()],
    );
    // The followed pose is the counted steps' pose: each step's quantisation rides on the second derivative, which a
    // window of 100 ms (attenuating a 1 Hz sine's acceleration by 0.7 %) smooths to within 8 % at the peak; over the
    // default 50 ms the peak reads 14 % high.
    let out = ringpod()
        .args([
            "plot",
            record.to_str().unwrap(),
            "--derivatives",
            "--window",
            "0.1",
            "--out",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let summary = String::from_utf8(out.stdout).unwrap();
    let (v, a) = peaks(&summary, "pitch beta");
    assert!((v / 0.3 - 1.0).abs() < 0.02, "{v}\n{summary}");
    assert!((a / (0.3 * std::f64::consts::TAU) - 1.0).abs() < 0.08, "{a}\n{summary}");
    // Parameters without a sine, a sine without them: exit 1 in one line.
    for args in [
        &[
            "stream", "--sim", "--fast", "--quiet", "--motion", "heave", "--axis", "z",
        ][..],
        &[
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--motion",
            "sine",
            "--axis",
            "z",
            "--frequency",
            "2",
        ][..],
        &[
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--motion",
            "sine",
            "--axis",
            "z",
            "--frequency=-2",
            "--amplitude",
            "0.01",
        ][..],
    ] {
        let out = ringpod().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert_eq!(String::from_utf8(out.stderr).unwrap().lines().count(), 1, "{args:?}");
    }
}

/// Standard gravity, as the tip-over check takes it.
const G: f64 = 9.80665;

#[test]
fn tip_over_of_trainer_ch5_matches_the_hand_values() {
    // KINEMATICS.md 2.1: at (0, 0, 1, 0, 0, 0) the carriages are (+-1, -sqrt 8) and (+-3/sqrt 5, 6/sqrt 5); a
    // payload 0.5 above the platform centre is 1.5 above the ring plane over the origin. An acceleration along
    // +Y throws it back onto the rear edge (sqrt 8 away): g sqrt 8 / 1.5; along -Y onto the front (6/sqrt 5).
    let v = json(&[
        "check",
        "--tip-over",
        "-m",
        "trainer-ch5",
        "--pose=0,0,1,0,0,0",
        "--payload-com=0,0,0.5",
        "--accel=3,0",
        "--json",
    ]);
    let close = |a: &serde_json::Value, b: f64| {
        let a = a.as_f64().unwrap();
        assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{a} != {b}");
    };
    let (s8, bx, by) = (8f64.sqrt(), 3.0 / 5f64.sqrt(), 6.0 / 5f64.sqrt());
    close(&v["height"], 1.5);
    assert_eq!(v["polygon"].as_array().unwrap().len(), 4);
    let dirs = v["directions"].as_array().unwrap();
    let named = |n: &str| &dirs.iter().find(|d| d["name"] == n).unwrap()["acceleration"];
    close(named("+Y"), G * s8 / 1.5);
    close(named("-Y"), G * by / 1.5);
    // The side edges, through (1, -sqrt 8) and (bx, by): the distance of the origin, and sideways the edge is
    // approached at the cosine of its normal's angle to X.
    let len = ((bx - 1.0).powi(2) + (by + s8).powi(2)).sqrt();
    let side = (by + bx * s8) / len;
    close(named("+X"), G * side / (1.5 * ((by + s8) / len)));
    close(named("-X"), G * side / (1.5 * ((by + s8) / len)));
    close(&v["static_margin"], side);
    close(&v["weakest"]["acceleration"], G * side / 1.5);
    // Under 3 m/s^2 along +X the projection moves back by 3 h / g.
    close(&v["under"]["point"][0], -3.0 * 1.5 / G);
    close(&v["under"]["point"][1], 0.0);
    assert_eq!(v["under"]["tips"], false);
    assert_eq!(v["tips"], false);
}

#[test]
fn tip_over_exits_3_when_it_tips() {
    let limit = G * 8f64.sqrt() / 1.5;
    let run = |a: f64| {
        ringpod()
            .args([
                "check",
                "--tip-over",
                "-m",
                "trainer-ch5",
                "--pose=0,0,1,0,0,0",
                "--payload-com=0,0,0.5",
                &format!("--accel=0,{a}"),
            ])
            .output()
            .unwrap()
    };
    let below = run(limit * 0.999);
    assert_eq!(below.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&below.stdout).contains("stands"));
    let above = run(limit * 1.001);
    assert_eq!(above.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&above.stdout).contains("TIPS"));
    // A centre of mass outside the polygon at rest tips without any acceleration.
    ringpod()
        .args([
            "check",
            "--tip-over",
            "-m",
            "trainer-ch5",
            "--pose=0,0,1,0,0,0",
            "--payload-com=5,0,0.5",
        ])
        .assert()
        .code(3)
        .stdout(predicate::str::contains("OUTSIDE"));
}

#[test]
fn tip_over_refuses_bad_input_in_one_line() {
    for args in [
        &["check", "--tip-over", "--accel=nan,0"][..],
        &["check", "--tip-over", "--accel=1"][..],
        &["check", "--tip-over", "--accel=1e9,0"][..],
        &["check", "--tip-over", "--payload-com=0,0"][..],
        &["check", "--tip-over", "--payload-com=0,inf,0.1"][..],
        &["check", "--tip-over", "--payload-com=0,0,-1"][..],
        &["check", "--tip-over", "-m", "tool5-ex"][..],
        &["check", "--tip-over", "-m", "trainer-ch5", "--pose=0,0,5,0,0,0"][..],
        &["check", "--tip-over", "--pose=0,0,nan,0,0,0"][..],
    ] {
        let out = ringpod().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ringpod: "), "{err}");
    }
    // The tip-over options belong to --tip-over.
    ringpod().args(["check", "--accel=1,0"]).assert().code(2);
}

#[test]
fn draw_puts_trainer_ch5s_joints_where_the_spec_does() {
    // KINEMATICS.md 2.1 at (0, 0, 1, 0, 0, 0): joints a_i + (0, 0, 1), carriages B1 = (-1, -sqrt 8),
    // B2 = (1, -sqrt 8), B3 = (3/sqrt 5, 6/sqrt 5), B4 = (-3/sqrt 5, 6/sqrt 5).
    let dir = std::env::temp_dir().join(format!("ringpod-draw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("fig.svg");
    let v = json(&[
        "draw",
        "-m",
        "trainer-ch5",
        "--pose=0,0,1,0,0,0",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    let (s8, bx, by) = (8f64.sqrt(), 3.0 / 5f64.sqrt(), 6.0 / 5f64.sqrt());
    let joints = [[-1.0, -2.0, 1.0], [1.0, -2.0, 1.0], [1.0, 2.0, 1.0], [-1.0, 2.0, 1.0]];
    let carriages = [[-1.0, -s8, 0.0], [1.0, -s8, 0.0], [bx, by, 0.0], [-bx, by, 0.0]];
    for (key, want) in [("joints", joints), ("carriages", carriages)] {
        let got = v[key].as_array().unwrap();
        assert_eq!(got.len(), 4);
        for (g, w) in got.iter().zip(want) {
            for k in 0..3 {
                let g = g[k].as_f64().unwrap();
                assert!((g - w[k]).abs() < 1e-9, "{key}: {g} vs {}", w[k]);
            }
        }
    }
    assert_eq!(v["chains"], serde_json::json!(["rod", "rod", "radial", "radial"]));
    let svg = std::fs::read_to_string(&out).unwrap();
    for label in ["A1", "A4", "B1", "B4", "X", "Y", "Z"] {
        assert!(svg.lines().any(|l| l.trim() == label), "{label} missing");
    }
    assert!(svg.contains("trainer-ch5 at x, y, z"));
    assert_eq!(svg.matches("<circle").count(), 8);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn draw_refuses_bad_input_in_one_line() {
    let dir = std::env::temp_dir().join(format!("ringpod-draw-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("fig.svg");
    let svg = svg.to_str().unwrap();
    let txt = dir.join("fig.txt");
    for args in [
        &["draw", "-m", "trainer-ch5", "--pose=0,0,5,0,0,0", "--out", svg][..],
        &["draw", "--pose=0,0,nan,0,0,0", "--out", svg][..],
        &["draw", "--pose=0,0,0.2", "--out", svg][..],
        &["draw", "-m", "tool5-ex", "--pose=0,0,0.4,0,0,0.1", "--out", svg][..],
        &["draw", "-m", "nothing", "--out", svg][..],
        &["draw", "--out", txt.to_str().unwrap()][..],
    ] {
        let out = ringpod().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ringpod: "), "{err}");
    }
    assert!(!dir.join("fig.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn draw_the_tool_carrier_at_the_sources_third_example() {
    // KINEMATICS.md 2.3: alpha = 15 deg 13', beta = 25 deg 20' gives q1 = 128.4 mm, q2 = 65 deg 01', q4 = 34 deg 22'.
    let dir = std::env::temp_dir().join(format!("ringpod-draw-tool-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("tool.svg");
    let v = json(&[
        "draw",
        "-m",
        "tool5-ex",
        "--degrees",
        &format!("--pose=0,0,0.4,{},{},0", 15.0 + 13.0 / 60.0, 25.0 + 20.0 / 60.0),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    let q = |i: usize| v["actuators"][i].as_f64().unwrap();
    assert!((q(0) - 0.1284).abs() < 1e-4, "{}", q(0));
    assert!((q(1) - (65.0 + 1.0 / 60.0)).abs() < 1.0 / 60.0, "{}", q(1));
    assert!((q(3) - (34.0 + 22.0 / 60.0)).abs() < 1.0 / 60.0, "{}", q(3));
    // The frame pivots are in the dyads' plane x = q1.
    for k in 0..2 {
        assert!((v["pivots"][k][0].as_f64().unwrap() - q(0)).abs() < 1e-12);
    }
    let svg = std::fs::read_to_string(&out).unwrap();
    for label in ["A2", "A3", "B", "D", "tool"] {
        assert!(svg.lines().any(|l| l.trim() == label), "{label} missing");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rig design --arms-only`: from the elbow trainer's rig file with arms too short for its spec, the search moves
/// only the arms, covers each spec axis (exit 0) and prints a rig file whose ring and rods are the template's; on a
/// rig without elbow chains it is refused by key, exit 1.
#[test]
fn rig_design_moves_only_the_elbow_arms_when_asked() {
    let dir = std::env::temp_dir().join(format!("ringpod-design-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let export = |preset: &str| {
        let out = ringpod().args(["presets", "--export", preset]).output().unwrap();
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    let elbow = export("trainer-elbow");
    let short = elbow
        .replace("upper_arm = 0.105", "upper_arm = 0.12")
        .replace("forearm = 0.189", "forearm = 0.12");
    assert_ne!(short, elbow);
    let (template, model) = (dir.join("short.toml"), dir.join("model.toml"));
    std::fs::write(&template, short).unwrap();
    std::fs::write(&model, export("trainer-model")).unwrap();
    let out = ringpod()
        .args([
            "rig",
            "design",
            "--arms-only",
            "--starts",
            "4",
            "--steps",
            "150",
            "--seed",
            "3",
        ])
        .arg(&template)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "covers each axis: {text}");
    assert!(
        text.contains("ring_radius = 0.286\n") && text.contains("rod_length = 0.312\n"),
        "{text}"
    );
    assert!(!text.contains("forearm = 0.12\n"), "the arms moved: {text}");
    assert_eq!(text.matches("forearm = ").count(), 2, "{text}");
    ringpod()
        .args(["rig", "design", "--arms-only"])
        .arg(&model)
        .assert()
        .code(1)
        .stderr(predicate::str::contains(
            "chains: designing the arms alone needs elbow chains",
        ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `ringpod gram`: paper 003's slice as a picture and a table (coarse here), its statistics printed; a step or a
/// height out of range refused.
#[test]
fn gram_draws_and_tabulates_the_paper_slice() {
    let dir = std::env::temp_dir().join(format!("ringpod-gram-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (svg, md) = (dir.join("gram.svg"), dir.join("gram.md"));
    let out = ringpod()
        .args(["gram", "--step", "0.01", "--out"])
        .arg(&svg)
        .arg("--table")
        .arg(&md)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("slice z = -0.18 m, 40 x 40 cells of 10 mm"), "{text}");
    assert!(std::fs::read_to_string(&svg)
        .unwrap()
        .contains("det G_C, constraint wrenches"));
    let table = std::fs::read_to_string(&md).unwrap();
    assert!(table.contains("| det G | all six |"), "{table}");
    assert!(table.contains("det M_C = -0.29281, det G_C = 0.08574"), "{table}");
    for bad in [&["--step", "0"][..], &["--step", "nan"], &["--z", "0.5"]] {
        ringpod().arg("gram").args(bad).arg("--out").arg(&svg).assert().code(1);
    }
}
