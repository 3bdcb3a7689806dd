//! The followed pose is where the counted steps put the platform: a `--motion yaw` run (1.9 rad/s, faster than the
//! carriages keep up with) recorded at every control tick, each row's followed pose checked against the steps the
//! same row counts.

use ringpod_core::kinematics::Pose;

#[test]
fn the_followed_pose_of_every_row_is_its_counted_steps() {
    let record = std::env::temp_dir().join(format!("ringpod-followed-{}.csv", std::process::id()));
    let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args([
            "stream",
            "--sim",
            "--fast",
            "--quiet",
            "--report-json",
            "--motion",
            "yaw",
            "--duration",
            "4",
        ])
        .args(["--record-hz", "1000", "--record"])
        .arg(&record)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["record"]["unsolved"], 0, "{report}");
    let text = std::fs::read_to_string(&record).unwrap();
    let _ = std::fs::remove_file(&record);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let pose_cols = ["x", "y", "z", "alpha", "beta", "gamma"].map(col);
    let step_cols = ["steps_1", "steps_2", "steps_3", "steps_4", "steps_5", "steps_6"].map(col);
    let (state, cmd_gamma) = (col("state"), col("cmd_gamma"));
    let (m, conv, mut q) = crate::common::trainer_homed();
    let (mut running, mut worst, mut lag) = (0, 0i64, 0.0f64);
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        if f[state] != "Running" {
            continue;
        }
        running += 1;
        let pose = pose_cols.map(|c| f[c].parse::<f32>().unwrap());
        let counted = step_cols.map(|c| f[c].parse::<i64>().unwrap());
        // Row by row, so that the carriages' whole turns are tracked as the device tracks them.
        q.inverse_near(&m, &Pose::from_array(pose)).unwrap();
        let steps = conv.to_steps(&q);
        for a in 0..6 {
            worst = worst.max((steps[a] - counted[a]).abs());
        }
        let d = (f[cmd_gamma].parse::<f64>().unwrap() - f64::from(pose[5])).rem_euclid(std::f64::consts::TAU);
        lag = lag.max(d.min(std::f64::consts::TAU - d));
    }
    assert!(running > 3_000, "{running} rows while running");
    // The followed pose gives back the counted steps, to within the f32 solve's rounding of a step.
    assert!(
        worst <= 2,
        "a followed pose is {worst} steps from its row's counted steps"
    );
    // And it is not the commanded pose: the carriages trail the 1.9 rad/s yaw.
    assert!(
        lag > 0.01,
        "the followed yaw never trails the commanded one (at most {lag} rad)"
    );
}
