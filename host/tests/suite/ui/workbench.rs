//! A `ringpod ui --sim` process on a free loopback port, and pages of it as WebSocket clients.

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// The server, killed when dropped.
pub struct Workbench {
    child: Child,
    /// `127.0.0.1:PORT`.
    pub addr: String,
    pub token: String,
}

impl Drop for Workbench {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Workbench {
    /// `ringpod ui --sim --listen 127.0.0.1:0 ARGS`, once it printed its URL. `RINGPOD_UI_BIN` names another
    /// build to try the tests on (an older one, to see them fail).
    pub fn start(args: &[&str]) -> Self {
        Self::on(&[&["--sim"][..], args].concat())
    }

    /// `ringpod ui --listen 127.0.0.1:0 ARGS` (the device named in them), once it printed its URL.
    pub fn on(args: &[&str]) -> Self {
        let bin =
            std::env::var_os("RINGPOD_UI_BIN").map_or_else(|| assert_cmd::cargo::cargo_bin("ringpod"), Into::into);
        let mut child = Command::new(bin)
            .args(["ui", "--listen", "127.0.0.1:0"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in {line:?}"));
        let rest = url.trim_start_matches("http://");
        let (addr, query) = rest.split_once("/?token=").unwrap();
        Self {
            child,
            addr: addr.to_owned(),
            token: query.to_owned(),
        }
    }

    /// A page: the WebSocket with the token, as the page opens it.
    pub fn page(&self) -> Page {
        let url = format!("ws://{}/ws?token={}", self.addr, self.token);
        let (ws, _) = tungstenite::connect(url).unwrap();
        if let MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_read_timeout(Some(Duration::from_millis(100))).unwrap();
        }
        Page { ws, next: 1 }
    }
}

/// One connected page.
pub struct Page {
    pub ws: WebSocket<MaybeTlsStream<TcpStream>>,
    next: u64,
}

impl Page {
    /// Sends a request with the next number; gives the number.
    pub fn send(&mut self, mut request: Value) -> u64 {
        let id = self.next;
        self.next += 1;
        request["id"] = json!(id);
        self.ws.send(Message::text(request.to_string())).unwrap();
        id
    }

    /// The next message within `within`: `Ok(None)` when none came, `Err` when the connection ended (with the
    /// close frame's code and reason, if one came).
    pub fn next(&mut self, within: Duration) -> Result<Option<Value>, String> {
        let deadline = Instant::now() + within;
        loop {
            match self.ws.read() {
                Ok(Message::Text(t)) => return Ok(Some(serde_json::from_str(&t).unwrap())),
                Ok(Message::Close(frame)) => {
                    return Err(frame.map_or("closed without a reason".into(), |f| {
                        format!("closed {} {}", u16::from(f.code), f.reason)
                    }))
                }
                Ok(_) => {}
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) =>
                {
                    if Instant::now() > deadline {
                        return Ok(None);
                    }
                }
                Err(e) => return Err(e.to_string()),
            }
        }
    }

    /// Reads until `done` says so; `Err` says what was last seen when `within` passed first.
    pub fn until(&mut self, within: Duration, mut done: impl FnMut(&Value) -> bool) -> Result<Value, String> {
        let deadline = Instant::now() + within;
        let mut last = Value::Null;
        while Instant::now() < deadline {
            if let Some(m) = self.next(deadline - Instant::now())? {
                if done(&m) {
                    return Ok(m);
                }
                last = m;
            }
        }
        Err(format!("not within {within:?}; last message {last}"))
    }

    /// Every message for `within`.
    pub fn watch(&mut self, within: Duration) -> Vec<Value> {
        let mut all = Vec::new();
        let _ = self.until(within, |m| {
            all.push(m.clone());
            false
        });
        all
    }

    /// Closes the connection as a page that goes away does.
    pub fn close(mut self) {
        let _ = self.ws.close(None);
        let _ = self.ws.flush();
    }
}

/// One HTTP/1.1 request by hand (to choose its `Host`): the status code and the body.
pub fn http(addr: &str, method: &str, path: &str, host: &str, body: Option<&Value>) -> (u16, String) {
    use std::io::Write;
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let body = body.map(Value::to_string).unwrap_or_default();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    answer(&mut s)
}

/// The whole answer on `s`, read to its end: the status code and the body.
pub fn answer(s: &mut TcpStream) -> (u16, String) {
    use std::io::Read;
    let mut answer = String::new();
    s.read_to_string(&mut answer).unwrap();
    let status = answer
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    let body = answer
        .split_once("\r\n\r\n")
        .map(|(_, b)| b.to_owned())
        .unwrap_or_default();
    (status, body)
}
