//! The command line against inputs an adversary would try, one test per class of input: every one ends with a
//! clear error said once and the documented exit code, or with a correct result; none panics, hangs or succeeds
//! when its job was not done. The book's Tests chapter counts these classes.

use assert_cmd::Command;
use std::path::PathBuf;

/// How the system says a file is not there: Linux's words; on Windows (and under Wine) its own words, whose common
/// part is the error number in Rust's text of the error.
const MISSING: &str = if cfg!(windows) { "(os error" } else { "No such file" };

/// How the system says a path is a directory where a file was asked for: Linux's words; Windows refuses to open it
/// ("Access denied", error 5).
const DIRECTORY: &str = if cfg!(windows) { "(os error 5)" } else { "directory" };

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

/// A scratch folder of this test process, removed when the test ends (also when it fails).
struct Scratch(PathBuf);

impl Scratch {
    fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    fn display(&self) -> std::path::Display<'_> {
        self.0.display()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn scratch(name: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!("ringpod-adversary-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    Scratch(dir)
}

/// Runs `ringpod ARGS` and returns (exit code, stdout, stderr); a panic (exit 101) fails the test.
fn run(args: &[&str]) -> (i32, String, String) {
    let out = ringpod()
        .args(args)
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let code = out.status.code().unwrap_or(-1);
    assert!(
        code != 101 && !stderr.contains("panicked"),
        "ringpod {args:?} panicked: {stderr}"
    );
    (code, String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

/// Class: a bad rig file (syntax, unknown key, a value out of range or not finite, missing, a folder, binary bytes)
/// is said once, with the file's path, by every command that reads one.
#[test]
fn a_bad_rig_file_is_said_once_with_its_path() {
    let dir = scratch("rig");
    let good = run(&["presets", "--export", "trainer-model"]).1;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path.display().to_string()
    };
    // The exported rig with one value changed.
    let edited = |name: &str, from: &str, to: &str| write(name, good.replace(from, to).as_bytes());
    let cases = [
        (write("syntax.toml", b"ring_radius = = 3\n"), "line 1"),
        (edited("typo.toml", "rod_length", "rod_lenght"), "rod_lenght"),
        (
            edited("nan.toml", "ring_radius = ", "ring_radius = nan #"),
            "ring_radius",
        ),
        (edited("spec.toml", "surge = 0.05", "surge = 1e300"), "spec.surge"),
        (
            edited("tilt.toml", "roll_deg = 20.0", "roll_deg = 400.0"),
            "spec.roll_deg",
        ),
        (
            edited("gear.toml", "gear_ratio = 8.0", "gear_ratio = 1e300"),
            "drives[0].gear_ratio",
        ),
        (
            edited("torque.toml", "[[0.0, 0.016],", "[[0.0, 1e300],"),
            "drives[0].pull_out",
        ),
        (write("binary.toml", &[0xff, 0xfe, 0x00, 0x80, 0x13, 0x37]), "UTF-8"),
        (dir.join("missing.toml").display().to_string(), MISSING),
        (dir.display().to_string(), DIRECTORY),
    ];
    let picture = dir.join("ws.svg").display().to_string();
    for (path, cause) in &cases {
        for args in [
            vec!["ik", "--geometry", path, "--pose", "0,0,0.227,0,0,0"],
            vec!["rig", "check", path],
            vec!["workspace", "--geometry", path, "--cells", "8", "--out", &picture],
            vec![
                "stream",
                "--sim",
                "--fast",
                "--quiet",
                "--geometry",
                path,
                "--motion",
                "demo",
                "--duration",
                "1",
            ],
            vec!["simulate", "--pty", "--geometry", path],
        ] {
            let (code, _, stderr) = run(&args);
            assert_ne!(code, 0, "{args:?}");
            assert!(stderr.contains(cause), "{args:?}: {stderr}");
            assert_eq!(
                stderr.matches(path.as_str()).count(),
                1,
                "{args:?}: the path once: {stderr}"
            );
            assert_eq!(stderr.matches(cause).count(), 1, "{args:?}: the cause once: {stderr}");
        }
    }
    // A valid mechanism that cannot be driven (a ring of 1e300 m: the home pose has no solution) is analysed and
    // judged by `rig check` (exit 3, the reason once), and refused once, with its path, by what would drive it.
    let huge = write(
        "huge.toml",
        good.replace("ring_radius = ", "ring_radius = 1e300 #").as_bytes(),
    );
    let (code, stdout, _) = run(&["rig", "check", &huge]);
    assert_eq!(code, 3, "{stdout}");
    assert!(stdout.contains("analysable: yes") && stdout.contains("drivable: no, because home: has no solution"));
    assert_eq!(stdout.matches("no solution").count(), 1, "{stdout}");
    for args in [
        vec![
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--geometry",
            &huge,
            "--motion",
            "demo",
            "--duration",
            "1",
        ],
        vec!["simulate", "--pty", "--geometry", &huge],
    ] {
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        assert_eq!(
            stderr.matches(huge.as_str()).count(),
            1,
            "{args:?}: the path once: {stderr}"
        );
        assert_eq!(
            stderr.matches("no solution").count(),
            1,
            "{args:?}: the cause once: {stderr}"
        );
    }
}

/// The source's own geometries are analysed whether or not they can be driven: chapter 5's trainer (its home pose
/// fails the carriage spacing) answers `ik`, `check` and `workspace`, and `rig check` says why it cannot be
/// driven (nor cued); the rotopod of chapters 3-4 is driven: `stream --sim --mechanism rotopod-ch4` homes its six carriages on
/// one ring and follows the demo.
#[test]
fn every_mechanism_of_the_source_is_analysed_and_the_rotopod_driven() {
    let dir = scratch("source-rigs");
    let ch5 = dir.join("ch5.toml").display().to_string();
    std::fs::write(&ch5, run(&["presets", "--export", "trainer-ch5"]).1).unwrap();
    let (code, stdout, stderr) = run(&["rig", "check", &ch5]);
    assert_eq!(code, 3, "{stderr}");
    assert!(
        stdout.contains("analysable: yes") && stdout.contains("drivable: no, because home: fails the carriage-spacing"),
        "{stdout}"
    );
    let (code, stdout, stderr) = run(&["ik", "--geometry", &ch5, "--pose", "0,0,1,0,0,0"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("q1"), "{stdout}");
    let (code, _, stderr) = run(&["check", "--geometry", &ch5, "--pose", "0,0,1,0,0,0"]);
    assert_eq!(code, 3, "the home pose fails a check: {stderr}");
    let picture = dir.join("ch5.svg").display().to_string();
    let (code, _, stderr) = run(&[
        "workspace",
        "--geometry",
        &ch5,
        "--cells",
        "10",
        "--quiet",
        "--out",
        &picture,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = run(&[
        "stream",
        "--sim",
        "--fast",
        "--quiet",
        "--geometry",
        &ch5,
        "--motion",
        "demo",
    ]);
    assert_eq!(code, 1, "not drivable: {stderr}");
    assert_eq!(stderr.matches("carriage-spacing").count(), 1, "{stderr}");
    // Nor cued: every pose about a home outside the envelope would be cut towards it, none inside.
    let drives = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let drive = drives.join("drive-telemetry.csv").display().to_string();
    let classical = drives.join("drives/classical.toml").display().to_string();
    let (poses, report) = (dir.join("ch5.csv"), dir.join("ch5.json"));
    let (poses_arg, report_arg) = (poses.display().to_string(), report.display().to_string());
    for args in [
        vec!["cue", "--geometry", &ch5, "--input", &drive, "--out", &poses_arg],
        vec![
            "cue",
            "--compare",
            &classical,
            &classical,
            "--geometry",
            &ch5,
            "--input",
            &drive,
            "--out",
            &report_arg,
        ],
    ] {
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        assert_eq!(
            stderr.matches("home fails the carriage-spacing check").count(),
            1,
            "{stderr}"
        );
    }
    assert!(!poses.exists() && !report.exists(), "an output was written");

    let (code, stdout, stderr) = run(&[
        "stream",
        "--sim",
        "--fast",
        "--quiet",
        "--mechanism",
        "rotopod-ch4",
        "--motion",
        "demo",
        "--duration",
        "3",
        "--report-json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(report["setpoints_sent"], report["setpoints_applied"], "{report}");
    assert_eq!(report["state"], "Ready", "{report}");
    // Homed: every axis moved, the last two as carriages (not as the trainer model's linear actuators).
    let steps = report["final_steps"].as_array().unwrap();
    assert!(steps.iter().all(|s| s.as_i64().unwrap() != 0), "{report}");
}

/// Class: files that are not what a command reads (`/dev/zero`, binary bytes, a folder, missing) end at once with
/// the file named and what is wrong, never by reading without end: every command that reads a file.
#[test]
fn a_file_that_is_not_a_text_file_is_refused_at_once() {
    let dir = scratch("files");
    let binary = dir.join("binary.csv");
    std::fs::write(&binary, [0xff, 0xfe, 0x00, 0x80, 0x13, 0x37, 0x0a]).unwrap();
    let out = dir.join("out.csv").display().to_string();
    let picture = dir.join("out.svg").display().to_string();
    let folder = dir.display().to_string();
    let binary = binary.display().to_string();
    let mut cases = vec![
        (binary.as_str(), "not UTF-8"),
        (folder.as_str(), DIRECTORY),
        ("/nonexistent/poses.csv", MISSING),
    ];
    // An endless file: Unix has one to hand.
    if cfg!(unix) {
        cases.push(("/dev/zero", "larger than"));
    }
    for (file, cause) in cases {
        for args in [
            vec!["stream", "--sim", "--fast", "--quiet", "--input", file],
            vec!["cue", "--input", file, "--out", &out],
            vec![
                "cue",
                "--input",
                "docs/drive-telemetry.csv",
                "--config",
                file,
                "--out",
                &out,
            ],
            vec!["plot", file, "--out", &picture],
            vec!["loads", "--mass", "0.1", "--input", file],
            vec!["rig", "check", file],
            vec!["dynamics", "--file", file],
        ] {
            let started = std::time::Instant::now();
            let (code, _, stderr) = run(&args);
            assert_eq!(code, 1, "{args:?}: {stderr}");
            assert!(stderr.contains(file) && stderr.contains(cause), "{args:?}: {stderr}");
            assert!(
                started.elapsed() < std::time::Duration::from_secs(20),
                "{args:?} took {:?}",
                started.elapsed()
            );
        }
    }
}

/// Class: numbers at the ends of f64 in a run record (a position of 1e308 on one row and -1e308 on the next, times
/// of 1e300): the record is still drawn, as SVG and as PNG, instead of hanging in the axis ticks.
#[test]
fn a_record_with_extreme_values_is_still_drawn() {
    let dir = scratch("plot");
    let record = dir.join("run.csv");
    let (code, _, stderr) = run(&[
        "stream",
        "--sim",
        "--fast",
        "--quiet",
        "--motion",
        "heave",
        "--duration",
        "1",
        "--record",
        record.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let text = std::fs::read_to_string(&record).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    // Column 9 is the followed x; the first column the host's time.
    for (row, value) in [(5, "1e308"), (6, "-1e308"), (7, "1e300")] {
        let mut fields: Vec<String> = lines[row].split(',').map(str::to_owned).collect();
        fields[8] = value.to_owned();
        if row == 7 {
            fields[0] = value.to_owned();
        }
        lines[row] = fields.join(",");
    }
    let extreme = dir.join("extreme.csv");
    std::fs::write(&extreme, lines.join("\n") + "\n").unwrap();
    for picture in ["extreme.svg", "extreme.png"] {
        let out = dir.join(picture);
        let (code, _, stderr) = run(&["plot", extreme.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{picture}: {stderr}");
        assert!(std::fs::metadata(&out).unwrap().len() > 1000, "{picture} drawn");
    }
}

/// Class: a reader that goes away (`| head -c1`: stdout a closed pipe) never makes a command panic; the run still
/// ends with its own exit code.
#[test]
fn a_closed_stdout_is_not_a_panic() {
    for args in [
        vec!["stream", "--sim", "--fast", "--motion", "heave", "--duration", "1"],
        vec![
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--report-json",
            "--motion",
            "heave",
            "--duration",
            "1",
        ],
        vec!["device", "inputs", "--sim"],
        vec!["device", "jog", "5", "1", "--sim"],
        vec!["presets"],
        vec!["ik", "--pose", "0,0,0.227,0,0,0"],
    ] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(&args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Close the reading end before anything is written.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_ne!(out.status.code(), Some(101), "{args:?}: {stderr}");
    }
}

/// Class: a job too large to hold (a built-in motion of 1e5 s at 10 kHz checked for loads: a billion poses) is
/// refused with its size and what to change, instead of an allocation that aborts the process.
#[test]
fn a_load_check_too_large_to_hold_is_refused() {
    let (code, _, stderr) = run(&[
        "stream",
        "--sim",
        "--fast",
        "--quiet",
        "--motion",
        "heave",
        "--duration",
        "1e5",
        "--rate",
        "1e4",
        "--check-loads",
        "--mass",
        "1",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("1e9 poses") && stderr.contains("--duration"),
        "{stderr}"
    );
}

/// Class: a pose that is not a number in a motion file given to `loads --input` is reported by its line and left
/// out; the rows before and after it are computed as without it (the unwrapping and differences are not poisoned).
#[test]
fn a_non_finite_row_of_a_load_input_is_left_out_by_line() {
    let dir = scratch("loads");
    let rows = |bad: Option<usize>| {
        let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
        for k in 0..100 {
            let alpha = if Some(k) == bad {
                "nan".to_string()
            } else {
                format!("{}", 0.001 * k as f64)
            };
            csv += &format!("{},0,0,0.227,{alpha},0,0\n", k as f64 * 0.01);
        }
        csv
    };
    let with = dir.join("with.csv");
    std::fs::write(&with, rows(Some(0))).unwrap();
    let (code, stdout, stderr) = run(&["loads", "--mass", "0.01", "--input", with.to_str().unwrap(), "--json"]);
    assert_eq!(code, 3, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let errors = json["errors"].as_array().unwrap_or_else(|| panic!("{json}"));
    assert_eq!(errors.len(), 1, "{json}");
    assert_eq!(errors[0]["line"], 2);
    assert!(stdout.contains("drives_keep_up") && !stdout.contains("NaN"), "{stdout}");
}

/// A load input none of whose rows the platform reaches: there is no peak, margin or "keep up" of no row; the
/// input is refused, naming why its first row was left out.
#[test]
fn a_load_input_with_no_reachable_row_is_refused() {
    let dir = scratch("loads-unreachable");
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..20 {
        csv += &format!("{},0,0,5,0,0,0\n", k as f64 * 0.01);
    }
    let path = dir.join("far.csv");
    std::fs::write(&path, csv).unwrap();
    for json in [false, true] {
        let mut args = vec!["loads", "--mass", "1", "--input", path.to_str().unwrap()];
        if json {
            args.push("--json");
        }
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}: {stdout}{stderr}");
        assert!(stdout.is_empty(), "{stdout}");
        assert!(
            stderr.contains("none of its 20 rows is a pose the platform reaches") && stderr.contains("line 2"),
            "{stderr}"
        );
        assert!(!stderr.contains("NaN") && !stderr.contains("keep up"), "{stderr}");
    }
}

/// Class: options that would do nothing with the others given are refused, not silently ignored.
#[test]
fn an_option_that_would_be_ignored_is_refused() {
    for (args, code) in [
        (
            vec!["stream", "--sim", "--udp", "127.0.0.1:0", "--cue-config", "x.toml"],
            2,
        ),
        (
            vec!["stream", "--sim", "--input", "x.csv", "--udp-from", "127.0.0.1"],
            2,
        ),
        (
            vec!["stream", "--sim", "--motion", "demo", "--udp-from", "127.0.0.1"],
            2,
        ),
        (vec!["stream", "--sim", "--input", "x.csv", "--pose-format", "flypt"], 2),
        (
            vec!["stream", "--sim", "--motion", "demo", "--pose-format", "simtools"],
            2,
        ),
        (
            vec!["workspace", "--section", "xz", "--z", "0.1", "--out", "/tmp/x.svg"],
            1,
        ),
    ] {
        let (got, _, stderr) = run(&args);
        assert_eq!(got, code, "{args:?}: {stderr}");
    }
}

/// Class: numbers at the ends of f64 in messages are written as a person reads them, not as 300 digits.
#[test]
fn huge_and_tiny_numbers_are_said_readably() {
    for args in [
        vec!["stream", "--sim", "--motion", "demo", "--duration=1e308"],
        vec!["stream", "--sim", "--motion", "demo", "--rate=1e308"],
        vec!["stream", "--sim", "--motion", "demo", "--duration=-1e-320"],
        vec!["stream", "--sim", "--udp", "127.0.0.1:0", "--udp-idle=1e308"],
        vec!["rates", "--pose-rates=1e300,0,0,0,0,0"],
        vec!["rates", "--pose-rates=0,0,0,0,0,-1e300"],
        vec!["rates", "--actuator-rates=0,0,0,0,1e300,0"],
        vec!["rates", "--degrees", "--actuator-rates=0,0,0,0,0,1e300"],
    ] {
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 1, "{args:?}: {stderr}");
        assert!(stderr.len() < 200 && !stderr.contains("00000000"), "{args:?}: {stderr}");
    }
}

/// Class: a CSV as spreadsheets write it (a UTF-8 byte-order mark before the header) is read; a header that is not
/// one is quoted in a line's worth, however long it is.
#[test]
fn a_spreadsheets_csv_is_read_and_a_wrong_header_is_quoted_briefly() {
    let dir = scratch("csv");
    let bom = dir.join("bom.csv");
    std::fs::write(
        &bom,
        "\u{feff}t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.01,0,0,0.2271,0,0,0\n",
    )
    .unwrap();
    let (code, _, stderr) = run(&["stream", "--sim", "--fast", "--quiet", "--input", bom.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let long = dir.join("long.csv");
    std::fs::write(&long, "x".repeat(1 << 20) + "\n0,0,0,0.227,0,0,0\n").unwrap();
    let (code, _, stderr) = run(&[
        "stream",
        "--sim",
        "--fast",
        "--quiet",
        "--input",
        long.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("header") && stderr.len() < 400,
        "{}",
        &stderr[..400.min(stderr.len())]
    );
}

/// Class: `monitor` with no terminal to draw on says so instead of an OS error number.
#[test]
fn the_monitor_without_a_terminal_says_so() {
    let (code, _, stderr) = run(&["monitor", "--sim", "--frames", "3"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("draws on a terminal"), "{stderr}");
}

/// Class: a drive the bench cannot score is refused, naming it, with or without the floor: too short (a header
/// alone, or one row: scored, it would come out as zeros, a perfect cueing), or with a row beyond any vehicle's
/// (the vehicle's own perceived force would be scored from it).
#[test]
fn a_drive_the_bench_cannot_score_is_refused() {
    let dir = scratch("short-drive");
    let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/drives");
    let (classical, optimal) = (docs.join("classical.toml"), docs.join("optimal.toml"));
    let out = dir.join("bench.json");
    let implausible = "t,ax,ay,az,wx,wy,wz\n0.0,0,0,9.80665,0,0,0\n0.01,1e30,0,9.80665,0,0,0\n0.02,0,0,9.80665,0,0,0\n";
    for (name, text, said) in [
        ("header.csv", "t,ax,ay,az,wx,wy,wz\n", "two rows or more"),
        (
            "one.csv",
            "t,ax,ay,az,wx,wy,wz\n0.0,0,0,9.80665,0,0,0\n",
            "two rows or more",
        ),
        (
            "implausible.csv",
            implausible,
            "line 3: a value is beyond any vehicle's",
        ),
    ] {
        let input = dir.join(name);
        std::fs::write(&input, text).unwrap();
        for floor in [&[][..], &["--floor"][..], &["--floor", "--envelope-floor"][..]] {
            let mut args = vec![
                "cue",
                "--compare",
                classical.to_str().unwrap(),
                optimal.to_str().unwrap(),
                "--input",
                input.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ];
            args.extend(floor);
            let (code, _, stderr) = run(&args);
            assert_eq!(code, 1, "{name} {floor:?}: {stderr}");
            assert!(stderr.contains(name) && stderr.contains(said), "{stderr}");
            assert!(!out.exists(), "{name} {floor:?}: a report was written");
        }
    }
}

/// Class: refusals say what and where, once: a folder that is not there is refused when the workbench starts, an
/// option is named with its two dashes, a file that cannot be written is named with the reason.
#[test]
fn refusals_name_what_they_refuse_once() {
    let started = std::time::Instant::now();
    let (code, _, stderr) = run(&[
        "ui",
        "--sim",
        "--listen",
        "127.0.0.1:0",
        "--files",
        "/nonexistent/poses",
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("/nonexistent/poses") && stderr.contains(MISSING),
        "{stderr}"
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(20));
    let (code, _, stderr) = run(&["stream", "--sim", "--mechanism", "tool5-ex", "--motion", "demo"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains(" --mechanism: tool5-ex is not a ring platform"),
        "{stderr}"
    );
    assert!(!stderr.contains("---"), "{stderr}");
    // sysfs takes no new file, even from root.
    if cfg!(target_os = "linux") {
        let (code, _, stderr) = run(&[
            "dynamics",
            "-m",
            "trainer-model",
            "--duration",
            "0.1",
            "--table",
            "/sys/ringpod-table.csv",
        ]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains("/sys/ringpod-table.csv: "), "{stderr}");
    }
}
