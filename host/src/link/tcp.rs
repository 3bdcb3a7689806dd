//! The controller over TCP: `--port tcp://HOST:PORT` reaches the simulated controller that `simulate --tcp` serves
//! (on every system: the pseudo-terminal is Unix only), or a board behind a serial-to-network bridge (ser2net, an
//! ESP-Link), which passes the same framed bytes.
//!
//! The socket is non-blocking both ways: a read returns what has arrived or nothing, and a write that the peer does
//! not take within [`WRITE_DEADLINE`] fails, so that no call waits forever on a peer that went away.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

use crate::link::client::Transport;
use crate::link::sim::SimDevice;

/// The scheme that makes `--port` a network address.
pub const SCHEME: &str = "tcp://";

/// How long a connection attempt may take (a bridge on the local network answers in milliseconds).
const CONNECT_DEADLINE: Duration = Duration::from_secs(3);

/// How long a write may wait for the peer to take its bytes.
const WRITE_DEADLINE: Duration = Duration::from_secs(1);

/// The `HOST:PORT` of a `tcp://HOST:PORT` port name; `None` for a serial port's name.
pub fn address(port: &str) -> Option<&str> {
    port.strip_prefix(SCHEME)
}

/// Keeps a transport on the wall clock: [`Transport::elapse`] sleeps until the clock reaches the time let pass, so
/// that round trips do not add up to a stream that falls behind real time.
struct Pacer {
    epoch: Instant,
    owed: Duration,
}

impl Pacer {
    fn new() -> Self {
        Self {
            epoch: Instant::now(),
            owed: Duration::ZERO,
        }
    }

    fn elapse(&mut self, dt: Duration) {
        self.owed = self.owed.saturating_add(dt);
        let due = self.epoch + self.owed;
        let now = Instant::now();
        if let Some(wait) = due.checked_duration_since(now) {
            std::thread::sleep(wait);
        } else if now - due > Duration::from_secs(1) {
            // Never owe more than a second: after a long stall, pace from now rather than rush.
            self.owed += now - due - Duration::from_secs(1);
        }
    }
}

/// What `simulate --tcp` sends a client that connects while another holds the controller, before it closes the
/// connection: the client's side tells it from a controller's bytes (every frame ends with a 0x00, which the notice
/// has not, so a whole frame never passes for it) and says why it was closed.
const BUSY: &[u8] = b"ringpod simulate: busy with another client\n";

/// What a client is told when the simulator closed its connection as busy.
const BUSY_SAID: &str = "the simulator is busy with another client (one at a time, as a serial port is one program's)";

/// A TCP connection to a controller.
pub struct Tcp {
    stream: TcpStream,
    pacer: Pacer,
    /// The first bytes of the connection, held back while they may still be [`BUSY`]; `None` once they are not.
    held: Option<Vec<u8>>,
    /// Bytes to hand on before reading more (the first ones, once they were not [`BUSY`]).
    release: Vec<u8>,
}

impl Tcp {
    /// Connects to `HOST:PORT` (the first address that answers within the deadline).
    pub fn connect(address: &str) -> std::io::Result<Self> {
        let mut last = std::io::Error::new(ErrorKind::NotFound, "the name resolves to no address");
        for addr in address.to_socket_addrs()? {
            match TcpStream::connect_timeout(&addr, CONNECT_DEADLINE) {
                Ok(stream) => return Self::over(stream),
                Err(e) => last = e,
            }
        }
        Err(last)
    }

    fn over(stream: TcpStream) -> std::io::Result<Self> {
        // Frames are small and a setpoint is due every millisecond: send each at once, not after Nagle's wait.
        stream.set_nodelay(true)?;
        stream.set_nonblocking(true)?;
        Ok(Self {
            stream,
            pacer: Pacer::new(),
            held: Some(Vec::new()),
            release: Vec::new(),
        })
    }

    /// Reads what has arrived, holding the first bytes back while they may be the busy notice.
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if !self.release.is_empty() {
            let n = buf.len().min(self.release.len());
            buf[..n].copy_from_slice(&self.release[..n]);
            self.release.drain(..n);
            return Ok(n);
        }
        let read = read_ready(&mut self.stream, buf);
        let Some(held) = self.held.as_mut() else {
            return read;
        };
        match read {
            Err(_) if held.as_slice() == BUSY => Err(std::io::Error::new(ErrorKind::ConnectionRefused, BUSY_SAID)),
            Err(e) => Err(e),
            Ok(n) => {
                held.extend_from_slice(&buf[..n]);
                if BUSY.starts_with(held) {
                    // The notice so far, or nothing yet: wait for the rest, or for the end that follows it.
                    return Ok(0);
                }
                self.release = self.held.take().unwrap_or_default();
                self.read(buf)
            }
        }
    }
}

