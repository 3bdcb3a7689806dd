//! The elbow chain (dissertation ch. 5.1, fig. 5.2): its closed-form IK against an independent derivation, IK -> FK
//! round trips, its Jacobians against finite differences, its two wrenches reciprocal to its unactuated joints, and
//! typed errors for everything that has no answer.

use crate::common::Lcg;
use nalgebra::{Vector3, Vector6};
use proptest::prelude::*;
use ringpod_core::kinematics::geometry::{Chain, ChainKind, Elbow, ElbowBranch, GeometryError, RingGeometry, DEG};
use ringpod_core::kinematics::presets::{self, Preset, TRAINER_ELBOW, TRAINER_ELBOW_ARM};
use ringpod_core::kinematics::{
    start_from_home, Actuators, AxisKind, KinematicsError, Mechanism, NewtonOptions, Pose, Reach, RingPlatform,
    FROM_HOME_DISTANCE,
};
use ringpod_core::screws::{line, reciprocal};

fn home() -> Pose<f64> {
    Pose::from_array(Preset::TrainerElbow.home())
}

/// The trainer-elbow with other arms on its two elbow chains.
fn with_arm(arm: Elbow) -> RingGeometry {
    let mut chains: Vec<Chain> = TRAINER_ELBOW.chains().to_vec();
    for c in &mut chains[2..] {
        c.kind = ChainKind::Elbow(arm);
    }
    RingGeometry::new(
        "test",
        TRAINER_ELBOW.ring_radius,
        TRAINER_ELBOW.rod_length,
        &chains,
        TRAINER_ELBOW.limits,
    )
    .unwrap()
}

