//! The processes the checks need: the CLI built, a run record, `ringpod ui --sim`, ChromeDriver.

use std::io::{BufRead, BufReader};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| repo().join("target"), PathBuf::from)
}

/// A child process killed when dropped (a failed check must not leave a server or a browser behind).
pub struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

pub fn free_port() -> Result<u16, String> {
    let l = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

/// A short run record of the simulated controller, for the Runs panel.
pub fn record(cli: &Path) -> Result<PathBuf, String> {
    let path = target_dir().join("browser-run.csv");
    let status = Command::new(cli)
        .args([
            "stream",
            "--sim",
            "--fast",
            "--motion",
            "demo",
            "--duration",
            "3",
            "--quiet",
            "--record",
        ])
        .arg(&path)
        .stdout(Stdio::null())
        .status()
        .map_err(|e| format!("ringpod stream: {e}"))?;
    if !status.success() {
        return Err(format!("ringpod stream --record failed ({status})"));
    }
    Ok(path)
}

/// `ringpod ui --sim` on a free port, and the URL it printed.
pub fn serve(cli: &Path, cue_config: &Path, rig: &Path) -> Result<(Running, String), String> {
    let mut child = Command::new(cli)
        .args(["ui", "--sim", "--listen", "127.0.0.1:0", "--cue-config"])
        .arg(cue_config)
        .arg("--geometry")
        .arg(rig)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("ringpod ui: {e}"))?;
    let stdout = child.stdout.take().ok_or("ringpod ui: no stdout")?;
    let running = Running(child);
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .map_err(|e| format!("ringpod ui: {e}"))?;
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .ok_or_else(|| format!("ringpod ui printed no URL: {line:?}"))?
        .to_owned();
    Ok((running, url))
}

/// The trainer model as a rig file (what the simulator runs without one), for the Rig panel to save to.
pub fn rig_file(cli: &Path) -> Result<PathBuf, String> {
    let path = target_dir().join("browser-rig.toml");
    let out = Command::new(cli)
        .args(["presets", "--export", "trainer-model"])
        .output()
        .map_err(|e| format!("presets --export: {e}"))?;
    if !out.status.success() {
        return Err(format!("presets --export: {}", String::from_utf8_lossy(&out.stderr)));
    }
    std::fs::write(&path, out.stdout).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

pub fn chromedriver() -> Result<(Running, String), String> {
    let port = free_port()?;
    let child = Command::new("chromedriver")
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("chromedriver: {e}"))?;
    let running = Running(child);
    let deadline = Instant::now() + Duration::from_secs(20);
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        if Instant::now() > deadline {
            return Err("chromedriver did not listen within 20 s".into());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok((running, format!("http://127.0.0.1:{port}")))
}
