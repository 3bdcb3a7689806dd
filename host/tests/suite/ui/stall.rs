//! The workbench on a device behind a link that stalls (`--port tcp://` through a proxy that holds the bytes): a
//! STOP given in the stall is shown as pending, given again, and lands when the link returns.

use std::time::Duration;

use serde_json::json;

use super::workbench::Workbench;
use super::{homed, state};
use crate::common::proxy::{Proxy, Served};

/// STOP 1.5 s into a 6 s stall, a demo motion running: the pages are told the STOP is pending; when the link
/// returns the device comes to rest and powers down (Off, supplies and drivers off), and the pages are told so.
#[test]
fn a_stop_given_while_the_link_stalls_lands_when_it_returns() {
    let server = Served::start();
    let proxy = Proxy::to(&server.addr);
    let bench = Workbench::on(&["--port", &proxy.addr]);
    let mut page = bench.page();
    homed(&mut page);
    page.send(json!({ "do": "motion", "motion": "demo", "seconds": 60, "rate_hz": 100 }));
    page.until(Duration::from_secs(30), |m| state(m) == Some("Running"))
        .unwrap();
    proxy.stall(true);
    std::thread::sleep(Duration::from_millis(1500));
    page.send(json!({ "do": "halt" }));
    page.until(Duration::from_secs(10), |m| {
        m["type"] == "stop_pending" && m["pending"] == true
    })
    .unwrap();
    std::thread::sleep(Duration::from_millis(4500));
    proxy.stall(false);
    let confirmed = page
        .until(Duration::from_secs(30), |m| {
            m["type"] == "stop_pending" && m["pending"] == false
        })
        .unwrap();
    assert!(
        confirmed["text"].as_str().unwrap().starts_with("STOP confirmed"),
        "{confirmed}"
    );
    let off = page
        .until(Duration::from_secs(20), |m| state(m) == Some("Off"))
        .unwrap();
    assert_eq!(
        off["outputs"].as_u64().unwrap() & 0b111,
        0,
        "supplies and drivers off: {off}"
    );
}
