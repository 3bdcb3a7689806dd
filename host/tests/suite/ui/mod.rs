//! `ringpod ui --sim` driven over its WebSocket and HTTP as a page (or a hostile client) drives it.

mod profiles;
mod requests;
mod rig;
mod runs;
mod spare;
mod stall;
mod workbench;

use std::time::{Duration, Instant};

use serde_json::{json, Value};
use workbench::{Page, Workbench};

pub fn state(m: &Value) -> Option<&str> {
    (m["type"] == "frame").then(|| m["state"].as_str()).flatten()
}

pub fn is_reply(m: &Value, id: u64) -> bool {
    m["type"] == "reply" && m["id"] == id
}

/// Powers up and asks for homing from the Control panel's buttons.
fn homing(page: &mut Page) {
    page.send(json!({ "do": "enable" }));
    page.until(Duration::from_secs(20), |m| {
        m["type"] == "frame" && m["gates"]["home"].is_null()
    })
    .unwrap();
    page.send(json!({ "do": "home" }));
}

/// Powers up and homes from the Control panel's buttons, and waits for `Ready`.
fn homed(page: &mut Page) {
    homing(page);
    page.until(Duration::from_secs(60), |m| state(m) == Some("Ready"))
        .unwrap();
}

#[test]
fn stop_from_any_page_preempts_the_queue_and_is_answered_at_once() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homed(&mut a);
    // Three streams asked in one burst: the first runs; the others wait in the device thread's queue, or, when
    // the page's socket takes one only after the first has begun streaming, are refused at once.
    let motion = json!({ "do": "motion", "motion": "demo", "seconds": 8, "rate_hz": 100 });
    let ids: Vec<u64> = (0..3).map(|_| a.send(motion.clone())).collect();
    let mut answers = Vec::new();
    let mut keep = |m: &Value| {
        if m["type"] == "reply" && ids.contains(&m["id"].as_u64().unwrap_or(0)) {
            answers.push(m.clone());
        }
    };
    a.until(Duration::from_secs(30), |m| {
        keep(m);
        m["type"] == "frame" && m["streaming"] == true && state(m) == Some("Running")
    })
    .unwrap();
    a.watch(Duration::from_secs(2)).iter().for_each(&mut keep);
    // STOP from another page.
    let mut b = bench.page();
    let stop = b.send(json!({ "do": "halt" }));
    let asked = Instant::now();
    let answer = b
        .until(Duration::from_secs(1), |m| is_reply(m, stop))
        .unwrap_or_else(|e| {
            panic!("STOP was not answered within 1 s: {e}");
        });
    assert_eq!(answer["ok"], true, "{answer}");
    // The queued streams are answered as cancelled, the running one as interrupted; none runs.
    let mut running_after = Vec::new();
    a.until(Duration::from_secs(20), |m| {
        keep(m);
        if m["type"] == "frame" && m["streaming"] == true && asked.elapsed() > Duration::from_secs(1) {
            running_after.push(m["t"].clone());
        }
        m["type"] == "halted" && m["id"] == stop
    })
    .unwrap();
    assert!(
        asked.elapsed() < Duration::from_secs(12),
        "at rest in {:?}",
        asked.elapsed()
    );
    a.until(Duration::from_secs(5), |m| state(m) == Some("Off")).unwrap();
    let watched = a.watch(Duration::from_secs(2));
    assert!(
        watched.iter().all(|m| m["type"] != "frame" || m["streaming"] == false),
        "a stream ran after STOP"
    );
    assert!(
        running_after.is_empty(),
        "streaming 1 s after STOP at device times {running_after:?}"
    );
    let text = |id: u64| {
        let of_id: Vec<_> = answers.iter().filter(|m| m["id"] == id).collect();
        assert_eq!(of_id.len(), 1, "request {id} answered once: {answers:?}");
        of_id[0]["text"].as_str().unwrap_or("").to_owned()
    };
    assert!(text(ids[0]).starts_with("interrupted"), "{}", text(ids[0]));
    for id in &ids[1..] {
        let text = text(*id);
        assert!(
            text.contains("cancelled")
                || text.starts_with("a stream is running")
                || text.starts_with("another stream was asked first"),
            "{text}"
        );
    }
}

