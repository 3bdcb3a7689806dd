//! Stopping on a signal. SIGINT (Ctrl-C), SIGTERM (`kill`, a service manager) and SIGHUP (the terminal closed) set
//! one flag that the long-running commands poll, so that they stop the platform, report, and exit with 128 plus the
//! signal's number, as shells and service managers expect.
//!
//! The handlers are installed explicitly: a shell starts a background job of a script (`ringpod simulate --pty &`)
//! with SIGINT ignored, and a program that relied on the default action would never end on `kill -INT`.
//!
//! Windows has no signals but console control events: Ctrl-C and Ctrl-Break stop a command as SIGINT does (exit
//! 130), and the console closed, the user logging off or the system shutting down as SIGTERM does (exit 143), so that
//! scripts read the same codes on both systems.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// SIGINT's number, the same on every Unix.
const SIGINT: usize = 2;
/// SIGHUP's number.
const SIGHUP: usize = 1;
/// SIGTERM's number.
const SIGTERM: usize = 15;

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
        platform::install(&stop, &last)?;
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
        let ctrl_c = 128 + SIGINT as u8;
        match self.last.load(Ordering::SeqCst) {
            0 => ctrl_c,
            n => u8::try_from(128 + n).unwrap_or(ctrl_c),
        }
    }

    /// The signal's name for messages: "Ctrl-C (SIGINT)", "SIGTERM", "SIGHUP" (on Windows, the console event).
    pub fn name(&self) -> &'static str {
        match self.last.load(Ordering::SeqCst) {
            SIGTERM if cfg!(windows) => "the console closing (as SIGTERM)",
            SIGTERM => "SIGTERM",
            SIGHUP => "SIGHUP",
            _ if cfg!(windows) => "Ctrl-C or Ctrl-Break (as SIGINT)",
            _ => "Ctrl-C (SIGINT)",
        }
    }
}

/// For the commands that only compute (a workspace scan, a rig design, a drawing): they have no platform to stop
/// and no loop that polls a flag, so a stopping signal ends the process from a watching thread, after a line that
/// names it, with 128 + the signal's number. Installed explicitly for the same reason as [`Signals::install`]: a
/// script's background job inherits SIGINT ignored, and `kill -INT` must still end it. Files these commands write
/// are renamed into place only when complete, so an end half-way leaves none under the target's name.
pub fn end_on_signal() -> std::io::Result<()> {
    let signals = Signals::install()?;
    std::thread::Builder::new().name("signals".into()).spawn(move || loop {
        if signals.received() {
            crate::out::console::err(&format!("ringpod: interrupted by {}", signals.name()));
            std::process::exit(i32::from(signals.exit_code()));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    })?;
    Ok(())
}

#[cfg(unix)]
mod platform {
    use std::sync::atomic::{AtomicBool, AtomicUsize};
    use std::sync::Arc;

    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

    pub(super) fn install(stop: &Arc<AtomicBool>, last: &Arc<AtomicUsize>) -> std::io::Result<()> {
        for signal in [SIGINT, SIGTERM, SIGHUP] {
            signal_hook::flag::register(signal, stop.clone())?;
            // The signal's number is small and positive, so it fits and is never 0 (0 means none received).
            signal_hook::flag::register_usize(signal, last.clone(), signal as usize)?;
        }
        Ok(())
    }

    #[test]
    fn the_numbers_are_the_systems() {
        assert_eq!(
            (SIGINT as usize, SIGTERM as usize, SIGHUP as usize),
            (super::SIGINT, super::SIGTERM, super::SIGHUP)
        );
    }
}

#[cfg(windows)]
mod platform {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::{Arc, Mutex};
    use std::time::Duration;

    use windows_sys::Win32::System::Console::{
        SetConsoleCtrlHandler, CTRL_BREAK_EVENT, CTRL_CLOSE_EVENT, CTRL_C_EVENT, CTRL_LOGOFF_EVENT, CTRL_SHUTDOWN_EVENT,
    };

    /// Every installed command's flags: the console handler is one function for the process.
    static FLAGS: Mutex<Vec<(Arc<AtomicBool>, Arc<AtomicUsize>)>> = Mutex::new(Vec::new());

    pub(super) fn install(stop: &Arc<AtomicBool>, last: &Arc<AtomicUsize>) -> std::io::Result<()> {
        let mut flags = FLAGS.lock().unwrap_or_else(|p| p.into_inner());
        if flags.is_empty() {
            // SAFETY: `handler` is a plain function that lives for the whole program.
            if unsafe { SetConsoleCtrlHandler(Some(handler), 1) } == 0 {
                return Err(std::io::Error::last_os_error());
            }
        }
        flags.push((stop.clone(), last.clone()));
        Ok(())
    }

    /// The signal a console event stands for: Ctrl-C and Ctrl-Break interrupt, the rest terminate.
    pub(super) fn signal_of(event: u32) -> Option<usize> {
        match event {
            CTRL_C_EVENT | CTRL_BREAK_EVENT => Some(super::SIGINT),
            CTRL_CLOSE_EVENT | CTRL_LOGOFF_EVENT | CTRL_SHUTDOWN_EVENT => Some(super::SIGTERM),
            _ => None,
        }
    }

    /// Runs on a thread of its own that the system starts for the event.
    pub(super) unsafe extern "system" fn handler(event: u32) -> i32 {
        let Some(signal) = signal_of(event) else {
            return 0;
        };
        for (stop, last) in FLAGS.lock().unwrap_or_else(|p| p.into_inner()).iter() {
            last.store(signal, Ordering::SeqCst);
            stop.store(true, Ordering::SeqCst);
        }
        if signal == super::SIGTERM {
            // The system ends the process as soon as this returns (and at the latest after 5 s): wait here so
            // that the command can stop the platform and report, and end the process itself with its exit code.
            std::thread::sleep(Duration::from_millis(4500));
        }
        1
    }
}

#[cfg(all(test, windows))]
mod tests {
    use super::*;
    use windows_sys::Win32::System::Console::{CTRL_BREAK_EVENT, CTRL_CLOSE_EVENT, CTRL_C_EVENT};

    #[test]
    fn console_events_stop_with_the_signals_exit_codes() {
        let signals = Signals::install().unwrap();
        assert!(!signals.received());
        // SAFETY: the handler only touches the flags.
        assert_eq!(unsafe { platform::handler(CTRL_BREAK_EVENT) }, 1);
        assert!(signals.received());
        assert_eq!(signals.exit_code(), 130);
        assert_eq!(platform::signal_of(CTRL_C_EVENT), Some(SIGINT));
        assert_eq!(platform::signal_of(CTRL_CLOSE_EVENT), Some(SIGTERM));
        // An event that is not a stop (none today past shutdown) is passed on to the next handler.
        assert_eq!(platform::signal_of(99), None);
        assert_eq!(unsafe { platform::handler(99) }, 0);
    }
}
