//! Every case of the reference files (`tests/reference/*.json`, copied from the project's shared reference

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]
//! folder) and the published examples of KINEMATICS.md, reproduced within their tolerances.

use ringpod_core::kinematics::{
    presets, Branch, Check, KinematicsError, Mechanism, Pose, Reach, RingPlatform, ToolCarrier,
};
use serde::Deserialize;

#[derive(Deserialize)]
struct RingFile {
    mechanism: String,
    tolerance: f64,
    geometry: RingGeometryJson,
    cases: Vec<RingCase>,
}

#[derive(Deserialize)]
struct RingGeometryJson {
    ring_radius: f64,
    rod_length: f64,
    platform_points: Vec<[f64; 3]>,
}

#[derive(Deserialize)]
struct RingCase {
    pose: [f64; 6],
    actuators: Option<[f64; 6]>,
}

fn load<T: for<'de> Deserialize<'de>>(name: &str) -> T {
    let path = format!("{}/tests/reference/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Difference of two angles modulo a turn, in (-pi, pi].
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

fn check_ring_file(file: &str, preset: &ringpod_core::kinematics::RingGeometry, ring_axes: usize) {
    let reference: RingFile = load(file);
    assert_eq!(reference.mechanism, preset.name);
    // The preset is the reference geometry.
    assert_eq!(reference.geometry.ring_radius, preset.ring_radius);
    assert!((reference.geometry.rod_length - preset.rod_length).abs() < 1e-15);
    for (chain, point) in preset.chains().iter().zip(&reference.geometry.platform_points) {
        assert_eq!(&chain.platform_point, point);
    }
    let mechanism = RingPlatform::<f64>::new(preset);
    for case in &reference.cases {
        let pose = Pose::from_array(case.pose);
        match (case.actuators, mechanism.inverse(&pose)) {
            (Some(expected), Ok(q)) => {
                for (i, (got, want)) in q.0.iter().zip(expected).enumerate() {
                    let err = if i < ring_axes {
                        angle_diff(*got, want)
                    } else {
                        got - want
                    };
                    assert!(
                        err.abs() <= reference.tolerance,
                        "{file} pose {:?} axis {i}: got {got}, want {want}",
                        case.pose
                    );
                }
            }
            (None, Err(KinematicsError::Unreachable { .. })) => {}
            (want, got) => panic!("{file} pose {:?}: want {want:?}, got {got:?}", case.pose),
        }
    }
}

#[test]
fn trainer_ch5_reference_cases() {
    check_ring_file("trainer-ch5.json", &presets::TRAINER_CH5, 4);
}

#[test]
fn rotopod_ch4_reference_cases() {
    check_ring_file("rotopod-ch4.json", &presets::ROTOPOD_CH4, 6);
}

#[test]
fn trainer_ch5_home_carriages_and_lengths() {
    // KINEMATICS.md 2.1: B1 = (-1, -2.8284), B2 = (1, -2.8284), B3 = (1.3416, 2.6833), B4 = (-1.3416, 2.6833).
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let q = m.inverse(&Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0)).unwrap();
    let expected = [(-1.0, -2.8284), (1.0, -2.8284), (1.3416, 2.6833), (-1.3416, 2.6833)];
    for (qi, (bx, by)) in q.0.iter().zip(expected) {
        assert!((3.0 * qi.cos() - bx).abs() < 1e-4 && (3.0 * qi.sin() - by).abs() < 1e-4);
    }
    assert!((angle_diff(q.0[0], 4.3726)).abs() < 1e-4, "q1 = -1.9106 + 2pi");
    assert!((q.0[4] - 1.258410).abs() < 5e-6 && (q.0[5] - 1.258410).abs() < 5e-6);
}

#[test]
fn trainer_ch4_radial_length_with_short_rods() {
    // KINEMATICS.md 2.1: with L = 1 and z = 0.172 the radial lengths are sqrt((3 - sqrt 5)^2 + 0.172^2) = 0.783.
    let g = ringpod_core::kinematics::RingGeometry::new(
        "ch4-short",
        3.0,
        1.0,
        presets::TRAINER_CH5.chains(),
        presets::TRAINER_CH5.limits,
    )
    .unwrap();
    let q = RingPlatform::<f64>::new(&g)
        .inverse(&Pose::new(0.0, 0.0, 0.172, 0.0, 0.0, 0.0))
        .unwrap();
    let want = ((3.0 - 5f64.sqrt()).powi(2) + 0.172f64.powi(2)).sqrt();
    assert!((q.0[4] - want).abs() < 1e-12 && (want - 0.783).abs() < 5e-4);
}

#[test]
fn rotopod_published_values_match_the_formulas() {
    // KINEMATICS.md 2.2: q ~ (5.508, 0.775, 1.319, 2.869, 3.414, 4.964) at (0, 0, 0.7, 0, 0, 0).
    let q = RingPlatform::<f64>::new(&presets::ROTOPOD_CH4)
        .inverse(&Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0))
        .unwrap();
    for (got, want) in q.0.iter().zip([5.508, 0.775, 1.319, 2.869, 3.414, 4.964]) {
        assert!(angle_diff(*got, want).abs() < 1e-3, "{got} vs {want}");
    }
}

