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
    let mut child = qemu(elf, None, args)
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
    Ok(emulated)
}
