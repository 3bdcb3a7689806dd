//! What a rehost run needs: the firmware ELF, the host CLI and the emulator's venv.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use ringpod_tests::setup;

const FIRMWARE: &str = "ringpod-firmware";

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

pub fn run(command: &mut Command, what: &str) -> Result<(), String> {
    let status = command.status().map_err(|e| format!("{what}: cannot start: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({status})"))
    }
}

/// The firmware ELF, built as for flashing (the `firmware` profile).
pub fn build_firmware() -> Result<PathBuf, String> {
    build_firmware_at(&repo(), &target_dir())
}

/// The firmware of the sources under `root`, built into `target` as for flashing; its ELF.
pub fn build_firmware_at(root: &Path, target: &Path) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    run(
        Command::new(cargo)
            .current_dir(root)
            .env("CARGO_TARGET_DIR", target)
            .args([
                "build",
                "-p",
                FIRMWARE,
                "--target",
                setup::TARGET,
                "--profile",
                "firmware",
            ]),
        "cargo build -p ringpod-firmware --profile firmware",
    )?;
    Ok(target.join(setup::TARGET).join("firmware").join(FIRMWARE))
}

/// The venv's Python, with `requirements.txt` installed exactly.
pub fn venv() -> Result<PathBuf, String> {
    let dir = target_dir().join("rehost-venv");
    let python = dir.join("bin/python");
    let requirements = repo().join("tests/rehost/requirements.txt");
    let wanted = std::fs::read_to_string(&requirements).map_err(|e| format!("{}: {e}", requirements.display()))?;
    let stamp = dir.join("ringpod-requirements.txt");
    if python.exists() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == wanted) {
        return Ok(python);
    }
    let create = format!("python3 -m venv --clear {}", dir.display());
    if !setup::may_install() {
        return Err(format!(
            "the emulator's venv is missing or stale: run `{create} && {} -m pip install -r {}`",
            python.display(),
            requirements.display()
        ));
    }
    println!("== {create}; pip install -r tests/rehost/requirements.txt");
    run(
        Command::new("python3").args(["-m", "venv", "--clear"]).arg(&dir),
        &create,
    )
    .map_err(|e| {
        format!("{e}: the rehost runner needs Python 3.8+ with venv (on Debian: apt-get install python3-venv)")
    })?;
    run(
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r"])
            .arg(&requirements),
        "pip install -r tests/rehost/requirements.txt",
    )?;
    std::fs::write(&stamp, wanted).map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(python)
}

/// run.py on `elf`, driving the CLI at `cli`, with `extra` arguments; its output piped.
pub fn run_py(python: &Path, elf: &Path, cli: &Path, extra: &[&str]) -> Result<Child, String> {
    Command::new(python)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .arg(repo().join("tests/rehost/run.py"))
        .arg("--elf")
        .arg(elf)
        .arg("--ringpod")
        .arg(cli)
        .args(extra)
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("run.py: {e}"))
}
