//! The `ringpod` CLI as the runs drive it, and the inputs they feed it: pose files and raw bytes on the pty.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// The CLI the suite drives ([`ringpod_tests::cli::host`], built or named before the first section that needs it).
pub(crate) fn ringpod() -> PathBuf {
    ringpod_tests::cli::host().unwrap_or_else(|e| PathBuf::from(format!("<no CLI: {e}>")))
}

/// The factor the CLI's waits for an answer are lengthened by (`RINGPOD_PATIENCE`). The emulated board runs in
/// virtual time (`-icount`): on a loaded machine QEMU runs it slower than a board, and an answer due within the
/// CLI's 2 s comes later (a stream into the rig's controller beside a release build waited longer than that). The
/// runs check what the firmware answers and does, not how fast the host machine is.
const PATIENCE: &str = "5";

/// The CLI with its waits for an answer lengthened by [`PATIENCE`], its input closed.
fn cli(args: &[&str]) -> Command {
    let mut c = Command::new(ringpod());
    c.args(args).env("RINGPOD_PATIENCE", PATIENCE).stdin(Stdio::null());
    c
}

/// Runs the CLI and parses the JSON it prints.
pub(crate) fn ringpod_json(args: &[&str]) -> Result<serde_json::Value, String> {
    let out = cli(args).output().map_err(|e| format!("ringpod: {e}"))?;
    if !out.status.success() {
        return Err(format!("ringpod {args:?}: {}", String::from_utf8_lossy(&out.stderr)));
    }
    serde_json::from_slice(&out.stdout).map_err(|e| format!("ringpod {args:?}: {e}"))
}

/// Runs the CLI; its exit status and what it printed on stdout.
pub(crate) fn ringpod_text(args: &[&str]) -> (bool, String) {
    cli(args)
        .stderr(Stdio::null())
        .output()
        .map(|o| (o.status.success(), String::from_utf8_lossy(&o.stdout).into_owned()))
        .unwrap_or((false, String::new()))
}

/// A 3 s input about the trainer model's home height: see [`write_input_about`].
pub(crate) fn write_input(path: &Path) -> std::io::Result<()> {
    write_input_about(path, 0.227)
}

/// A 3 s input about home height `z0` (m): 2 s of motion on every axis, then 1 s holding the last pose, so that
/// both runs end at rest at the same pose whatever their timing.
pub(crate) fn write_input_about(path: &Path, z0: f64) -> std::io::Result<()> {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for k in 0..=300 {
        let t = f64::from(k) * 0.01;
        let u = t.min(2.0);
        csv += &format!(
            "{t:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}\n",
            0.01 * (2.0 * u).sin(),
            0.008 * (1.5 * u).sin(),
            z0 + 0.006 * (2.5 * u).sin(),
            0.03 * u.sin(),
            0.04 * (2.0 * u).sin(),
            0.3 * u
        );
    }
    std::fs::write(path, csv)
}

/// A 6 s stream as simulator software sends it, beyond what the model can do: every axis at once up to 1.5 times
/// its spec range, surge at up to twice its speed limit, yaw turning, at 100 Hz; the excursion fades out over the
/// last 1.5 s and the input holds home for its last 0.5 s, so both runs end at rest at the same pose.
pub(crate) fn write_beyond_envelope(path: &Path) -> std::io::Result<()> {
    let mut csv = String::from(
        "t,x,y,z,alpha,beta,gamma
",
    );
    let r = ringpod_core::kinematics::presets::TRAINER_MODEL_RANGES;
    for k in 0..=600 {
        let t = f64::from(k) * 0.01;
        let fade = (t / 0.5).min(1.0) * ((5.5 - t) / 1.5).clamp(0.0, 1.0);
        let a = |i: usize| 1.5 * r[i] * fade;
        csv += &format!(
            "{t:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}
",
            a(0) * (1.3 * t).sin(),
            a(1) * (0.9 * t + 1.0).sin(),
            0.227 + a(2) * (1.1 * t + 2.0).sin(),
            a(3) * (0.8 * t + 0.5).sin(),
            a(4) * (0.7 * t + 1.5).sin(),
            0.4 * t.min(5.5)
        );
    }
    std::fs::write(path, csv)
}

/// Writes `garbage` to the device's pty and returns what it answers within half a second.
pub(crate) fn send_garbage(pty: &str, garbage: &[u8]) -> Result<Vec<u8>, String> {
    use std::io::Write;
    let status = Command::new("stty")
        .args(["-F", pty, "raw", "-echo", "min", "0", "time", "5"])
        .status()
        .map_err(|e| format!("stty: {e}"))?;
    if !status.success() {
        return Err("stty failed".into());
    }
    let mut port = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(pty)
        .map_err(|e| format!("{pty}: {e}"))?;
    // QEMU's pty backend notices an opened slave side by polling (about once a second) and drops what the guest
    // sends until then.
    std::thread::sleep(Duration::from_millis(1_500));
    port.write_all(garbage).map_err(|e| e.to_string())?;
    let mut answer = Vec::new();
    let mut buf = [0u8; 256];
    while let Ok(n) = port.read(&mut buf) {
        if n == 0 {
            break;
        }
        answer.extend_from_slice(&buf[..n]);
    }
    Ok(answer)
}
