//! The Rig panel's routes: the rig file checked as the form sends it, saved to the file `ringpod ui --sim
//! --geometry FILE` was started with (and to no other), under the token, Origin and Host rules; what the form
//! saves is what the command line reads.

use std::path::Path;

use serde_json::{json, Value};

use super::profiles::raw;
use super::workbench::{http, Workbench};

fn post(bench: &Workbench, path: &str, body: &Value) -> (u16, Value) {
    let (status, text) = http(
        &bench.addr,
        "POST",
        &format!("{path}?token={}", bench.token),
        &bench.addr,
        Some(body),
    );
    (status, serde_json::from_str(&text).unwrap_or(json!(text)))
}

/// The trainer model's rig file in `dir`.
pub(super) fn trainer(dir: &Path) -> std::path::PathBuf {
    let out = assert_cmd::Command::cargo_bin("ringpod")
        .unwrap()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let path = dir.join("rig.toml");
    std::fs::write(&path, out.stdout).unwrap();
    path
}

/// The form's values of the rig the panel starts from (the file, every section written out).
fn form(bench: &Workbench) -> Value {
    // Without a rig file the panel starts from the device's rig, known once the device thread has asked for it.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let (status, current) = loop {
        let (status, current) = http(
            &bench.addr,
            "GET",
            &format!("/api/rig/current?token={}", bench.token),
            &bench.addr,
            None,
        );
        if status == 200 || !current.contains("not known yet") || std::time::Instant::now() > deadline {
            break (status, current);
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    assert_eq!(status, 200, "{current}");
    let current: Value = serde_json::from_str(&current).unwrap();
    let (status, checked) = post(bench, "/api/rig/check", &json!({ "text": current["text"] }));
    assert_eq!(status, 200, "{checked}");
    assert_eq!(checked["drivable"], true, "{checked}");
    checked["file"].clone()
}

fn rig_check(path: &Path) -> String {
    let out = assert_cmd::Command::cargo_bin("ringpod")
        .unwrap()
        .args(["rig", "check"])
        .arg(path)
        .output()
        .unwrap();
    String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr)
}

/// Saved from the form, the rig file holds the form's values in its own units (m, deg), keeps its mode, reads back
/// through the panel as the same values, and `ringpod rig check` reads it as that rig.
#[test]
fn what_the_form_saves_is_what_the_cli_reads() {
    let dir = tempfile::tempdir().unwrap();
    let path = trainer(dir.path());
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    let bench = Workbench::start(&["--geometry", path.to_str().unwrap()]);
    let mut rig = form(&bench);
    assert_eq!(rig["axes"].as_array().map(Vec::len), Some(6), "axes written out: {rig}");
    assert!(rig["homing"]["axes"].is_array(), "homing written out: {rig}");
    rig["ring_radius"] = json!(0.306);
    rig["limits"]["base_cone_deg"] = json!(12.5);
    rig["supervisor"]["discharge_ms"] = json!(600);
    let (status, saved) = post(&bench, "/api/rig/save", &json!({ "rig": rig }));
    assert_eq!(status, 200, "{saved}");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("ring_radius = 0.306\n")
            && text.contains("base_cone_deg = 12.5\n")
            && text.contains("discharge_ms = 600\n"),
        "{text}"
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "the file keeps its mode");
    }
    let (_, again) = post(&bench, "/api/rig/check", &json!({ "text": text }));
    assert_eq!(again["file"], rig, "read back, the same values");
    let report = rig_check(&path);
    assert!(
        report.contains("ring radius 0.306 m") && report.contains("drivable: yes"),
        "{report}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no other file made");
}

/// Every bad input is refused and nothing is written: a value of the wrong type, out of range (named as the form
/// shows it, with its unit and range), an unknown key in the file or the request, a rig the controller cannot
/// drive; without the token, with a wrong one, from another Origin or Host. Without a rig file nothing is saved.
#[test]
fn bad_rig_saves_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = trainer(dir.path());
    let before = std::fs::read(&path).unwrap();
    let bench = Workbench::start(&["--geometry", path.to_str().unwrap()]);
    let rig = form(&bench);
    let with = |edit: &dyn Fn(&mut Value)| {
        let mut r = rig.clone();
        edit(&mut r);
        json!({ "rig": r })
    };
    let cases: Vec<(Value, &[&str])> = vec![
        (with(&|r| r["ring_radius"] = json!("big")), &["ring_radius", "invalid type"]),
        (
            with(&|r| r["ring_radius"] = json!(-0.005)),
            &["Geometry · ring radius (mm): -5 mm is out of range: more than 0 mm"],
        ),
        (
            with(&|r| r["limits"]["base_cone_deg"] = json!(90)),
            &["Limits · least angle of a link to the base (deg): 90 deg is out of range: 0 to 90 deg, 90 itself excluded"],
        ),
        (
            with(&|r| r["chains"][1]["upper_arm"] = json!(0.1)),
            &["Chain 2 · upper arm", "only elbow chains have it"],
        ),
        (with(&|r| r["limits"]["colour"] = json!(1)), &["unknown field `colour`"]),
        (with(&|r| r["home"][2] = json!(0.6)), &["Home pose", "not saved"]),
        // The controller takes it, but its homing, simulated as `rig check` does, faults: not drivable.
        (with(&|r| r["axes"][4]["reverse"] = json!(true)), &["it does not home", "not saved"]),
        (
            with(&|r| r["axes"][0]["steps_per_unit"] = json!(0.0)),
            &["Axis 1 · steps (steps/deg)", "out of range"],
        ),
        (json!({ "rig": rig, "text": "name = \"x\"" }), &["`text`"]),
        (json!({ "rig": rig, "path": "/tmp/elsewhere.toml" }), &["unknown field `path`"]),
    ];
    for (body, said) in &cases {
        let (status, answer) = post(&bench, "/api/rig/save", body);
        assert_eq!(status, 422, "{answer}");
        let text = answer["error"]
            .as_str()
            .map_or_else(|| answer.to_string(), str::to_owned);
        for s in *said {
            assert!(text.contains(s), "{s:?} not in {text}");
        }
        assert_eq!(std::fs::read(&path).unwrap(), before, "nothing written: {text}");
    }
    let body = json!({ "rig": rig }).to_string();
    let port = bench.addr.rsplit(':').next().unwrap();
    for (query, host, origin) in [
        (String::new(), bench.addr.clone(), None),
        ("?token=0000".to_owned(), bench.addr.clone(), None),
        (
            format!("?token={}", bench.token),
            bench.addr.clone(),
            Some("http://evil.example"),
        ),
        (
            format!("?token={}", bench.token),
            format!("rebound.example:{port}"),
            None,
        ),
    ] {
        let status = raw(&bench.addr, &format!("/api/rig/save{query}"), &host, origin, &body);
        assert_eq!(status, 403, "{query} Host {host} Origin {origin:?}");
    }
    assert_eq!(std::fs::read(&path).unwrap(), before, "nothing written");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no other file made");
    // Started without a rig file, the workbench saves none.
    let plain = Workbench::start(&[]);
    let rig = form(&plain);
    let (status, answer) = post(&plain, "/api/rig/save", &json!({ "rig": rig }));
    assert_eq!(status, 422);
    assert!(
        answer["error"].as_str().unwrap().contains("download the TOML"),
        "{answer}"
    );
}
