//! What a page's requests may reach: files, sockets, the cueing file, the `Host`, and what a page is sent.

use std::time::Duration;

use serde_json::{json, Value};

use super::workbench::{http, Workbench};
use super::{is_reply, state};

/// A loopback UDP port free when asked (the socket that found it is closed again).
fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn reply(page: &mut super::workbench::Page, request: Value, within: Duration) -> Value {
    let id = page.send(request);
    page.until(within, |m| is_reply(m, id)).unwrap()
}

#[test]
fn a_file_is_read_only_when_picked_or_under_the_named_directory_and_never_quoted() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("poses");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(root.path().join("secret.txt"), "SECRET-LINE\n").unwrap();
    std::fs::write(dir.join("bad.csv"), "SECRET-HEADER,a,b\n1,2,3\n").unwrap();
    let bench = Workbench::start(&["--files", dir.to_str().unwrap()]);
    let mut a = bench.page();
    for request in [
        json!({ "do": "file", "path": "/etc/passwd" }),
        json!({ "do": "file", "name": "/etc/passwd" }),
        json!({ "do": "file", "name": "../secret.txt" }),
        json!({ "do": "file", "name": "bad.csv" }),
    ] {
        let r = reply(&mut a, request.clone(), Duration::from_secs(10));
        let text = r["text"].as_str().unwrap();
        assert_eq!(r["ok"], false, "{request}: {r}");
        assert!(
            !text.contains("root:") && !text.contains("SECRET"),
            "{request}: the answer quotes the file: {text}"
        );
        // The file is named once.
        if let Some(name) = request["name"].as_str() {
            assert!(!text.contains(&format!("{name}: {name}")), "{request}: {text}");
        }
    }
    // A file the user picked comes as its text, and is followed.
    let text = "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n0.5,0,0,0.229,0,0,0\n";
    let r = reply(
        &mut a,
        json!({ "do": "file", "name": "mine.csv", "text": text }),
        Duration::from_secs(60),
    );
    assert_eq!(r["ok"], true, "{r}");
    assert!(r["text"].as_str().unwrap().starts_with("followed"), "{r}");
}

