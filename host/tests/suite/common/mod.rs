//! What the test modules share: a stream into the simulated controller, started as a user starts it.

// Some of it serves only the modules of one platform (the Unix-only ones, or the Windows one).
#![allow(dead_code)]

pub mod packets;
pub mod proxy;
#[cfg(unix)]
pub mod simulator;

use ringpod_core::kinematics::{presets, Mechanism, MultiTurn, Pose, RingPlatform};
use ringpod_core::motion::{AxisScale, StepConverter};

/// The trainer model's mechanism, its steps converter after homing (step 0 of every axis at the home pose), and
/// that position.
pub fn trainer_homed() -> (RingPlatform<f32>, StepConverter, MultiTurn<f32>) {
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let c = AxisScale::MODEL_CARRIAGE;
    let l = AxisScale::MODEL_LINEAR;
    let mut conv = StepConverter::new([c, c, c, c, l, l], m.axes());
    let home = MultiTurn::new(
        m.inverse(&Pose::from_array(presets::Preset::TrainerModel.home()).cast())
            .unwrap(),
    );
    for a in 0..6 {
        conv.set_home(a, &home, 0);
    }
    (m, conv, home)
}

/// The numbers of a JSON array (a report's pose or steps).
pub fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Starts `ringpod stream --sim --report-json --quiet ARGS` with its output piped.
pub fn spawn_sim_stream(args: &[&str]) -> std::process::Child {
    std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["stream", "--sim", "--report-json", "--quiet"])
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Starts `ringpod stream --sim ARGS` with a live source and waits until it announces the address to send to.
pub fn spawn_live_stream(
    args: &[&str],
) -> (
    std::process::Child,
    std::io::BufReader<std::process::ChildStderr>,
    String,
) {
    use std::io::BufRead;
    let mut child = spawn_sim_stream(args);
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    while !line.contains("send datagrams to") {
        line.clear();
        assert!(
            stderr.read_line(&mut line).unwrap() > 0,
            "the stream announces its address"
        );
    }
    let addr = line.trim().rsplit(' ').next().unwrap().to_owned();
    (child, stderr, addr)
}
