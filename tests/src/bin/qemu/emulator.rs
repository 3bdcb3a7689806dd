//! QEMU itself: building the Cortex-M4F programs of `tests/qemu`, running one to its
//! end under a time limit, or starting the controller program with its UART on a pseudo-terminal.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::Stdio;

pub(crate) use ringpod_tests::emulator::build;
use ringpod_tests::emulator::qemu;
use std::time::{Duration, Instant};

use crate::Tally;

/// Longest a QEMU run may take before it is killed and counted as failed.
pub(crate) const QEMU_LIMIT: Duration = Duration::from_secs(240);

/// Runs a program to its end (or the limit) and returns what it printed.
pub(crate) fn run_to_end(elf: &Path) -> Result<String, String> {
    let mut child = qemu(elf, Some("shift=0"), &[])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e} (apt-get install qemu-system-arm)"))?;
    let mut out = child.stdout.take().ok_or("no stdout")?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            let text = reader.join().unwrap_or_default();
            return if status.success() {
                Ok(text)
            } else {
                Err(format!("qemu exited with {status}:\n{text}"))
            };
        }
        if start.elapsed() > QEMU_LIMIT {
            let _ = child.kill();
            return Err(format!("qemu still running after {} s: killed", QEMU_LIMIT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// QEMU running the controller program, its UART on a pseudo-terminal.
pub(crate) struct Emulated {
    child: std::process::Child,
    pub(crate) pty: String,
    /// What the program prints over semihosting (and QEMU on its stderr), line by line.
    lines: std::sync::mpsc::Receiver<String>,
}

impl Emulated {
    /// Lines printed until one satisfies `done` (included), or an error with what came when `limit` passes first.
    pub(crate) fn wait_for(&self, limit: Duration, done: impl Fn(&str) -> bool) -> Result<Vec<String>, String> {
        let deadline = Instant::now() + limit;
        let mut seen = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    let last = done(&line);
                    seen.push(line);
                    if last {
                        return Ok(seen);
                    }
                }
                Err(_) => return Err(format!("waited {} s; printed: {seen:?}", limit.as_secs())),
            }
        }
    }

    /// Lines printed so far and not yet read.
    pub(crate) fn printed(&self) -> Vec<String> {
        self.lines.try_iter().collect()
    }

    /// Holds the emulated MCU up for `stall`: QEMU's process stopped (`kill -STOP`) and continued. Its clock follows
    /// the host's, so the firmware finds `stall` gone at once, as a board does after a flash erase.
    pub(crate) fn hold_up(&self, stall: Duration) -> Result<(), String> {
        let signal = |name: &str| {
            std::process::Command::new("kill")
                .args([name, &self.child.id().to_string()])
                .status()
                .map_err(|e| format!("kill: {e}"))
                .and_then(|s| {
                    if s.success() {
                        Ok(())
                    } else {
                        Err(format!("kill {name} failed"))
                    }
                })
        };
        signal("-STOP")?;
        std::thread::sleep(stall);
        signal("-CONT")
    }
}

impl Drop for Emulated {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Builds and starts the controller program with `args`; a failure is reported and counted.
pub(crate) fn start_or_fail(t: &mut Tally, args: &[&str]) -> Option<Emulated> {
    match build("ringpod-qemu-controller").and_then(|elf| start_controller(&elf, args)) {
        Ok(e) => Some(e),
        Err(e) => {
            eprintln!("{e}");
            t.check(false, "the controller starts on the emulated Cortex-M4F");
            None
        }
    }
}

/// Starts the controller program with the semihosting command line `args` and waits for its pty and its `READY`.
pub(crate) fn start_controller(elf: &Path, args: &[&str]) -> Result<Emulated, String> {
    // Device time under `-icount` (8 ns an instruction, 125 MHz): while the emulated CPU runs, its clock advances
    // with the instructions it executes, so a busy host slows the device down instead of stealing its time; while
    // it sleeps (`sleep=on`) the clock follows the host's, so the controller keeps pace with the real-time CLI. A
    // hold-up of the emulator while the CPU sleeps still shows as a jump of device time, which the firmware
    // catches up as a board does after a hold-up (passing what it is far behind); with icount the catch-up
    // always ends, where on the host's clock a starved emulator could stay behind.
    let mut child = qemu(elf, Some("shift=3,sleep=on"), args)
        .args(["-serial", "pty"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e}"))?;
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    for stream in [
        child.stdout.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
        child.stderr.take().map(|s| Box::new(s) as Box<dyn Read + Send>),
    ]
    .into_iter()
    .flatten()
    {
        let tx = tx.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stream).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
    }
    let mut emulated = Emulated {
        child,
        pty: String::new(),
        lines: rx,
    };
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut ready = false;
    while !ready || emulated.pty.is_empty() {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = emulated
            .lines
            .recv_timeout(left)
            .map_err(|_| "the controller did not come up in 30 s".to_string())?;
        if let Some(at) = line.find("/dev/pts/") {
            emulated.pty = line[at..].split_whitespace().next().unwrap_or("").to_string();
        }
        ready |= line.trim() == "READY";
        if line.starts_with("ERROR") {
            return Err(line);
        }
    }
    // The emulator, the host CLI and the suite share this machine's cores, where a board has a CPU of its own: on a
    // busy machine the CLI can be descheduled for longer than the stream timeout (100 ms) between two setpoints,
    // which on a board would be a host that is gone. The emulated controller is given a timeout that outlasts
    // such a hold-up of the test machine (up to 0.9 s measured on a test run's busiest minutes; its own hold-ups
    // it passes, as a board does); a killed host is still braked by it (`controller`'s stream-loss check).
    let timeout = format!("{}", STREAM_TIMEOUT_MS);
    let (set, _) = crate::host_cli::ringpod_text(&[
        "device",
        "config",
        "set",
        "stream.timeout_ms",
        &timeout,
        "--port",
        &emulated.pty,
    ]);
    if !set {
        return Err("the emulated controller took no stream timeout".into());
    }
    Ok(emulated)
}

/// The emulated controller's stream timeout (see [`start_controller`]).
pub(crate) const STREAM_TIMEOUT_MS: u32 = 1000;