/// Linux only: it tells senders apart by loopback aliases (127.0.0.2, 127.0.0.3), which Wine does not keep apart.
#[test]
#[cfg(unix)]
fn a_udp_session_binds_the_workbench_address_and_takes_only_its_sender() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    let port = free_udp_port();
    a.send(json!({ "do": "udp", "port": port, "holds": "poses", "from": "127.0.0.2", "idle": 60 }));
    a.until(Duration::from_secs(60), |m| {
        m["type"] == "frame" && m["streaming"] == true && state(m) == Some("Ready")
    })
    .unwrap();
    // Bound to 127.0.0.1 only: another loopback address's port is free (a socket on 0.0.0.0 would hold it).
    std::net::UdpSocket::bind(("127.0.0.3", port)).expect("the session holds only 127.0.0.1's port");
    let send = |from: &str| {
        let s = std::net::UdpSocket::bind((from, 0)).unwrap();
        for _ in 0..60 {
            s.send_to(b"0 0 0.237 0 0 0", ("127.0.0.1", port)).unwrap();
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    send("127.0.0.1");
    let ignored = a.watch(Duration::from_millis(500));
    assert!(
        ignored
            .iter()
            .filter(|m| m["type"] == "frame")
            .all(|m| m["pose"][2].as_f64().unwrap() < 0.232),
        "another sender's poses were followed"
    );
    send("127.0.0.2");
    a.until(Duration::from_secs(10), |m| {
        m["type"] == "frame" && (m["pose"][2].as_f64().unwrap() - 0.237).abs() < 0.0005
    })
    .unwrap();
    let stop = a.send(json!({ "do": "halt" }));
    a.until(Duration::from_secs(20), |m| m["type"] == "halted" && m["id"] == stop)
        .unwrap();
}

/// A session of a motion front end's pose strings: a template that cannot be read is refused naming its
/// character, before anything binds; a preset's strings are followed as offsets from neutral.
#[test]
fn a_udp_session_reads_a_front_ends_strings() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    let port = free_udp_port();
    let bad = json!({ "do": "udp", "port": port, "holds": "strings", "format": "dec8:<Axis7a>" });
    let r = reply(&mut a, bad, Duration::from_secs(10));
    assert_eq!(r["ok"], false, "{r}");
    assert!(r["text"].as_str().unwrap().contains("character 6"), "{r}");
    a.send(json!({ "do": "udp", "port": port, "holds": "strings", "format": "simtools", "idle": 60 }));
    a.until(Duration::from_secs(60), |m| {
        m["type"] == "frame" && m["streaming"] == true && state(m) == Some("Ready")
    })
    .unwrap();
    let s = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    // SimTools' 16-bit decimal: heave 49151 is +20 mm of its 40 mm range, from the home pose's 0.227 m.
    for _ in 0..60 {
        s.send_to(b"32768~32768~49151~32768~32768~32768~", ("127.0.0.1", port))
            .unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    a.until(Duration::from_secs(10), |m| {
        m["type"] == "frame" && (m["pose"][2].as_f64().unwrap() - 0.247).abs() < 0.0005
    })
    .unwrap();
    let stop = a.send(json!({ "do": "halt" }));
    a.until(Duration::from_secs(20), |m| m["type"] == "halted" && m["id"] == stop)
        .unwrap();
}

#[cfg(unix)]
#[test]
fn the_live_cueing_file_is_private_and_replaced_whole() {
    use std::os::unix::fs::PermissionsExt;
    let bench = Workbench::start(&[]);
    let host = bench.addr.clone();
    let path = |p: &str| format!("{p}?token={}", bench.token);
    let (status, defaults) = http(&bench.addr, "GET", &path("/api/cue/defaults"), &host, None);
    assert_eq!(status, 200, "{defaults}");
    let config = serde_json::from_str::<Value>(&defaults).unwrap()["config"].clone();
    let apply = || {
        http(
            &bench.addr,
            "POST",
            &path("/api/cue/apply"),
            &host,
            Some(&json!({ "config": config })),
        )
    };
    let (status, body) = apply();
    assert_eq!(status, 200, "{body}");
    let file = std::path::PathBuf::from(
        serde_json::from_str::<Value>(&body).unwrap()["applied"]
            .as_str()
            .unwrap(),
    );
    let dir = file.parent().unwrap();
    assert_ne!(
        dir,
        std::env::temp_dir(),
        "a directory of its own, not a name in the shared temp directory"
    );
    assert_eq!(std::fs::metadata(dir).unwrap().permissions().mode() & 0o777, 0o700);
    // A link planted at the file's name is replaced, its target left alone.
    let victim = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(victim.path(), "keep").unwrap();
    std::fs::remove_file(&file).unwrap();
    std::os::unix::fs::symlink(victim.path(), &file).unwrap();
    assert_eq!(apply().0, 200);
    assert_eq!(std::fs::read_to_string(victim.path()).unwrap(), "keep");
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("translation_scale"), "{text}");
}

#[test]
fn the_host_is_checked_on_every_request_and_unknown_fields_are_refused() {
    let bench = Workbench::start(&[]);
    let own = bench.addr.clone();
    let port = own.rsplit(':').next().unwrap();
    let page = format!("/?token={}", bench.token);
    assert_eq!(http(&bench.addr, "GET", &page, &own, None).0, 200);
    for host in [
        format!("rebound.example:{port}"),
        format!("127.0.0.1:{}", port.parse::<u16>().unwrap() ^ 1),
    ] {
        let (status, body) = http(&bench.addr, "GET", &page, &host, None);
        assert_eq!(status, 403, "Host {host} without an Origin: {body}");
    }
    let check = format!("/api/rig/check?token={}", bench.token);
    let (status, _) = http(
        &bench.addr,
        "POST",
        &check,
        &own,
        Some(&json!({ "text": "", "also": 1 })),
    );
    assert_eq!(status, 422, "an unknown field of a body");
    let mut a = bench.page();
    for request in [
        json!({ "do": "enable", "axis": 2 }),
        json!({ "do": "halt", "now": true }),
    ] {
        let r = reply(&mut a, request.clone(), Duration::from_secs(5));
        assert_eq!(r["ok"], false, "{request}: {r}");
    }
}

