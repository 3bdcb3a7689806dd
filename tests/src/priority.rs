//! How the test command shares two cores: builds that may only take what the timing-sensitive tests (the host's
//! suite, the emulators, Wine) leave, so as not to starve their answers, and tests that wait more than they compute
//! run many at a time.

use std::process::Command;

/// `c` at the lowest CPU priority (`nice -n 19`), with its arguments, folder and environment.
pub fn yielding(c: &Command) -> Command {
    let mut niced = Command::new("nice");
    niced.args(["-n", "19"]).arg(c.get_program()).args(c.get_args());
    if let Some(dir) = c.get_current_dir() {
        niced.current_dir(dir);
    }
    for (key, value) in c.get_envs() {
        match value {
            Some(v) => niced.env(key, v),
            None => niced.env_remove(key),
        };
    }
    niced
}

/// Tests at a time in the test command's `cargo test` runs (the host's and Wine's), unless `RUST_TEST_THREADS` says
/// otherwise: most tests wait on a child `ringpod` in real time, not on a core (the host suite took 74 s at eight,
/// 256 s at two; under Wine 56 s and 180 s). Four, not eight: at eight, beside the niced builds and the Windows
/// runner on two cores, a simulated device's process waited up to 1 s for a core on a slow day, past the stream
/// timeouts the live tests give it, and the device took the host for gone.
pub const TEST_THREADS: &str = "4";

/// `cargo test` with [`TEST_THREADS`] tests at a time, unless the caller's `RUST_TEST_THREADS` is set.
pub fn many_tests_at_once(c: &mut Command) {
    if std::env::var_os("RUST_TEST_THREADS").is_none() {
        c.env("RUST_TEST_THREADS", TEST_THREADS);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;
    use std::path::Path;

    #[test]
    fn a_yielding_command_is_the_same_command_under_nice() {
        let mut c = Command::new("cargo");
        c.args(["test", "--no-run"])
            .current_dir("/tmp")
            .env("A", "1")
            .env_remove("B");
        let n = yielding(&c);
        assert_eq!(n.get_program(), "nice");
        let args: Vec<_> = n.get_args().collect();
        assert_eq!(args, ["-n", "19", "cargo", "test", "--no-run"]);
        assert_eq!(n.get_current_dir(), Some(Path::new("/tmp")));
        let envs: Vec<_> = n.get_envs().collect();
        assert!(envs.contains(&(OsStr::new("A"), Some(OsStr::new("1")))));
        assert!(envs.contains(&(OsStr::new("B"), None)));
    }
}
