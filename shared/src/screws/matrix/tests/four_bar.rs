//! The planar four-bar of SCREWS.md 4 (T1, T3) as a [`Mechanism`]: its recomputed positions, rates, accelerations
//! and mass; its equation of motion: energy kept without friction, the friction's and forces' power, forward
//! dynamics of the inverse dynamics' forces reproducing the motion, `tau(u'') - tau(0) = M u''`; every bad input.

use nalgebra::{Matrix4, Vector3};
use proptest::prelude::*;

use super::super::mechanism::{MAX_DRIVES, MAX_VARIABLES};
use super::super::*;

fn tx(a: f64) -> Matrix4<f64> {
    translation(Vector3::new(a, 0.0, 0.0))
}

fn four_bar() -> Result<Mechanism, LoopError> {
    let pair = |parent: usize, place: Matrix4<f64>| Pair {
        joint: Joint::Revolute,
        parent,
        place,
    };
    let pairs = [
        pair(GROUND, Matrix4::identity()),
        pair(1, tx(0.10)),
        pair(2, tx(0.35)),
        pair(3, tx(0.20)),
    ];
    let closure = Closure {
        a: 4,
        b: GROUND,
        offset: tx(-0.30),
    };
    Mechanism::new(&pairs, &[closure], &[0])
}

/// T3's rods (1, 2 and 1.5 kg from each joint along its link), gravity along -y, a spring and a damper on the
/// coupler's pair and a force on the rocker's.
fn model(damping: f64, force: f64) -> Result<Model, LoopError> {
    let bodies = [
        Body {
            link: 1,
            inertia: rod_along_x(1.0, 0.10),
        },
        Body {
            link: 2,
            inertia: rod_along_x(2.0, 0.35),
        },
        Body {
            link: 3,
            inertia: rod_along_x(1.5, 0.20),
        },
    ];
    let elements = [
        Element {
            variable: 1,
            stiffness: 3.0,
            rest: -0.6,
            damping,
            ..Element::default()
        },
        Element {
            variable: 2,
            force,
            ..Element::default()
        },
    ];
    Model::new(four_bar()?, &bodies, &elements, Vector3::new(0.0, -9.81, 0.0))
}

const DEG: f64 = core::f64::consts::PI / 180.0;

fn guess() -> [f64; MAX_VARIABLES] {
    let mut q = [0.0; MAX_VARIABLES];
    q[..4].copy_from_slice(&[60.0 * DEG, -52.0 * DEG, -137.0 * DEG, 120.0 * DEG]);
    q
}

#[test]
fn t1_positions_rates_and_accelerations() -> Result<(), LoopError> {
    let m = four_bar()?;
    let (q, iterations) = m.close(&guess(), 1e-13, 30)?;
    let expected = [60.0, -44.535497, -131.354371, 115.889868];
    for (got, want) in q.iter().zip(&expected) {
        assert!((got / DEG - want).abs() < 1e-6, "{:?}", &q[..4]);
    }
    assert!(iterations <= 6, "{iterations}");
    assert!(m.closure_error(&q)? < 1e-14);
    let f = m.frames(&q)?;
    let qd = m.rates(&f, &[10.0])?;
    for (got, want) in qd.iter().zip(&[10.0, -10.272811, 4.944514, -4.671703]) {
        assert!((got - want).abs() < 1e-6 * 10.0, "{:?}", &qd[..4]);
    }
    let qdd = m.accelerations(&f, &qd, &[0.0])?;
    for (got, want) in qdd.iter().zip(&[0.0, 21.416201, 7.027740, -28.443941]) {
        assert!((got - want).abs() < 1e-6 * 30.0, "{:?}", &qdd[..4]);
    }
    Ok(())
}

#[test]
fn t3_mass_and_the_single_loops_agree() -> Result<(), LoopError> {
    let model = model(0.0, 0.0)?;
    let q = model.closed(&guess(), &[60.0 * DEG])?;
    let m = model.mass(&model.mechanism.frames(&q)?)?;
    assert!((m[0][0] - 0.0263978).abs() < 1e-7, "{}", m[0][0]);
    Ok(())
}

#[test]
fn a_link_points_velocity_and_acceleration_are_the_derivatives_of_its_path() -> Result<(), LoopError> {
    let model = model(0.0, 0.0)?;
    let m = &model.mechanism;
    let u = |t: f64| 1.0 + 0.3 * libm::sin(3.0 * t);
    let r = Vector3::new(0.2, 0.05, 0.01);
    let at = |t: f64, q: &[f64; MAX_VARIABLES]| -> Result<_, LoopError> {
        let s = model.solve_point(q, &[u(t)], &[0.9 * libm::cos(3.0 * t)], &[-2.7 * libm::sin(3.0 * t)])?;
        Ok(m.point(&s.frames, &s.state.qd, &s.qdd, 2, &r))
    };
    let q = model.closed(&guess(), &[u(0.4)])?;
    let h = 1e-5;
    let [_, v, a] = at(0.4, &q)?;
    let ([xm, vm, _], [xp, vp, _]) = (at(0.4 - h, &q)?, at(0.4 + h, &q)?);
    assert!(((xp - xm) / (2.0 * h) - v).amax() < 1e-7, "{v}");
    assert!(((vp - vm) / (2.0 * h) - a).amax() < 1e-6, "{a}");
    assert!(v.norm() > 0.01, "{v}");
    Ok(())
}

