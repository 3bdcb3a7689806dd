//! Files saved on Windows end their lines in CRLF (Notepad, Excel's "CSV UTF-8" with its byte-order mark): rig
//! files, pose files, telemetry tables and cueing files read exactly as their LF copies do.

use assert_cmd::Command;

fn dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("ringpod-crlf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn crlf(text: &str) -> String {
    text.replace("\r\n", "\n").replace('\n', "\r\n")
}

/// Runs ringpod on `file` written twice, with LF and with CRLF (and a BOM for CSV), and returns both stdouts.
fn both(name: &str, text: &str, args: &dyn Fn(&str) -> Vec<String>) -> (String, String) {
    let lf = dir().join(format!("lf-{name}"));
    let cr = dir().join(format!("crlf-{name}"));
    std::fs::write(&lf, text.replace("\r\n", "\n")).unwrap();
    let bom = if name.ends_with(".csv") { "\u{feff}" } else { "" };
    std::fs::write(&cr, format!("{bom}{}", crlf(text))).unwrap();
    assert!(std::fs::read(&cr).unwrap().windows(2).any(|w| w == b"\r\n"));
    let run = |path: &std::path::Path| {
        let out = Command::cargo_bin("ringpod")
            .unwrap()
            .args(args(path.to_str().unwrap()))
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    (run(&lf), run(&cr))
}

#[test]
fn a_crlf_rig_file_checks_as_its_lf_copy() {
    let rig = Command::cargo_bin("ringpod")
        .unwrap()
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    let text = String::from_utf8(rig.stdout).unwrap();
    let (lf, cr) = both("rig.toml", &text, &|p| {
        vec!["rig".into(), "check".into(), p.into(), "--json".into()]
    });
    let (lf, cr): (serde_json::Value, serde_json::Value) =
        (serde_json::from_str(&lf).unwrap(), serde_json::from_str(&cr).unwrap());
    assert_eq!(lf["valid"], true, "{lf}");
    assert_eq!(lf["drivable"], true, "{lf}");
    // Everything read from the file is the same (the report does not name the file).
    assert_eq!(lf, cr);
}

#[test]
fn a_crlf_pose_file_streams_every_row_as_its_lf_copy() {
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma\n");
    for i in 0..200 {
        let t = f64::from(i) * 0.005;
        // About the trainer model's home height (z = 0.227 m), yawing.
        csv += &format!("{t},0,0,0.227,0,0,{}\n", 0.2 * (t * 3.0).sin());
    }
    let args = |p: &str| -> Vec<String> {
        ["stream", "--sim", "--fast", "--quiet", "--report-json", "--input", p]
            .map(String::from)
            .to_vec()
    };
    let (lf, cr) = both("poses.csv", &csv, &args);
    let (lf, cr): (serde_json::Value, serde_json::Value) =
        (serde_json::from_str(&lf).unwrap(), serde_json::from_str(&cr).unwrap());
    assert_eq!(lf["setpoints_sent"], 200, "{lf}");
    assert_eq!(lf["setpoints_applied"], 200, "{lf}");
    assert_eq!(cr["setpoints_sent"], lf["setpoints_sent"], "{cr}");
    assert_eq!(cr["setpoints_applied"], lf["setpoints_applied"], "{cr}");
    assert_eq!(cr["input_errors"], lf["input_errors"]);
}
