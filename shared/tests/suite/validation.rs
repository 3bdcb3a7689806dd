//! Bad input classes: geometries that cannot be built, and forward kinematics that has no answer.

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use ringpod_core::kinematics::geometry::{Branch, Chain, ChainKind, RingGeometry, ToolGeometry, DEG};
use ringpod_core::kinematics::{
    presets, Actuators, Check, GeometryError, KinematicsError, Mechanism, NewtonOptions, Pose, RingPlatform,
    Singularity,
};

fn rod(x: f64, y: f64) -> Chain {
    Chain {
        kind: ChainKind::Rod(Branch::Plus),
        platform_point: [x, y, 0.0],
    }
}
fn radial(x: f64, y: f64) -> Chain {
    Chain {
        kind: ChainKind::Radial,
        platform_point: [x, y, 0.0],
    }
}

#[test]
fn ring_geometry_errors() {
    let chains = presets::TRAINER_MODEL.chains();
    let limits = presets::TRAINER_MODEL.limits;
    let new = |r: f64, l: f64, c: &[Chain]| RingGeometry::new("t", r, l, c, limits).map(|_| ());
    assert_eq!(new(0.3, 0.3, chains), Ok(()));
    assert_eq!(new(-0.3, 0.3, chains), Err(GeometryError::NonPositiveLength));
    assert_eq!(new(0.3, 0.0, chains), Err(GeometryError::NonPositiveLength));
    assert_eq!(new(f64::NAN, 0.3, chains), Err(GeometryError::NonFinite));
    assert_eq!(new(0.3, f64::INFINITY, chains), Err(GeometryError::NonFinite));
    assert_eq!(
        new(
            0.3,
            0.3,
            &[rod(0.1, 0.0), rod(0.1, 0.0), radial(0.0, 0.1), radial(0.0, -0.1)]
        ),
        Err(GeometryError::CoincidentPoints)
    );
    assert_eq!(
        new(0.3, 0.3, &[rod(0.1, 0.0), rod(0.0, 0.1), rod(-0.1, 0.0)]),
        Err(GeometryError::ChainCount)
    );
    assert_eq!(
        new(
            0.3,
            0.3,
            &[radial(0.1, 0.0), radial(0.0, 0.1), radial(-0.1, 0.0), radial(0.0, -0.1)]
        ),
        Err(GeometryError::ChainCount)
    );
    assert_eq!(
        new(
            0.3,
            0.3,
            &[rod(0.1, f64::NAN), rod(0.0, 0.1), radial(-0.1, 0.0), radial(0.0, -0.1)]
        ),
        Err(GeometryError::NonFinite)
    );
    let bad = |f: &dyn Fn(&mut ringpod_core::kinematics::RingLimits)| {
        let mut l = limits;
        f(&mut l);
        RingGeometry::new("t", 0.3, 0.3, chains, l).map(|_| ())
    };
    assert_eq!(bad(&|l| l.stroke = [0.2, 0.1]), Err(GeometryError::BadLimits));
    assert_eq!(bad(&|l| l.carriage_spacing = [0.0, 7.0]), Err(GeometryError::BadLimits));
    assert_eq!(bad(&|l| l.platform_cone = 90.0 * DEG), Err(GeometryError::BadLimits));
    assert_eq!(bad(&|l| l.min_singularity_index = 1.0), Err(GeometryError::BadLimits));
    assert_eq!(
        bad(&|l| l.centre_of_mass = [0.0, f64::NAN, 0.0]),
        Err(GeometryError::NonFinite)
    );
}

#[test]
fn tool_geometry_errors() {
    let t = presets::TOOL5_EX;
    let with_stroke = |l2: f64, b: [f64; 3], d: [f64; 3], stroke: [f64; 2]| {
        ToolGeometry::new("t", t.l1, l2, t.l3, t.a, t.b, b, d, [Branch::Minus; 2], stroke, 0.02).map(|_| ())
    };
    let new = |l2: f64, b: [f64; 3], d: [f64; 3]| with_stroke(l2, b, d, t.stroke);
    assert_eq!(
        with_stroke(0.33, t.pivot_b, t.pivot_d, [0.2, 0.2]),
        Err(GeometryError::BadLimits)
    );
    assert_eq!(
        with_stroke(0.33, t.pivot_b, t.pivot_d, [-0.2, f64::INFINITY]),
        Err(GeometryError::NonFinite)
    );
    assert_eq!(new(0.33, t.pivot_b, t.pivot_d), Ok(()));
    assert_eq!(new(0.0, t.pivot_b, t.pivot_d), Err(GeometryError::NonPositiveLength));
    assert_eq!(new(0.33, t.pivot_b, t.pivot_b), Err(GeometryError::CoincidentPoints));
    assert_eq!(
        new(0.33, [f64::NAN, 0.0, 0.0], t.pivot_d),
        Err(GeometryError::NonFinite)
    );
}

