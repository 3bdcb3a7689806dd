//! The profile routes: a cueing file's `[profiles.NAME]` chosen, loaded, saved and duplicated from the page, under
//! the token, Origin and Host rules; a name is a key of the file, never a path.

use serde_json::{json, Value};

use super::workbench::{http, Workbench};

fn get(bench: &Workbench, path: &str) -> (u16, Value) {
    let (status, body) = http(&bench.addr, "GET", path, &bench.addr, None);
    (status, serde_json::from_str(&body).unwrap_or(Value::Null))
}

fn post(bench: &Workbench, path: &str, body: &Value) -> (u16, Value) {
    let (status, text) = http(&bench.addr, "POST", path, &bench.addr, Some(body));
    (status, serde_json::from_str(&text).unwrap_or(json!(text)))
}

fn defaults(bench: &Workbench) -> Value {
    get(bench, &format!("/api/cue/defaults?token={}", bench.token)).1["config"].clone()
}

/// Saved from the page, a profile is the file's `[profiles.NAME]`, read back by the page and by `ringpod cue
/// --config FILE --profile NAME`; a duplicate under a taken name is refused; the file's other content stays.
#[test]
fn a_profile_saved_from_the_page_is_the_files_and_the_clis() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("cue.toml");
    std::fs::write(&file, "tilt_scale = 0.5\n[profiles.lfs]\noutsim_opts = \"1ff\"\n").unwrap();
    let bench = Workbench::start(&["--cue-config", file.to_str().unwrap()]);
    let t = &bench.token;
    let (status, list) = get(&bench, &format!("/api/profiles?token={t}"));
    assert_eq!(status, 200, "{list}");
    assert_eq!(list["names"], json!(["lfs"]));
    assert_eq!(list["kept"], true);
    let f1 = list["games"]
        .as_array()
        .unwrap()
        .iter()
        .find(|g| g["format"] == "f1")
        .unwrap()
        .clone();
    assert_eq!((f1["port"].clone(), f1["profile"].clone()), (json!(20777), json!("f1")));
    let mut config = defaults(&bench);
    config["tilt_scale"] = json!([0.9, 0.5]);
    let (status, saved) = post(
        &bench,
        &format!("/api/profile?token={t}"),
        &json!({ "name": "f1", "config": config, "new": true }),
    );
    assert_eq!(status, 200, "{saved}");
    let (status, back) = get(&bench, &format!("/api/profile?token={t}&name=f1"));
    assert_eq!(status, 200, "{back}");
    assert_eq!(back["config"]["tilt_scale"], json!([0.9, 0.5]));
    let (_, base) = get(&bench, &format!("/api/profile?token={t}"));
    assert_eq!(base["config"]["tilt_scale"], json!([0.5, 0.5]), "the base stays");
    let (status, again) = post(
        &bench,
        &format!("/api/profile?token={t}"),
        &json!({ "name": "f1", "config": config, "new": true }),
    );
    assert_eq!(status, 422, "a duplicate does not overwrite: {again}");
    assert!(again["error"].as_str().unwrap().contains("exists already"), "{again}");
    // The command line reads the profile the page saved: its pitch tilt (0.9 over the base's 0.5) pitches the
    // platform further in the example drive's braking (0.171 rad against 0.154: the tilt's rate limit holds both
    // back; without the profile the two runs are the same).
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(
        text.contains("[profiles.f1]") && text.contains("outsim_opts = \"1ff\""),
        "{text}"
    );
    let pitch = |profile: Option<&str>| -> f64 {
        let out = dir.path().join("poses.csv");
        let mut cmd = assert_cmd::Command::cargo_bin("ringpod").unwrap();
        cmd.args([
            "cue",
            "--input",
            concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/drive-telemetry.csv"),
            "--out",
        ])
        .arg(&out)
        .arg("--config")
        .arg(&file);
        if let Some(p) = profile {
            cmd.args(["--profile", p]);
        }
        let run = cmd.output().unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let csv = std::fs::read_to_string(&out).unwrap();
        csv.lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(5)?.parse::<f64>().ok())
            .fold(0.0, |m: f64, b| m.max(b.abs()))
    };
    let (f1, base) = (pitch(Some("f1")), pitch(None));
    assert!(
        f1 > base * 1.05,
        "largest pitch {f1} rad with the profile, {base} without"
    );
}

