//! `cargo run -p ringpod-tests --bin browser`: `ringpod ui --sim` in a real browser (Debian's headless Chromium,
//! driven through ChromeDriver over WebDriver).
//!
//! 1. Chromium and ChromeDriver (installed with apt-get when missing and allowed, as QEMU is), and the CLI
//!    (`cargo build -p ringpod`), and a run record made by `ringpod stream --sim --record`.
//! 2. `ringpod ui --sim --listen 127.0.0.1:0`, its URL read from its first line; ChromeDriver on a free port.
//! 3. The checks, each a `PASS`/`FAIL` line: the page connects and draws; Enable and Home through the buttons, a
//!    disabled button says why; the demo runs and the 3D pose and the counters advance; STOP (the button, and the
//!    space bar) stops and powers down; a UDP session is followed; a page of another origin cannot open the WebSocket, nor can a request
//!    without the token; the rig editor names a bad key; cueing redraws when a parameter changes; a run record
//!    opens; a page that goes away stops the stream it started.
//!
//! `--screenshots DIR` saves a picture of each panel there (the book's are in `docs/book/src/images/ui/`). The last line is the
//! sum, `N passed, N failed`; the exit status is 1 when anything failed.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use fantoccini::{Client, ClientBuilder, Locator};
use hyper_util::client::legacy::connect::HttpConnector;
use ringpod_tests::setup;
use serde_json::{json, Value};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

/// A child process killed when dropped (a failed check must not leave a server or a browser behind).
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn free_port() -> Result<u16, String> {
    let l = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

fn build_cli() -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(repo())
        .args(["build", "-p", "ringpod"])
        .status()
        .map_err(|e| format!("cargo build -p ringpod: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build -p ringpod failed ({status})"));
    }
    Ok(target_dir().join("debug").join("ringpod"))
}

/// A short run record of the simulated controller, for the Runs panel.
fn record(cli: &Path) -> Result<PathBuf, String> {
    let path = target_dir().join("browser-run.csv");
    let status = Command::new(cli)
        .args([
            "stream",
            "--sim",
            "--fast",
            "--motion",
            "demo",
            "--duration",
            "3",
            "--quiet",
            "--record",
        ])
        .arg(&path)
        .stdout(Stdio::null())
        .status()
        .map_err(|e| format!("ringpod stream: {e}"))?;
    if !status.success() {
        return Err(format!("ringpod stream --record failed ({status})"));
    }
    Ok(path)
}

/// `ringpod ui --sim` on a free port, and the URL it printed.
fn serve(cli: &Path) -> Result<(Running, String), String> {
    let mut child = Command::new(cli)
        .args(["ui", "--sim", "--listen", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("ringpod ui: {e}"))?;
    let stdout = child.stdout.take().ok_or("ringpod ui: no stdout")?;
    let running = Running(child);
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .map_err(|e| format!("ringpod ui: {e}"))?;
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .ok_or_else(|| format!("ringpod ui printed no URL: {line:?}"))?
        .to_owned();
    Ok((running, url))
}

fn chromedriver() -> Result<(Running, String), String> {
    let port = free_port()?;
    let child = Command::new("chromedriver")
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("chromedriver: {e}"))?;
    let running = Running(child);
    let deadline = Instant::now() + Duration::from_secs(20);
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        if Instant::now() > deadline {
            return Err("chromedriver did not listen within 20 s".into());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok((running, format!("http://127.0.0.1:{port}")))
}

/// A WebSocket handshake by hand, as a page of `origin` (or a tool, without one) would send it: the status line.
fn handshake(url: &str, origin: Option<&str>, token: Option<&str>) -> Result<String, String> {
    let host = url
        .trim_start_matches("http://")
        .split('/')
        .next()
        .ok_or("no host")?
        .to_owned();
    let mut s = TcpStream::connect(&host).map_err(|e| e.to_string())?;
    s.set_read_timeout(Some(Duration::from_secs(5)))
        .map_err(|e| e.to_string())?;
    let path = token.map_or("/ws".to_owned(), |t| format!("/ws?token={t}"));
    let origin = origin.map(|o| format!("Origin: {o}\r\n")).unwrap_or_default();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n{origin}\r\n"
    )
    .map_err(|e| e.to_string())?;
    let mut buf = [0u8; 256];
    let n = s.read(&mut buf).map_err(|e| e.to_string())?;
    Ok(String::from_utf8_lossy(&buf[..n])
        .lines()
        .next()
        .unwrap_or("")
        .to_owned())
}

