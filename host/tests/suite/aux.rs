//! The auxiliary outputs from the command line: `device aux N on|off` against the simulated controller
//! served on a pseudo-terminal, and a pose file's `aux1`, `aux2` columns streamed into it.

#![cfg(unix)]

use crate::common::simulator::Simulator;

/// Refused unpowered and before homing with the supervisor's reason; on when Ready, reported in the status; off
/// again by the command; both off after an e-stop-free disable; a wrong number is a usage error.
#[test]
fn device_aux_switches_only_where_the_supervisor_allows() {
    let sim = Simulator::start();
    let (code, _, err) = sim.ringpod(&["device", "aux", "1", "on"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("not possible in the current state"), "{err}");
    let (code, _, err) = sim.ringpod(&["device", "aux", "3", "on"]);
    assert!(code == Some(1) && err.contains("usage: `device aux N on|off`"), "{err}");
    let (code, _, err) = sim.ringpod(&["device", "aux", "1", "up"]);
    assert!(code == Some(1) && err.contains("usage"), "{err}");
    assert_eq!(sim.ringpod(&["device", "enable"]).0, Some(0));
    let (code, _, err) = sim.ringpod(&["device", "home"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(sim.status()["state"], "Ready");
    let (code, out, err) = sim.ringpod(&["device", "aux", "2", "on"]);
    assert_eq!(code, Some(0), "{err}");
    let status: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(status["aux"], 2, "AUX2 on: {out}");
    assert_eq!(sim.ringpod(&["device", "aux", "1", "on"]).0, Some(0));
    assert_eq!(sim.status()["aux"], 3);
    assert_eq!(sim.ringpod(&["device", "aux", "2", "off"]).0, Some(0));
    assert_eq!(sim.status()["aux"], 1);
    let (code, out, _) = sim.ringpod(&["device", "disable"]);
    assert_eq!(code, Some(0));
    let status: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(status["aux"], 0, "a disable switches them off: {out}");
}

/// A pose file with `aux1` and `aux2` columns: the outputs follow its rows while it streams (the run record's
/// `aux1`, `aux2` columns show them) and stay as its last row left them; a value other than 0 or 1 is
/// an input error of its row.
#[test]
fn a_pose_file_switches_them_as_it_streams() {
    let sim = Simulator::start();
    let dir = std::env::temp_dir().join(format!("ringpod-aux-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut csv = String::from("t,x,y,z,alpha,beta,gamma,aux1,aux2\n");
    for k in 0..=200 {
        let t = k as f64 * 0.01;
        // AUX1 on for the middle second, AUX2 on from 1.5 s to the end.
        let aux1 = u8::from((0.5..1.5).contains(&t));
        let aux2 = u8::from(t >= 1.5);
        csv += &format!(
            "{t:.3},0,0,{:.6},0,0,0,{aux1},{aux2}\n",
            0.227 + 0.003 * (t * 3.0).sin()
        );
    }
    csv += "2.5,0,0,0.227,0,0,0,2,0\n";
    let file = dir.join("aux.csv");
    std::fs::write(&file, &csv).unwrap();
    let record = dir.join("record.csv");
    let (code, out, err) = sim.ringpod(&[
        "stream",
        "--input",
        file.to_str().unwrap(),
        "--quiet",
        "--report-json",
        "--record",
        record.to_str().unwrap(),
    ]);
    let report: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}{err}"));
    assert_eq!(report["state"], "Ready", "{out}{err}");
    assert_eq!(report["counts_agree"], true, "{out}");
    let errors = report["input_errors"].as_array().cloned().unwrap_or_default();
    assert!(
        errors
            .iter()
            .any(|e| e["line"] == 203 && e["reason"].as_str().unwrap_or("").contains("must be 0 or 1")),
        "the row with aux1 = 2 is refused: {out}"
    );
    let _ = code;
    // The recorded telemetry: the outputs column's bits 3 and 4 over time.
    let text = std::fs::read_to_string(&record).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{name} in {header:?}"))
    };
    let (aux1, aux2, state) = (col("aux1"), col("aux2"), col("state"));
    let seen: Vec<u64> = lines
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let bit = |k: usize| f[k].parse::<u64>().unwrap();
            (f[state] == "Running").then(|| bit(aux1) | bit(aux2) << 1)
        })
        .collect();
    let changes: Vec<u64> = seen.iter().copied().fold(Vec::new(), |mut v, a| {
        if v.last() != Some(&a) {
            v.push(a);
        }
        v
    });
    assert_eq!(changes, [0, 1, 2], "off, AUX1, then AUX2 only, while running: {seen:?}");
    assert_eq!(sim.status()["aux"], 2, "the last row left AUX2 on");
    let _ = std::fs::remove_dir_all(&dir);
}
