//! Invariants over many random inputs: IK/FK round trips, Jacobians against finite differences, velocity and

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]
//! statics consistency, multi-turn tracking, and no panic on any input.

use proptest::prelude::*;
use ringpod_core::kinematics::{
    presets, Actuators, AxisKind, Check, KinematicsError, Mechanism, MultiTurn, NewtonOptions, Pose, RingPlatform,
    ToolCarrier,
};

fn trainer() -> RingPlatform<f64> {
    RingPlatform::new(&presets::TRAINER_MODEL)
}
fn rotopod() -> RingPlatform<f64> {
    RingPlatform::new(&presets::ROTOPOD_CH4)
}
fn tool() -> ToolCarrier<f64> {
    ToolCarrier::new(&presets::TOOL5_EX)
}

/// Poses around the trainer model's home, a little beyond its spec ranges, any yaw.
fn trainer_pose() -> impl Strategy<Value = Pose<f64>> {
    let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES;
    let z0 = presets::TRAINER_MODEL_HOME_Z;
    (-t..t, -t..t, z0 - h..z0 + h, -r..r, -r..r, -40.0..40.0f64)
        .prop_map(|(x, y, z, a, b, g)| Pose::new(x, y, z, a, b, g))
}

fn rotopod_pose() -> impl Strategy<Value = Pose<f64>> {
    (
        -0.1..0.1f64,
        -0.1..0.1f64,
        0.55..0.85f64,
        -0.15..0.15f64,
        -0.15..0.15f64,
        -7.0..7.0f64,
    )
        .prop_map(|(x, y, z, a, b, g)| Pose::new(x, y, z, a, b, g))
}

fn tool_pose() -> impl Strategy<Value = Pose<f64>> {
    (-0.2..0.2f64, -0.1..0.1f64, 0.30..0.50f64, -0.4..0.4f64, -0.5..0.5f64)
        .prop_map(|(x, y, z, a, b)| Pose::new(x, y, z, a, b, 0.0))
}

/// The last known pose of a 1 kHz loop is close to the new one: offset the truth by up to 2 mm and 1 degree
/// (20 times a tick at the model's top speed of 0.05 m/s).
fn near(p: &Pose<f64>, e: [f64; 6], dof: usize) -> Pose<f64> {
    let mut v = p.to_array();
    for (i, c) in v.iter_mut().enumerate().take(dof) {
        *c += e[i] * if i < 3 { 0.002 } else { 1f64.to_radians() };
    }
    Pose::from_array(v)
}

fn offsets() -> impl Strategy<Value = [f64; 6]> {
    prop::array::uniform6(-1.0..1.0f64)
}

