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
    assert!((l.closure(&q).unwrap() - Matrix4::identity()).amax() < 1e-12);
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
    let b = l.derivatives(&q).unwrap();
    let o = Vector3::zeros();
    // Joint 1 at the origin, joint 2 at the end of the 0.10 link turned by q1.
    let p2 = Vector3::new(0.10 * q[0].cos(), 0.10 * q[0].sin(), 0.0);
    let t1 = ringpod_core::screws::twist_of(&b[0]);
    let t2 = ringpod_core::screws::twist_of(&b[1]);
    assert!((t1 - line(&Vector3::z(), &o, &o)).amax() < 1e-12, "{t1}");
    assert!((t2 - line(&Vector3::z(), &p2, &o)).amax() < 1e-12, "{t2}");
}

mod paper_003 {
    //! The 3-DOF translational mechanism of paper 003: three chains of five revolute joints A-E, A the actuated one.

    use nalgebra::{Matrix3, Vector3, Vector6};
    use ringpod_core::screws::line;
    use ringpod_core::screws::reactions::{actuation_wrench, constraint_wrench, reactions};

    use super::DEG;

    /// `det M_C = s1 s2 s3 - c1 c2 c3` (SCREWS.md 3), the determinant of the constraint couples' moments.
    fn det_mc(theta: [f64; 3]) -> f64 {
        let (s, c) = (theta.map(|t| t.sin()), theta.map(|t| t.cos()));
        let m = Matrix3::new(0.0, s[0], -c[0], -c[1], 0.0, s[1], s[2], -c[2], 0.0);
        m.determinant()
    }

    #[test]
    fn t4_the_constraint_determinant() {
        assert!((det_mc([30.0 * DEG, 40.0 * DEG, 50.0 * DEG]) + 0.180232).abs() < 1e-6);
        assert!(det_mc([45.0 * DEG; 3]).abs() < 1e-15);
    }

    struct Mechanism {
        /// Per chain: the actuated twist, the four passive twists, about F.
        actuated: [Vector6<f64>; 3],
        passive: [[Vector6<f64>; 4]; 3],
        /// The closed-form constraint wrenches.
        w_c: [Vector6<f64>; 3],
    }

    fn mechanism() -> Mechanism {
        let f = Vector3::new(-0.25, -0.12, -0.18);
        let theta = [-157.2695 * DEG, -175.4759 * DEG, -290.4576 * DEG];
        let (s, c) = (theta.map(|t| t.sin()), theta.map(|t| t.cos()));
        let e = [Vector3::x(), Vector3::y(), Vector3::z()];
        let u = [
            Vector3::new(0.0, c[0], s[0]),
            Vector3::new(s[1], 0.0, c[1]),
            Vector3::new(c[2], s[2], 0.0),
        ];
        let b = [
            Vector3::new(-0.5, 0.0773, -0.1845),
            Vector3::new(-0.1994, -0.5, 0.0158),
            Vector3::new(-0.1874, 0.0699, -0.5),
        ];
        let cc = [
            Vector3::new(-0.55, 0.0025, -0.0059),
            Vector3::new(-0.0166, -0.42, 0.0013),
            Vector3::new(-0.0009, 0.0004, -0.48),
        ];
        let d = [
            Vector3::new(-0.55, 0.0797, -0.1903),
            Vector3::new(-0.216, -0.42, 0.0171),
            Vector3::new(-0.1883, 0.0703, -0.48),
        ];
        let a = e.map(|ei| -0.5 * ei);
        Mechanism {
            actuated: core::array::from_fn(|i| line(&e[i], &a[i], &f)),
            passive: core::array::from_fn(|i| {
                [
                    line(&u[i], &b[i], &f),
                    line(&u[i], &cc[i], &f),
                    line(&e[i], &d[i], &f),
                    line(&e[i], &(f - 0.3 * e[i]), &f),
                ]
            }),
            w_c: [
                Vector6::new(0.0, 0.0, 0.0, 0.0, s[0], -c[0]),
                Vector6::new(0.0, 0.0, 0.0, -c[1], 0.0, s[1]),
                Vector6::new(0.0, 0.0, 0.0, s[2], -c[2], 0.0),
            ],
        }
    }

