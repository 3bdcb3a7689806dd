use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use proptest::prelude::*;
use ringpod_core::kinematics::Pose;

use super::*;

/// ringpod's base frame (x forward, y left, z up) in OpenXR's (x right, y up, z back).
fn to_openxr() -> Matrix3<f64> {
    Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0)
}

/// What OXRMC makes of the six values: DirectXMath's `XMQuaternionRotationRollPitchYaw(p, y, r)` is roll about z
/// first, then pitch about x, then yaw about y; the translation `(sway, heave, -surge) / 1000` is rotated by it.
fn oxrmc_reads(tracker: Tracker, d: &SixDof) -> (Matrix3<f64>, Vector3<f64>) {
    let (p, y, r) = match tracker {
        Tracker::Flypt => (d.pitch, d.yaw, -d.roll),
        Tracker::Srs => (-d.pitch, d.yaw, d.roll),
    };
    let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), y.to_radians())
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p.to_radians())
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), r.to_radians());
    let t = q * Vector3::new(d.sway / 1000.0, d.heave / 1000.0, -d.surge / 1000.0);
    (*q.to_rotation_matrix().matrix(), t)
}

fn pose(p: [f64; 6]) -> Pose<f64> {
    Pose::from_array(p)
}

#[test]
fn reference_values_in_the_files_units_and_signs() {
    let home = pose([0.0, 0.0, 0.3, 0.0, 0.0, 0.0]);
    // 30 degrees to the left (counter-clockwise from above), 10 mm forward and 5 mm up, about the platform origin.
    let d = six_dof(
        Tracker::Flypt,
        &pose([0.01, 0.0, 0.305, 0.0, 0.0, std::f64::consts::FRAC_PI_6]),
        &home,
        [0.0; 3],
    );
    assert!((d.yaw - 30.0).abs() < 1e-9, "{d:?}");
    // In the rig's own (yawed) axes, 10 mm forward in the base frame is partly to the right.
    assert!(
        (d.surge - 10.0 * std::f64::consts::FRAC_PI_6.cos()).abs() < 1e-6
            && (d.sway - 10.0 * std::f64::consts::FRAC_PI_6.sin()).abs() < 1e-6
    );
    assert!((d.heave - 5.0).abs() < 1e-9);
    // Nose up is -beta in ringpod, +pitch for FlyPT, -pitch for SimRacingStudio; roll right (alpha > 0) likewise.
    let up = pose([0.0, 0.0, 0.3, 0.1, -0.2, 0.0]);
    let f = six_dof(Tracker::Flypt, &up, &home, [0.0; 3]);
    let s = six_dof(Tracker::Srs, &up, &home, [0.0; 3]);
    assert!((f.pitch - 0.2f64.to_degrees()).abs() < 1e-9 && (f.roll - 0.1f64.to_degrees()).abs() < 1e-9);
    assert!(
        (s.pitch + f.pitch).abs() < 1e-9 && (s.roll + f.roll).abs() < 1e-9,
        "{s:?} {f:?}"
    );
    // At home everything is zero, wherever the centre is.
    assert_eq!(
        six_dof(Tracker::Flypt, &home, &home, [0.1, 0.2, 0.5]),
        SixDof::default()
    );
    // A multi-turn yaw is an angle to the reader.
    let turned = six_dof(
        Tracker::Flypt,
        &pose([0.0, 0.0, 0.3, 0.0, 0.0, 4.0 * std::f64::consts::PI + 0.1]),
        &home,
        [0.0; 3],
    );
    assert!((turned.yaw - 0.1f64.to_degrees()).abs() < 1e-9);
}

#[test]
fn a_pitch_about_a_centre_above_the_platform_moves_it_back() {
    // The centre 0.5 m above the platform origin; nose up by 0.1 rad (beta = -0.1) about the origin swings the centre
    // backwards by 0.5 sin 0.1 in the base frame.
    let home = pose([0.0; 6]);
    let d = six_dof(
        Tracker::Flypt,
        &pose([0.0, 0.0, 0.0, 0.0, -0.1, 0.0]),
        &home,
        [0.0, 0.0, 0.5],
    );
    let (_, t) = oxrmc_reads(Tracker::Flypt, &d);
    // OpenXR's z is back.
    assert!((t.z - 0.5 * 0.1f64.sin()).abs() < 1e-9, "{t:?}");
    assert!((t.y - 0.5 * (0.1f64.cos() - 1.0)).abs() < 1e-9);
}

#[test]
fn the_bytes_are_six_little_endian_doubles_in_the_readers_order() {
    let d = SixDof {
        sway: 1.0,
        surge: 2.0,
        heave: 3.0,
        yaw: 4.0,
        roll: 5.0,
        pitch: 6.0,
    };
    let b = d.to_bytes();
    assert_eq!(&b[0..8], &1.0f64.to_le_bytes());
    assert_eq!(&b[40..48], &6.0f64.to_le_bytes());
    assert_eq!(SixDof::from_bytes(&b), d);
}

#[test]
fn names_are_the_ones_oxrmc_opens() {
    assert_eq!(Tracker::Flypt.mapping_name(), r"Local\motionRigPose");
    assert_eq!(Tracker::Srs.mapping_name(), r"Local\SimRacingStudioMotionRigPose");
}

#[cfg(not(windows))]
#[test]
fn off_windows_it_is_refused_by_name() {
    let e = Compensation::open(Tracker::Flypt, pose([0.0; 6]), [0.0; 3])
        .err()
        .unwrap();
    assert!(
        e.to_string().contains(r"Local\motionRigPose") && e.to_string().contains("Windows"),
        "{e}"
    );
}

proptest! {
    /// What OXRMC reconstructs is the centre of rotation's pose relative to home, in OpenXR's frame, for both
    /// trackers: orientation and position.
    #[test]
    fn the_reader_reconstructs_the_centres_pose(
        x in -0.05..0.05f64, y in -0.05..0.05f64, z in 0.25..0.35f64,
        alpha in -0.35..0.35f64, beta in -0.35..0.35f64, gamma in -7.0..7.0f64,
        cx in -0.3..0.3f64, cy in -0.3..0.3f64, cz in -0.2..0.8f64,
        srs: bool,
    ) {
        let tracker = if srs { Tracker::Srs } else { Tracker::Flypt };
        let home = pose([0.0, 0.0, 0.3, 0.0, 0.0, 0.0]);
        let p = pose([x, y, z, alpha, beta, gamma]);
        let c = Vector3::new(cx, cy, cz);
        let (r, t) = oxrmc_reads(tracker, &six_dof(tracker, &p, &home, [cx, cy, cz]));
        let m = to_openxr();
        let want_r = m * p.rotation() * m.transpose();
        let want_t = m * ((p.rotation() * c + p.position()) - (c + home.position()));
        prop_assert!((r - want_r).abs().max() < 1e-9, "{r} vs {want_r}");
        prop_assert!((t - want_t).abs().max() < 1e-9, "{t} vs {want_t}");
    }
}
