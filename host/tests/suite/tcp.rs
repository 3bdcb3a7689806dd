//! The simulated controller served over TCP (`simulate --tcp`, on every system) and driven through `--port tcp://`
//! as a board is through its serial port: the same framed bytes, end to end.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use assert_cmd::cargo::CommandCargoExt;

/// A server killed when dropped, so that a failed assertion leaves nothing running.
struct Server(Child, String);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `ringpod simulate --tcp 127.0.0.1:0` and reads the address it serves on from its first line.
fn serve() -> Server {
    let mut child = Command::cargo_bin("ringpod")
        .unwrap()
        .args(["simulate", "--tcp", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let port = line.trim().to_owned();
    assert!(port.starts_with("tcp://127.0.0.1:"), "{port}");
    Server(child, port)
}

fn ringpod(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("ringpod").unwrap().args(args).output().unwrap()
}

#[test]
fn a_stream_over_tcp_is_followed_and_a_second_command_finds_the_same_device() {
    let server = serve();
    let args = format!(
        "stream --port {} --motion demo --duration 2 --quiet --report-json",
        server.1
    );
    let out = ringpod(&args.split(' ').collect::<Vec<_>>());
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(out.status.code(), Some(0), "{report}");
    assert_eq!(report["outcome"], "followed");
    let sent = report["setpoints_sent"].as_u64().unwrap();
    assert!(sent > 1500, "{report}");
    assert_eq!(report["setpoints_applied"], sent);
    // The controller lives on between clients, as a board does: it counts the setpoints the stream gave it.
    let status = ringpod(&["device", "status", "--port", &server.1]);
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let status: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
    assert!(status["applied"].as_u64().unwrap() >= sent, "{status}");
}

#[test]
fn one_client_at_a_time_the_second_is_closed_at_once() {
    let server = serve();
    let address = server.1.trim_start_matches("tcp://");
    let first = std::net::TcpStream::connect(address).unwrap();
    // Let the server accept the first before the second arrives.
    std::thread::sleep(Duration::from_millis(200));
    let mut second = std::net::TcpStream::connect(address).unwrap();
    second.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let started = Instant::now();
    // Told, then closed: end of stream, well before the timeout.
    let mut told = Vec::new();
    let _ = second.read_to_end(&mut told);
    assert_eq!(
        String::from_utf8_lossy(&told),
        "ringpod simulate: busy with another client\n"
    );
    assert!(started.elapsed() < Duration::from_secs(4));
    // A command on the busy simulator says so, not that "the peer closed the connection".
    let out = ringpod(&["device", "status", "--port", &server.1]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("the simulator is busy with another client"), "{said}");
    drop(first);
}

/// An address the simulator cannot listen on (a port another program holds) is named with the reason.
#[test]
fn an_address_that_cannot_be_listened_on_is_named() {
    let held = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = held.local_addr().unwrap().to_string();
    let out = ringpod(&["simulate", "--tcp", &addr]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains(&format!("cannot listen on {addr}")), "{said}");
}

#[test]
fn nobody_at_the_address_fails_at_once_naming_it() {
    // Bound then dropped: a free port with nobody listening.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let address = format!("tcp://127.0.0.1:{port}");
    let started = Instant::now();
    let out = ringpod(&["device", "status", "--port", &address]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(&address),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(started.elapsed() < Duration::from_secs(10));
}

/// A peer that hangs up at once: the error names the cause once ("transport: the peer closed the connection"),
/// not a second time as the cause of itself.
#[test]
fn a_peer_that_hangs_up_is_said_once() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let address = format!("tcp://{}", listener.local_addr().unwrap());
    let hang_up = std::thread::spawn(move || drop(listener.accept().unwrap()));
    let out = ringpod(&["device", "status", "--port", &address]);
    hang_up.join().unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    let line = said.lines().next().unwrap_or_default();
    let mut parts: Vec<&str> = line.split(": ").skip(1).collect();
    let all = parts.len();
    parts.sort_unstable();
    parts.dedup();
    assert_eq!(parts.len(), all, "a part said twice: {said}");
}

#[cfg(not(unix))]
#[test]
fn a_pseudo_terminal_is_refused_by_name_off_unix() {
    let out = ringpod(&["simulate", "--pty"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--pty") && err.contains("--tcp"), "{err}");
}