fn same_pose(a: &Pose<f64>, b: &Pose<f64>, tol: f64) -> bool {
    a.to_array().iter().zip(b.to_array()).enumerate().all(|(i, (x, y))| {
        let d = if i == 5 {
            (x - y + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        } else {
            x - y
        };
        d.abs() <= tol
    })
}

fn round_trip<M: Mechanism<f64>>(m: &M, pose: &Pose<f64>, e: [f64; 6]) -> Result<(), TestCaseError> {
    let Ok((q, report)) = m.inverse_checked(pose) else {
        return Ok(());
    };
    // Within 2x the singularity thresholds the FK may rightly refuse; elsewhere it must converge. The poses reach a
    // little beyond the checks: FK is asked for the math, not for a pose the platform may take.
    if report.singularity_index < 0.05 || m.jacobians(pose, &q).index_a() < 0.02 {
        return Ok(());
    }
    let options = NewtonOptions {
        inside: false,
        ..NewtonOptions::default()
    };
    let fk = m.forward(&q, &near(pose, e, m.dof()), &options);
    let sol = fk.map_err(|err| TestCaseError::fail(format!("FK failed at {pose:?}: {err}")))?;
    prop_assert!(same_pose(&sol.pose, pose, 1e-9), "{:?} vs {:?}", sol.pose, pose);
    prop_assert!(sol.iterations <= 8, "{} iterations", sol.iterations);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// IK alone solves without the configuration the checks read: the same actuators, bit for bit, or the same
    /// error, as IK with the checks, for the rod, radial and elbow chains, in `f32` and `f64`, inside the
    /// workspace and well beyond it.
    #[test]
    fn ik_alone_equals_ik_with_the_checks(pose in trainer_pose(), scale in 1.0..4.0f64) {
        let home = presets::TRAINER_MODEL_HOME_Z;
        let p = Pose::new(pose.x * scale, pose.y * scale, home + (pose.z - home) * scale, pose.alpha * scale,
            pose.beta * scale, pose.gamma);
        for geometry in [&presets::TRAINER_MODEL, &presets::TRAINER_ELBOW] {
            let m64 = RingPlatform::<f64>::new(geometry);
            let m32 = RingPlatform::<f32>::new(geometry);
            prop_assert_eq!(m64.inverse(&p), m64.inverse_checked(&p).map(|(q, _)| q));
            let p32 = p.cast::<f32>();
            prop_assert_eq!(m32.inverse(&p32), m32.inverse_checked(&p32).map(|(q, _)| q));
        }
    }

    /// The checks evaluated in order up to the first short of its room find what the full report finds: the same
    /// actuators, or the same first check (reach when there is no IK), with rooms from negative to wide.
    #[test]
    fn checks_up_to_the_first_short_equal_the_full_report(
        pose in trainer_pose(),
        scale in 1.0..4.0f64,
        room in prop::array::uniform6(-0.05..0.1f64),
    ) {
        let home = presets::TRAINER_MODEL_HOME_Z;
        let p = Pose::new(pose.x * scale, pose.y * scale, home + (pose.z - home) * scale, pose.alpha * scale,
            pose.beta * scale, pose.gamma);
        fn full<T: ringpod_core::Real>(m: &RingPlatform<T>, p: &Pose<T>, room: &[T; 6]) -> Result<Actuators<T>, Check> {
            match m.inverse_checked(p) {
                Ok((q, report)) => report.first_below(room).map_or(Ok(q), Err),
                Err(_) => Err(Check::Reach),
            }
        }
        for geometry in [&presets::TRAINER_MODEL, &presets::TRAINER_ELBOW, &presets::ROTOPOD_CH4] {
            let m64 = RingPlatform::<f64>::new(geometry);
            prop_assert_eq!(m64.inverse_within(&p, &room), full(&m64, &p, &room));
            let (m32, p32, room32) = (RingPlatform::<f32>::new(geometry), p.cast::<f32>(), room.map(|r| r as f32));
            prop_assert_eq!(m32.inverse_within(&p32, &room32), full(&m32, &p32, &room32));
        }
    }

    #[test]
    fn trainer_ik_fk_round_trip(pose in trainer_pose(), e in offsets()) {
        round_trip(&trainer(), &pose, e)?;
    }

    #[test]
    fn rotopod_ik_fk_round_trip(pose in rotopod_pose(), e in offsets()) {
        round_trip(&rotopod(), &pose, e)?;
    }

    #[test]
    fn tool_ik_fk_round_trip(pose in tool_pose(), e in offsets()) {
        round_trip(&tool(), &pose, e)?;
    }

    /// Every assembly of the tool carrier's dyads closes the pose it was solved for (FK from near it returns it),
    /// and the branches differ in the dyad's drive unless that dyad is stretched straight.
    #[test]
    fn tool_every_assembly_round_trips(pose in tool_pose(), e in offsets()) {
        use ringpod_core::kinematics::geometry::Branch::{Minus, Plus};
        for branches in [[Minus, Minus], [Minus, Plus], [Plus, Minus], [Plus, Plus]] {
            round_trip(&tool().with_branches(branches), &pose, e)?;
        }
        if let (Ok(minus), Ok(plus)) = (tool().inverse(&pose), tool().with_branches([Plus, Plus]).inverse(&pose)) {
            for drive in [1, 3] {
                prop_assert!((minus.0[drive] - plus.0[drive]).abs() > 1e-6, "q{} {minus:?} {plus:?}", drive + 1);
            }
            prop_assert_eq!(minus.0[0], plus.0[0]);
        }
    }

    /// IK solutions satisfy the constraint equations the FK and the Jacobians are built on.
    #[test]
    fn ik_solutions_zero_the_residuals(pose in trainer_pose(), rp in rotopod_pose(), tp in tool_pose()) {
        fn zero<M: Mechanism<f64>>(m: &M, p: &Pose<f64>) -> Result<(), TestCaseError> {
            if let Ok(q) = m.inverse(p) {
                let r = m.residuals(p, &q);
                prop_assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
            }
            Ok(())
        }
        zero(&trainer(), &pose)?;
        zero(&rotopod(), &rp)?;
        zero(&tool(), &tp)?;
    }

    /// The fused IK + checks (carriages from the IK's triangle, no angle) reports what the checks of the pose and
    /// its actuators report (carriages from the angles), in f64 and in the f32 the MCU runs.
    #[test]
    fn fused_checks_agree_with_separate_ones(pose in trainer_pose(), rp in rotopod_pose()) {
        fn agree<T: ringpod_core::Real>(m: &RingPlatform<T>, p: &Pose<f64>, tol: f64) -> Result<(), TestCaseError> {
            let p = p.cast::<T>();
            let Ok((q, fused)) = m.inverse_checked(&p) else {
                prop_assert!(m.inverse(&p).is_err());
                return Ok(());
            };
            prop_assert_eq!(m.inverse(&p).ok(), Some(q));
            let separate = m.workspace(&p, &q);
            for check in Check::ALL {
                let (a, b) = (fused.margin(check).map(|v| v.to_f64()), separate.margin(check).map(|v| v.to_f64()));
                let (a, b) = (a.unwrap_or(f64::NAN), b.unwrap_or(f64::NAN));
                prop_assert!((a - b).abs() <= tol, "{check}: fused {a} vs separate {b}");
            }
            Ok(())
        }
        agree(&trainer(), &pose, 1e-12)?;
        agree(&rotopod(), &rp, 1e-12)?;
        agree(&RingPlatform::<f32>::new(&presets::TRAINER_MODEL), &pose, 2e-5)?;
        agree(&RingPlatform::<f32>::new(&presets::ROTOPOD_CH4), &rp, 2e-5)?;
    }
}

/// Central differences of the residuals against the analytic Jacobians.
fn jacobians_match<M: Mechanism<f64>>(m: &M, pose: &Pose<f64>) -> Result<(), TestCaseError> {
    let Ok(q) = m.inverse(pose) else { return Ok(()) };
    let j = m.jacobians(pose, &q);
    let h = 1e-6;
    for k in 0..6 {
        let mut p1 = pose.to_array();
        let mut p0 = pose.to_array();
        p1[k] += h;
        p0[k] -= h;
        let d = (m.residuals(&Pose::from_array(p1), &q) - m.residuals(&Pose::from_array(p0), &q)) / (2.0 * h);
        for r in 0..6 {
            prop_assert!(
                (d[r] - j.a[(r, k)]).abs() < 1e-6,
                "A[{r},{k}] {} vs {}",
                j.a[(r, k)],
                d[r]
            );
        }
        let (mut q1, mut q0) = (q, q);
        q1.0[k] += h;
        q0.0[k] -= h;
        let d = (m.residuals(pose, &q1) - m.residuals(pose, &q0)) / (2.0 * h);
        for r in 0..6 {
            prop_assert!(
                (d[r] - j.b[(r, k)]).abs() < 1e-6,
                "B[{r},{k}] {} vs {}",
                j.b[(r, k)],
                d[r]
            );
        }
    }
    Ok(())
}

/// Pose rates -> actuator rates -> pose rates is the identity over the DOF, and actuator rates match the IK's
/// finite difference along the motion.
fn rates_consistent<M: Mechanism<f64>>(m: &M, pose: &Pose<f64>, dir: [f64; 6]) -> Result<(), TestCaseError> {
    let Ok((q, report)) = m.inverse_checked(pose) else {
        return Ok(());
    };
    // Finite differences need distance from both singularity types (see drive_loads_balance_virtual_work).
    if report.singularity_index < 0.05 || report.margin(Check::Reach).unwrap() < 1e-3 {
        return Ok(());
    }
    let mut pd = nalgebra::Vector6::from(dir);
    for r in m.dof()..6 {
        pd[r] = 0.0;
    }
    let j = m.jacobians(pose, &q);
    let qd = j.actuator_rates(&pd).map_err(|e| TestCaseError::fail(e.to_string()))?;
    let back = j.pose_rates(&qd).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert!((back - pd).amax() < 1e-8, "{back:?} vs {pd:?}");
    let h = 1e-6;
    let step = |s: f64| Pose::from_vector(&(pose.to_vector() + pd * s));
    if let (Ok(q1), Ok(q0)) = (m.inverse(&step(h)), m.inverse(&step(-h))) {
        for i in 0..6 {
            let mut d = q1.0[i] - q0.0[i];
            if m.axes()[i] == AxisKind::Ring {
                d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            }
            // Central differences lose digits where rates are large (near type-1 edges); a wrong term is off by order one.
            prop_assert!(
                (d / (2.0 * h) - qd[i]).abs() < 1e-4 * (1.0 + qd[i].abs()),
                "axis {i}: {} vs {}",
                d / (2.0 * h),
                qd[i]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    #[test]
    fn jacobians_are_the_derivatives(pose in trainer_pose(), rp in rotopod_pose(), tp in tool_pose()) {
        jacobians_match(&trainer(), &pose)?;
        jacobians_match(&rotopod(), &rp)?;
        jacobians_match(&tool(), &tp)?;
    }

    #[test]
    fn velocities_are_consistent(pose in trainer_pose(), rp in rotopod_pose(), tp in tool_pose(), dir in prop::array::uniform6(-1.0..1.0f64)) {
        rates_consistent(&trainer(), &pose, dir)?;
        rates_consistent(&rotopod(), &rp, dir)?;
        rates_consistent(&tool(), &tp, dir)?;
    }

    /// Statics by virtual work: the drives' work plus the external wrench's work is zero for any small motion.
    #[test]
    fn drive_loads_balance_virtual_work(pose in trainer_pose(), dir in prop::array::uniform6(-1.0..1.0f64), mass in 0.1..5.0f64) {
        let m = trainer();
        let Ok((q, report)) = m.inverse_checked(&pose) else { return Ok(()) };
        // Away from type-2 (wrench index) and type-1 (reach boundary, where angles go like a square root and finite
        // differences lose digits as (h / distance)^2) singularities.
        prop_assume!(report.singularity_index > 0.05 && report.margin(Check::Reach).unwrap() > 1e-3);
        let w = m.gravity_wrench(&pose, mass);
        let loads = m.loads(&pose, &q, &w).unwrap();
        let h = 1e-6;
        let step = |s: f64| Pose::from_vector(&(pose.to_vector() + nalgebra::Vector6::from(dir) * s));
        let (p1, p0) = (step(h), step(-h));
        let (q1, q0) = (m.inverse(&p1).unwrap(), m.inverse(&p0).unwrap());
        let (mut drive_work, mut magnitude) = (0.0, 0.0);
        for i in 0..6 {
            let mut dq = q1.0[i] - q0.0[i];
            if i < 4 {
                dq = (dq + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            }
            drive_work += loads.drives[i] * dq;
            magnitude += (loads.drives[i] * dq).abs();
        }
        // Work of the wrench [F; M about O]: F . (velocity of the body point at O) + M . (rotation).
        let (r1, r0) = (p1.rotation(), p0.rotation());
        let dr = (r1 - r0) * r0.transpose();
        let dtheta = nalgebra::Vector3::new(dr[(2, 1)], dr[(0, 2)], dr[(1, 0)]);
        let dpos = p1.position() - p0.position();
        let v_origin = dpos - dtheta.cross(&pose.position());
        let load_work = w.fixed_rows::<3>(0).dot(&v_origin) + w.fixed_rows::<3>(3).dot(&dtheta);
        // Central differences agree to about 1e-6 of the terms that add up; a wrong sign or lever arm is off by order one.
        magnitude += w.fixed_rows::<3>(0).abs().dot(&v_origin.abs()) + w.fixed_rows::<3>(3).abs().dot(&dtheta.abs());
        prop_assert!((drive_work + load_work).abs() <= 1e-5 * magnitude, "{drive_work} + {load_work} (terms {magnitude})");
    }
}

/// Any bit pattern as an f64/f32: NaN, infinities, subnormals, huge values.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<u64>().prop_map(f64::from_bits),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        -1e6..1e6f64,
        -2.0..2.0f64,
    ]
}

fn never_panics<T: ringpod_core::Real, M: Mechanism<T>>(m: &M, v: [f64; 6], w: [f64; 6]) {
    let pose = Pose::from_array(v.map(T::of));
    let q = Actuators(w.map(T::of));
    let _ = m.inverse(&pose);
    let _ = m.inverse_checked(&pose);
    let _ = m.residuals(&pose, &q);
    let j = m.jacobians(&pose, &q);
    let _ = j.actuator_rates(&q.to_vector());
    let _ = j.pose_rates(&q.to_vector());
    let _ = j.classify(T::of(0.01));
    let _ = m.workspace(&pose, &q);
    if let Ok(sol) = m.forward(&q, &pose, &NewtonOptions::default()) {
        assert!(sol.pose.to_array().iter().all(|c| c.finite()));
    }
    let mut mt = MultiTurn::new(q);
    let _ = mt.inverse_near(m, &pose);
    let _ = mt.ring_steps(0, 25_600);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, ..ProptestConfig::default() })]

    #[test]
    fn garbage_never_panics(v in prop::array::uniform6(any_f64()), w in prop::array::uniform6(any_f64())) {
        never_panics(&RingPlatform::<f64>::new(&presets::TRAINER_MODEL), v, w);
        never_panics(&RingPlatform::<f32>::new(&presets::TRAINER_MODEL), v, w);
        never_panics(&RingPlatform::<f64>::new(&presets::ROTOPOD_CH4), v, w);
        never_panics(&ToolCarrier::<f64>::new(&presets::TOOL5_EX), v, w);
        never_panics(&ToolCarrier::<f32>::new(&presets::TOOL5_EX), v, w);
        let m = RingPlatform::<f64>::new(&presets::TRAINER_MODEL);
        let pose = Pose::from_array(v);
        let _ = m.loads(&pose, &Actuators(w), &nalgebra::Vector6::from(w));
        let _ = m.reach_margin(&pose);
    }

    /// NaN or infinity anywhere in a pose is always the NonFinite error, never an answer.
    #[test]
    fn non_finite_poses_are_rejected(mut v in prop::array::uniform6(-0.1..0.1f64), at in 0..6usize, bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)]) {
        v[at] = bad;
        prop_assert_eq!(trainer().inverse(&Pose::from_array(v)), Err(KinematicsError::NonFinite));
        prop_assert_eq!(tool().inverse(&Pose::from_array(v)), Err(KinematicsError::NonFinite));
        let fk = trainer().forward(&Actuators(v), &Pose::default(), &NewtonOptions::default());
        prop_assert_eq!(fk.map(|_| ()), Err(KinematicsError::NonFinite));
    }

    /// The f32 kinematics agree with f64 to within a small fraction of a motor step (4,000 steps/rad, 1.6 M steps/m).
    #[test]
    fn f32_tracks_f64(pose in trainer_pose()) {
        let wide = trainer();
        let narrow = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
        let pose = Pose { gamma: pose.gamma.rem_euclid(std::f64::consts::TAU), ..pose };
        if let Ok(q64) = wide.inverse(&pose) {
            let q32 = narrow.inverse(&pose.cast()).unwrap();
            for i in 0..6 {
                let d = (q64.0[i] - f64::from(q32.0[i])).abs();
                let d = if i < 4 { d.min(std::f64::consts::TAU - d) } else { d };
                let step = if i < 4 { 1.0 / 4000.0 } else { 1.0 / 1.6e6 };
                prop_assert!(d < 0.25 * step, "axis {i}: {d} ({} steps)", d / step);
            }
        }
    }
}

/// Share of 1000 samples that a round-trip property really exercises (reachable, index >= 0.05).
fn usable<M: Mechanism<f64>>(m: &M, strategy: impl Strategy<Value = Pose<f64>>) -> usize {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    (0..1000)
        .filter(|_| {
            let pose = strategy.new_tree(&mut runner).unwrap().current();
            m.inverse_checked(&pose).is_ok_and(|(_, r)| r.singularity_index >= 0.05)
        })
        .count()
}

/// The round-trip properties skip unreachable and near-singular poses: make sure most samples are real trips.
#[test]
fn round_trips_are_not_vacuous() {
    let (t, r, k) = (
        usable(&trainer(), trainer_pose()),
        usable(&rotopod(), rotopod_pose()),
        usable(&tool(), tool_pose()),
    );
    assert!(
        t > 400 && r > 900 && k > 500,
        "usable samples of 1000: trainer {t}, rotopod {r}, tool {k}"
    );
    println!("usable samples of 1000: trainer {t}, rotopod {r}, tool {k}");
}
