//! Transports: a serial port to a board, the in-process simulated controller ([`super::sim`]), a TCP connection.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use crate::link::client::Transport;
use crate::link::sim::SimDevice;

/// USB CDC serial to a board.
pub struct Serial {
    port: Box<dyn serialport::SerialPort>,
    /// The host's clock: time let pass since the port opened. [`Transport::elapse`] sleeps until the wall clock
    /// reaches it, so round trips do not add up to a stream that falls behind real time.
    epoch: Instant,
    owed: Duration,
}

impl Serial {
    /// Opens a port at the firmware's USART baud rate (921600, for a USB-serial adapter on the board's USART1;
    /// USB CDC ignores it).
    pub fn open(path: &str) -> Result<Self, serialport::Error> {
        let builder = serialport::new(path, 921_600).timeout(Duration::from_millis(1));
        #[cfg(unix)]
        let port: Box<dyn serialport::SerialPort> = {
            // No wait in a read or a write: each polls the port (poll(2) with no timeout) and returns at once; see
            // `receive` for why a read is not preceded by `bytes_to_read`.
            let port = builder.timeout(Duration::ZERO).open_native()?;
            // Non-blocking: the bytes `bytes_to_read` counted can be taken by another process that opened the same
            // port before this one reads them, and a blocking read would then wait for the next byte, for good
            // and deaf to signals. A read that finds nothing now returns at once.
            nonblocking(&port)?;
            Box::new(port)
        };
        #[cfg(not(unix))]
        let port = builder.open()?;
        Ok(Self {
            port,
            epoch: Instant::now(),
            owed: Duration::ZERO,
        })
    }
}

/// Sets `O_NONBLOCK` on a port's descriptor (serialport opens it blocking).
#[cfg(unix)]
fn nonblocking(port: &serialport::TTYPort) -> Result<(), serialport::Error> {
    use nix::fcntl::{fcntl, FcntlArg, OFlag};
    use std::os::fd::{AsRawFd, BorrowedFd};
    // SAFETY: the descriptor belongs to `port`, which outlives this borrow.
    let fd = unsafe { BorrowedFd::borrow_raw(port.as_raw_fd()) };
    let flags = fcntl(fd, FcntlArg::F_GETFL).map_err(std::io::Error::from)?;
    fcntl(
        fd,
        FcntlArg::F_SETFL(OFlag::from_bits_truncate(flags) | OFlag::O_NONBLOCK),
    )
    .map_err(std::io::Error::from)?;
    Ok(())
}

/// Longest a write to a port may wait for room: a board that takes nothing for this long is stalled or gone.
/// Longer than any hold-up a board recovers from (a flash erase stalls it about 2 s).
const SEND_PATIENCE: Duration = Duration::from_secs(5);

impl Transport for Serial {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        // Partial writes and a full output buffer are waited out, up to a deadline: a plain `write_all` would
        // fail on the first `EAGAIN` of a non-blocking port, or on the port's 1 ms timeout.
        let deadline = Instant::now() + super::patience(SEND_PATIENCE);
        let mut rest = bytes;
        while !rest.is_empty() {
            match self.port.write(rest) {
                Ok(n) => rest = &rest[n..],
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    if Instant::now() >= deadline {
                        return Err(std::io::Error::new(
                            std::io::ErrorKind::TimedOut,
                            format!("the port took nothing for {} s", SEND_PATIENCE.as_secs()),
                        ));
                    }
                    std::thread::sleep(Duration::from_micros(200));
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
    fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        // Never block: a read with nothing to read would wait out the port's timeout on every poll, and a 1 kHz
        // stream has no millisecond to spare. On Unix the port's timeout is zero and a read that finds nothing
        // returns at once. Not `bytes_to_read` there: Linux answers FIONREAD on a terminal under the lock its input
        // is delivered under, and polled every 200 us it held a pseudo-terminal's answers back for seconds while
        // other processes kept both cores busy (a `stream` to `simulate --pty` beside two busy loops, even at
        // nice 19, failed with no answer within 2 s; `poll(2)` takes no such lock).
        #[cfg(unix)]
        let want = buf.len();
        #[cfg(not(unix))]
        let want = {
            let ready = self.port.bytes_to_read().map_err(std::io::Error::from)? as usize;
            if ready == 0 {
                return Ok(0);
            }
            ready.min(buf.len())
        };
        match self.port.read(&mut buf[..want]) {
            Ok(n) => Ok(n),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted | std::io::ErrorKind::WouldBlock
                ) =>
            {
                Ok(0)
            }
            Err(e) => Err(e),
        }
    }
    fn elapse(&mut self, dt: Duration) {
        self.owed = self.owed.saturating_add(dt);
        // Behind the clock (slow round trips): catch up without sleeping.
        if let Some(wait) = (self.epoch + self.owed).checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        } else if let Some(late) = Instant::now().checked_duration_since(self.epoch + self.owed) {
            // Never owe more than a second: after a long stall, pace from now rather than rush.
            if late > Duration::from_secs(1) {
                self.owed += late - Duration::from_secs(1);
            }
        }
    }
}

/// Either transport, chosen on the command line.
pub enum AnyTransport {
    /// A board.
    Serial(Serial),
    /// A board behind a serial-to-network bridge, or `simulate --tcp`.
    Tcp(super::tcp::Tcp),
    /// The simulator.
    Sim(Box<SimDevice>),
}

impl Transport for AnyTransport {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        match self {
            Self::Serial(t) => t.send(bytes),
            Self::Tcp(t) => t.send(bytes),
            Self::Sim(t) => t.send(bytes),
        }
    }
    fn receive(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Self::Serial(t) => t.receive(buf),
            Self::Tcp(t) => t.receive(buf),
            Self::Sim(t) => t.receive(buf),
        }
    }
    fn elapse(&mut self, dt: Duration) {
        match self {
            Self::Serial(t) => t.elapse(dt),
            Self::Tcp(t) => t.elapse(dt),
            Self::Sim(t) => t.elapse(dt),
        }
    }
    fn keep_pace(&mut self) {
        if let Self::Sim(t) = self {
            t.keep_pace();
        }
    }
}
