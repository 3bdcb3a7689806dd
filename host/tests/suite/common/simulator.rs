//! `ringpod simulate --pty` for the tests that drive it as a board.

use std::process::{Child, Command, Stdio};

/// The simulator's stream timeout in the tests (see [`Simulator::start`]).
pub const STREAM_TIMEOUT_MS: u32 = 500;

/// The factor [`Simulator::ringpod`]'s commands lengthen the CLI's waits for an answer by (`RINGPOD_PATIENCE`):
/// four tests at a time, each with a simulator and a CLI, beside the test command's niced builds and whatever else
/// runs, can leave a simulator unscheduled for longer than the CLI's 2 s (seen at a load of 5 on two cores).
const ANSWER_PATIENCE: &str = "5";

/// `ringpod simulate --pty`, killed when dropped: also when an assertion fails half-way.
pub struct Simulator {
    /// The simulator's process.
    pub child: Child,
    /// Its pseudo-terminal.
    pub path: String,
}

impl Simulator {
    pub fn start() -> Self {
        Self::start_with(&[])
    }

    /// `ringpod simulate --pty ARGS` (`--mechanism trainer-elbow`).
    pub fn start_with(args: &[&str]) -> Self {
        use std::io::BufRead;
        let mut child = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["simulate", "--pty"])
            .args(args)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut path = String::new();
        let stdout = child.stdout.take();
        let mut server = Simulator {
            child,
            path: String::new(),
        };
        std::io::BufReader::new(stdout.unwrap()).read_line(&mut path).unwrap();
        server.path = path.trim().to_owned();
        // The simulator, the CLI and the other tests share the test machine's cores, where a board has a CPU of its
        // own: under load the CLI can be descheduled for longer than the default stream timeout (100 ms) between
        // two setpoints, which to the device is a host that is gone. A timeout that outlasts the machine's own
        // hold-ups (the QEMU suite gives its emulated board the same); tests of the timeout set their own.
        let (code, _, err) = server.ringpod(&[
            "device",
            "config",
            "set",
            "stream.timeout_ms",
            &STREAM_TIMEOUT_MS.to_string(),
        ]);
        assert_eq!(code, Some(0), "{err}");
        server
    }

    /// `ringpod WORDS --port PTY`: the exit code and everything it said. Its waits for an answer are lengthened
    /// ([`ANSWER_PATIENCE`]): these commands test what the simulated board answers, not how soon a loaded machine
    /// schedules it.
    pub fn ringpod(&self, words: &[&str]) -> (Option<i32>, String, String) {
        let out = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(words)
            .args(["--port", &self.path])
            .env("RINGPOD_PATIENCE", ANSWER_PATIENCE)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }

    /// Whether the simulator's process still runs.
    pub fn child_running(&self) -> bool {
        // `try_wait` needs `&mut`; a signal 0 asks the kernel whether the process is there without reaping it.
        nix::sys::signal::kill(nix::unistd::Pid::from_raw(self.child.id() as i32), None).is_ok()
            && !std::fs::read_to_string(format!("/proc/{}/stat", self.child.id()))
                .is_ok_and(|s| s.split_whitespace().nth(2) == Some("Z"))
    }

    /// `device status`, parsed.
    pub fn status(&self) -> serde_json::Value {
        let (code, out, err) = self.ringpod(&["device", "status"]);
        assert_eq!(code, Some(0), "{err}");
        serde_json::from_str(&out).unwrap()
    }
}

impl Drop for Simulator {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
