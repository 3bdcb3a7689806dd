//! The command line against inputs an adversary would try, one test per class of input: every one ends with a
//! clear error said once and the documented exit code, or with a correct result; none panics, hangs or succeeds
//! when its job was not done. The README's Tests section counts these classes.

use assert_cmd::Command;
use std::path::PathBuf;

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

/// A scratch folder of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ringpod-adversary-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `ringpod ARGS` and returns (exit code, stdout, stderr); a panic (exit 101) fails the test.
fn run(args: &[&str]) -> (i32, String, String) {
    let out = ringpod()
        .args(args)
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let code = out.status.code().unwrap_or(-1);
    assert!(
        code != 101 && !stderr.contains("panicked"),
        "ringpod {args:?} panicked: {stderr}"
    );
    (code, String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

/// Class: a bad rig file (syntax, unknown key, a value out of range or not finite, missing, a folder, binary bytes)
/// is said once, with the file's path, by every command that reads one.
#[test]
fn a_bad_rig_file_is_said_once_with_its_path() {
    let dir = scratch("rig");
    let good = run(&["presets", "--export", "trainer-model"]).1;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path.display().to_string()
    };
    let cases = [
        (write("syntax.toml", b"ring_radius = = 3\n"), "line 1"),
        (
            write("typo.toml", good.replace("rod_length", "rod_lenght").as_bytes()),
            "rod_lenght",
        ),
        (
            write(
                "nan.toml",
                good.replace("ring_radius = ", "ring_radius = nan #").as_bytes(),
            ),
            "ring_radius",
        ),
        (
            write(
                "huge.toml",
                good.replace("ring_radius = ", "ring_radius = 1e300 #").as_bytes(),
            ),
            "no solution",
        ),
        (write("binary.toml", &[0xff, 0xfe, 0x00, 0x80, 0x13, 0x37]), "UTF-8"),
        (dir.join("missing.toml").display().to_string(), "No such file"),
        (dir.display().to_string(), "directory"),
    ];
    let picture = dir.join("ws.svg").display().to_string();
    for (path, cause) in &cases {
        for args in [
            vec!["ik", "--geometry", path, "--pose", "0,0,0.227,0,0,0"],
            vec!["rig", "check", path],
            vec!["workspace", "--geometry", path, "--cells", "8", "--out", &picture],
            vec![
                "stream",
                "--sim",
                "--fast",
                "--quiet",
                "--geometry",
                path,
                "--motion",
                "demo",
                "--duration",
                "1",
            ],
            vec!["simulate", "--pty", "--geometry", path],
        ] {
            let (code, _, stderr) = run(&args);
            assert_ne!(code, 0, "{args:?}");
            assert!(stderr.contains(cause), "{args:?}: {stderr}");
            assert_eq!(
                stderr.matches(path.as_str()).count(),
                1,
                "{args:?}: the path once: {stderr}"
            );
            assert_eq!(stderr.matches(cause).count(), 1, "{args:?}: the cause once: {stderr}");
        }
    }
}