/// Integrates the drive from `u0` at rest for `steps` of `dt` under the drive force `tau(t)`.
fn integrate(
    model: &Model,
    u0: f64,
    ud0: f64,
    steps: usize,
    dt: f64,
    tau: impl Fn(f64) -> f64,
) -> Result<Vec<(f64, f64, [f64; MAX_VARIABLES])>, LoopError> {
    let mut q = model.closed(&guess(), &[u0])?;
    let (mut u, mut ud) = ([0.0; MAX_DRIVES], [0.0; MAX_DRIVES]);
    (u[0], ud[0]) = (u0, ud0);
    let mut out = vec![(u0, ud0, q)];
    for k in 0..steps {
        let t0 = k as f64 * dt;
        (u, ud, q) = model.step(&q, &u, &ud, dt, |t| {
            let mut f = [0.0; MAX_DRIVES];
            f[0] = tau(t0 + t);
            f
        })?;
        out.push((u[0], ud[0], q));
    }
    Ok(out)
}

fn total_energy(model: &Model, u: f64, ud: f64, q: &[f64; MAX_VARIABLES]) -> Result<f64, LoopError> {
    let s = model.solve_point(q, &[u], &[ud], &[0.0])?;
    let e = model.energy(&s.frames, &s.state);
    Ok(e.kinetic + e.gravity + e.springs)
}

#[test]
fn without_friction_the_energy_is_kept() -> Result<(), LoopError> {
    let model = model(0.0, 0.0)?;
    let path = integrate(&model, 60.0 * DEG, 0.0, 800, 5e-4, |_| 0.0)?;
    let start = total_energy(&model, path[0].0, path[0].1, &path[0].2)?;
    let mut swing = 0.0f64;
    for (u, ud, q) in &path {
        let e = total_energy(&model, *u, *ud, q)?;
        // RK4's drift at this step is below 1e-9 J over the 0.4 s (a step twice as long drifts 1e-8 J).
        assert!((e - start).abs() < 2e-9, "{e} vs {start}");
        swing = swing.max((u - path[0].0).abs());
    }
    assert!(swing > 0.2, "the linkage must move: {swing}");
    Ok(())
}

#[test]
fn the_drives_and_elements_power_is_the_energys_rate() -> Result<(), LoopError> {
    let model = model(0.4, 1.5)?;
    let (u, ud, udd) = (
        |t: f64| 1.0 + 0.3 * libm::sin(3.0 * t),
        |t: f64| 0.9 * libm::cos(3.0 * t),
        |t: f64| -2.7 * libm::sin(3.0 * t),
    );
    let q = model.closed(&guess(), &[u(0.5)])?;
    let energy = |t: f64| -> Result<f64, LoopError> {
        let s = model.solve_point(&q, &[u(t)], &[ud(t)], &[udd(t)])?;
        let e = model.energy(&s.frames, &s.state);
        Ok(e.kinetic + e.gravity + e.springs)
    };
    let s = model.solve_point(&q, &[u(0.5)], &[ud(0.5)], &[udd(0.5)])?;
    let power = s.forces[0] * ud(0.5) + model.element_power(&s.state);
    let h = 1e-5;
    let rate = (energy(0.5 + h)? - energy(0.5 - h)?) / (2.0 * h);
    assert!((power - rate).abs() < 1e-7, "{power} vs {rate}");
    assert!(model.element_power(&s.state).abs() > 0.01);
    Ok(())
}

#[test]
fn forward_dynamics_of_the_inverse_dynamics_forces_reproduces_the_motion() -> Result<(), LoopError> {
    let model = model(0.4, 1.5)?;
    let u = |t: f64| 1.0 + 0.3 * libm::sin(3.0 * t);
    let ud = |t: f64| 0.9 * libm::cos(3.0 * t);
    let udd = |t: f64| -2.7 * libm::sin(3.0 * t);
    let q = model.closed(&guess(), &[u(0.0)])?;
    let tau = |t: f64| {
        model
            .solve_point(&q, &[u(t)], &[ud(t)], &[udd(t)])
            .map_or(f64::NAN, |s| s.forces[0])
    };
    let (steps, dt) = (500, 2e-3);
    let path = integrate(&model, u(0.0), ud(0.0), steps, dt, tau)?;
    for (k, (got, rate, _)) in path.iter().enumerate() {
        let t = k as f64 * dt;
        assert!((got - u(t)).abs() < 1e-8, "t {t}: {got} vs {}", u(t));
        assert!((rate - ud(t)).abs() < 1e-7, "t {t}: {rate} vs {}", ud(t));
    }
    Ok(())
}

