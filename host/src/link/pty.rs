//! The simulated controller on a pseudo-terminal: a program opens the printed path as it would a board's
//! USB serial port.

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::time::Duration;

use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};

use crate::link::client::Transport;
use crate::link::sim::SimDevice;
use crate::link::LinkError;

/// Opens a pseudo-terminal, prints the path of its device side, and runs the simulated controller behind it in
/// real time (1 ms steps) until `stop` says so (a signal); returning closes the pseudo-terminal.
pub fn serve(mut device: SimDevice, stop: &dyn Fn() -> bool) -> Result<(), LinkError> {
    let pty = openpty(None, None)?;
    // Raw mode on the device side: no echo, no line editing, no newline translation of the framed bytes.
    let mut termios = tcgetattr(&pty.slave)?;
    cfmakeraw(&mut termios);
    tcsetattr(&pty.slave, SetArg::TCSANOW, &termios)?;
    let path = std::fs::read_link(format!("/proc/self/fd/{}", pty.slave.as_raw_fd()))?;
    let flags = OFlag::from_bits_truncate(fcntl(&pty.master, FcntlArg::F_GETFL)?);
    fcntl(&pty.master, FcntlArg::F_SETFL(flags | OFlag::O_NONBLOCK))?;
    let mut master = std::fs::File::from(pty.master);
    // Keep the device side open so that the terminal survives clients that come and go.
    let _slave = pty.slave;
    // A reader that went away (`| head -1`) does not stop the simulator: the path is known to whoever took it.
    let mut out = std::io::stdout();
    let _ = writeln!(out, "{}", path.display()).and_then(|()| out.flush());
    let mut buf = [0u8; 1024];
    let mut outbox = Outbox::default();
    while !stop() {
        match master.read(&mut buf) {
            Ok(n) if n > 0 => device.send(&buf[..n])?,
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            // EIO: no client has the device side open right now.
            Err(e) if e.raw_os_error() == Some(nix::libc::EIO) => {}
            Err(e) => return Err(e.into()),
        }
        device.elapse(Duration::from_millis(1));
        loop {
            let n = device.receive(&mut buf)?;
            if n == 0 {
                break;
            }
            outbox.push(&buf[..n]);
        }
        outbox.write_to(&mut master)?;
    }
    if outbox.dropped > 0 {
        let _ = writeln!(
            std::io::stderr(),
            "ringpod: {} frames dropped: a client did not read them",
            outbox.dropped
        );
    }
    Ok(())
}

/// Most bytes kept for a client that does not read (a suspended or killed recorder): about four seconds of
/// telemetry at 1 kHz. Past it the oldest frames are dropped, so the simulator keeps serving (and keeps its
/// settings and stored rig) instead of blocking on, or failing at, a full terminal.
const OUTBOX_LIMIT: usize = 256 * 1024;

/// What the simulator said and the client has not read yet.
#[derive(Default)]
struct Outbox {
    bytes: VecDeque<u8>,
    /// Frames dropped because the client did not read them.
    dropped: u64,
}

impl Outbox {
    fn push(&mut self, bytes: &[u8]) {
        self.bytes.extend(bytes);
        while self.bytes.len() > OUTBOX_LIMIT {
            // Whole frames from the front, up to and including their delimiter: what is left starts a frame.
            let end = self
                .bytes
                .iter()
                .position(|b| *b == 0)
                .map_or(self.bytes.len(), |i| i + 1);
            self.bytes.drain(..end);
            self.dropped += 1;
        }
    }

    /// Writes what the terminal takes now; a full terminal (`EAGAIN`) or one nobody holds open (`EIO`) takes
    /// nothing, and the bytes wait.
    fn write_to(&mut self, out: &mut impl Write) -> std::io::Result<()> {
        while !self.bytes.is_empty() {
            let (front, _) = self.bytes.as_slices();
            match out.write(front) {
                Ok(0) => return Ok(()),
                Ok(n) => {
                    self.bytes.drain(..n);
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return Ok(()),
                Err(e) if e.raw_os_error() == Some(nix::libc::EIO) => return Ok(()),
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A terminal that takes `room` bytes, then says `EAGAIN`.
    struct Full {
        taken: Vec<u8>,
        room: usize,
    }

    impl Write for Full {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            let n = buf.len().min(self.room - self.taken.len());
            if n == 0 {
                return Err(std::io::ErrorKind::WouldBlock.into());
            }
            self.taken.extend(&buf[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_full_terminal_keeps_the_bytes_and_a_reader_that_never_reads_costs_whole_frames_only() {
        let mut outbox = Outbox::default();
        let mut term = Full {
            taken: Vec::new(),
            room: 10,
        };
        outbox.push(&[1, 2, 3, 0, 4, 5, 6, 7, 8, 9, 10, 11, 0]);
        outbox.write_to(&mut term).unwrap();
        assert_eq!(term.taken, [1, 2, 3, 0, 4, 5, 6, 7, 8, 9]);
        assert_eq!(outbox.bytes, [10, 11, 0]);
        // Frames of 100 bytes each until the limit is passed many times over: the oldest go, whole.
        let frame: Vec<u8> = (1..100).chain([0]).collect();
        for _ in 0..(3 * OUTBOX_LIMIT / frame.len()) {
            outbox.push(&frame);
        }
        assert!(outbox.bytes.len() <= OUTBOX_LIMIT);
        assert!(outbox.dropped > 0);
        assert_eq!(outbox.bytes.front(), Some(&1), "what is kept starts a frame");
        assert_eq!(outbox.bytes.back(), Some(&0));
    }
}