/// OutSim Opts from the page: refused before any session when they cannot apply (poses, a format that never
/// reads OutSimPack2) or are not an option set; nothing moves (the device stays Off).
#[test]
fn outsim_options_from_the_page_are_checked_before_a_session() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    for (request, says) in [
        (
            json!({ "do": "udp", "port": 1, "holds": "poses", "outsim_opts": "1ff" }),
            "telemetry",
        ),
        (
            json!({ "do": "udp", "port": 1, "holds": "telemetry", "format": "f1", "outsim_opts": "1ff" }),
            "outsim2 or auto",
        ),
        (
            json!({ "do": "udp", "port": 1, "holds": "telemetry", "format": "outsim2", "outsim_opts": "zz" }),
            "hexadecimal",
        ),
        (
            json!({ "do": "udp", "port": 1, "holds": "telemetry", "format": "auto", "outsim_opts": "7" }),
            "main section",
        ),
    ] {
        let r = reply(&mut a, request.clone(), Duration::from_secs(10));
        assert_eq!(r["ok"], false, "{request}: {r}");
        assert!(r["text"].as_str().unwrap().contains(says), "{request}: {r}");
    }
    let frame = a.until(Duration::from_secs(10), |m| m["type"] == "frame").unwrap();
    assert_eq!(state(&frame), Some("Off"), "{frame}");
}

#[test]
fn replies_are_never_dropped_for_a_page_that_lags() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    const N: u64 = 3000;
    // A burst, read only afterwards: the device thread answers far faster than the page reads.
    for _ in 0..N {
        a.send(json!({ "do": "clear" }));
    }
    let mut replies = 0;
    let mut coalesced = 0;
    let _ = a.until(Duration::from_secs(60), |m| {
        if m["type"] == "reply" {
            replies += 1;
        }
        if m["type"] == "frame" {
            coalesced = m["coalesced"].as_u64().unwrap_or(0);
        }
        replies == N
    });
    assert_eq!(replies, N, "replies received (frames coalesced: {coalesced})");
}

#[test]
fn a_message_over_the_limit_is_closed_with_1009() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    let big = format!("{{\"id\":1,\"do\":\"load_rig\",\"text\":\"{}\"}}", "x".repeat(17 << 20));
    a.ws.send(tungstenite::Message::text(big))
        .expect("sent whole before the workbench answers");
    let closed = loop {
        match a.next(Duration::from_secs(10)) {
            Ok(Some(_)) => {}
            Ok(None) => panic!("no close within 10 s"),
            Err(e) => break e,
        }
    };
    assert!(closed.starts_with("closed 1009"), "{closed}");
}

/// The Cueing panel's replay scores what the rider perceives, and with `compare` cues the same drive by the
/// other algorithm too: both scored, the other's delivered force sample for sample; without it, none.
#[test]
fn the_cueing_panel_scores_both_algorithms_on_one_drive() {
    let bench = Workbench::start(&[]);
    let host = bench.addr.clone();
    let path = |p: &str| format!("{p}?token={}", bench.token);
    let (_, defaults) = http(&bench.addr, "GET", &path("/api/cue/defaults"), &host, None);
    let config = serde_json::from_str::<Value>(&defaults).unwrap()["config"].clone();
    let cue = |compare: bool| {
        let body = json!({ "config": config, "compare": compare });
        // The device's rig comes with its first status: asked again until it has.
        let deadline = std::time::Instant::now() + Duration::from_secs(20);
        loop {
            let (status, text) = http(&bench.addr, "POST", &path("/api/cue"), &host, Some(&body));
            if status == 200 || std::time::Instant::now() > deadline {
                assert_eq!(status, 200, "{text}");
                return serde_json::from_str::<Value>(&text).unwrap();
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    };
    let both = cue(true);
    let (mine, other) = (&both["score"], &both["other"]["score"]);
    assert_eq!(
        (&mine["algorithm"], &other["algorithm"]),
        (&json!("classical"), &json!("optimal")),
        "{both}"
    );
    assert_eq!(mine["fallbacks"], Value::Null, "{both}");
    assert!(other["fallbacks"].is_u64(), "{both}");
    for s in [mine, other] {
        assert!(
            s["force_rms"].as_f64().unwrap() > 0.0 && s["false_cues"].is_u64(),
            "{both}"
        );
    }
    let samples = both["t"].as_array().unwrap().len();
    assert!(samples > 1000, "{both}");
    assert_eq!(both["other"]["delivered"].as_array().unwrap().len(), samples);
    assert_ne!(both["other"]["delivered"], both["delivered"]);
    let one = cue(false);
    assert_eq!(one["other"], Value::Null);
    assert_eq!(one["score"], *mine, "the same replay scored the same");
}
