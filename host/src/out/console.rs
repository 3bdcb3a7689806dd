//! Standard output and standard error, written without a panic. `println!` and `eprintln!` panic when their
//! stream cannot be written (a reader that went away: `2>&1 | head -1`; a full disk), and a panic in the middle of
//! a stream leaves the platform moving until the device's stream timeout brakes it. Every write here reports its
//! failure instead: the first one is kept, a flag registered by a long-running command (its stop flag) is set, so
//! that the command ends as a stop does, and `main` exits with [`super::EXIT_OUTPUT`] naming it.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// The first write that failed: which stream and why.
static FAILED: Mutex<Option<String>> = Mutex::new(None);
/// Set once a write has failed (read without the lock, from a stream's loop).
static ANY: AtomicBool = AtomicBool::new(false);
/// A flag to set on the first failure (a command's stop flag).
static NOTIFY: Mutex<Option<Arc<AtomicBool>>> = Mutex::new(None);

/// Keeps the first failure and sets the registered flag.
fn fail(stream: &str, e: &std::io::Error) {
    let mut first = FAILED.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    first.get_or_insert_with(|| format!("{stream}: {e}"));
    ANY.store(true, Ordering::SeqCst);
    if let Some(flag) = NOTIFY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .as_ref()
    {
        flag.store(true, Ordering::SeqCst);
    }
}

/// Writes `text` to standard output; false (and the failure kept) when it could not be written.
pub fn out(text: &str) -> bool {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()) {
        Ok(()) => true,
        Err(e) => {
            fail("standard output", &e);
            false
        }
    }
}

/// Flushes standard output now (a watch's line seen as it happens); false (and the failure kept) when it could not
/// be written.
pub fn flush_stdout() -> bool {
    match std::io::stdout().lock().flush() {
        Ok(()) => true,
        Err(e) => {
            fail("standard output", &e);
            false
        }
    }
}

/// Whether standard output's reader went away (a pipe whose reader closed: `| head -1`), found without writing,
/// so that a command that prints only on a change (`device inputs --watch`) notices it while nothing changes. It
/// is kept as the failure the next write would meet (a broken pipe), and the command exits as any closed output
/// does. Always false where this cannot be asked (Windows: there the next write finds it).
pub fn stdout_closed() -> bool {
    let closed = platform::stdout_hung_up();
    if closed {
        fail("standard output", &platform::broken_pipe());
    }
    closed
}

/// Writes `line` and a newline to standard error, unbuffered; false (and the failure kept) when it could not be
/// written.
pub fn err(line: &str) -> bool {
    let mut stderr = std::io::stderr().lock();
    match stderr.write_all(format!("{line}\n").as_bytes()) {
        Ok(()) => true,
        Err(e) => {
            fail("standard error", &e);
            false
        }
    }
}

/// Flushes standard output (what a command printed last may still be in its buffer); the first failure of the
/// command's writes, if any.
pub fn finish() -> Option<String> {
    if let Err(e) = std::io::stdout().lock().flush() {
        fail("standard output", &e);
    }
    failed()
}

/// Whether a write has failed.
pub fn has_failed() -> bool {
    ANY.load(Ordering::SeqCst)
}

/// The first write that failed, in words.
pub fn failed() -> Option<String> {
    FAILED.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone()
}

/// Sets `flag` on the first failure (also at once, when one has happened already): a stream's stop flag, so that
/// a closed output ends the run as a stop does, also while it waits for the device.
pub fn on_failure(flag: Arc<AtomicBool>) {
    if has_failed() {
        flag.store(true, Ordering::SeqCst);
    }
    *NOTIFY.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(flag);
}

#[cfg(unix)]
mod platform {
    use std::os::fd::AsFd;

    use nix::poll::{poll, PollFd, PollFlags, PollTimeout};

    /// Asks poll() about standard output without waiting: a pipe without a reader reports POLLERR (Linux) or
    /// POLLHUP (the BSDs, macOS), as does a terminal that hung up; a file or a live reader reports neither.
    pub(super) fn stdout_hung_up() -> bool {
        let stdout = std::io::stdout();
        let mut fds = [PollFd::new(stdout.as_fd(), PollFlags::empty())];
        matches!(poll(&mut fds, PollTimeout::ZERO), Ok(1..))
            && fds[0]
                .revents()
                .is_some_and(|r| r.intersects(PollFlags::POLLERR | PollFlags::POLLHUP))
    }

    /// The error a write to a pipe without a reader returns.
    pub(super) fn broken_pipe() -> std::io::Error {
        nix::errno::Errno::EPIPE.into()
    }
}

#[cfg(not(unix))]
mod platform {
    pub(super) fn stdout_hung_up() -> bool {
        false
    }

    pub(super) fn broken_pipe() -> std::io::Error {
        std::io::ErrorKind::BrokenPipe.into()
    }
}
