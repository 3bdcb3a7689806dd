//! `ringpod dynamics` run as a user runs it: the matrix method's drive forces agree with the ring platform's own
//! inverse dynamics (exit 0), the table holds what its header says and keeps the energy balance, the plot is drawn,
//! and every bad argument is refused with exit 1 and nothing written.

use assert_cmd::Command;

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("ringpod-dynamics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs `dynamics` with `args` and the table to `csv`; asserts exit 0 and that the text says `says`; returns the
/// table's header and rows.
fn table_of(args: &[&std::ffi::OsStr], csv: &std::path::Path, says: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let out = ringpod()
        .arg("dynamics")
        .args(args)
        .arg("--table")
        .arg(csv)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains(says), "{text}");
    let table = std::fs::read_to_string(csv).unwrap();
    let mut lines = table.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

#[test]
fn the_trainer_and_the_rotopod_agree_with_the_ring_platforms_inverse_dynamics() {
    for (preset, amplitude) in [("rotopod-ch4", "0.05"), ("trainer-ch5", "0.0125")] {
        let csv = scratch(&format!("{preset}.csv"));
        let png = scratch(&format!("{preset}.png"));
        let args: Vec<std::ffi::OsString> = ["-m", preset, "--amplitude", amplitude, "--duration", "0.5"]
            .iter()
            .map(|a| a.into())
            .chain([
                "--step".into(),
                "0.01".into(),
                "--plot".into(),
                png.clone().into_os_string(),
            ])
            .collect();
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let (head, rows) = table_of(&args, &csv, "51 samples over 0.5 s, 6 drives");
        assert_eq!(rows.len(), 51);
        let column = |name: &str| head.iter().position(|h| *h == name).unwrap();
        // The drives' power is the total energy's rate: central differences of kinetic + potential.
        let (kinetic, potential, power) = (column("kinetic"), column("potential"), column("power"));
        for k in 1..rows.len() - 1 {
            let energy = |r: &Vec<f64>| r[kinetic] + r[potential];
            let rate = (energy(&rows[k + 1]) - energy(&rows[k - 1])) / 0.02;
            let scale = rows[k][power].abs().max(1.0);
            assert!(
                (rate - rows[k][power]).abs() < 2e-3 * scale,
                "{preset} row {k}: {rate} vs {}",
                rows[k][power]
            );
        }
        // The positions' rates are the rates' integral's derivative, likewise.
        let (u1, ud1) = (column("u1"), column("ud1"));
        let rate = (rows[26][u1] - rows[24][u1]) / 0.02;
        assert!(
            (rate - rows[25][ud1]).abs() < 1e-3 * rows[25][ud1].abs().max(1e-3),
            "{preset}"
        );
        assert_eq!(&std::fs::read(&png).unwrap()[..4], b"\x89PNG");
    }
}

#[test]
fn bad_arguments_are_refused_and_write_nothing() {
    let csv = scratch("refused.csv");
    for args in [
        &["--step", "0"][..],
        &["--step=-0.1"],
        &["--duration", "NaN"],
        &["--duration", "1e9", "--step", "1e-6"],
        &["--amplitude=-1"],
        &["--mass=-2"],
        &["--inertia", "1,2"],
        &["-m", "tool5-ex"],
        &["-m", "trainer-elbow"],
        &["-m", "no-such-preset"],
        &["--amplitude", "0.5"],
    ] {
        let out = ringpod()
            .arg("dynamics")
            .args(args)
            .arg("--table")
            .arg(&csv)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(1),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(!String::from_utf8_lossy(&out.stderr).is_empty(), "{args:?}");
        assert!(!csv.exists(), "{args:?} wrote the table");
    }
}

#[test]
fn a_mechanism_file_gives_its_drive_forces_and_keeps_the_energy_balance() {
    let csv = scratch("four-bar.csv");
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/dynamics/four-bar.toml");
    let (_, rows) = table_of(
        &["--file".as_ref(), file.as_ref()],
        &csv,
        "four-bar: 201 samples over 2 s, 1 drives",
    );
    // Columns t, u1, ud1, udd1, force1, kinetic, potential, power: the power (the drive's, the damper's) is the
    // energy's rate, and the damper takes some.
    for k in 1..rows.len() - 1 {
        let energy = |r: &Vec<f64>| r[5] + r[6];
        let rate = (energy(&rows[k + 1]) - energy(&rows[k - 1])) / 0.02;
        assert!(
            (rate - rows[k][7]).abs() < 2e-3 * rows[k][7].abs().max(0.1),
            "row {k}: {rate} vs {}",
            rows[k][7]
        );
    }
    let drive_only: Vec<f64> = rows.iter().map(|r| r[4] * r[2]).collect();
    assert!(rows.iter().zip(&drive_only).any(|(r, d)| (r[7] - d).abs() > 1e-4));
    ringpod()
        .args(["dynamics", "--file", file, "--mass", "2"])
        .assert()
        .code(2);
    ringpod()
        .args(["dynamics", "--file", "/no/such/file.toml"])
        .assert()
        .code(1);
}

/// A motion file instead of the built-in motion: its timed poses, rates and accelerations by differences, give
/// the drive forces the ring platform's inverse dynamics gives (exit 0), one row a line; a file the motion cannot
/// be read from is refused by its line, with nothing written.
#[test]
fn a_motion_file_is_followed_and_a_bad_one_refused() {
    let motion = scratch("motion.csv");
    let mut text = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..=50 {
        let t = k as f64 * 0.01;
        let s = (std::f64::consts::TAU * 2.0 * t).sin();
        text += &format!(
            "{t},{},{},{},{},{},{}\n",
            0.004 * s,
            -0.003 * s,
            0.227 + 0.002 * s,
            0.02 * s,
            -0.03 * s,
            0.5 * t
        );
    }
    std::fs::write(&motion, &text).unwrap();
    let csv = scratch("motion-table.csv");
    let args = [
        std::ffi::OsStr::new("-m"),
        "trainer-model".as_ref(),
        "--input".as_ref(),
        motion.as_os_str(),
    ];
    let (head, rows) = table_of(&args, &csv, "51 samples over 0.5 s, 6 drives");
    assert_eq!(rows.len(), 51);
    assert_eq!(rows[50][head.iter().position(|h| h == "t").unwrap()], 0.5);
    let bad = scratch("bad-motion.csv");
    for (file, says) in [
        (text.replace("\n0.02,", "\n0.005,"), "line 4: time is not increasing"),
        (text.replace("\n0.03,", "\n0.03,x"), "line 5"),
        ("t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n".to_owned(), "at least 3"),
        // As `loads` and `stream` take it: no peak force of a pose of garbage.
        (
            text.replacen(",0.015\n", ",1e300\n", 1),
            "line 5: gamma = 1e300 is out of range",
        ),
    ] {
        std::fs::write(&bad, file).unwrap();
        let out = ringpod()
            .args(["dynamics", "-m", "trainer-model", "--input"])
            .arg(&bad)
            .arg("--table")
            .arg(scratch("not-written.csv"))
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{says}: {said}");
        assert!(said.contains(says), "{says}: {said}");
        assert!(!scratch("not-written.csv").exists());
    }
    let both = ringpod()
        .args(["dynamics", "--amplitude", "0.01", "--input"])
        .arg(&motion)
        .output()
        .unwrap();
    assert_eq!(
        both.status.code(),
        Some(2),
        "the built-in motion's amplitude with a motion file"
    );
}