#[test]
fn forward_errors() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let home = Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, 0.0);
    let q = m.inverse(&home).unwrap();
    // Rods cannot reach radial lengths of 2 m: no pose satisfies the constraints.
    let mut impossible = q;
    impossible.0[4] = 2.0;
    impossible.0[5] = 2.0;
    let err = m.forward(&impossible, &home, &NewtonOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            KinematicsError::NoConvergence { .. } | KinematicsError::NearSingularity
        ),
        "{err:?}"
    );
    // A guess at a singular configuration: the platform flat in the ring plane makes every rod horizontal.
    let flat = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert_eq!(
        m.forward(&q, &flat, &NewtonOptions::default()).map(|_| ()),
        Err(KinematicsError::NearSingularity)
    );
    // One iteration is not enough from 1 cm away.
    let opts = NewtonOptions {
        max_iterations: 1,
        ..NewtonOptions::default()
    };
    let guess = Pose { x: 0.01, ..home };
    assert_eq!(
        m.forward(&q, &guess, &opts).map(|_| ()),
        Err(KinematicsError::NoConvergence { iterations: 1 })
    );
    assert_eq!(
        m.forward(&Actuators([f64::NAN; 6]), &home, &NewtonOptions::default())
            .map(|_| ()),
        Err(KinematicsError::NonFinite)
    );
    assert_eq!(
        m.forward(
            &q,
            &Pose {
                z: f64::INFINITY,
                ..home
            },
            &NewtonOptions::default()
        )
        .map(|_| ()),
        Err(KinematicsError::NonFinite)
    );
}

#[test]
fn singularity_classification() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let home = Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z, 0.0, 0.0, 0.0);
    let q = m.inverse(&home).unwrap();
    assert_eq!(m.jacobians(&home, &q).classify(0.01), Singularity::None);
    // Type 2: the platform in the ring plane, all chains horizontal, cannot resist a vertical force.
    let flat = Pose::new(0.0, 0.0, 1e-9, 0.0, 0.0, 0.0);
    let qf = m.inverse(&flat).unwrap();
    assert!(matches!(
        m.jacobians(&flat, &qf).classify(0.01),
        Singularity::Type2 | Singularity::Type3
    ));
    // Type 1: a rod chain at full stretch (joint at rod length from its carriage, rod horizontal through the ring
    // axis direction) cannot move its joint outward: B loses rank when the rod is tangent to the carriage circle.
    let ch5 = RingPlatform::<f64>::new(&presets::TRAINER_CH5);
    let pose = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
    let mut j = ch5.jacobians(&pose, &ch5.inverse(&pose).unwrap());
    j.b[(0, 0)] = 0.0;
    assert_eq!(j.classify(0.01), Singularity::Type1);
    j.a.set_row(1, &j.a.row(0).clone_owned());
    assert_eq!(j.classify(0.01), Singularity::Type3);
}

