//! Paper 002's matrix method against SCREWS.md's tests T1-T3 (tolerance 1e-6 relative), and the screw basics.

use nalgebra::{Matrix4, Vector3};
use ringpod_core::screws::matrix::{rod_along_x, rot_x, translation, Joint, Loop};
use ringpod_core::screws::{line, reciprocal};

const DEG: f64 = std::f64::consts::PI / 180.0;

fn tx(a: f64) -> Matrix4<f64> {
    translation(Vector3::new(a, 0.0, 0.0))
}

fn close_enough(got: &[f64], want: &[f64], what: &str) {
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= 1e-6 * w.abs().max(1.0), "{what}: {got:?} vs {want:?}");
    }
}

/// T1: the four-bar `J(q1) Tx(.10) J(q2) Tx(.35) J(q3) Tx(.20) J(q4) Tx(-.30) = E`.
fn four_bar() -> Loop<4> {
    Loop {
        joints: [Joint::Revolute; 4],
        links: [tx(0.10), tx(0.35), tx(0.20), tx(-0.30)],
    }
}

#[test]
fn t1_four_bar_position_velocity_acceleration() {
    let l = four_bar();
    let want = [60.0, -44.535497, -131.354371, 115.889868];
    let start = [
        60.0 * DEG,
        (want[1] + 8.0) * DEG,
        (want[2] - 6.0) * DEG,
        (want[3] + 5.0) * DEG,
    ];
    let (q, iterations) = l.close(0, &start, 1e-12, 20).unwrap();
    assert!(iterations <= 6, "{iterations} iterations");
    close_enough(&q.map(|v| v / DEG), &want, "position");
    assert!((l.closure(&q) - Matrix4::identity()).amax() < 1e-12);
    let qd = l.rates(0, &q, 10.0).unwrap();
    close_enough(&qd, &[10.0, -10.272811, 4.944514, -4.671703], "velocity");
    let qdd = l.accelerations(0, &q, &qd, 0.0).unwrap();
    close_enough(&qdd, &[0.0, 21.416201, 7.027740, -28.443941], "acceleration");
}

#[test]
fn t2_bennett_linkage() {
    let link = |a: f64, alpha: f64| tx(a) * rot_x(alpha * DEG);
    let l = Loop {
        joints: [Joint::Revolute; 4],
        links: [
            link(0.1, 30.0),
            link(0.173205, 60.0),
            link(0.1, 30.0),
            link(0.173205, 60.0),
        ],
    };
    let want = [60.0, 156.135075, -60.0, -156.135075];
    let start = [60.0 * DEG, 150.0 * DEG, -55.0 * DEG, -150.0 * DEG];
    let (q, _) = l.close(0, &start, 1e-12, 30).unwrap();
    close_enough(&q.map(|v| v / DEG), &want, "position");
    // Bennett's condition.
    let product = (q[0] / 2.0).tan() * (q[1] / 2.0).tan();
    assert!((product - (1.0 + 3f64.sqrt())).abs() < 1e-5, "{product}");
    let ratios = l.rates(0, &q, 1.0).unwrap();
    close_enough(&ratios, &[1.0, -0.467171, -1.0, 0.467171], "dq/dq1");
    let qdd = l.accelerations(0, &q, &ratios, 0.0).unwrap();
    assert!((qdd[1] + 0.223600).abs() < 1e-6, "{qdd:?}");
}

#[test]
fn t3_four_bar_mass() {
    let l = four_bar();
    let start = [60.0 * DEG, -40.0 * DEG, -130.0 * DEG, 110.0 * DEG];
    let (q, _) = l.close(0, &start, 1e-13, 20).unwrap();
    // Uniform rods of 1, 2 and 1.5 kg from each moving joint along its link's +x; the fourth link is the ground.
    let inertia = [
        Some(rod_along_x(1.0, 0.10)),
        Some(rod_along_x(2.0, 0.35)),
        Some(rod_along_x(1.5, 0.20)),
        None,
    ];
    let m = l.mass(0, &q, &inertia).unwrap();
    assert!((m - 0.0263978).abs() <= 1e-6 * 0.0263978 + 1e-9, "M = {m}");
}

#[test]
fn the_reciprocal_product_is_the_work_and_independent_of_the_origin() {
    // A force along z through (1, 0, 0) on a rotation about z through the origin: no work; on a rotation about
    // the y axis: the lever arm.
    let o = Vector3::zeros();
    let force = line(&Vector3::z(), &Vector3::new(1.0, 0.0, 0.0), &o);
    let spin_z = line(&Vector3::z(), &o, &o);
    let spin_y = line(&Vector3::y(), &o, &o);
    assert!(reciprocal(&spin_z, &force).abs() < 1e-15);
    assert!((reciprocal(&spin_y, &force) + 1.0).abs() < 1e-15);
    // The same screws about another origin give the same product.
    let o2 = Vector3::new(0.3, -0.7, 2.0);
    let (f2, y2) = (
        line(&Vector3::z(), &Vector3::new(1.0, 0.0, 0.0), &o2),
        line(&Vector3::y(), &o, &o2),
    );
    assert!((reciprocal(&y2, &f2) - reciprocal(&spin_y, &force)).abs() < 1e-12);
}

#[test]
fn at_closure_each_derivative_is_its_joints_twist() {
    let l = four_bar();
    let start = [60.0 * DEG, -40.0 * DEG, -130.0 * DEG, 110.0 * DEG];
    let (q, _) = l.close(0, &start, 1e-13, 20).unwrap();
    let b = l.derivatives(&q);
    let o = Vector3::zeros();
    // Joint 1 at the origin, joint 2 at the end of the 0.10 link turned by q1.
    let p2 = Vector3::new(0.10 * q[0].cos(), 0.10 * q[0].sin(), 0.0);
    let t1 = ringpod_core::screws::twist_of(&b[0]);
    let t2 = ringpod_core::screws::twist_of(&b[1]);
    assert!((t1 - line(&Vector3::z(), &o, &o)).amax() < 1e-12, "{t1}");
    assert!((t2 - line(&Vector3::z(), &p2, &o)).amax() < 1e-12, "{t2}");
}
