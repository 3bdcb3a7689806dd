//! A link that stalls mid-stream (`--port tcp://` through a proxy that holds the bytes): the CLI says so as it
//! happens, and a stop given in the stall is given again until the device confirms it when the link comes back.
//! Unix only: the test interrupts the stream with SIGINT, as Ctrl-C does.
#![cfg(unix)]

use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::proxy::{Proxy, Served};

/// Ctrl-C 1.5 s into a 9.5 s stall of the link: the CLI says the link stalled and that the stop is pending, gives it
/// again until the link returns, and reports the platform at rest (exit 130, state Ready) instead of a lost link.
#[test]
fn ctrl_c_in_a_stalled_link_is_confirmed_when_the_link_returns() {
    // Longer than the answers in flight are waited for (5 s): the stop itself goes unanswered and is given again.
    let (code, report, said) = ctrl_c_in_a_stall(None, 8000);
    assert_eq!(code, Some(130), "{report}\n{said}");
    assert_eq!(report["state"], "Ready", "{report}\n{said}");
    assert!(said.contains("the link is stalled"), "{said}");
    assert!(said.contains("STOP pending"), "{said}");
    assert!(said.contains("the stop was confirmed after"), "{said}");
}

/// A stall longer than the device's time for a host gone (set to 2 s): the device brakes when its stream is lost
/// and powers down on its own before the link returns; the pending stop is then confirmed by a device that is Off,
/// supplies off, and the CLI says so (exit 130, state Off).
#[test]
fn a_stall_longer_than_the_host_gone_time_ends_with_the_device_off() {
    let (code, report, said) = ctrl_c_in_a_stall(Some(2000), 8000);
    assert_eq!(code, Some(130), "{report}\n{said}");
    assert_eq!(report["state"], "Off", "{report}\n{said}");
    assert!(said.contains("STOP pending"), "{said}");
    assert!(said.contains("the stop was confirmed after"), "{said}");
}

/// `stream --motion demo` through a proxy to `simulate --tcp` (its `stream.host_gone_ms` set first when given), the
/// link stalled once the motion runs, SIGINT 1.5 s into the stall, the link back `stalled_ms` later: the exit code,
/// the JSON report and what the CLI said.
fn ctrl_c_in_a_stall(host_gone_ms: Option<u32>, stalled_ms: u64) -> (Option<i32>, serde_json::Value, String) {
    let server = Served::start();
    if let Some(ms) = host_gone_ms {
        let set = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args([
                "device",
                "config",
                "set",
                "stream.host_gone_ms",
                &ms.to_string(),
                "--port",
                &server.addr,
            ])
            .output()
            .unwrap();
        assert!(set.status.success(), "{}", String::from_utf8_lossy(&set.stderr));
    }
    let proxy = Proxy::to(&server.addr);
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["stream", "--port", &proxy.addr, "--motion", "demo", "--duration", "60"])
        .args(["--report-json", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Powering up and homing take about 10 s of the simulator's real time; the demo motion runs after them.
    std::thread::sleep(Duration::from_secs(15));
    proxy.stall(true);
    std::thread::sleep(Duration::from_millis(1500));
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    std::thread::sleep(Duration::from_millis(stalled_ms));
    proxy.stall(false);
    let mut said = String::new();
    let mut stderr = child.stderr.take().unwrap();
    let status = child.wait().unwrap();
    std::io::Read::read_to_string(&mut stderr, &mut said).unwrap();
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut stdout).unwrap();
    let report = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {said}"));
    (status.code(), report, said)
}

/// SIGINT while the CLI greets a port that never answers (a listening socket nobody serves): it ends at once with
/// 130, not after the 5 s the greeting waits for.
#[test]
fn a_signal_while_connecting_to_a_silent_port_ends_at_once() {
    let silent = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = format!("tcp://{}", silent.local_addr().unwrap());
    let child = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["stream", "--port", &port, "--motion", "demo", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    let asked = std::time::Instant::now();
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let out = child.wait_with_output().unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{said}");
    assert!(
        asked.elapsed() < Duration::from_millis(1500),
        "{:?}: {said}",
        asked.elapsed()
    );
}
