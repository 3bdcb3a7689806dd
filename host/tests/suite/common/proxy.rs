//! A TCP proxy between a host program and `simulate --tcp` whose link can be stalled: while stalled, the bytes of
//! both ways are held (as a USB host controller or a bridge that hangs holds them) and delivered when it resumes.
//! It can also lose one setpoint's frame on its way to the device, as noise or a UART overrun loses one.

use std::io::{ErrorKind, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
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
    cut: Arc<Cut>,
}

/// Setpoint frames to lose on the way to the device (`to_lose`), and those lost so far.
#[derive(Default)]
struct Cut {
    to_lose: AtomicU32,
    lost: AtomicU32,
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
        let cut = Arc::new(Cut::default());
        let (s, d, c) = (stalled.clone(), done.clone(), cut.clone());
        listener.set_nonblocking(true).unwrap();
        std::thread::spawn(move || {
            while !d.load(Ordering::SeqCst) {
                match listener.accept() {
                    Ok((host, _)) => {
                        let device = TcpStream::connect(&upstream).unwrap();
                        pass(host, device, &s, &d, &c);
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(Duration::from_millis(5)),
                    Err(_) => return,
                }
            }
        });
        Self {
            addr,
            stalled,
            done,
            cut,
        }
    }

    /// Loses the next setpoint frame the host sends (the device never sees it).
    pub fn lose_a_setpoint(&self) {
        self.cut.to_lose.fetch_add(1, Ordering::SeqCst);
    }

    /// Setpoint frames lost so far.
    pub fn setpoints_lost(&self) -> u32 {
        self.cut.lost.load(Ordering::SeqCst)
    }

    /// Stalls the link (`true`) or lets it go on.
    pub fn stall(&self, stalled: bool) {
        self.stalled.store(stalled, Ordering::SeqCst);
    }
}

/// The whole frames at the start of `held` with the first setpoint among them taken out, when one is to be lost.
fn lose_setpoint(held: &mut Vec<u8>, cut: &Cut) {
    if cut.to_lose.load(Ordering::SeqCst) == 0 {
        return;
    }
    let mut start = 0;
    while let Some(len) = held[start..].iter().position(|&b| b == 0) {
        let end = start + len + 1;
        let request = ringpod_core::protocol::decode::<ringpod_core::protocol::Request>(&held[start..end - 1]);
        if matches!(request, Ok(r) if matches!(r.body, ringpod_core::protocol::HostMessage::Setpoint(_))) {
            held.drain(start..end);
            cut.to_lose.fetch_sub(1, Ordering::SeqCst);
            cut.lost.fetch_add(1, Ordering::SeqCst);
            return;
        }
        start = end;
    }
}

/// Passes bytes both ways until either side closes, holding them while stalled.
fn pass(mut host: TcpStream, mut device: TcpStream, stalled: &AtomicBool, done: &AtomicBool, cut: &Cut) {
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
        lose_setpoint(&mut to_device, cut);
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