#[test]
fn trainer_model_covers_every_spec_axis() {
    // The design claim of the preset: each axis over its full range, at any yaw, passes all six checks.
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let mut checked = 0;
    for (axis, range) in presets::TRAINER_MODEL_RANGES.iter().enumerate() {
        for k in 0..=40 {
            for yaw in 0..36 {
                let mut c = [
                    0.0,
                    0.0,
                    presets::TRAINER_MODEL_HOME_Z,
                    0.0,
                    0.0,
                    yaw as f64 * 10.0 * DEG,
                ];
                c[axis] += -range + 2.0 * range * k as f64 / 40.0;
                let (_, report) = m.inverse_checked(&Pose::from_array(c)).unwrap();
                assert!(report.all_pass(), "{c:?}: {:?} fails", report.first_failure());
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 5 * 41 * 36);
}

#[test]
fn checks_fail_where_they_should() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let z0 = presets::TRAINER_MODEL_HOME_Z;
    let fails = |p: Pose<f64>, c: Check| m.inverse_checked(&p).map(|(_, r)| !r.passes(c)).unwrap_or(false);
    // Stroke: far down the radial actuators are shorter than 160 mm.
    assert!(fails(Pose::new(0.0, 0.0, z0 - 0.09, 0.0, 0.0, 0.0), Check::Reach));
    // Tilted beyond the platform cone.
    assert!(
        fails(Pose::new(0.0, 0.0, z0, 0.0, 40.0 * DEG, 0.0), Check::JointCones)
            || m.inverse(&Pose::new(0.0, 0.0, z0, 0.0, 40.0 * DEG, 0.0)).is_err()
    );
    // Centre of mass far outside the carriages when the platform shifts far sideways.
    let g = RingGeometry::new(
        "heavy-side",
        0.286,
        0.312,
        presets::TRAINER_MODEL.chains(),
        ringpod_core::kinematics::RingLimits {
            centre_of_mass: [0.0, 0.5, 0.0],
            ..presets::TRAINER_MODEL.limits
        },
    )
    .unwrap();
    let heavy = RingPlatform::<f64>::new(&g);
    let (_, r) = heavy.inverse_checked(&Pose::new(0.0, 0.0, z0, 0.0, 0.0, 0.0)).unwrap();
    assert!(r.margin(Check::Stability).unwrap() < 0.0);
}

/// With the carriage order broken, the spacing margin is measured between carriages that are neighbours around the
/// ring (chain-order gaps stop meaning "how far outside"): checked against the gaps sorted here, on random poses
/// whose order is broken.
#[test]
fn spacing_is_measured_in_ring_order_when_the_order_is_broken() {
    let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    let limits = presets::TRAINER_MODEL.limits.carriage_spacing;
    let mut rng = crate::common::Lcg(11);
    let mut uniform = || rng.uniform();
    let mut broken = 0;
    for _ in 0..200_000 {
        let pose = Pose::new(
            uniform() * 0.08,
            uniform() * 0.08,
            0.227 + uniform() * 0.09,
            uniform() * 0.4,
            uniform() * 0.4,
            uniform() * 3.2,
        );
        let Ok((q, report)) = m.inverse_checked(&pose) else {
            continue;
        };
        if report.passes(Check::RodCrossing) {
            continue;
        }
        broken += 1;
        let mut angles: Vec<f64> = q.0[..4].iter().map(|a| a.rem_euclid(std::f64::consts::TAU)).collect();
        angles.sort_by(f64::total_cmp);
        let expected = (0..4)
            .map(|k| {
                let gap = (angles[(k + 1) % 4] - angles[k]).rem_euclid(std::f64::consts::TAU);
                (gap - limits[0]).min(limits[1] - gap)
            })
            .fold(f64::INFINITY, f64::min);
        let got = report.margin(Check::CarriageSpacing).unwrap();
        assert!((got - expected).abs() < 1e-9, "{pose:?}: {got} vs {expected}");
        assert!(got > -std::f64::consts::PI, "{got}");
    }
    assert!(broken > 100, "only {broken} poses with the order broken");
    // The pose of the issue: -4.109 rad over chain-order gaps, -0.374 around the ring.
    let pose = Pose::new(
        0.058449912683985,
        0.058730575477737,
        0.147915588699746,
        0.022745240243061,
        -0.137177905770529,
        1.633892256484312,
    );
    let (_, report) = m.inverse_checked(&pose).unwrap();
    assert!((report.margin(Check::CarriageSpacing).unwrap() + 0.3743).abs() < 1e-3);
}

/// Each kind of singularity is measured on the way in, not only at an exact zero: along a path from a healthy pose
/// to a singular one of the geometry, the index of that kind falls to zero and the classification follows.
#[test]
fn singularities_are_measured_on_the_way_in() {
    fn path(m: &RingPlatform<f64>, zs: &[f64]) -> Vec<(f64, f64, Singularity)> {
        zs.iter()
            .map(|z| {
                let p = Pose::new(0.0, 0.0, *z, 0.0, 0.0, 0.0);
                let j = m.jacobians(&p, &m.inverse(&p).unwrap());
                (j.index_a(), j.index_b(), j.classify(0.01))
            })
            .collect()
    }
    fn falls(values: &[f64]) -> bool {
        values.windows(2).all(|w| w[1] < w[0])
    }
    let trainer = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
    // Type 1: raising the platform until the first rod chain's carriage moves along the rod's sphere
    // (dF1/dq1 = 3.7e-7 at z = 0.298875897118, labelled "none" before).
    let up = path(&trainer, &[0.25, 0.298, 0.2988, 0.29887, 0.298875, 0.298875897118]);
    assert!(falls(&up.iter().map(|s| s.1).collect::<Vec<_>>()), "{up:?}");
    assert_eq!(up[0].2, Singularity::None);
    assert_eq!(up[5].2, Singularity::Type1);
    assert!(up[5].1 < 1e-5 && up.iter().all(|s| s.0 > 0.01), "{up:?}");
    // Type 2: lowering the platform into the ring plane.
    let down = path(&trainer, &[0.1, 0.05, 0.02, 0.01, 0.001, 1e-5]);
    assert!(falls(&down.iter().map(|s| s.0).collect::<Vec<_>>()), "{down:?}");
    assert_eq!(down[0].2, Singularity::None);
    assert_eq!(down[5].2, Singularity::Type2);
    assert!(down.iter().all(|s| s.1 > 0.4), "{down:?}");
    // Type 3: the rotopod raised until every rod is at full stretch (labelled type 2 before).
    let rotopod = RingPlatform::<f64>::new(&presets::ROTOPOD_CH4);
    let both = path(&rotopod, &[0.7, 0.9, 0.95, 0.969, 0.96934, 0.969345008824996]);
    assert!(falls(&both.iter().map(|s| s.0).collect::<Vec<_>>()), "{both:?}");
    assert!(falls(&both.iter().map(|s| s.1).collect::<Vec<_>>()), "{both:?}");
    assert_eq!(both[0].2, Singularity::None);
    assert_eq!(both[5].2, Singularity::Type3);
}