    fn near(got: &[f64], want: &[f64], what: &str) {
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() <= 1e-4 * w.abs().max(1.0), "{what}: {got:?} vs {want:?}");
        }
    }

    #[test]
    fn t5_wrenches_of_the_chains() {
        let m = mechanism();
        for i in 0..3 {
            // The kernel of the chain's twists is the closed-form couple, up to sign.
            let all: Vec<Vector6<f64>> = core::iter::once(m.actuated[i]).chain(m.passive[i]).collect();
            let w = constraint_wrench(&all).unwrap();
            let closed = m.w_c[i].normalize();
            assert!(
                (w - closed).amax().min((w + closed).amax()) < 1e-3,
                "chain {i}: {w} vs {closed}"
            );
        }
        let w_a1 = actuation_wrench(&m.actuated[0], &m.passive[0], &m.w_c[0]).unwrap();
        near(
            w_a1.as_slice(),
            &[0.60186, 5.37088, -0.27702, 0.0, -0.58207, -0.24385],
            "w_A1",
        );
        let moments = Matrix3::from_fn(|r, c| m.w_c[r][3 + c]);
        assert!(
            (moments.determinant() + 0.29281).abs() < 1e-4,
            "{}",
            moments.determinant()
        );
    }

    #[test]
    fn t6_reactions_with_and_without_projection() {
        let m = mechanism();
        let w_a: Vec<Vector6<f64>> = (0..3)
            .map(|i| actuation_wrench(&m.actuated[i], &m.passive[i], &m.w_c[i]).unwrap())
            .collect();
        let r = reactions(&w_a, &m.w_c, &Vector6::new(0.0, 0.0, 10.0, 0.0, 0.0, 0.0)).unwrap();
        near(&r.actuators[..3], &[1.44913, 2.26914, 1.73180], "r_A, pure force");
        near(&r.constraints[..3], &[0.21048, 2.80049, -2.96711], "r_C, pure force");
        near(
            &r.constraints_projected[..3],
            &[0.0, 0.0, 0.0],
            "projected r_C, pure force",
        );
        let p = Vector6::new(1.0, 2.0, 3.0, 0.1, -0.2, 0.3);
        let r = reactions(&w_a, &m.w_c, &p).unwrap();
        near(&r.actuators[..3], &[0.11628, 0.66516, -0.26431], "r_A");
        near(&r.constraints[..3], &[0.22839, -0.07950, 0.17509], "r_C");
        near(
            &r.constraints_projected[..3],
            &[0.31592, -0.10924, 0.22297],
            "projected r_C",
        );
    }
}

mod paper_003_slice {
    //! The translational mechanism placed by its assumed layout (`screws::translational`), and the Gram
    //! determinants of paper 003's figs. 3-5.

    use nalgebra::Vector3;
    use nalgebra::Vector6;
    use proptest::prelude::*;
    use ringpod_core::screws::translational::{
        chain, gram, max_reactions, TranslationalError, FIG_LOAD, MIXED, SLICE_Z,
    };

    use super::DEG;

    /// Figs. 3 and 5's `r_max` at T5 is the largest constraint reaction of T6 (unit actuation wrenches change only
    /// the actuators' reactions): unprojected 2.96711 and projected 0 for a pure force, 0.22839 and 0.31592 for T6's
    /// general load (within 2e-3: T6 takes the joints as printed to four decimals, these the layout's exact ones).
    #[test]
    fn figs_3_and_5_r_max_at_t5() {
        let f = Vector3::new(-0.25, -0.12, -0.18);
        let r = max_reactions(&f, MIXED, &Vector6::new(0.0, 0.0, 10.0, 0.0, 0.0, 0.0)).unwrap();
        assert!(
            (r.unprojected - 2.96711).abs() < 2e-3 && r.projected.abs() < 1e-9,
            "{r:?}"
        );
        let r = max_reactions(&f, MIXED, &Vector6::new(1.0, 2.0, 3.0, 0.1, -0.2, 0.3)).unwrap();
        assert!(
            (r.unprojected - 0.22839).abs() < 2e-3 && (r.projected - 0.31592).abs() < 2e-3,
            "{r:?}"
        );
        // The figures' load: its couple alone sets the projected reactions.
        let load = Vector6::from(FIG_LOAD);
        let couple = Vector6::new(0.0, 0.0, 0.0, 0.1, 0.1, 0.1);
        let (a, b) = (
            max_reactions(&f, MIXED, &load).unwrap(),
            max_reactions(&f, MIXED, &couple).unwrap(),
        );
        assert!((a.projected - b.projected).abs() < 1e-12 && (a.unprojected - b.unprojected).abs() > 1e-3);
        assert_eq!(
            max_reactions(&Vector3::new(0.05, -0.1, SLICE_Z), MIXED, &load),
            Err(TranslationalError::Unreachable(0))
        );
    }

