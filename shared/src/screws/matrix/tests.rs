//! The pairs against finite differences of their transforms, the paper's printed tables where they are right, the
//! initial guess, and a spatial loop of several-variable pairs closed, moved and differentiated.

use nalgebra::{Matrix4, Vector3};

use super::*;

const PAIRS: [Joint; 6] = [
    Joint::Revolute,
    Joint::Prismatic,
    Joint::Screw { pitch: 0.004 },
    Joint::Cylindrical,
    Joint::Hooke,
    Joint::Spherical,
];

const Q: [f64; 3] = [0.7, 1.1, -0.4];

fn is_rigid(a: &Matrix4<f64>) -> bool {
    let l = a.fixed_view::<3, 3>(1, 1).into_owned();
    let first_row = a.fixed_view::<1, 4>(0, 0).into_owned();
    (l.transpose() * l - nalgebra::Matrix3::identity()).amax() < 1e-14
        && (l.determinant() - 1.0).abs() < 1e-14
        && (first_row - nalgebra::RowVector4::new(1.0, 0.0, 0.0, 0.0)).amax() == 0.0
}

#[test]
fn every_pair_is_a_rigid_motion_whose_generators_are_its_derivatives() -> Result<(), LoopError> {
    let h = 1e-6;
    for joint in PAIRS {
        let n = joint.variables();
        let a = joint.transform(&Q[..n]);
        assert!(is_rigid(&a), "{joint:?}");
        for k in 0..n {
            let (mut up, mut down) = (Q, Q);
            up[k] += h;
            down[k] -= h;
            let fd = (joint.transform(&up[..n]) - joint.transform(&down[..n])) / (2.0 * h);
            let g = joint.generator(k, &Q[..n]);
            assert!((fd - g * a).amax() < 1e-9, "{joint:?} variable {k}");
            // The paper's table 2: every generator's rotation part is skew-symmetric.
            let r = g.fixed_view::<3, 3>(1, 1).into_owned();
            assert!((r + r.transpose()).amax() < 1e-15, "{joint:?} variable {k}");
        }
        assert_eq!(joint.generator(n, &Q[..n]), Matrix4::zeros(), "{joint:?}");
    }
    Ok(())
}

#[test]
fn hooke_matches_the_papers_tables_but_for_the_misprinted_entry() {
    let (phi, theta): (f64, f64) = (0.7, -1.1);
    let (sp, cp, st, ct) = (phi.sin(), phi.cos(), theta.sin(), theta.cos());
    // Table 1, rows 1 to 3 of the rotation; the print's third row starts with -sin(phi), which is not orthogonal.
    let printed = nalgebra::Matrix3::new(-cp * ct, cp * st, sp, -sp * ct, sp * st, -cp, -st, -ct, 0.0);
    let a = Joint::Hooke.transform(&[phi, theta]);
    assert!((a.fixed_view::<3, 3>(1, 1) - printed).amax() < 1e-15);
    // Table 2, the second generator: a rotation about (sin phi, -cos phi, 0).
    let mut q2 = Matrix4::zeros();
    q2[(1, 3)] = -cp;
    q2[(2, 3)] = -sp;
    q2[(3, 1)] = cp;
    q2[(3, 2)] = sp;
    assert!((Joint::Hooke.generator(1, &[phi, theta]) - q2).amax() < 1e-15);
}

/// Table 1's spherical matrix as printed, with `(theta, phi, psi)` as it names them.
fn printed_spherical(theta: f64, phi: f64, psi: f64) -> nalgebra::Matrix3<f64> {
    let (st, ct, sf, cf, ss, cs) = (theta.sin(), theta.cos(), phi.sin(), phi.cos(), psi.sin(), psi.cos());
    nalgebra::Matrix3::new(
        -ct * cf * cs + st * ss,
        -st * cf * cs + ct * ss,
        sf * cs,
        -st * cs + ct * cf * ss,
        st * ss * cf - ct * cs,
        sf * ss,
        ct * sf,
        -st * sf,
        -cf,
    )
}

/// The print's spherical matrix is no rotation: at zero angles it is `-I` (a point reflection, determinant -1), and
/// elsewhere its determinant wanders (0.0096 at (0.3, 0.5, 0.7), -0.476 at (0.5, 0.2, 0.1); from -1 to 1.18 over
/// every angle) and its rows are not orthonormal. ringpod's pair is `Rz(psi) Rx(theta) Rz(phi)`, a rotation at
/// every angle.
#[test]
fn the_papers_spherical_matrix_is_no_rotation() {
    assert!((printed_spherical(0.0, 0.0, 0.0) + nalgebra::Matrix3::identity()).amax() < 1e-15);
    assert!((printed_spherical(0.3, 0.5, 0.7).determinant() - 0.009_574_5).abs() < 1e-7);
    assert!((printed_spherical(0.5, 0.2, 0.1).determinant() + 0.475_629).abs() < 1e-6);
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..24 {
        for j in 0..24 {
            for k in 0..24 {
                let a = |n: i32| -core::f64::consts::PI + f64::from(n) * core::f64::consts::TAU / 24.0;
                let m = printed_spherical(a(i), a(j), a(k));
                low = low.min(m.determinant());
                high = high.max(m.determinant());
                let r = Joint::Spherical.transform(&[a(i), a(j), a(k)]);
                let r = r.fixed_view::<3, 3>(1, 1);
                assert!((r * r.transpose() - nalgebra::Matrix3::identity()).amax() < 1e-14);
                assert!((r.determinant() - 1.0).abs() < 1e-14);
            }
        }
    }
    assert!((low + 1.0).abs() < 1e-12 && high > 1.1 && high < 1.19, "{low} {high}");
}

#[test]
fn screw_and_cylindrical_share_the_revolute_axes() {
    let (g, s) = (0.9, 0.03);
    let cyl = Joint::Cylindrical.transform(&[g, s]);
    assert_eq!(cyl, translation(Vector3::new(0.0, 0.0, s)) * rot_z(g));
    let screw = Joint::Screw { pitch: 0.01 }.transform(&[g]);
    assert!((screw - Joint::Cylindrical.transform(&[g, 0.01 * g])).amax() < 1e-16);
}

#[test]
fn each_pairs_variables_are_read_back_from_its_transform() -> Result<(), LoopError> {
    for joint in PAIRS {
        let n = joint.variables();
        let got = values(joint, &joint.transform(&Q[..n]));
        for k in 0..n {
            assert!((got[k] - Q[k]).abs() < 1e-12, "{joint:?} {k}: {got:?}");
        }
    }
    Ok(())
}

#[test]
fn a_frame_from_three_points_and_the_revolute_angle_between_two() -> Result<(), LoopError> {
    let o = Vector3::new(0.1, 0.2, 0.3);
    let base = frame(&o, &(o + Vector3::x()), &(o + Vector3::z()))?;
    // Ten degrees round z, with the +X point 5 % off the perpendicular (a sketch's error).
    let (s, c) = (10f64.to_radians().sin(), 10f64.to_radians().cos());
    let other = frame(&o, &(o + Vector3::new(c, s, 0.05)), &(o + Vector3::z() * 2.0))?;
    assert!(is_rigid(&other));
    let g = values(Joint::Revolute, &relative(&base, &other))[0];
    assert!((g - 10f64.to_radians()).abs() < 1e-15);
    assert_eq!(
        frame(&o, &(o + Vector3::z()), &(o + Vector3::z())),
        Err(LoopError::NonFinite)
    );
    Ok(())
}

mod four_bar;
mod ring_dynamics;
mod spatial_loop;
