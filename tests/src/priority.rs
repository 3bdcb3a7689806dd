//! Work that may only take what the machine's other work leaves: the test command's builds beside its
//! timing-sensitive tests (the host's suite, the emulators, Wine), which must not starve their answers.

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