    /// SCREWS.md 4, T5: the layout and the mixed assembly give the specification's test pose (the paper prints
    /// none), its actuator angles and joints.
    #[test]
    fn t5_the_test_pose_from_the_layout() {
        let f = Vector3::new(-0.25, -0.12, -0.18);
        let theta = [-157.2695, -175.4759, -290.4576];
        let joints = [
            [
                [-0.5, 0.0773, -0.1845],
                [-0.55, 0.0025, -0.0059],
                [-0.55, 0.0797, -0.1903],
            ],
            [
                [-0.1994, -0.5, 0.0158],
                [-0.0166, -0.42, 0.0013],
                [-0.216, -0.42, 0.0171],
            ],
            [
                [-0.1874, 0.0699, -0.5],
                [-0.0009, 0.0004, -0.48],
                [-0.1883, 0.0703, -0.48],
            ],
        ];
        for i in 0..3 {
            let c = chain(i, &f, MIXED[i]).unwrap();
            let turn = (c.theta / DEG - theta[i]).rem_euclid(360.0);
            assert!(turn.min(360.0 - turn) < 1e-3, "theta {i}: {}", c.theta / DEG);
            for (k, want) in joints[i].iter().enumerate() {
                let got = c.joints[k + 1];
                for a in 0..3 {
                    assert!(
                        (got[a] - want[a]).abs() < 1e-4,
                        "chain {i} joint {k}: {got} vs {want:?}"
                    );
                }
            }
            // Every link its length, E's axis through F.
            let j = c.joints;
            for (p, q, l) in [(0, 1, 0.2), (1, 2, 0.2), (2, 3, 0.2), (3, 4, 0.2)] {
                assert!(((j[q] - j[p]).norm() - l).abs() < 1e-12);
            }
            assert!(((f - j[4]).norm() - 0.3).abs() < 1e-12);
        }
        let g = gram(&f, MIXED).unwrap();
        assert!((g.det_mc + 0.29281).abs() < 1e-4, "{}", g.det_mc);
        assert!((g.constraints - 0.29281f64.powi(2)).abs() < 1e-4, "{}", g.constraints);
    }

    #[test]
    fn points_out_of_reach_are_refused() {
        // cos(alpha) = (F_x + 0.2) / 0.2 > 1 past x = 0.
        assert_eq!(
            gram(&Vector3::new(0.05, -0.1, SLICE_Z), MIXED),
            Err(TranslationalError::Unreachable(0))
        );
        assert_eq!(
            gram(&Vector3::new(-0.2, 0.05, SLICE_Z), MIXED),
            Err(TranslationalError::Unreachable(1))
        );
        assert_eq!(
            gram(&Vector3::new(f64::NAN, -0.1, SLICE_Z), MIXED),
            Err(TranslationalError::NonFinite)
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

        /// Over the slice: `det G_C = det M_C^2`; each determinant of unit wrenches in [0, 1] (Hadamard); and
        /// `det G <= det G_C det G_A` (Fischer), so `G` is singular wherever `G_C` is.
        #[test]
        fn the_slices_determinants_keep_their_invariants(x in -0.4..0.0f64, y in -0.4..0.0f64) {
            if let Ok(g) = gram(&Vector3::new(x, y, SLICE_Z), MIXED) {
                prop_assert!((g.constraints - g.det_mc * g.det_mc).abs() < 1e-12, "{g:?}");
                for d in [g.constraints, g.actuation, g.all] {
                    prop_assert!((-1e-12..=1.0 + 1e-12).contains(&d), "{g:?}");
                }
                prop_assert!(g.all <= g.constraints * g.actuation + 1e-12, "{g:?}");
            }
        }
    }

    /// Where `det M_C` changes sign on the slice (a constraint singularity, `tan t1 tan t2 tan t3 = 1`), `det G_C`
    /// and `det G` vanish: bisected along rows of the paper's 2 mm grid, the first twenty crossings.
    #[test]
    fn both_vanish_at_the_constraint_singularity() {
        let at = |x: f64, y: f64| gram(&Vector3::new(x, y, SLICE_Z), MIXED).ok();
        let mut found = 0;
        for row in 0..200 {
            let y = -0.399 + 0.002 * row as f64;
            for col in 0..199 {
                let (x0, x1) = (-0.399 + 0.002 * col as f64, -0.397 + 0.002 * col as f64);
                let (Some(g0), Some(g1)) = (at(x0, y), at(x1, y)) else {
                    continue;
                };
                if g0.det_mc.signum() == g1.det_mc.signum() || found >= 20 {
                    continue;
                }
                let (mut lo, mut hi) = (x0, x1);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let Some(g) = at(mid, y) else { break };
                    if g.det_mc.signum() == g0.det_mc.signum() {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let g = at(lo, y).unwrap();
                // Zero to rounding (a determinant of unit vectors by LU: a few ulps of 1).
                assert!(g.det_mc.abs() < 1e-12, "at ({lo}, {y}): {g:?}");
                assert!(
                    g.constraints.abs() < 1e-14 && g.all.abs() < 1e-14,
                    "at ({lo}, {y}): {g:?}"
                );
                found += 1;
            }
        }
        assert!(
            found >= 5,
            "{found} crossings of the constraint singularity on the slice"
        );
    }
}
