//! The simulated controller on a pseudo-terminal: a program opens the printed path as it would a board's
//! USB serial port.

use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::time::Duration;

use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};

use crate::link::client::Transport;
use crate::link::transport::SimDevice;
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
            master.write_all(&buf[..n])?;
        }
    }
    Ok(())
}
