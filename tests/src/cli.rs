//! The host CLI the runners drive, one optimised build of `ringpod` shared by the QEMU suite, the rehost run and the
//! browser tests. Run alone, a runner uses the build the README's main command makes (`cargo run --release -p
//! ringpod`), so after that command no runner compiles the host again. Under the test command, `all` names the
//! `ringpod` its `cargo test --no-run` built (the test profile: optimised, with debug assertions) in
//! [`CLI_VAR`]: a release build beside it would compile the host and its dependencies a second time, minutes on two
//! cores.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

/// The variable in which `all` names the CLI it built with the test programs.
pub const CLI_VAR: &str = "RINGPOD_CLI";

/// The CLI the runners drive: the one [`CLI_VAR`] names, or else the release build (built once per process).
pub fn host() -> Result<PathBuf, String> {
    static CLI: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    CLI.get_or_init(|| match std::env::var_os(CLI_VAR) {
        Some(named) => {
            let path = PathBuf::from(named);
            path.is_file()
                .then_some(path)
                .ok_or_else(|| format!("{CLI_VAR} names no file"))
        }
        None => build_release(),
    })
    .clone()
}

/// Builds `ringpod` with the release profile and returns its executable, where cargo says it wrote it.
pub fn build_release() -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .args([
            "build",
            "--release",
            "-p",
            "ringpod",
            "--bin",
            "ringpod",
            "--message-format=json-render-diagnostics",
        ])
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cargo build --release -p ringpod: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo build --release -p ringpod failed ({})", out.status));
    }
    executable(&out.stdout, "ringpod").ok_or_else(|| "cargo built ringpod but named no executable for it".into())
}

/// The executable of binary `bin` in cargo's JSON messages (a `CARGO_TARGET_DIR` or a configured target directory
/// moves it: a guessed path would run a stale build or none); under `cargo test`, the program and not its unit tests'.
pub fn executable(messages: &[u8], bin: &str) -> Option<PathBuf> {
    messages
        .split(|b| *b == b'\n')
        .filter_map(|line| serde_json::from_slice::<serde_json::Value>(line).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == bin)
        .filter(|m| m["profile"]["test"] != true)
        .find_map(|m| m["executable"].as_str().map(PathBuf::from))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_executable_is_where_cargo_says() {
        let messages = concat!(
            "{\"reason\":\"compiler-artifact\",\"target\":{\"name\":\"ringpod-core\"},\"executable\":null}\n",
            "not json\n",
            "{\"reason\":\"compiler-artifact\",\"target\":{\"name\":\"suite\"},",
            "\"executable\":\"/t/thumbv7em-none-eabihf/release/suite\"}\n",
            "{\"reason\":\"build-finished\",\"success\":true}\n"
        );
        // Under `cargo test` the binary's unit tests come as an artifact of the same name.
        let tested = concat!(
            "{\"reason\":\"compiler-artifact\",\"target\":{\"name\":\"ringpod\"},\"profile\":{\"test\":true},",
            "\"executable\":\"/t/debug/deps/ringpod-0123\"}\n",
            "{\"reason\":\"compiler-artifact\",\"target\":{\"name\":\"ringpod\"},\"profile\":{\"test\":false},",
            "\"executable\":\"/t/debug/ringpod\"}\n",
        );
        assert_eq!(
            executable(tested.as_bytes(), "ringpod"),
            Some(PathBuf::from("/t/debug/ringpod"))
        );
        assert_eq!(
            executable(messages.as_bytes(), "suite"),
            Some(PathBuf::from("/t/thumbv7em-none-eabihf/release/suite"))
        );
        assert_eq!(executable(messages.as_bytes(), "other"), None);
    }
}
