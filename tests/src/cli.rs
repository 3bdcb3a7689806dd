//! The host CLI the runners drive: one optimised build of `ringpod`, shared by the QEMU suite, the rehost run and the
//! browser tests. It is the build the README's main command makes (`cargo run --release -p ringpod`), so after that
//! command no runner compiles the host again; a debug build of its own would recompile the host and the
//! dependencies whose features differ under `cargo test`, minutes on two cores.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

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
/// moves it: a guessed path would run a stale build or none).
pub fn executable(messages: &[u8], bin: &str) -> Option<PathBuf> {
    messages
        .split(|b| *b == b'\n')
        .filter_map(|line| serde_json::from_slice::<serde_json::Value>(line).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == bin)
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
        assert_eq!(
            executable(messages.as_bytes(), "suite"),
            Some(PathBuf::from("/t/thumbv7em-none-eabihf/release/suite"))
        );
        assert_eq!(executable(messages.as_bytes(), "other"), None);
    }
}
