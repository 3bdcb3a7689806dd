//! A TCP proxy between a host program and `simulate --tcp` whose link can be stalled: while stalled, the bytes of
//! both ways are held (as a USB host controller or a bridge that hangs holds them) and delivered when it resumes.

use std::io::{ErrorKind, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// `ringpod simulate --tcp 127.0.0.1:0`, killed when dropped; `addr` is what it serves (`tcp://127.0.0.1:PORT`).
pub struct Served {
    child: std::process::Child,
    pub addr: String,
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Served {
    pub fn start() -> Self {
        use std::io::BufRead;
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["simulate", "--tcp", "127.0.0.1:0"])
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        Self {
            child,
            addr: line.trim().to_owned(),
        }
    }
}

/// The proxy: `addr` is what the host connects to (`tcp://127.0.0.1:PORT`).
pub struct Proxy {
    pub addr: String,
    stalled: Arc<AtomicBool>,
    done: Arc<AtomicBool>,
}

impl Drop for Proxy {
    fn drop(&mut self) {
        self.done.store(true, Ordering::SeqCst);
    }
}

impl Proxy {
    /// Proxies one connection at a time to `upstream` (`tcp://HOST:PORT`).
    pub fn to(upstream: &str) -> Self {
        let upstream = upstream.trim_start_matches("tcp://").to_owned();
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = format!("tcp://{}", listener.local_addr().unwrap());
        let stalled = Arc::new(AtomicBool::new(false));
        let done = Arc::new(AtomicBool::new(false));
        let (s, d) = (stalled.clone(), done.clone());
        listener.set_nonblocking(true).unwrap();
        std::thread::spawn(move || {
            while !d.load(Ordering::SeqCst) {
                match listener.accept() {
                    Ok((host, _)) => {
                        let device = TcpStream::connect(&upstream).unwrap();
                        pass(host, device, &s, &d);
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(Duration::from_millis(5)),
                    Err(_) => return,
                }
            }
        });
        Self { addr, stalled, done }
    }

    /// Stalls the link (`true`) or lets it go on.
    pub fn stall(&self, stalled: bool) {
        self.stalled.store(stalled, Ordering::SeqCst);
    }
}

/// Passes bytes both ways until either side closes, holding them while stalled.
fn pass(mut host: TcpStream, mut device: TcpStream, stalled: &AtomicBool, done: &AtomicBool) {
    for s in [&host, &device] {
        s.set_nonblocking(true).unwrap();
        s.set_nodelay(true).unwrap();
    }
    let (mut to_device, mut to_host) = (Vec::new(), Vec::new());
    let mut buf = [0u8; 4096];
    while !done.load(Ordering::SeqCst) {
        for (from, held) in [(&mut host, &mut to_device), (&mut device, &mut to_host)] {
            match from.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => held.extend_from_slice(&buf[..n]),
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                Err(_) => return,
            }
        }
        if !stalled.load(Ordering::SeqCst) {
            for (to, held) in [(&mut device, &mut to_device), (&mut host, &mut to_host)] {
                while !held.is_empty() {
                    match to.write(held) {
                        Ok(n) => {
                            held.drain(..n);
                        }
                        Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                        Err(_) => return,
                    }
                }
            }
        }
        std::thread::sleep(Duration::from_micros(200));
    }
}