/// A page of another origin (this port, not the workbench's) that tries the workbench's WebSocket with the
/// right token and writes what happened into its title.
fn hostile_page(ws_url: String) -> Result<String, String> {
    let listener = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    let port = listener.local_addr().map_err(|e| e.to_string())?.port();
    let page = format!(
        "<!doctype html><title>trying</title><script>\
         const ws = new WebSocket({ws_url:?});\
         ws.onopen = () => {{ document.title = 'opened'; }};\
         ws.onerror = () => {{ document.title = 'refused'; }};\
         </script>"
    );
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten().take(4) {
            let mut stream = stream;
            let mut buf = [0u8; 2048];
            let _ = stream.read(&mut buf);
            let _ = write!(
                stream,
                "HTTP/1.1 200 OK\r\nContent-Type: text/html\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{page}",
                page.len()
            );
        }
    });
    Ok(format!("http://127.0.0.1:{port}/"))
}

struct Checks {
    passed: u32,
    failed: u32,
}

impl Checks {
    fn report(&mut self, name: &str, result: Result<String, String>) {
        match result {
            Ok(detail) => {
                self.passed += 1;
                println!("PASS {name}: {detail}");
            }
            Err(why) => {
                self.failed += 1;
                println!("FAIL {name}: {why}");
            }
        }
    }
}

/// Evaluates a JavaScript expression in the page.
async fn js(c: &Client, expression: &str) -> Result<Value, String> {
    c.execute(&format!("return ({expression});"), vec![])
        .await
        .map_err(|e| format!("{expression}: {e}"))
}