/// Writes all of `bytes` to a non-blocking stream, waiting at most [`WRITE_DEADLINE`] for the peer to take them.
fn write_within(stream: &mut TcpStream, mut bytes: &[u8]) -> std::io::Result<()> {
    let deadline = Instant::now() + WRITE_DEADLINE;
    while !bytes.is_empty() {
        match stream.write(bytes) {
            Ok(0) => return Err(ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == ErrorKind::WouldBlock && Instant::now() < deadline => {
                std::thread::sleep(Duration::from_micros(200));
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                return Err(std::io::Error::new(
                    ErrorKind::TimedOut,
                    format!("the peer took no bytes for {WRITE_DEADLINE:?}"),
                ))
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Reads what has arrived: `Ok(0)` when nothing has, an error when the peer closed the connection (a closed link
/// is lost, not quiet).
fn read_ready(stream: &mut TcpStream, buf: &mut [u8]) -> std::io::Result<usize> {
    match stream.read(buf) {
        Ok(0) if !buf.is_empty() => Err(std::io::Error::new(
            ErrorKind::ConnectionAborted,
            "the peer closed the connection",
        )),
        Ok(n) => Ok(n),
        Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => Ok(0),
        Err(e) => Err(e),
    }
}

impl Transport for Tcp {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        write_within(&mut self.stream, bytes)
    }
    fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.read(buf)
    }
    fn elapse(&mut self, dt: Duration) {
        self.pacer.elapse(dt);
    }
}

/// Binds `addr`, prints the address clients connect to (`tcp://127.0.0.1:PORT`; port 0 picks a free one), and
/// runs the simulated controller (a real-time one) behind it in 1 ms steps until `stop` says so. One client at a time,
/// as a serial port is one program's: another one that connects meanwhile is closed at once. The controller lives
/// on across clients, as a board does across the host programs that open its port.
pub fn serve(mut device: SimDevice, addr: SocketAddr, stop: &dyn Fn() -> bool) -> std::io::Result<()> {
    let listener =
        TcpListener::bind(addr).map_err(|e| std::io::Error::new(e.kind(), format!("cannot listen on {addr}: {e}")))?;
    listener.set_nonblocking(true)?;
    let mut out = std::io::stdout();
    // A reader that went away (`| head -1`) does not stop the simulator: the address is known to whoever took it.
    let _ = writeln!(out, "{SCHEME}{}", listener.local_addr()?).and_then(|()| out.flush());
    let mut client: Option<TcpStream> = None;
    let mut buf = [0u8; 1024];
    while !stop() {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nodelay(true)?;
                stream.set_nonblocking(true)?;
                admit(&mut client, stream, &mut |bytes| device.send(bytes))?;
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => {}
            Err(e) => return Err(e),
        }
        if let Some(stream) = client.as_mut() {
            if !drain(stream, &mut |bytes| device.send(bytes))? {
                // The client went away: wait for the next.
                client = None;
            }
        }
        // A real-time simulator: this sleeps to keep pace with the wall clock.
        device.elapse(Duration::from_millis(1));
        loop {
            let n = device.receive(&mut buf)?;
            if n == 0 {
                break;
            }
            // With nobody connected the device's answers and telemetry go nowhere, as a board's do.
            if let Some(stream) = client.as_mut() {
                if write_within(stream, &buf[..n]).is_err() {
                    client = None;
                }
            }
        }
    }
    Ok(())
}

/// Passes everything the client has sent to `feed`, until nothing more has arrived. `false` when the client has
/// closed the connection (or it broke), after the bytes it sent before.
fn drain(stream: &mut TcpStream, feed: &mut dyn FnMut(&[u8]) -> std::io::Result<()>) -> std::io::Result<bool> {
    let mut buf = [0u8; 1024];
    loop {
        match read_ready(stream, &mut buf) {
            Ok(0) => return Ok(true),
            Ok(n) => feed(&buf[..n])?,
            Err(_) => return Ok(false),
        }
    }
}

/// A new connection takes the controller when nobody holds it, or when the one who held it has gone: a program
/// that exits just before the next one connects has closed its connection, but the server may not have read that
/// yet. Otherwise the new one is closed at once, as a second program that opens a busy serial port is refused.
fn admit(
    client: &mut Option<TcpStream>,
    new: TcpStream,
    feed: &mut dyn FnMut(&[u8]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if let Some(held) = client.as_mut() {
        if drain(held, feed)? {
            refuse(new);
            return Ok(());
        }
    }
    *client = Some(new);
    Ok(())
}

/// Closes a newcomer's connection with the busy notice: the notice, then the end of what it reads, and what it
/// sent read and dropped first (a socket closed with unread bytes resets the connection, which may overtake the
/// notice).
fn refuse(mut new: TcpStream) {
    let _ = write_within(&mut new, BUSY);
    let _ = new.shutdown(std::net::Shutdown::Write);
    let _ = drain(&mut new, &mut |_| Ok(()));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tcp_port_name_is_told_from_a_serial_one() {
        assert_eq!(address("tcp://127.0.0.1:5760"), Some("127.0.0.1:5760"));
        assert_eq!(address("tcp://bridge.local:23"), Some("bridge.local:23"));
        assert_eq!(address("COM5"), None);
        assert_eq!(address("/dev/ttyACM0"), None);
    }

    #[test]
    fn reads_never_block_and_a_closed_peer_is_an_error() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let mut tcp = Tcp::connect(&addr).unwrap();
        let (mut peer, _) = listener.accept().unwrap();
        let mut buf = [0u8; 16];
        let started = Instant::now();
        assert_eq!(tcp.receive(&mut buf).unwrap(), 0);
        assert!(started.elapsed() < Duration::from_millis(100));
        peer.write_all(b"abc").unwrap();
        let mut got = Vec::new();
        while got.len() < 3 && started.elapsed() < Duration::from_secs(5) {
            let n = tcp.receive(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, b"abc");
        tcp.send(b"xyz").unwrap();
        let mut back = [0u8; 3];
        peer.read_exact(&mut back).unwrap();
        assert_eq!(&back, b"xyz");
        drop(peer);
        let err = loop {
            match tcp.receive(&mut buf) {
                Ok(0) if started.elapsed() < Duration::from_secs(5) => {}
                other => break other.unwrap_err(),
            }
        };
        assert_eq!(err.kind(), ErrorKind::ConnectionAborted);
    }

    /// Two connected pairs: (client side, server side), the server side non-blocking as `serve` makes it.
    fn pair(listener: &TcpListener) -> (TcpStream, TcpStream) {
        let near = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (far, _) = listener.accept().unwrap();
        far.set_nonblocking(true).unwrap();
        (near, far)
    }

    #[test]
    fn a_newcomer_takes_over_from_a_client_that_has_gone_and_is_refused_beside_one_that_stays() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let mut fed = Vec::new();
        // The first client says its last words and closes; the server has not read either yet.
        let (mut first, held) = pair(&listener);
        first.write_all(b"bye").unwrap();
        drop(first);
        std::thread::sleep(Duration::from_millis(50));
        let (_second, newcomer) = pair(&listener);
        let newcomer_port = newcomer.peer_addr().unwrap();
        let mut client = Some(held);
        admit(&mut client, newcomer, &mut |b| {
            fed.extend_from_slice(b);
            Ok(())
        })
        .unwrap();
        assert_eq!(client.as_ref().unwrap().peer_addr().unwrap(), newcomer_port);
        assert_eq!(fed, b"bye", "the first client's last bytes still reach the controller");
        // A third arrives while the second stays: it is refused, the second keeps the controller.
        let (mut third, refused) = pair(&listener);
        admit(&mut client, refused, &mut |_| Ok(())).unwrap();
        assert_eq!(client.as_ref().unwrap().peer_addr().unwrap(), newcomer_port);
        third.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut told = Vec::new();
        let _ = third.read_to_end(&mut told);
        assert_eq!(told, BUSY, "the newcomer is told, then closed");
    }

    /// The client's side: the busy notice and the end after it are said as busy; a controller's bytes, even ones
    /// that begin as the notice does, are handed on whole and in order.
    #[test]
    fn the_busy_notice_is_said_and_a_controllers_bytes_pass_whole() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let read_all = |tcp: &mut Tcp| {
            let (mut got, mut buf, started) = (Vec::new(), [0u8; 4], Instant::now());
            loop {
                match tcp.receive(&mut buf) {
                    Ok(n) if started.elapsed() < Duration::from_secs(5) => got.extend_from_slice(&buf[..n]),
                    Ok(_) => return (got, None),
                    Err(e) => return (got, Some(e)),
                }
            }
        };
        let mut tcp = Tcp::connect(&addr).unwrap();
        let (peer, _) = listener.accept().unwrap();
        peer.set_nonblocking(true).unwrap();
        refuse(peer);
        let (got, e) = read_all(&mut tcp);
        assert!(got.is_empty(), "{got:?}");
        let e = e.expect("closed");
        assert_eq!(e.kind(), ErrorKind::ConnectionRefused);
        assert!(e.to_string().contains("busy with another client"), "{e}");
        let mut tcp = Tcp::connect(&addr).unwrap();
        let (mut peer, _) = listener.accept().unwrap();
        let bytes = [&BUSY[..10], b"\x00\x07frame"].concat();
        peer.write_all(&bytes).unwrap();
        drop(peer);
        let (got, e) = read_all(&mut tcp);
        assert_eq!(got, bytes);
        assert_eq!(e.expect("closed").kind(), ErrorKind::ConnectionAborted);
    }

    #[test]
    fn nobody_listening_fails_to_connect_rather_than_hang() {
        // Bind then drop: the port is free and closed.
        let addr = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap();
        let started = Instant::now();
        assert!(Tcp::connect(&addr.to_string()).is_err());
        assert!(started.elapsed() <= CONNECT_DEADLINE + Duration::from_secs(1));
    }
}