/// The shoulder angle by the law of cosines, derived here apart from the core: `psi` the direction from shoulder to
/// joint in the arm's plane (`u` toward the axis, `z` up), `phi` the triangle's angle at the shoulder; up is the
/// counter-clockwise side. Returns `None` when the triangle cannot close.
fn law_of_cosines(arm: &Elbow, joint: &Vector3<f64>) -> Option<f64> {
    let rho = joint.x.hypot(joint.y);
    let (w, v) = (arm.shoulder_radius - rho, joint.z - arm.shoulder_height);
    let d = w.hypot(v);
    let (l1, l2) = (arm.upper_arm, arm.forearm);
    let cos_phi = (l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d);
    if !(-1.0..=1.0).contains(&cos_phi) {
        return None;
    }
    let psi = v.atan2(w);
    Some(match arm.branch {
        ElbowBranch::Up => psi + cos_phi.acos(),
        ElbowBranch::Down => psi - cos_phi.acos(),
    })
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

fn random_arm(v: &[f64; 5], up: bool) -> Elbow {
    Elbow {
        shoulder_radius: 0.20 + 0.15 * v[0],
        shoulder_height: -0.05 + 0.15 * v[1],
        upper_arm: 0.06 + 0.2 * v[2],
        forearm: 0.06 + 0.2 * v[3],
        branch: if up { ElbowBranch::Up } else { ElbowBranch::Down },
        shoulder_angle: [-180.0 * DEG + 60.0 * DEG * v[4], 180.0 * DEG + 60.0 * DEG * v[4]],
        elbow_angle: [0.0, 180.0 * DEG],
    }
}

fn random_pose(v: &[f64; 6]) -> Pose<f64> {
    Pose::new(
        0.1 * v[0],
        0.1 * v[1],
        0.227 + 0.1 * v[2],
        0.5 * v[3],
        0.5 * v[4],
        3.2 * v[5],
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// Over random arms (both branches) and random poses: the core's closed form agrees with the law of cosines, the
    /// carriage is at the joint's azimuth, the arm closes (upper arm and forearm at their lengths), the elbow is on
    /// its branch's side of the shoulder-to-joint line (the higher side for `up` while the joint is nearer the axis
    /// than the shoulder), and the shoulder angle is within half a turn of the middle of its travel. Where the
    /// triangle cannot close the core says which chain and why.
    #[test]
    fn ik_agrees_with_the_law_of_cosines(
        a in prop::array::uniform5(0.0..1.0f64),
        up in any::<bool>(),
        p in prop::array::uniform6(-1.0..1.0f64),
    ) {
        let arm = random_arm(&a, up);
        let g = with_arm(arm);
        let m = RingPlatform::<f64>::new(&g);
        let pose = random_pose(&p);
        let joints = m.joints(&pose);
        let expected: Vec<Option<f64>> = joints[2..4].iter().map(|j| law_of_cosines(&arm, j)).collect();
        match m.inverse(&pose) {
            Ok(q) => {
                for (k, j) in joints[2..4].iter().enumerate() {
                    let (chain, s) = (2 + k, q.0[4 + k]);
                    let law = expected[k].expect("the core solved a triangle that cannot close");
                    prop_assert!(wrap(s - law).abs() < 1e-9, "chain {chain}: {s} vs {law}");
                    let middle = 0.5 * (arm.shoulder_angle[0] + arm.shoulder_angle[1]);
                    prop_assert!((s - middle).abs() <= std::f64::consts::PI + 1e-12);
                    prop_assert!(wrap(q.0[chain] - j.y.atan2(j.x)).abs() < 1e-12);
                    // The arm in base coordinates, from the carriage angle and the shoulder angle.
                    let c = Vector3::new(q.0[chain].cos(), q.0[chain].sin(), 0.0);
                    let shoulder = c * arm.shoulder_radius + Vector3::z() * arm.shoulder_height;
                    let elbow = shoulder + (-c * s.cos() + Vector3::z() * s.sin()) * arm.upper_arm;
                    prop_assert!(((elbow - shoulder).norm() - arm.upper_arm).abs() < 1e-12);
                    prop_assert!(((j - elbow).norm() - arm.forearm).abs() < 1e-9);
                    // Side of the line in the arm's plane, coordinates (toward the axis, up).
                    let plane = |x: &Vector3<f64>| (-(x - shoulder).dot(&c), x.z - shoulder.z);
                    let (eu, ez) = plane(&elbow);
                    let (ju, jz) = plane(j);
                    let ccw = ju * ez - jz * eu;
                    let on_its_side = if up { ccw >= -1e-12 } else { ccw <= 1e-12 };
                    prop_assert!(on_its_side, "chain {}: cross product {}", chain, ccw);
                    if ju > 1e-6 {
                        let line_height = jz * eu / ju;
                        prop_assert_eq!(ez >= line_height - 1e-12, up, "elbow at ({}, {})", eu, ez);
                    }
                }
            }
            Err(KinematicsError::Unreachable { chain, reason: Reach::Dyad }) => {
                prop_assert!(chain >= 2);
                prop_assert!(expected[usize::from(chain) - 2].is_none(), "chain {chain} refused a closable arm");
            }
            // The rod chains may fail first; they are not what this tests.
            Err(KinematicsError::Unreachable { chain, .. }) => prop_assert!(chain < 2),
            Err(e) => prop_assert!(false, "{e:?}"),
        }
    }

    /// Non-finite or wild input never panics: every entry point returns a value or a typed error.
    #[test]
    fn garbage_never_panics(v in prop::array::uniform6(prop::num::f64::ANY), w in prop::array::uniform6(prop::num::f64::ANY)) {
        let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
        let pose = Pose::from_array(v);
        let q = Actuators(w);
        let _ = m.inverse(&pose);
        let _ = m.inverse_checked(&pose);
        let _ = m.residuals(&pose, &q);
        let _ = m.jacobians(&pose, &q).classify(0.01);
        let _ = m.workspace(&pose, &q);
        let _ = m.reach_margin(&pose);
        let _ = m.loads(&pose, &q, &Vector6::new(0.0, 0.0, -10.0, 0.0, 0.0, 0.0));
        let _ = m.forward(&q, &pose, &NewtonOptions::default());
        let _ = m.forward(&q, &home(), &NewtonOptions::default());
        let m32 = RingPlatform::<f32>::new(&TRAINER_ELBOW);
        let _ = m32.inverse_checked(&pose.cast());
        if !v.iter().all(|x| x.is_finite()) {
            prop_assert_eq!(m.inverse(&pose), Err(KinematicsError::NonFinite));
        }
    }
}

/// Poses around home inside every check of the preset: random in the spec box, at any yaw.
fn inside_poses(seed: u64, count: usize) -> Vec<(Pose<f64>, Actuators<f64>)> {
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    let mut rng = Lcg(seed);
    let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES;
    let mut out = Vec::new();
    for _ in 0..count * 20 {
        if out.len() == count {
            break;
        }
        let pose = Pose::new(
            t * rng.uniform(),
            t * rng.uniform(),
            presets::TRAINER_MODEL_HOME_Z + h * rng.uniform(),
            r * rng.uniform(),
            r * rng.uniform(),
            4.0 * rng.uniform(),
        );
        if let Ok((q, report)) = m.inverse_checked(&pose) {
            if report.all_pass() {
                out.push((pose, q));
            }
        }
    }
    assert_eq!(out.len(), count, "too few poses inside the checks");
    out
}

#[test]
fn the_preset_is_inside_every_check_at_home_with_margin() {
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    assert_eq!(
        m.axes(),
        [
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Angle,
            AxisKind::Angle
        ]
    );
    let (q, report) = m.inverse_checked(&home()).unwrap();
    assert!(report.all_pass(), "{report:?}");
    // The shoulders well inside their travel, the index well above its threshold.
    for s in &q.0[4..] {
        let travel = TRAINER_ELBOW_ARM.shoulder_angle;
        assert!(
            *s > travel[0] + 20.0 * DEG && *s < travel[1] - 20.0 * DEG,
            "{}",
            s / DEG
        );
    }
    assert!(report.singularity_index > 0.05, "{report:?}");
    // The spec table, axis by axis at 24 yaws (how the design example judged it): every pose inside.
    for (axis, range) in presets::TRAINER_MODEL_RANGES.iter().enumerate() {
        for k in 0..=10 {
            for y in 0..24 {
                let mut c = Preset::TrainerElbow.home();
                c[axis] += range * (k as f64 / 5.0 - 1.0);
                c[5] = y as f64 * 15.0 * DEG;
                let (_, report) = m.inverse_checked(&Pose::from_array(c)).unwrap();
                assert!(report.all_pass(), "{c:?}: {report:?}");
            }
        }
    }
}

#[test]
fn ik_then_fk_gives_the_pose_back() {
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    let options = NewtonOptions {
        max_distance: FROM_HOME_DISTANCE,
        ..NewtonOptions::default()
    };
    let (mut near, mut from_home) = (0, 0);
    for (pose, q) in inside_poses(7, 500) {
        // From a nearby guess (the control loop's case) and from home turned by the carriages' yaw.
        let guess = Pose::new(
            pose.x + 0.004,
            pose.y - 0.003,
            pose.z + 0.002,
            pose.alpha - 0.02,
            pose.beta + 0.02,
            pose.gamma + 0.03,
        );
        let fk = m.forward(&q, &guess, &NewtonOptions::default()).unwrap();
        let (a, b) = (fk.pose.to_array(), pose.to_array());
        assert!((0..6).all(|i| (a[i] - b[i]).abs() < 1e-9), "{:?} vs {pose:?}", fk.pose);
        near += 1;
        match m.forward(&q, &start_from_home(&m, &q, &home()), &options) {
            Ok(fk) => {
                let a = fk.pose.to_array();
                assert!((0..5).all(|i| (a[i] - b[i]).abs() < 1e-9), "{:?} vs {pose:?}", fk.pose);
                assert!(wrap(a[5] - b[5]).abs() < 1e-9);
                from_home += 1;
            }
            Err(e) => assert_eq!(e, KinematicsError::NearSingularity, "{pose:?}"),
        }
    }
    assert_eq!(near, 500);
    assert!(from_home > 450, "{from_home} of 500 from home");
}

#[test]
fn jacobians_are_the_derivatives_of_the_residuals() {
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    let h = 1e-6;
    for (pose, q) in inside_poses(11, 50) {
        let j = m.jacobians(&pose, &q);
        let f0 = m.residuals(&pose, &q);
        assert!(f0.amax() < 1e-12, "{f0:?}");
        for k in 0..6 {
            let (mut plus, mut minus) = (pose.to_array(), pose.to_array());
            plus[k] += h;
            minus[k] -= h;
            let d = (m.residuals(&Pose::from_array(plus), &q) - m.residuals(&Pose::from_array(minus), &q)) / (2.0 * h);
            for r in 0..6 {
                assert!(
                    (d[r] - j.a[(r, k)]).abs() < 1e-7,
                    "dF{r}/dp{k}: {} vs {}",
                    d[r],
                    j.a[(r, k)]
                );
            }
            let (mut qp, mut qm) = (q, q);
            qp.0[k] += h;
            qm.0[k] -= h;
            let d = (m.residuals(&pose, &qp) - m.residuals(&pose, &qm)) / (2.0 * h);
            for r in 0..6 {
                assert!(
                    (d[r] - j.b[(r, k)]).abs() < 1e-7,
                    "dF{r}/dq{k}: {} vs {}",
                    d[r],
                    j.b[(r, k)]
                );
            }
        }
        // Velocities through the Jacobians agree with differences of IK.
        let rates = Vector6::new(0.01, -0.02, 0.015, 0.1, -0.05, 0.3);
        let qd = j.actuator_rates(&rates).unwrap();
        let step = |sign: f64| {
            let p = pose.to_array();
            m.inverse(&Pose::from_array(core::array::from_fn(|i| p[i] + sign * h * rates[i])))
                .unwrap()
        };
        let (qp, qm) = (step(1.0), step(-1.0));
        for i in 0..6 {
            let d = wrap(qp.0[i] - qm.0[i]) / (2.0 * h);
            assert!((d - qd[i]).abs() < 1e-6, "q{i}' {d} vs {}", qd[i]);
        }
    }
}

/// Dissertation ch. 5.1: an elbow chain transmits two wrenches, reciprocal to its unactuated joints (the elbow
/// revolute and the spherical joint at the platform): a force along the forearm and a force through the spherical
/// joint parallel to the elbow axis. Each row of the wrench matrix is checked against the twists of those joints,
/// built here from the carriage and shoulder angles alone; the actuated joints (carriage, shoulder) do work on them.
#[test]
fn the_wrenches_are_reciprocal_to_the_unactuated_joints() {
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    let arm = TRAINER_ELBOW_ARM;
    let o = Vector3::zeros();
    let mut actuated_work: f64 = 0.0;
    for (pose, q) in inside_poses(3, 200) {
        let w = m.wrench_matrix(&pose, &q);
        let joints = m.joints(&pose);
        // Rows: chains 3 and 4's forearm lines (rows 2, 3), then their tangent forces (rows 4, 5).
        for (k, chain) in [2usize, 3].into_iter().enumerate() {
            let (qc, s) = (q.0[chain], q.0[4 + k]);
            let c = Vector3::new(qc.cos(), qc.sin(), 0.0);
            let t = Vector3::new(-qc.sin(), qc.cos(), 0.0);
            let shoulder = c * arm.shoulder_radius + Vector3::z() * arm.shoulder_height;
            let elbow = shoulder + (-c * s.cos() + Vector3::z() * s.sin()) * arm.upper_arm;
            let a = joints[chain];
            let unactuated = [
                line(&t, &elbow, &o),
                line(&Vector3::x(), &a, &o),
                line(&Vector3::y(), &a, &o),
                line(&Vector3::z(), &a, &o),
            ];
            let actuated = [line(&Vector3::z(), &o, &o), line(&t, &shoulder, &o)];
            for row in [chain, 4 + k] {
                let wrench = Vector6::from_fn(|i, _| w[(row, i)]);
                assert!((wrench.fixed_rows::<3>(0).norm() - 1.0).abs() < 1e-12);
                for twist in &unactuated {
                    let r = reciprocal(twist, &wrench);
                    assert!(r.abs() < 1e-9, "row {row}: {r}");
                }
                for twist in &actuated {
                    actuated_work = actuated_work.max(reciprocal(twist, &wrench).abs());
                }
            }
            // The forearm row is the line through elbow and joint; the tangent row is parallel to the elbow axis.
            let u = (a - elbow).normalize();
            let along = line(&u, &a, &o);
            assert!((0..6).all(|i| (w[(chain, i)] - along[i]).abs() < 1e-12));
            let tangent = line(&t, &a, &o);
            assert!((0..6).all(|i| (w[(4 + k, i)] - tangent[i]).abs() < 1e-12));
        }
    }
    assert!(
        actuated_work > 1e-2,
        "the drives do work on the chain's wrenches ({actuated_work})"
    );
}

#[test]
fn unreachable_and_invalid_inputs_are_typed_errors() {
    // Arms too short for the home pose: chain 3 (index 2) is the first elbow chain.
    let short = with_arm(Elbow {
        upper_arm: 0.08,
        forearm: 0.08,
        ..TRAINER_ELBOW_ARM
    });
    let m = RingPlatform::<f64>::new(&short);
    assert_eq!(
        m.inverse(&home()),
        Err(KinematicsError::Unreachable {
            chain: 2,
            reason: Reach::Dyad
        })
    );
    assert!(m.reach_margin(&home()) < 0.0);
    // A joint on the ring axis has no azimuth.
    let m = RingPlatform::<f64>::new(&TRAINER_ELBOW);
    let on_axis = Pose::new(-0.181, -0.160, 0.2, 0.0, 0.0, 0.0);
    assert_eq!(
        m.inverse(&on_axis),
        Err(KinematicsError::Unreachable {
            chain: 2,
            reason: Reach::Centre
        })
    );
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..6 {
            let mut p = Preset::TrainerElbow.home();
            p[i] = bad;
            assert_eq!(m.inverse(&Pose::from_array(p)), Err(KinematicsError::NonFinite));
            let mut q = m.inverse(&home()).unwrap();
            q.0[i] = bad;
            assert_eq!(
                m.forward(&q, &home(), &NewtonOptions::default()),
                Err(KinematicsError::NonFinite)
            );
        }
    }
    // Outside the shoulder's travel: reach fails with the margin the travel leaves, in metres of elbow arc.
    let narrow = with_arm(Elbow {
        shoulder_angle: [150.0 * DEG, 190.0 * DEG],
        ..TRAINER_ELBOW_ARM
    });
    let m = RingPlatform::<f64>::new(&narrow);
    let (q, report) = m.inverse_checked(&home()).unwrap();
    let margin = report.margin(ringpod_core::kinematics::Check::Reach).unwrap();
    assert!(q.0[4] < 150.0 * DEG);
    assert!(
        (margin - TRAINER_ELBOW_ARM.upper_arm * (q.0[4] - 150.0 * DEG)).abs() < 1e-12,
        "{margin}"
    );
}

#[test]
fn bad_arms_are_refused_when_built() {
    let chains = |arm: Elbow| {
        let mut c: Vec<Chain> = TRAINER_ELBOW.chains().to_vec();
        c[3].kind = ChainKind::Elbow(arm);
        c
    };
    let build = |arm: Elbow| RingGeometry::new("bad", 0.286, 0.312, &chains(arm), TRAINER_ELBOW.limits).map(|_| ());
    let a = TRAINER_ELBOW_ARM;
    let cases = [
        (
            Elbow {
                shoulder_radius: f64::NAN,
                ..a
            },
            GeometryError::NonFinite,
        ),
        (
            Elbow {
                shoulder_height: f64::INFINITY,
                ..a
            },
            GeometryError::NonFinite,
        ),
        (
            Elbow {
                elbow_angle: [f64::NAN, 1.0],
                ..a
            },
            GeometryError::NonFinite,
        ),
        (
            Elbow {
                shoulder_radius: 0.0,
                ..a
            },
            GeometryError::NonPositiveLength,
        ),
        (Elbow { upper_arm: -0.1, ..a }, GeometryError::NonPositiveLength),
        (Elbow { forearm: 0.0, ..a }, GeometryError::NonPositiveLength),
        (
            Elbow {
                shoulder_angle: [1.0, 1.0],
                ..a
            },
            GeometryError::BadLimits,
        ),
        (
            Elbow {
                shoulder_angle: [-4.0, 4.0],
                ..a
            },
            GeometryError::BadLimits,
        ),
        (
            Elbow {
                elbow_angle: [-0.1, 1.0],
                ..a
            },
            GeometryError::BadLimits,
        ),
        (
            Elbow {
                elbow_angle: [0.5, 3.2],
                ..a
            },
            GeometryError::BadLimits,
        ),
    ];
    for (arm, expected) in cases {
        assert_eq!(build(arm), Err(expected), "{arm:?}");
    }
    assert_eq!(build(a), Ok(()));
    // An elbow chain drives two actuators, as a radial chain does: five chains with one elbow make seven.
    let mut five: Vec<Chain> = presets::ROTOPOD_CH4.chains()[..5].to_vec();
    five[0].kind = ChainKind::Elbow(a);
    five[1].kind = ChainKind::Elbow(a);
    assert_eq!(
        RingGeometry::new("seven", 1.0198, 0.98, &five, presets::ROTOPOD_CH4.limits).map(|_| ()),
        Err(GeometryError::ChainCount)
    );
}

/// Actuator order: carriages, then radial lengths, then shoulder angles, whatever the chain order.
#[test]
fn shoulders_come_after_every_radial_length() {
    let limits = presets::TRAINER_MODEL.limits;
    let chains = [
        Chain {
            kind: ChainKind::Elbow(TRAINER_ELBOW_ARM),
            platform_point: [0.181, 0.160, 0.0],
        },
        Chain {
            kind: ChainKind::Radial,
            platform_point: [-0.181, 0.160, 0.0],
        },
        Chain {
            kind: ChainKind::Rod(ringpod_core::kinematics::Branch::Plus),
            platform_point: [-0.194, -0.031, 0.0],
        },
        Chain {
            kind: ChainKind::Rod(ringpod_core::kinematics::Branch::Minus),
            platform_point: [0.194, -0.031, 0.0],
        },
    ];
    let g = RingGeometry::new("mixed", 0.286, 0.312, &chains, limits).unwrap();
    let m = RingPlatform::<f64>::new(&g);
    assert_eq!(
        m.axes(),
        [
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Ring,
            AxisKind::Linear,
            AxisKind::Angle
        ]
    );
    let q = m.inverse(&home()).unwrap();
    let j = m.joints(&home());
    // Axis 5 is the radial chain's length, axis 6 the elbow chain's shoulder.
    let rho = j[1].x.hypot(j[1].y);
    assert!((q.0[4] - ((0.286 - rho).powi(2) + j[1].z.powi(2)).sqrt()).abs() < 1e-12);
    let law = law_of_cosines(&TRAINER_ELBOW_ARM, &j[0]).unwrap();
    assert!(wrap(q.0[5] - law).abs() < 1e-12);
    let fk = m.forward(
        &q,
        &Pose::new(0.003, 0.0, 0.23, 0.01, 0.0, 0.02),
        &NewtonOptions::default(),
    );
    let p = fk.unwrap().pose.to_array();
    assert!(
        p.iter().zip(home().to_array()).all(|(a, b)| (a - b).abs() < 1e-9),
        "{p:?}"
    );
}

#[test]
fn a_geometry_names_its_axes_as_its_platform_drives_them() {
    // A carriage per chain, then a length per radial chain, then a shoulder per elbow chain.
    use AxisKind::{Angle, Linear, Ring};
    assert_eq!(presets::TRAINER_MODEL.axes(), [Ring, Ring, Ring, Ring, Linear, Linear]);
    assert_eq!(TRAINER_ELBOW.axes(), [Ring, Ring, Ring, Ring, Angle, Angle]);
    assert_eq!(presets::ROTOPOD_CH4.axes(), [Ring; 6]);
}
