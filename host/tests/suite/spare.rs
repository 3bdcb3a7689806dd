//! The spare axes 7 and 8 from the command line, against the simulated controller served on a pseudo-terminal: a
//! rig file's `[[spare]]` loaded with the rig (refused, by its key, while the rig senses a supply), a pose file's
//! `axis7` column streamed, and the steps the status counts.

#![cfg(unix)]

use crate::common::simulator::Simulator;

/// The trainer model's rig file with the supply senses off and spare axis 7 fitted (400 steps per unit).
fn rig_with_spare(senses: bool) -> String {
    let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["presets", "--export", "trainer-model"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
        + &format!(
            "\n[supervisor]\nlogic_sense = {senses}\npower_sense = {senses}\nlogic_settle_ms = 100\n\
         power_settle_ms = 200\nsupply_timeout_ms = 1000\ndriver_off_ms = 20\ndischarge_ms = 500\n\n\
         [[spare]]\nenabled = true\nsteps_per_unit = 400.0\nvelocity = 50.0\nacceleration = 500.0\n\
         travel = [-5.0, 120.0]\n"
        )
}

#[test]
fn a_rig_fits_axis_7_and_a_pose_file_moves_it() {
    let sim = Simulator::start();
    let dir = std::env::temp_dir().join(format!("ringpod-spare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sensing = dir.join("sensing.toml");
    std::fs::write(&sensing, rig_with_spare(true)).unwrap();
    let (code, _, err) = sim.ringpod(&["device", "rig", "load", sensing.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("spare[0].enabled") && err.contains("LOGIC_OK"), "{err}");

    let rig = dir.join("rig.toml");
    std::fs::write(&rig, rig_with_spare(false)).unwrap();
    let (code, _, err) = sim.ringpod(&["device", "rig", "load", rig.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(sim.ringpod(&["device", "restart"]).0, Some(0));
    let (code, out, err) = sim.ringpod(&["device", "config", "get", "spare"]);
    assert_eq!(code, Some(0), "{err}");
    let section: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(section["value"][0]["steps_per_unit"], 400.0, "{out}");
    assert_eq!(section["value"][1]["enabled"], false, "{out}");
    assert_eq!(sim.ringpod(&["device", "enable"]).0, Some(0));
    let (code, _, err) = sim.ringpod(&["device", "home"]);
    assert_eq!(code, Some(0), "{err}");

    // 25 units at 400 steps each; the last rows without a change hold it there.
    let poses = "t,x,y,z,alpha,beta,gamma,axis7\n0,0,0,0.227,0,0,0,0\n0.5,0,0,0.227,0,0,0,10\n\
                 1.0,0,0,0.227,0,0,0,25\n1.5,0,0,0.227,0,0,0,25\n";
    let file = dir.join("poses.csv");
    std::fs::write(&file, poses).unwrap();
    let (code, out, err) = sim.ringpod(&["stream", "--input", file.to_str().unwrap(), "--quiet", "--report-json"]);
    assert_eq!(code, Some(0), "{out}{err}");
    let status = sim.status();
    assert_eq!(status["spare_steps"], serde_json::json!([10_000, 0]), "{status}");
    assert_eq!(
        status["steps"],
        serde_json::json!([0, 0, 0, 0, 0, 0]),
        "the platform held its pose"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
