//! Stopping on a signal. SIGINT (Ctrl-C), SIGTERM (`kill`, a service manager) and SIGHUP (the terminal closed) set
//! one flag that the long-running commands poll, so that they stop the platform, report, and exit with 128 plus the
//! signal's number, as shells and service managers expect.
//!
//! The handlers are installed explicitly: a shell starts a background job of a script (`ringpod simulate --pty &`)
//! with SIGINT ignored, and a program that relied on the default action would never end on `kill -INT`.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

/// The signals that stop a command, as they were received.
pub struct Signals {
    stop: Arc<AtomicBool>,
    last: Arc<AtomicUsize>,
}

impl Signals {
    /// Installs the handlers (once per command; a second install adds handlers that set the same kind of flags).
    pub fn install() -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let last = Arc::new(AtomicUsize::new(0));
        for signal in [SIGINT, SIGTERM, SIGHUP] {
            signal_hook::flag::register(signal, stop.clone())?;
            // The signal's number is small and positive, so it fits and is never 0 (0 means none received).
            signal_hook::flag::register_usize(signal, last.clone(), signal as usize)?;
        }
        Ok(Self { stop, last })
    }

    /// The flag the handlers set, for code that polls an `AtomicBool` (the client's cancel flag).
    pub fn flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// Whether a stopping signal arrived.
    pub fn received(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    /// The exit code for the signal that arrived: 128 + its number (130 for SIGINT, 143 for SIGTERM, 129 for
    /// SIGHUP); 130 when the flag was set without a number (it is not, but Ctrl-C is what a user expects then).
    pub fn exit_code(&self) -> u8 {
        match self.last.load(Ordering::SeqCst) {
            0 => 130,
            n => u8::try_from(128 + n).unwrap_or(130),
        }
    }

    /// The signal's name for messages: "Ctrl-C (SIGINT)", "SIGTERM", "SIGHUP".
    pub fn name(&self) -> &'static str {
        match self.last.load(Ordering::SeqCst) as i32 {
            SIGTERM => "SIGTERM",
            SIGHUP => "SIGHUP",
            _ => "Ctrl-C (SIGINT)",
        }
    }
}