/// Every bad input is refused and lands nothing: a name that is a path or not a name, a value out of range or of
/// the wrong kind, an unknown field or profile; without the token, from another Origin or Host, nothing is read
/// or written.
#[test]
fn bad_profile_requests_are_refused_and_no_path_leaves_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("cueing");
    std::fs::create_dir(&folder).unwrap();
    let file = folder.join("cue.toml");
    let bench = Workbench::start(&["--cue-config", file.to_str().unwrap()]);
    let t = &bench.token;
    let config = defaults(&bench);
    let save = |body: Value| post(&bench, &format!("/api/profile?token={t}"), &body);
    let long = "a".repeat(41);
    for name in [
        "",
        "../escape",
        "../../etc/passwd",
        "/tmp/x",
        "a/b",
        "a\\b",
        ".",
        "..",
        "f1.toml",
        "f 1",
        "é",
        &long,
    ] {
        let (status, body) = save(json!({ "name": name, "config": config }));
        assert_eq!(status, 422, "{name:?}: {body}");
        let (status, body) = get(&bench, &format!("/api/profile?token={t}&name={}", urlencode(name)));
        assert!(status == 422 || name.is_empty(), "{name:?}: {status} {body}");
    }
    let mut out_of_range = config.clone();
    out_of_range["tilt_scale"][1] = json!(-1.0);
    let (status, body) = save(json!({ "name": "f1", "config": out_of_range }));
    assert_eq!(status, 422);
    assert!(body["error"].as_str().unwrap().contains("tilt_scale"), "{body}");
    let mut wrong = config.clone();
    wrong["forward"] = json!("sideways");
    assert_eq!(save(json!({ "name": "f1", "config": wrong })).0, 422);
    assert_eq!(
        save(json!({ "name": "f1", "config": config, "path": "/tmp" })).0,
        422,
        "an unknown field"
    );
    assert_eq!(save(json!({ "name": "f1" })).0, 422, "no parameters");
    let (status, body) = get(&bench, &format!("/api/profile?token={t}&name=gt3"));
    assert_eq!(status, 422, "{body}");
    // Nothing was written: not the file, not anything beside it or above it.
    assert!(!file.exists());
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // The guard: no token, a wrong one, another site's page, a rebound host name.
    let body = json!({ "name": "f1", "config": config }).to_string();
    for (path, host, origin) in [
        ("/api/profile".to_owned(), bench.addr.clone(), None),
        ("/api/profile?token=0000".to_owned(), bench.addr.clone(), None),
        (
            format!("/api/profile?token={t}"),
            bench.addr.clone(),
            Some("http://evil.example"),
        ),
        (
            format!("/api/profile?token={t}"),
            format!("rebound.example:{}", bench.addr.rsplit(':').next().unwrap()),
            None,
        ),
    ] {
        let status = raw(&bench.addr, &path, &host, origin, &body);
        assert_eq!(status, 403, "{path} Host {host} Origin {origin:?}");
        assert!(!file.exists());
    }
    // With a classical washout the optimal cueing's hidden values are not read: -5 for its step does not block.
    let mut hidden = config.clone();
    hidden["optimal"]["step_s"] = json!(-5.0);
    let (status, body) = save(json!({ "name": "f1", "config": hidden }));
    assert_eq!(status, 200, "{body}");
    hidden["algorithm"] = json!("optimal");
    let (status, body) = save(json!({ "name": "f1", "config": hidden }));
    assert_eq!(status, 422, "chosen, the optimal cueing's values are checked: {body}");
    assert!(body["error"].as_str().unwrap().contains("step"), "{body}");
}

fn urlencode(s: &str) -> String {
    s.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() {
                (b as char).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

/// A POST with an Origin of the caller's choosing; the status.
pub(super) fn raw(addr: &str, path: &str, host: &str, origin: Option<&str>, body: &str) -> u16 {
    use std::io::Write;
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    let origin = origin.map(|o| format!("Origin: {o}\r\n")).unwrap_or_default();
    write!(
        s,
        "POST {path} HTTP/1.1\r\nHost: {host}\r\n{origin}Content-Type: application/json\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    super::workbench::answer(&mut s).0
}

/// While a telemetry session runs, each frame carries what the game asks, in the units the Live view shows:
/// a braking of 2 m/s^2 and a yaw rate of 0.5 rad/s arrive as -0.204 g (surge), 1 g (heave) and 28.6 deg/s; none
/// before the session, none half a second after its last datagram.
#[test]
fn frames_carry_the_games_cue_in_g_and_deg_per_s() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    let before = a
        .until(std::time::Duration::from_secs(10), |m| m["type"] == "frame")
        .unwrap();
    assert_eq!(before["cue_input"], Value::Null, "{before}");
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    a.send(json!({ "do": "udp", "port": port, "holds": "telemetry", "format": "text", "idle": 60 }));
    a.until(std::time::Duration::from_secs(60), |m| {
        m["type"] == "frame" && m["streaming"] == true && (m["state"] == "Ready" || m["state"] == "Running")
    })
    .unwrap();
    let s = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let mut cued = None;
    for i in 0..150 {
        let datagram = format!("{} -2 0 9.80665 0 0 0.5", f64::from(i) * 0.02);
        s.send_to(datagram.as_bytes(), ("127.0.0.1", port)).unwrap();
        for m in a.watch(std::time::Duration::from_millis(20)) {
            if m["type"] == "frame" && !m["cue_input"].is_null() {
                cued = Some(m["cue_input"].clone());
            }
        }
    }
    let cued = cued.expect("no frame carried the game's cue");
    let g = |i: usize| cued["force_g"][i].as_f64().unwrap();
    let rate = |i: usize| cued["rate_deg_s"][i].as_f64().unwrap();
    assert!(
        (g(0) + 2.0 / 9.80665).abs() < 1e-6 && g(1).abs() < 1e-9 && (g(2) - 1.0).abs() < 1e-6,
        "{cued}"
    );
    assert!(
        rate(0).abs() < 1e-9 && (rate(2) - 0.5f64.to_degrees()).abs() < 1e-6,
        "{cued}"
    );
    // The frames of the next second and a half: the newest, sent after the cue went stale, carries none.
    let frames: Vec<Value> = a
        .watch(std::time::Duration::from_millis(1500))
        .into_iter()
        .filter(|m| m["type"] == "frame")
        .collect();
    let last = frames.last().expect("frames after the last datagram");
    assert_eq!(
        last["cue_input"],
        Value::Null,
        "a cue over half a second old is not shown as the game's: {last}"
    );
    let stop = a.send(json!({ "do": "halt" }));
    a.until(std::time::Duration::from_secs(20), |m| {
        m["type"] == "halted" && m["id"] == stop
    })
    .unwrap();
}