/// Two pages ask for a motion at the same moment: one runs, the other is refused at once (it does not run after
/// the first, unasked for by then).
#[test]
fn of_two_streams_asked_at_once_from_two_pages_one_is_refused() {
    let bench = Workbench::start(&[]);
    let number = |p: &mut Page| p.until(Duration::from_secs(10), |m| m["type"] == "hello").unwrap()["page"].clone();
    let mut a = bench.page();
    let pa = number(&mut a);
    homed(&mut a);
    // Opened now: a page that reads nothing while the other homes is taken as gone.
    let mut b = bench.page();
    let pb = number(&mut b);
    let motion = json!({ "do": "motion", "motion": "heave", "seconds": 2, "rate_hz": 100 });
    let (ida, idb) = (a.send(motion.clone()), b.send(motion));
    // Both pages read in turn (each answers the workbench's pings as it reads), until both replies came.
    let (mut ra, mut rb) = (None, None);
    let deadline = Instant::now() + Duration::from_secs(60);
    while (ra.is_none() || rb.is_none()) && Instant::now() < deadline {
        if let Some(m) = a.next(Duration::from_millis(50)).unwrap() {
            if is_reply(&m, ida) && m["page"] == pa {
                ra = Some(m);
            }
        }
        if let Some(m) = b.next(Duration::from_millis(50)).unwrap() {
            if is_reply(&m, idb) && m["page"] == pb {
                rb = Some(m);
            }
        }
    }
    let (ra, rb) = (ra.expect("page a's reply"), rb.expect("page b's reply"));
    let refused: Vec<_> = [&ra, &rb].into_iter().filter(|r| r["ok"] == false).collect();
    assert_eq!(refused.len(), 1, "{ra}\n{rb}");
    assert!(
        refused[0]["text"]
            .as_str()
            .unwrap()
            .starts_with("another stream was asked first")
            || refused[0]["text"].as_str().unwrap().starts_with("a stream is running"),
        "{}",
        refused[0]
    );
}

#[test]
fn a_stream_asked_just_before_stop_never_moves() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homed(&mut a);
    let motion = a.send(json!({ "do": "motion", "motion": "heave", "seconds": 5, "rate_hz": 100 }));
    let stop = a.send(json!({ "do": "halt" }));
    let mut seen = Vec::new();
    a.until(Duration::from_secs(20), |m| {
        seen.push(m.clone());
        m["type"] == "halted" && m["id"] == stop
    })
    .unwrap();
    let position = |pred: &dyn Fn(&Value) -> bool| seen.iter().position(pred);
    let stopped = position(&|m| is_reply(m, stop)).expect("STOP answered");
    assert!(
        position(&|m| is_reply(m, motion)).is_some(),
        "the stream is answered (cancelled or interrupted)"
    );
    assert!(
        !seen[stopped..].iter().any(|m| state(m) == Some("Running")),
        "the platform ran after STOP was answered"
    );
}

/// The first frame a page sees.
fn first_frame(page: &mut Page) -> Value {
    page.until(Duration::from_secs(10), |m| m["type"] == "frame").unwrap()
}

#[test]
fn a_page_closed_mid_stream_leaves_the_platform_at_rest_and_powered_down() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homed(&mut a);
    a.send(json!({ "do": "motion", "motion": "demo", "seconds": 60, "rate_hz": 100 }));
    a.until(Duration::from_secs(30), |m| {
        m["type"] == "frame" && state(m) == Some("Running")
    })
    .unwrap();
    a.close();
    // Past the grace and the ramp to rest, another page finds the supplies off.
    std::thread::sleep(Duration::from_secs(5));
    let mut b = bench.page();
    let f = first_frame(&mut b);
    assert_eq!(state(&f), Some("Off"), "{f}");
    assert_eq!(
        f["outputs"].as_u64().unwrap() & 0b111,
        0,
        "supplies and drivers off: {f}"
    );
}

#[test]
fn a_page_killed_during_homing_leaves_the_platform_powered_down() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homing(&mut a);
    a.until(Duration::from_secs(20), |m| state(m) == Some("Homing"))
        .unwrap();
    // A killed browser: the connection ends with no close frame.
    drop(a);
    std::thread::sleep(Duration::from_secs(5));
    let mut b = bench.page();
    let f = first_frame(&mut b);
    assert_eq!(state(&f), Some("Off"), "{f}");
}

/// A page that answers no ping (a browser frozen, a machine asleep) is closed as gone, once it has left five
/// unanswered, one a second; a page that reads answers them and stays.
#[test]
fn a_page_that_answers_no_ping_is_taken_as_gone() {
    let bench = Workbench::start(&[]);
    let mut quiet = bench.page();
    let mut awake = bench.page();
    let started = Instant::now();
    awake.watch(Duration::from_secs(8));
    let end = quiet.until(Duration::from_secs(5), |_| false).unwrap_err();
    // The close frame, or, when the frames the page left unread filled the connection so that the close frame
    // could not follow them, the connection reset or aborted (Linux's and Windows' error numbers).
    let ended = [
        "(os error 104)",
        "(os error 103)",
        "(os error 10054)",
        "(os error 10053)",
    ];
    assert!(
        end.starts_with("closed 1001 no answer to the pings") || ended.iter().any(|e| end.contains(e)),
        "{end}"
    );
    assert!(started.elapsed() >= Duration::from_secs(5), "{:?}", started.elapsed());
    assert!(
        awake.until(Duration::from_secs(5), |m| m["type"] == "frame").is_ok(),
        "the page that answered was closed"
    );
}