#[test]
fn trainer_ch5_wrench_determinant() {
    // KINEMATICS.md 4.5: |det| = 8.065 at (0, 0, 1, 0, 0, 0); the source's -3.945 is a sign typo in one row.
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let pose = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
    let q = m.inverse(&pose).unwrap();
    let det = m.wrench_matrix(&pose, &q).determinant();
    assert!((det.abs() - 8.065).abs() < 1e-3, "det = {det}");
}

#[derive(Deserialize)]
struct ToolFile {
    tolerance_deg: f64,
    tolerance_mm: f64,
    cases: Vec<ToolCase>,
}

#[derive(Deserialize)]
struct ToolCase {
    alpha: f64,
    beta: f64,
    x: f64,
    y: f64,
    z: f64,
    q1: f64,
    q2: [f64; 2],
    q4: [f64; 2],
    q5: f64,
}

#[test]
fn tool5_reference_cases_both_branches() {
    let reference: ToolFile = load("tool5-ex.json");
    for case in &reference.cases {
        let pose = Pose::new(case.x / 1e3, case.y / 1e3, case.z / 1e3, case.alpha, case.beta, 0.0);
        for (k, branch) in [Branch::Minus, Branch::Plus].into_iter().enumerate() {
            let m = ToolCarrier::<f64>::new(&presets::TOOL5_EX.with_branches(branch, branch));
            let q = m.inverse(&pose).unwrap();
            assert!((q.0[0] * 1e3 - case.q1).abs() <= reference.tolerance_mm);
            assert!(
                (q.0[1].to_degrees() - case.q2[k]).abs() <= reference.tolerance_deg,
                "q2 {}",
                q.0[1].to_degrees()
            );
            assert!(
                (q.0[3].to_degrees() - case.q4[k]).abs() <= reference.tolerance_deg,
                "q4 {}",
                q.0[3].to_degrees()
            );
            assert!((q.0[4].to_degrees() - case.q5).abs() <= reference.tolerance_deg);
        }
    }
}

#[test]
fn tool5_published_minutes() {
    // KINEMATICS.md 2.3, in degrees and minutes: 40deg39' / 139deg21'; 36deg12' / 143deg48'.
    let m = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    let dm = |d: f64, m: f64| d + m / 60.0;
    let q = m.inverse(&Pose::new(0.0, 0.0, 0.4, 0.0, 0.0, 0.0)).unwrap();
    assert!((q.0[1].to_degrees() - dm(40.0, 39.0)).abs() < 1.0 / 60.0);
    let q = m
        .inverse(&Pose::new(0.0, 0.0, 0.4, 0.0, 30f64.to_radians(), 0.0))
        .unwrap();
    assert!((q.0[0] - 0.150).abs() < 1e-9 && (q.0[1].to_degrees() - dm(36.0, 12.0)).abs() < 1.0 / 60.0);
    let plus = ToolCarrier::<f64>::new(&presets::TOOL5_EX.with_branches(Branch::Plus, Branch::Plus));
    let q = plus
        .inverse(&Pose::new(0.0, 0.0, 0.4, 0.0, 30f64.to_radians(), 0.0))
        .unwrap();
    assert!((q.0[1].to_degrees() - dm(143.0, 48.0)).abs() < 1.0 / 60.0);
}

#[test]
fn tool5_has_no_yaw() {
    let m = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    assert_eq!(
        m.inverse(&Pose::new(0.0, 0.0, 0.4, 0.0, 0.0, 0.1)),
        Err(KinematicsError::OutsideMobility)
    );
}

