//! Outputs never replace an input, nor each other: every command that writes files refuses, before anything runs,
//! an output that is one of the files it reads (a rig file, a mechanism file, a motion, a drive, a cueing file) or
//! another of its outputs, and leaves every file as it was.

use std::path::{Path, PathBuf};

use assert_cmd::Command;

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

/// A copy of a file of the repository in `dir`.
fn copy(dir: &Path, from: &str, name: &str) -> PathBuf {
    let to = dir.join(name);
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(from), &to).unwrap();
    to
}

/// Runs `args` (paths as given), and asserts it failed naming the clash, with every file in `dir` as it was.
fn refused(dir: &Path, args: &[&std::ffi::OsStr], clash: &str) {
    let before: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect();
    let count = before.len();
    let out = ringpod().args(args).output().unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded: {said}");
    assert!(said.contains(clash), "{args:?}: {said}");
    for (p, bytes) in before {
        assert_eq!(std::fs::read(&p).unwrap(), bytes, "{args:?} changed {}", p.display());
    }
    let files = std::fs::read_dir(dir).unwrap().count();
    assert_eq!(files, count, "{args:?} left a file");
}

#[test]
fn an_output_that_is_an_input_or_another_output_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let rig = d.join("rig.toml");
    let exported = ringpod()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    assert!(exported.status.success());
    std::fs::write(&rig, &exported.stdout).unwrap();
    let drive = copy(d, "docs/drive-telemetry.csv", "drive.csv");
    let mechanism = copy(d, "docs/dynamics/four-bar.toml", "mech.toml");
    let motion = d.join("in.csv");
    std::fs::write(
        &motion,
        "t,x,y,z,alpha,beta,gamma\n0,0,0,0.227,0,0,0\n1,0,0,0.23,0,0,0\n",
    )
    .unwrap();
    let (s_svg, x, g_png) = (d.join("s.svg"), d.join("x.pcap"), d.join("g.png"));
    let s = |v: &str| std::ffi::OsString::from(v);
    let cases: Vec<(Vec<std::ffi::OsString>, &str)> = vec![
        (
            vec![
                s("stream"),
                s("--sim"),
                s("--fast"),
                s("--input"),
                motion.clone().into(),
                s("--geometry"),
                rig.clone().into(),
                s("--record"),
                rig.clone().into(),
            ],
            "is also an input",
        ),
        (
            vec![
                s("dynamics"),
                s("--file"),
                mechanism.clone().into(),
                s("--table"),
                mechanism.clone().into(),
            ],
            "is also an input",
        ),
        (
            vec![
                s("dynamics"),
                s("--input"),
                motion.clone().into(),
                s("--table"),
                motion.clone().into(),
            ],
            "is also an input",
        ),
        (
            vec![
                s("cue"),
                s("--input"),
                drive.clone().into(),
                s("--out"),
                s_svg.clone().into(),
                s("--plot"),
                s_svg.clone().into(),
            ],
            "is also another output",
        ),
        (
            vec![
                s("dynamics"),
                s("--table"),
                d.join("t.png").into(),
                s("--plot"),
                d.join("t.png").into(),
            ],
            "is also another output",
        ),
        (
            vec![
                s("gram"),
                s("--step"),
                s("0.01"),
                s("--out"),
                g_png.clone().into(),
                s("--table"),
                g_png.clone().into(),
            ],
            "is also another output",
        ),
        (
            vec![
                s("stream"),
                s("--sim"),
                s("--fast"),
                s("--udp"),
                s("127.0.0.1:0"),
                s("--record"),
                x.clone().into(),
                s("--capture"),
                x.clone().into(),
            ],
            "is also another output",
        ),
    ];
    for (args, clash) in cases {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        refused(d, &args, clash);
    }
}