/// A page reloaded while its stream runs: the workbench cannot tell a reload from a page closed or killed, and a
/// page being loaded has no STOP; it does what STOP does. The new page is told what happened before it opened.
#[test]
fn a_page_reloaded_during_its_stream_stops_it_powers_down_and_the_new_page_is_told() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homed(&mut a);
    a.send(json!({ "do": "motion", "motion": "heave", "seconds": 60, "rate_hz": 100 }));
    a.until(Duration::from_secs(30), |m| state(m) == Some("Running"))
        .unwrap();
    a.close();
    std::thread::sleep(Duration::from_millis(500));
    let mut b = bench.page();
    let mut notices = Vec::new();
    let off = b
        .until(Duration::from_secs(20), |m| {
            if m["type"] == "notice" || m["type"] == "stop_pending" {
                notices.push(m["text"].as_str().unwrap_or("").to_owned());
            }
            state(m) == Some("Off")
        })
        .unwrap();
    assert_eq!(
        off["outputs"].as_u64().unwrap() & 0b111,
        0,
        "supplies and drivers off: {off}"
    );
    // The notices of before the page, and the STOP's confirmation (before it opened or while it watched).
    notices.extend(
        b.watch(Duration::from_secs(1))
            .iter()
            .filter(|m| m["type"] == "notice" || m["type"] == "stop_pending")
            .map(|m| m["text"].as_str().unwrap_or("").to_owned()),
    );
    assert!(
        notices
            .iter()
            .any(|n| n.contains("started the stream, went away") && n.contains("comes to rest and powers down")),
        "{notices:?}"
    );
    assert!(notices.iter().any(|n| n.starts_with("STOP confirmed")), "{notices:?}");
}

/// A page reloaded with no stream of its own: nothing moved, the platform stays powered for the page that comes
/// back within the grace.
#[test]
fn a_reload_with_no_stream_within_the_grace_keeps_the_platform_powered() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    homed(&mut a);
    a.close();
    std::thread::sleep(Duration::from_millis(500));
    let mut b = bench.page();
    let watched = b.watch(Duration::from_secs(4));
    let frames: Vec<_> = watched.iter().filter(|m| m["type"] == "frame").collect();
    assert!(!frames.is_empty());
    assert!(
        frames.iter().all(|m| state(m) == Some("Ready")),
        "powered down although a page was back within the grace"
    );
}

/// STOP while a UDP session powers up and homes, before its first datagram: the session is answered as stopped
/// (what the operator asked), not in red as a stream that failed to start.
#[test]
fn a_stop_before_the_first_datagram_is_answered_as_stopped_not_failed() {
    let bench = Workbench::start(&[]);
    let mut a = bench.page();
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let session = a.send(json!({ "do": "udp", "port": port, "holds": "poses", "idle": 60 }));
    a.until(Duration::from_secs(30), |m| state(m) == Some("Homing"))
        .unwrap();
    a.send(json!({ "do": "halt" }));
    let answer = a.until(Duration::from_secs(20), |m| is_reply(m, session)).unwrap();
    assert_eq!(answer["ok"], true, "{answer}");
    assert!(
        answer["text"]
            .as_str()
            .unwrap()
            .starts_with("stopped by STOP before it started"),
        "{answer}"
    );
}

#[test]
fn the_rig_message_names_the_firmware_the_device_runs_and_its_protocol() {
    use ringpod_core::protocol::firmware::BUILT_VERSION;
    use ringpod_core::protocol::PROTOCOL_VERSION;
    // The simulated controller runs this build's core, with no flashed image; the page shows the line beside the
    // rig's name (app.js, `rig-name`).
    let wb = Workbench::start(&[]);
    let mut page = wb.page();
    let rig = page.until(Duration::from_secs(20), |m| m["type"] == "rig").unwrap();
    let [major, minor, patch] = BUILT_VERSION;
    assert_eq!(
        rig["firmware"],
        format!("ringpod {major}.{minor}.{patch} (no image: simulated), protocol {PROTOCOL_VERSION}")
    );
}
