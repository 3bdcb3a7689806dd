//! The commands that only compute end on a stopping signal with 128 + its number, also when started the way a
//! script starts a background job (`ringpod workspace ... &`), where the shell hands them SIGINT ignored.

#![cfg(unix)]

use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use nix::sys::signal::{kill, signal, SigHandler, Signal};
use nix::unistd::Pid;

/// Starts `ringpod ARGS` with SIGINT ignored (as `cmd &` in a script does, and as `exec` keeps it), sends SIGINT
/// once it runs, and gives back its exit code and what it said on standard error. SIGINT is sent again every
/// half second: one sent before the command installed its handlers is ignored, as the shell meant.
fn interrupted(args: &[&str], dir: &std::path::Path) -> (Option<i32>, String) {
    let mut command = Command::new(assert_cmd::cargo::cargo_bin("ringpod"));
    command
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    // SAFETY: between fork and exec only `signal`, which is async-signal-safe, runs.
    unsafe {
        command.pre_exec(|| {
            signal(Signal::SIGINT, SigHandler::SigIgn)
                .map(|_| ())
                .map_err(std::io::Error::from)
        });
    }
    let mut child = command.spawn().unwrap();
    let pid = Pid::from_raw(child.id() as i32);
    std::thread::sleep(Duration::from_millis(300));
    let deadline = Instant::now() + Duration::from_secs(8);
    let mut next = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`ringpod {}` still runs 8 s after SIGINT", args.join(" "));
        }
        if Instant::now() >= next {
            let _ = kill(pid, Signal::SIGINT);
            next = Instant::now() + Duration::from_millis(500);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut said = String::new();
    let _ = std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut said);
    (status.code(), said)
}

/// `workspace`, `gram` and `rig design` with work for minutes (a fine grid, a long search), started with SIGINT
/// ignored: SIGINT ends each within seconds with exit 130 and a line naming it, and leaves no picture behind.
#[test]
fn the_computing_commands_end_on_sigint_even_started_with_it_ignored() {
    let dir = std::env::temp_dir().join(format!("ringpod-signals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let template = dir.join("rig.toml");
    let export = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    assert!(export.status.success());
    std::fs::write(&template, export.stdout).unwrap();
    let template = template.to_str().unwrap();
    let cases: [&[&str]; 3] = [
        &["workspace", "--cells", "2000", "--quiet", "--out", "workspace.svg"],
        &["gram", "--step", "0.0005", "--out", "gram.png"],
        &["rig", "design", "--starts", "10000", "--steps", "100000", template],
    ];
    for args in cases {
        let (code, said) = interrupted(args, &dir);
        assert_eq!(code, Some(130), "`ringpod {}`: {said}", args.join(" "));
        assert!(said.contains("interrupted by Ctrl-C (SIGINT)"), "{said}");
    }
    assert!(!dir.join("workspace.svg").exists() && !dir.join("gram.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `device home` waits for the homing's end (seconds in real time); started with SIGINT ignored, SIGINT still ends
/// the wait with exit 130 (the controller goes on homing, as it does when the default action ends the command).
#[test]
fn a_device_command_that_waits_ends_on_sigint_even_started_with_it_ignored() {
    use std::io::BufRead;
    let mut simulator = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["simulate", "--pty"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut path = String::new();
    std::io::BufReader::new(simulator.stdout.take().unwrap())
        .read_line(&mut path)
        .unwrap();
    let path = path.trim().to_owned();
    let enable = Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["device", "enable", "--port", &path])
        .output()
        .unwrap();
    assert!(enable.status.success(), "{}", String::from_utf8_lossy(&enable.stderr));
    // Past the supplies' settling, so that the homing starts and the command waits for its end.
    std::thread::sleep(Duration::from_millis(800));
    let (code, said) = interrupted(&["device", "home", "--port", &path], &std::env::temp_dir());
    let _ = simulator.kill();
    let _ = simulator.wait();
    assert_eq!(code, Some(130), "{said}");
    assert!(said.contains("interrupted by Ctrl-C (SIGINT)"), "{said}");
}
