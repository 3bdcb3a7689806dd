//! QEMU for the Cortex-M4F programs of `tests/qemu`: building them and the emulator's command line, shared by the
//! QEMU suite (`bin/qemu`) and the latency measurement (`bin/latency`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `tests/qemu` workspace.
pub fn qemu_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("qemu")
}

/// Builds a program of the `tests/qemu` workspace for the M4F (its own `.cargo/config.toml` selects the target,
/// so cargo runs in that folder) and returns its ELF, where cargo says it wrote it (a `CARGO_TARGET_DIR` or a
/// configured target directory moves it out of `tests/qemu/target`, and a path guessed there would run a stale
/// build or none).
pub fn build(bin: &str) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(qemu_dir())
        .args([
            "build",
            "--release",
            "--bin",
            bin,
            "--message-format=json-render-diagnostics",
        ])
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!("building {bin} failed"));
    }
    crate::cli::executable(&out.stdout, bin).ok_or_else(|| format!("cargo built {bin} but named no executable for it"))
}

/// QEMU's command line for an ELF on mps2-an386 with semihosting; `args` are the program's semihosting command
/// line. `icount` is QEMU's `-icount` option (`shift=0`: virtual time advances one nanosecond per instruction, the
/// cost table's counter); without it virtual time follows the host's clock, which a controller streamed in real
/// time needs.
pub fn qemu(elf: &Path, icount: Option<&str>, args: &[&str]) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-nographic",
        "-monitor",
        "none",
    ])
    .arg("-semihosting-config")
    .arg(
        args.iter()
            .fold("enable=on,target=native".to_string(), |c, a| c + ",arg=" + a),
    );
    if let Some(icount) = icount {
        c.args(["-icount", icount]);
    }
    c.arg("-kernel").arg(elf);
    c
}