/// Polls `expression` until it is truthy; returns its value, or says what it was last.
async fn until(c: &Client, expression: &str, within: Duration) -> Result<Value, String> {
    let deadline = Instant::now() + within;
    loop {
        let v = js(c, expression).await?;
        let truthy = !matches!(v, Value::Null | Value::Bool(false)) && v != json!(0) && v != json!("");
        if truthy {
            return Ok(v);
        }
        if Instant::now() > deadline {
            let state = js(
                c,
                "window.ringpod && window.ringpod.frame && window.ringpod.frame.state",
            )
            .await
            .unwrap_or(Value::Null);
            return Err(format!(
                "`{expression}` not true within {within:?} (device state {state})"
            ));
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

async fn click(c: &Client, css: &str) -> Result<(), String> {
    c.find(Locator::Css(css))
        .await
        .map_err(|e| format!("{css}: {e}"))?
        .click()
        .await
        .map_err(|e| format!("click {css}: {e}"))
}

async fn tab(c: &Client, panel: &str) -> Result<(), String> {
    click(c, &format!(".tab[data-panel={panel}]")).await
}

async fn screenshot(c: &Client, dir: Option<&Path>, name: &str) -> Result<(), String> {
    let Some(dir) = dir else { return Ok(()) };
    let png = c.screenshot().await.map_err(|e| format!("screenshot: {e}"))?;
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    std::fs::write(dir.join(format!("{name}.png")), png).map_err(|e| e.to_string())
}

const STATE: &str = "window.ringpod.frame && window.ringpod.frame.state";

async fn connects(c: &Client, url: &str) -> Result<String, String> {
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(
        c,
        "window.ringpod && window.ringpod.frames > 3 && window.ringpod.rig",
        Duration::from_secs(20),
    )
    .await?;
    let state = js(c, STATE).await?;
    let pose = js(c, "document.getElementById('view3d').dataset.pose").await?;
    Ok(format!("state {state}, pose {pose}"))
}

async fn enable_and_home(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "control").await?;
    let why = js(
        c,
        "document.querySelector('[data-do=home]').disabled && document.querySelector('[data-do=home]').title",
    )
    .await?;
    if !why.as_str().is_some_and(|w| w.contains("not possible")) {
        return Err(format!("Home while Off is not disabled with a reason: {why}"));
    }
    click(c, "[data-do=enable]").await?;
    until(
        c,
        "!document.querySelector('[data-do=home]').disabled",
        Duration::from_secs(15),
    )
    .await?;
    click(c, "[data-do=home]").await?;
    until(c, &format!("{STATE} === 'Ready'"), Duration::from_secs(60)).await?;
    screenshot(c, shots, "control").await?;
    Ok(format!("Home was disabled ({why}), then enabled; homed to Ready"))
}

async fn demo_runs(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    js(c, "(document.getElementById('motion-seconds').value = '60', true)").await?;
    click(c, "#run-motion").await?;
    until(
        c,
        &format!("{STATE} === 'Running' && window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    let before = js(
        c,
        "[window.ringpod.frame.applied, document.getElementById('view3d').dataset.pose]",
    )
    .await?;
    tokio::time::sleep(Duration::from_secs(3)).await;
    let after = js(
        c,
        "[window.ringpod.frame.applied, document.getElementById('view3d').dataset.pose]",
    )
    .await?;
    let applied = |v: &Value| v[0].as_u64().unwrap_or(0);
    if applied(&after) <= applied(&before) + 100 {
        return Err(format!("the applied counter did not advance: {before} -> {after}"));
    }
    if after[1] == before[1] {
        return Err(format!("the 3D view's pose did not move: {}", after[1]));
    }
    // The counters on screen are the frame's.
    let shown = js(c, "+document.getElementById('count-applied').textContent").await?;
    if shown.as_u64().unwrap_or(0) < applied(&after) {
        return Err(format!("the counters show {shown}, the frame {}", applied(&after)));
    }
    let busy = js(c, "document.querySelector('[data-do=home]').title").await?;
    if !busy.as_str().is_some_and(|w| w.contains("stream is running")) {
        return Err(format!("Home during a stream is not gated: {busy}"));
    }
    tab(c, "live").await?;
    tokio::time::sleep(Duration::from_millis(800)).await;
    screenshot(c, shots, "live").await?;
    Ok(format!(
        "applied {} -> {}, pose {} -> {}",
        applied(&before),
        applied(&after),
        before[1],
        after[1]
    ))
}

async fn stop_button(c: &Client) -> Result<String, String> {
    // Homed and Ready: the demo again, straight away.
    tab(c, "control").await?;
    until(
        c,
        "!document.getElementById('run-motion').disabled",
        Duration::from_secs(20),
    )
    .await?;
    click(c, "#run-motion").await?;
    until(
        c,
        &format!("{STATE} === 'Running' && window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    click(c, "#halt").await?;
    until(
        c,
        &format!("{STATE} === 'Off' && !window.ringpod.frame.streaming"),
        Duration::from_secs(30),
    )
    .await?;
    let replies = js(c, "window.ringpod.replies.map(r => r.text).join(' | ')").await?;
    Ok(format!("Running -> Off; replies: {replies}"))
}

async fn space_bar(c: &Client) -> Result<String, String> {
    tab(c, "control").await?;
    click(c, "[data-do=enable]").await?;
    until(c, &format!("{STATE} !== 'Off'"), Duration::from_secs(10)).await?;
    c.find(Locator::Css("body"))
        .await
        .map_err(|e| e.to_string())?
        .send_keys(" ")
        .await
        .map_err(|e| e.to_string())?;
    until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(20)).await?;
    Ok("enabled, then space: Off".into())
}

async fn udp_session(c: &Client) -> Result<String, String> {
    tab(c, "control").await?;
    let port = free_port()?;
    js(
        c,
        &format!(
            "(document.getElementById('udp-port').value = '{port}', document.getElementById('udp-holds').value = 'poses', true)"
        ),
    )
    .await?;
    until(
        c,
        "!document.getElementById('run-udp').disabled",
        Duration::from_secs(20),
    )
    .await?;
    click(c, "#run-udp").await?;
    // It powers up and homes first (from where the demo and STOP left the platform), then waits for datagrams.
    until(
        c,
        &format!("window.ringpod.frame.streaming && ({STATE} === 'Ready' || {STATE} === 'Running')"),
        Duration::from_secs(60),
    )
    .await?;
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    for _ in 0..150 {
        socket
            .send_to(b"0 0 0.237 0 0 0", ("127.0.0.1", port))
            .map_err(|e| e.to_string())?;
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // The platform is led in to the 10 mm higher pose the datagrams hold.
    let z = until(
        c,
        "Math.abs(window.ringpod.frame.pose[2] - 0.237) < 0.0005 && window.ringpod.frame.pose[2]",
        Duration::from_secs(10),
    )
    .await?;
    click(c, "#halt").await?;
    until(c, &format!("{STATE} === 'Off'"), Duration::from_secs(30)).await?;
    let report = until(
        c,
        "window.ringpod.replies.map(r => r.text).filter(t => t.startsWith('interrupted') && !t.startsWith('interrupted: 0 ')).pop()",
        Duration::from_secs(10),
    )
    .await?;
    Ok(format!("followed to z = {z}; {report}"))
}

async fn other_origin(c: &Client, url: &str) -> Result<String, String> {
    let token = url.split("token=").nth(1).ok_or("no token in the URL")?;
    let ws = url.replace("http://", "ws://").replace("/?token=", "/ws?token=");
    let host = url.trim_start_matches("http://").split('/').next().unwrap_or("");
    // The workbench's own origin is let in, so the refusals below are the origin's and the token's.
    let own = handshake(url, Some(&format!("http://{host}")), Some(token))?;
    if !own.contains("101") {
        return Err(format!("the workbench's own origin was refused: {own}"));
    }
    let no_token = handshake(url, Some(&format!("http://{host}")), None)?;
    let wrong = handshake(url, None, Some("0123"))?;
    if !no_token.contains("403") || !wrong.contains("403") {
        return Err(format!("without the token: {no_token}; wrong token: {wrong}"));
    }
    let page = hostile_page(ws)?;
    c.goto(&page).await.map_err(|e| e.to_string())?;
    let title = until(
        c,
        "document.title !== 'trying' && document.title",
        Duration::from_secs(10),
    )
    .await?;
    if title != json!("refused") {
        return Err(format!("a page of another origin opened the WebSocket: {title}"));
    }
    Ok(format!(
        "own origin {own}; no token {no_token}; wrong token {wrong}; {page}: {title}"
    ))
}

async fn rig_editor(c: &Client, url: &str, shots: Option<&Path>) -> Result<String, String> {
    c.goto(url).await.map_err(|e| e.to_string())?;
    until(c, "window.ringpod && window.ringpod.rig", Duration::from_secs(20)).await?;
    tab(c, "rig").await?;
    until(
        c,
        "document.getElementById('rig-messages').textContent.includes('drivable: yes')",
        Duration::from_secs(20),
    )
    .await?;
    screenshot(c, shots, "rig").await?;
    js(
        c,
        "(() => { const t = document.getElementById('rig-text'); \
         t.value = t.value.replace('ring_radius', 'ring_raduis'); \
         t.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    let message = until(
        c,
        "document.querySelector('.rig-error') && document.querySelector('.rig-error').textContent",
        Duration::from_secs(10),
    )
    .await?;
    if !message.as_str().is_some_and(|m| m.contains("ring_raduis")) {
        return Err(format!("the message does not name the key: {message}"));
    }
    Ok(format!("valid rig drawn; the typo says: {message}"))
}

async fn cueing(c: &Client, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "cueing").await?;
    until(c, "window.ringpod.cueRuns >= 1", Duration::from_secs(20)).await?;
    let first = js(c, "[window.ringpod.cueRuns, window.ringpod.cuePeak]").await?;
    screenshot(c, shots, "cueing").await?;
    // Three times the surge scale: the replay runs again and delivers more surge at its peak.
    let changed = js(
        c,
        "(() => { const i = document.querySelector('[data-path=\"translation_scale.0\"]'); if (!i) return false; \
         i.value = '0.3'; i.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    if changed != json!(true) {
        return Err("no control for translation_scale.0".into());
    }
    let runs = first[0].as_u64().unwrap_or(0);
    until(c, &format!("window.ringpod.cueRuns > {runs}"), Duration::from_secs(20)).await?;
    let second = js(c, "[window.ringpod.cueRuns, window.ringpod.cuePeak]").await?;
    let (p1, p2) = (first[1].as_f64().unwrap_or(0.0), second[1].as_f64().unwrap_or(0.0));
    // The peak is mostly tilt coordination (the sustained braking); the onset the scale cues adds to it.
    if p2 <= p1 * 1.02 {
        return Err(format!("the delivered surge did not grow with its scale: {p1} -> {p2}"));
    }
    js(
        c,
        "(() => { const i = document.querySelector('[data-path=\"translation_scale.0\"]'); \
         i.value = '-5'; i.dispatchEvent(new Event('input')); return true; })()",
    )
    .await?;
    let refused = until(
        c,
        "document.getElementById('cue-status').className.includes('bad') && document.getElementById('cue-status').textContent",
        Duration::from_secs(10),
    )
    .await?;
    Ok(format!(
        "largest surge delivered {p1:.3} -> {p2:.3} m/s^2; -5 refused: {refused}"
    ))
}

async fn runs(c: &Client, record: &Path, shots: Option<&Path>) -> Result<String, String> {
    tab(c, "runs").await?;
    let input = c.find(Locator::Css("#run-file")).await.map_err(|e| e.to_string())?;
    let path = record.canonicalize().map_err(|e| e.to_string())?;
    input
        .send_keys(&path.display().to_string())
        .await
        .map_err(|e| e.to_string())?;
    let status = until(
        c,
        "document.getElementById('run-status').textContent.includes('rows') && document.getElementById('run-status').textContent",
        Duration::from_secs(20),
    )
    .await?;
    let charts = js(c, "document.querySelectorAll('#run-charts canvas').length").await?;
    if charts != json!(12) {
        return Err(format!("{charts} charts instead of 12"));
    }
    screenshot(c, shots, "runs").await?;
    Ok(format!("{status}"))
}

async fn lost_page(c: &Client, url: &str) -> Result<String, String> {
    // The demo of the check before still runs (60 s): its page goes away, and another one watches.
    let running = js(c, &format!("{STATE} === 'Running' && window.ringpod.frame.streaming")).await?;
    if running != json!(true) {
        return Err("no stream runs to begin with".into());
    }
    c.goto("about:blank").await.map_err(|e| e.to_string())?;
    tokio::time::sleep(Duration::from_secs(1)).await;
    c.goto(url).await.map_err(|e| e.to_string())?;
    let state = until(
        c,
        &format!("window.ringpod && window.ringpod.frame && !window.ringpod.frame.streaming && {STATE} === 'Ready' && {STATE}"),
        Duration::from_secs(30),
    )
    .await?;
    Ok(format!(
        "the stream of the page that left ended at rest; device {state}"
    ))
}

async fn checks(driver: &str, url: &str, record: &Path, shots: Option<&Path>) -> Result<Checks, String> {
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        json!({
            "binary": "/usr/bin/chromium",
            "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1400,1000", "--hide-scrollbars"],
        }),
    );
    let c = ClientBuilder::new(HttpConnector::new())
        .capabilities(caps)
        .connect(driver)
        .await
        .map_err(|e| format!("WebDriver session: {e}"))?;
    let mut k = Checks { passed: 0, failed: 0 };
    k.report("the page connects and draws the platform", connects(&c, url).await);
    k.report(
        "Enable and Home from the Control panel, gated by the supervisor",
        enable_and_home(&c, shots).await,
    );
    k.report(
        "the demo runs: the 3D pose and the counters advance",
        demo_runs(&c, shots).await,
    );
    k.report(
        "a page that goes away stops the stream it started",
        lost_page(&c, url).await,
    );
    k.report("STOP ends the stream and powers down", stop_button(&c).await);
    k.report("the space bar is STOP", space_bar(&c).await);
    k.report(
        "a UDP poses session from the Control panel is followed",
        udp_session(&c).await,
    );
    k.report(
        "a page of another origin cannot open the WebSocket",
        other_origin(&c, url).await,
    );
    k.report("the rig editor names a bad key", rig_editor(&c, url, shots).await);
    k.report("cueing redraws when a parameter changes", cueing(&c, shots).await);
    k.report("a run record opens in the Runs panel", runs(&c, record, shots).await);
    let _ = c.close().await;
    Ok(k)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let shots = match args.as_slice() {
        [] => None,
        [flag, dir] if flag == "--screenshots" => Some(PathBuf::from(dir)),
        _ => {
            eprintln!("usage: browser [--screenshots DIR]");
            return ExitCode::from(2);
        }
    };
    let prepared = setup::ensure_browser()
        .and_then(|()| build_cli())
        .and_then(|cli| Ok((record(&cli)?, cli)))
        .and_then(|(record, cli)| Ok((record, serve(&cli)?, chromedriver()?)));
    let (record, (_ui, url), (_driver, driver)) = match prepared {
        Ok(p) => p,
        Err(e) => {
            eprintln!("browser: {e}");
            println!("0 passed, 1 failed");
            return ExitCode::FAILURE;
        }
    };
    let runtime = match tokio::runtime::Builder::new_multi_thread().enable_all().build() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("browser: {e}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(checks(&driver, &url, &record, shots.as_deref())) {
        Ok(k) => {
            println!("{} passed, {} failed", k.passed, k.failed);
            if k.failed == 0 {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("browser: {e}");
            println!("0 passed, 1 failed");
            ExitCode::FAILURE
        }
    }
}
