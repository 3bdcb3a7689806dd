//! A background build its parent pauses while timing-sensitive tests run. The test command starts the Windows
//! cross-build at once, beside its own build, but the host's tests wait on child processes in real time and measure
//! them, and a build beside them (even in the idle scheduling class) takes the cores they wake on: so the parent
//! says `pause` before `cargo test` and `go` after it, and the build's process group is stopped (SIGSTOP) and
//! continued (SIGCONT) in between. The gate also holds the runner's own tests until `go`.

use std::io::BufRead;
use std::process::{Child, Command};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// What the parent said, and the build it applies to.
#[derive(Default)]
struct State {
    /// The build's process group, while it runs.
    group: Option<u32>,
    paused: bool,
    /// `go`, or the end of the parent's lines: the tests may run.
    open: bool,
}

/// The parent's word on a background build: `pause`, `go`.
#[derive(Default)]
pub struct Gate {
    state: Mutex<State>,
    opened: Condvar,
}

impl Gate {
    /// A gate that follows `input`'s lines in a thread of its own: `pause` stops the build, `go` (or the end of
    /// the lines, a parent that went away) continues it and opens the gate; other lines are ignored.
    pub fn following(input: impl BufRead + Send + 'static) -> Arc<Gate> {
        let gate = Arc::new(Gate::default());
        let follower = Arc::clone(&gate);
        std::thread::spawn(move || {
            for line in input.lines().map_while(Result::ok) {
                match line.trim() {
                    "pause" => follower.pause(),
                    "go" => break,
                    _ => {}
                }
            }
            follower.go();
        });
        gate
    }

    /// Runs `c` in a process group of its own, stopped at once if the parent has said `pause`, and waits for it.
    /// (Elsewhere than on Unix, where the test command runs only `cargo test`, it just runs `c`.)
    pub fn run(&self, c: &mut Command) -> std::io::Result<std::process::ExitStatus> {
        #[cfg(unix)]
        std::os::unix::process::CommandExt::process_group(c, 0);
        let mut child: Child = c.spawn()?;
        {
            let mut s = self.lock();
            s.group = Some(child.id());
            if s.paused {
                signal(child.id(), "-STOP");
            }
        }
        let status = child.wait();
        self.lock().group = None;
        status
    }

    /// Waits until the gate is open; how long that took.
    pub fn wait_open(&self) -> Duration {
        let started = Instant::now();
        let mut s = self.lock();
        while !s.open {
            s = self.opened.wait(s).unwrap_or_else(PoisonError::into_inner);
        }
        started.elapsed()
    }

    fn pause(&self) {
        let mut s = self.lock();
        s.paused = true;
        if let Some(group) = s.group {
            signal(group, "-STOP");
        }
    }

    fn go(&self) {
        let mut s = self.lock();
        s.paused = false;
        s.open = true;
        if let Some(group) = s.group {
            signal(group, "-CONT");
        }
        self.opened.notify_all();
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// `kill SIGNAL -- -GROUP`: every process of the group (cargo and each rustc it started).
fn signal(group: u32, which: &str) {
    if !cfg!(unix) {
        return;
    }
    let _ = Command::new("kill").args([which, "--", &format!("-{group}")]).status();
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::io::{BufReader, Write};

    /// A paused build does not run on: its group is stopped until `go`, then it ends, and the gate opens.
    #[test]
    fn a_paused_build_waits_for_go() {
        let (reader, mut writer) = std::io::pipe().unwrap();
        let gate = Gate::following(BufReader::new(reader));
        writer.write_all(b"pause\n").unwrap();
        std::thread::sleep(Duration::from_millis(100));
        let runner = Arc::clone(&gate);
        let started = Instant::now();
        let build = std::thread::spawn(move || {
            // A shell counting to a point: stopped, it stays short of it.
            let mut c = Command::new("sh");
            c.args(["-c", "sleep 0.2; exit 3"]);
            runner.run(&mut c).unwrap().code()
        });
        std::thread::sleep(Duration::from_millis(800));
        assert!(!build.is_finished(), "a build paused before it started ran on");
        writer.write_all(b"go\n").unwrap();
        assert_eq!(build.join().unwrap(), Some(3));
        assert!(started.elapsed() >= Duration::from_millis(800));
        assert!(gate.wait_open() < Duration::from_secs(1));
    }

    /// A parent that went away opens the gate: its runner's tests are not held for ever.
    #[test]
    fn the_end_of_the_lines_opens_the_gate() {
        let gate = Gate::following(BufReader::new(&b"pause\n"[..]));
        let waited = gate.wait_open();
        assert!(waited < Duration::from_secs(2), "{waited:?}");
        let mut c = Command::new("sh");
        c.args(["-c", "exit 0"]);
        assert!(gate.run(&mut c).unwrap().success());
    }
}