proptest! {
    #[test]
    fn the_forces_are_the_mass_times_the_acceleration_plus_the_rest(
        u in 0.6f64..1.4, ud in -3.0f64..3.0, udd in -20.0f64..20.0,
    ) {
        let fail = |e: LoopError| TestCaseError::fail(format!("{e:?}"));
        let model = model(0.4, 1.5).map_err(fail)?;
        let q = model.closed(&guess(), &[u]).map_err(fail)?;
        let moving = model.solve_point(&q, &[u], &[ud], &[udd]).map_err(fail)?;
        let coasting = model.solve_point(&q, &[u], &[ud], &[0.0]).map_err(fail)?;
        let m = model.mass(&moving.frames).map_err(fail)?[0][0];
        prop_assert!(m > 0.0);
        let inertial = moving.forces[0] - coasting.forces[0];
        prop_assert!((inertial - m * udd).abs() <= 1e-10 * (1.0 + (m * udd).abs()), "{} vs {}", inertial, m * udd);
    }
}

#[test]
fn every_bad_mechanism_and_model_is_refused() -> Result<(), LoopError> {
    let r = |parent| Pair {
        joint: Joint::Revolute,
        parent,
        place: Matrix4::identity(),
    };
    let closure = |a, b| Closure {
        a,
        b,
        offset: Matrix4::identity(),
    };
    let ok_loop = [closure(2, GROUND)];
    // A pair hanging from a link not built yet; a loop to a missing link or to itself.
    assert_eq!(Mechanism::new(&[r(1), r(1)], &ok_loop, &[0]), Err(LoopError::Shape));
    assert_eq!(
        Mechanism::new(&[r(0), r(1)], &[closure(3, 0)], &[0]),
        Err(LoopError::Shape)
    );
    assert_eq!(
        Mechanism::new(&[r(0), r(1)], &[closure(2, 2)], &[0]),
        Err(LoopError::Shape)
    );
    // A drive out of range or repeated; too many unknowns for the loops; past the capacities.
    assert_eq!(Mechanism::new(&[r(0), r(1)], &ok_loop, &[2]), Err(LoopError::Shape));
    assert_eq!(Mechanism::new(&[r(0), r(1)], &ok_loop, &[0, 0]), Err(LoopError::Shape));
    assert_eq!(Mechanism::new(&[r(0); 8], &ok_loop, &[0]), Err(LoopError::Shape));
    assert_eq!(Mechanism::new(&[r(0); 25], &[], &[]), Err(LoopError::Shape));
    let spheres = [Pair {
        joint: Joint::Spherical,
        ..r(0)
    }; 15];
    assert_eq!(Mechanism::new(&spheres, &[], &[]), Err(LoopError::Shape));
    // Non-finite placements and offsets.
    let mut bad = r(0);
    bad.place[(1, 0)] = f64::NAN;
    assert_eq!(Mechanism::new(&[bad, r(1)], &ok_loop, &[0]), Err(LoopError::NonFinite));
    let mut off = closure(2, 0);
    off.offset[(2, 0)] = f64::INFINITY;
    assert_eq!(Mechanism::new(&[r(0), r(1)], &[off], &[0]), Err(LoopError::NonFinite));
    // A model's body on a missing link, an element on a missing variable, a non-finite number.
    let m = four_bar()?;
    let g = Vector3::new(0.0, 0.0, -9.81);
    let body = |link| Body {
        link,
        inertia: rod_along_x(1.0, 0.1),
    };
    assert_eq!(Model::new(m, &[body(5)], &[], g), Err(LoopError::Shape));
    let el = Element {
        variable: 4,
        ..Element::default()
    };
    assert_eq!(Model::new(m, &[], &[el], g), Err(LoopError::Shape));
    assert_eq!(
        Model::new(m, &[body(1)], &[], Vector3::new(0.0, f64::NAN, 0.0)),
        Err(LoopError::NonFinite)
    );
    // Points of a motion: a wrong drive count, non-finite drives and positions.
    let model = model(0.0, 0.0)?;
    let q = guess();
    assert_eq!(
        model.solve_point(&q, &[1.0, 2.0], &[0.0], &[0.0]).err(),
        Some(LoopError::Shape)
    );
    assert_eq!(
        model.solve_point(&q, &[1.0], &[f64::NAN], &[0.0]).err(),
        Some(LoopError::NonFinite)
    );
    assert_eq!(model.closed(&q, &[f64::INFINITY]).err(), Some(LoopError::NonFinite));
    assert_eq!(
        model.drive_accelerations(&q, &[1.0], &[0.0], &[f64::NAN]).err(),
        Some(LoopError::NonFinite)
    );
    Ok(())
}