#[test]
fn unreachable_reasons_are_specific() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    assert_eq!(
        m.inverse(&Pose::new(0.0, 0.0, 1.4, 0.0, 0.0, 0.0)),
        Err(KinematicsError::Unreachable {
            chain: 0,
            reason: Reach::Height
        })
    );
    assert!(matches!(
        m.inverse(&Pose::new(0.0, 0.0, 1.0, 0.0, -0.087266463, 0.0)),
        Err(KinematicsError::Unreachable {
            reason: Reach::Ring,
            ..
        })
    ));
    // Chain 1's joint a1 = (-1, -2) moved onto the ring axis.
    assert_eq!(
        m.inverse(&Pose::new(1.0, 2.0, 1.0, 0.0, 0.0, 0.0))
            .map(|_| ())
            .unwrap_err(),
        KinematicsError::Unreachable {
            chain: 0,
            reason: Reach::Centre
        }
    );
    let tool = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    assert!(matches!(
        tool.inverse(&Pose::new(0.0, 0.0, 1.5, 0.0, 0.0, 0.0)),
        Err(KinematicsError::Unreachable {
            reason: Reach::Dyad,
            ..
        })
    ));
}

#[test]
fn home_checks_report_margins() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let (_, report) = m.inverse_checked(&Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0)).unwrap();
    // 4 carriages at -109.5, -70.5, 63.4 and 116.6 degrees: the largest gaps are 134 degrees, beyond the source's 120.
    let spacing = report.margin(Check::CarriageSpacing).unwrap();
    assert!((spacing - (120f64 - 133.9).to_radians()).abs() < 2e-3, "{spacing}");
    assert!(report.margin(Check::RodCrossing).unwrap() > 0.0);
    assert!(report.passes(Check::Reach) && report.passes(Check::JointCones) && report.passes(Check::Stability));
    assert!(report.singularity_index > 0.0 && report.singularity_index <= 1.0);
}

/// The four assemblies (each dyad on either branch) at the source's third example: `q2` from the B-side branch and
/// `q4` from the D-side one, whatever the other dyad takes, and the drives the dyads share equal.
#[test]
fn tool5_mixed_branches_take_each_dyads_own() {
    let reference: ToolFile = load("tool5-ex.json");
    let case = &reference.cases[2];
    let pose = Pose::new(case.x / 1e3, case.y / 1e3, case.z / 1e3, case.alpha, case.beta, 0.0);
    let base = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    for (kb, b) in [Branch::Minus, Branch::Plus].into_iter().enumerate() {
        for (kd, d) in [Branch::Minus, Branch::Plus].into_iter().enumerate() {
            let m = base.with_branches([b, d]);
            assert_eq!(m.branches(), [b, d]);
            let q = m.inverse(&pose).unwrap();
            assert!((q.0[1].to_degrees() - case.q2[kb]).abs() <= reference.tolerance_deg);
            assert!((q.0[3].to_degrees() - case.q4[kd]).abs() <= reference.tolerance_deg);
            assert!((q.0[0] * 1e3 - case.q1).abs() <= reference.tolerance_mm);
        }
    }
}

/// The X carriage's stroke (`+-0.5` m, assumed) bounds `q1 = x + L1 sin(beta)`: the reach check fails past it,
/// and a tilt moves the carriage as much as the tool.
#[test]
fn tool5_stroke_bounds_the_carriage() {
    let m = ToolCarrier::<f64>::new(&presets::TOOL5_EX);
    let at = |x: f64, beta: f64| m.inverse_checked(&Pose::new(x, 0.0, 0.4, 0.0, beta, 0.0)).unwrap().1;
    let inside = at(0.45, 0.0);
    assert!(inside.all_pass());
    assert!((inside.margin(Check::Reach).unwrap() - 0.05).abs() < 1e-12);
    let past = at(0.55, 0.0);
    assert_eq!(past.first_failure(), Some(Check::Reach));
    assert!((past.margin(Check::Reach).unwrap() + 0.05).abs() < 1e-12);
    // q1 = 0.45 + 0.3 sin(30 deg) = 0.6: out, though x alone is inside.
    assert_eq!(at(0.45, 30f64.to_radians()).first_failure(), Some(Check::Reach));
    assert!(at(-0.45, 0.0).all_pass());
    assert_eq!(at(-0.55, 0.0).first_failure(), Some(Check::Reach));
}
