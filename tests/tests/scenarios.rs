//! Runs every scenario file under `tests/scenarios/` against the controller core and the simulated plant.

use std::path::PathBuf;

#[test]
fn every_scenario_file_passes() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    files.sort();
    assert!(files.len() >= 9, "scenario files found: {}", files.len());
    let mut failures = Vec::new();
    for path in &files {
        let scenario = ringpod_tests::scenario::load(path).unwrap();
        match ringpod_tests::scenario::run(&scenario) {
            Ok(report) => println!(
                "ok   {} ({} setpoints)",
                path.file_name().unwrap().to_string_lossy(),
                report.sent
            ),
            Err(e) => failures.push(format!("{}: {e}", path.display())),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
