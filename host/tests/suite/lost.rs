//! A frame lost on the link (noise, a UART overrun): the device never sees one setpoint, answers the next ones, and
//! the stream neither waits for the lost answer nor loses count of it.

use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::proxy::{Proxy, Served};

/// One setpoint's frame lost mid-stream through the proxy: the stream runs to its end (exit 0, followed), the report
/// counts the setpoint whose answer never came and says the counts do not agree, and every other setpoint was
/// answered: without it, the stream waits for that answer until its patience ends and reports a lost link.
#[test]
fn a_setpoint_lost_on_the_link_is_counted_and_the_stream_goes_on() {
    let server = Served::start();
    let proxy = Proxy::to(&server.addr);
    let child = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["stream", "--port", &proxy.addr, "--motion", "demo", "--duration", "6"])
        .args(["--report-json", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Powering up and homing take about 10 s of the simulator's real time; the demo motion runs after them (the
    // setpoint lost may be one of the lead-in's if homing took longer).
    std::thread::sleep(Duration::from_secs(12));
    proxy.lose_a_setpoint();
    let out = child.wait_with_output().unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {said}"));
    assert_eq!(proxy.setpoints_lost(), 1, "{report}\n{said}");
    assert_eq!(out.status.code(), Some(0), "{report}\n{said}");
    assert_eq!(report["outcome"], "followed", "{report}\n{said}");
    assert_eq!(report["setpoints_unanswered"], 1, "{report}\n{said}");
    assert_eq!(report["counts_agree"], false, "{report}\n{said}");
    let (sent, applied) = (&report["setpoints_sent"], &report["setpoints_applied"]);
    let missing = sent.as_u64().unwrap() - applied.as_u64().unwrap();
    assert!(missing <= 1, "{sent} sent, {applied} applied: {report}\n{said}");
    assert!(said.contains("answer was lost on the link"), "{said}");
}
