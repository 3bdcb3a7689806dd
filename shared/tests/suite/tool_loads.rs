//! The tool carrier's loads by paper 003's method (`screws::tool`): equilibrium, virtual work against the IK's
//! joint rates, and every bad input class.

use crate::common::Lcg;
use nalgebra::{Vector3, Vector6};
use ringpod_core::kinematics::{presets, KinematicsError, Mechanism, Pose, ToolCarrier};
use ringpod_core::screws::chains::solve;
use ringpod_core::screws::tool::{chains, tool_loads};

fn carrier() -> ToolCarrier<f64> {
    ToolCarrier::new(&presets::TOOL5_EX)
}

/// A pose around the worked example's (0, 0, 0.4), tilted.
fn pose(rng: &mut Lcg) -> Pose<f64> {
    Pose::new(
        0.05 * rng.uniform(),
        0.08 * rng.uniform(),
        0.4 + 0.05 * rng.uniform(),
        0.3 * rng.uniform(),
        0.4 * rng.uniform(),
        0.0,
    )
}

fn wrench(rng: &mut Lcg) -> [f64; 6] {
    std::array::from_fn(|i| if i < 3 { 50.0 } else { 5.0 } * rng.uniform())
}

/// The wrench the chains exert: minus the tool wrench, about the origin.
fn held(p: &Pose<f64>, w: &[f64; 6]) -> Vector6<f64> {
    let (f, m) = (Vector3::new(w[0], w[1], w[2]), Vector3::new(w[3], w[4], w[5]));
    let m_o = m + Vector3::new(p.x, p.y, p.z).cross(&f);
    -Vector6::new(f.x, f.y, f.z, m_o.x, m_o.y, m_o.z)
}

/// The chains' wrenches add up to the wrench that holds the tool, and each dyad carries a pure force through its
/// frame pivot (a two-force member: its moment about the pivot is zero).
#[test]
fn the_chains_hold_the_tool_wrench() {
    let (m, mut rng) = (carrier(), Lcg(7));
    for _ in 0..300 {
        let (p, w) = (pose(&mut rng), wrench(&mut rng));
        let c = chains(&m, &p).unwrap();
        let h = held(&p, &w);
        let r = solve(&[&c.carriage, &c.dyads[0], &c.dyads[1]], &h).unwrap();
        let sum: Vector6<f64> = r.chain_wrenches[..3].iter().sum();
        assert!((sum - h).norm() < 1e-9 * (1.0 + h.norm()), "{sum} vs {h}");
        for (side, dyad) in c.dyads.iter().enumerate() {
            let w = r.chain_wrenches[1 + side];
            let (f, m_o) = (w.fixed_rows::<3>(0).into_owned(), w.fixed_rows::<3>(3).into_owned());
            let m_pivot = m_o - pivot_of(dyad).cross(&f);
            assert!(m_pivot.norm() < 1e-9 * (1.0 + w.norm()), "dyad {side}: {m_pivot}");
        }
    }
}

/// The spherical joint's point from its three revolute twists `[e; A x e]`.
fn pivot_of(dyad: &[ringpod_core::screws::chains::Joint; 6]) -> Vector3<f64> {
    // A x e_x = (0, A_z, -A_y), A x e_y = (-A_z, 0, A_x).
    let (tx, ty) = (dyad[3].twist, dyad[4].twist);
    Vector3::new(ty[5], -tx[5], tx[4])
}

/// Virtual work: along any motion the platform can make, the drives' power equals the power of the wrench the
/// chains exert on the platform. The joint rates come from the IK by central differences.
#[test]
fn the_drives_do_the_work_of_the_wrench() {
    let (m, mut rng) = (carrier(), Lcg(11));
    let h = 1e-6;
    for _ in 0..300 {
        let (p, w) = (pose(&mut rng), wrench(&mut rng));
        let loads = tool_loads(&m, &p, &w).unwrap();
        let rate: [f64; 5] = std::array::from_fn(|_| rng.uniform());
        let at = |s: f64| {
            let mut a = p.to_array();
            for k in 0..5 {
                a[k] += s * rate[k];
            }
            Pose::from_array(a)
        };
        let (qp, qm) = (m.inverse(&at(h)).unwrap().0, m.inverse(&at(-h)).unwrap().0);
        let dq: [f64; 6] = std::array::from_fn(|k| (qp[k] - qm[k]) / (2.0 * h));
        // Joint rates in the drives' order: q1, q2, elbow (q3 - q2), q4, q5.
        let joint = [dq[0], dq[1], dq[2] - dq[1], dq[3], dq[4]];
        let power: f64 = loads.drives.iter().zip(joint).map(|(t, r)| t * r).sum();
        // The platform's twist about the origin: w = alpha' e_x + beta' (0, cos alpha, sin alpha).
        let omega = Vector3::new(rate[3], rate[4] * p.alpha.cos(), rate[4] * p.alpha.sin());
        let v_p = Vector3::new(rate[0], rate[1], rate[2]);
        let v_o = v_p - omega.cross(&Vector3::new(p.x, p.y, p.z));
        let hw = held(&p, &w);
        let wrench_power = omega.dot(&hw.fixed_rows::<3>(3)) + v_o.dot(&hw.fixed_rows::<3>(0));
        let scale = 1.0 + loads.drives.iter().map(|d| d.abs()).sum::<f64>();
        assert!(
            (power - wrench_power).abs() < 1e-6 * scale,
            "{power} vs {wrench_power} at {p:?}"
        );
    }
}

/// The guide carries what the carriage chain transmits but its drive: its X force is the q1 drive's, and the
/// projected constraint couple is the pseudo-inverse solution, bounded where the unprojected one may not be.
#[test]
fn the_guide_load_contains_the_drive_and_the_couple_is_about_the_frame_normal() {
    let (m, mut rng) = (carrier(), Lcg(3));
    for _ in 0..100 {
        let (p, w) = (pose(&mut rng), wrench(&mut rng));
        let l = tool_loads(&m, &p, &w).unwrap();
        assert!(
            (l.guide_force[0] - l.drives[0]).abs() < 1e-9 * (1.0 + l.drives[0].abs()),
            "{l:?}"
        );
        // The couple is along e_x x (R e_y): no component along e_x or along the pitch axis.
        let pitch_axis = Vector3::new(0.0, p.alpha.cos(), p.alpha.sin());
        for couple in [l.constraint_couple, l.constraint_couple_projected] {
            let c = Vector3::from(couple);
            assert!(c.x.abs() < 1e-9 * (1.0 + c.norm()) && c.dot(&pitch_axis).abs() < 1e-9 * (1.0 + c.norm()));
        }
    }
}

#[test]
fn every_bad_input_is_an_error() {
    let m = carrier();
    let home = Pose::new(0.0, 0.0, 0.4, 0.0, 0.0, 0.0);
    assert_eq!(
        tool_loads(&m, &home, &[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]),
        Err(KinematicsError::NonFinite)
    );
    assert_eq!(
        tool_loads(&m, &Pose::new(0.0, 0.0, 0.4, 0.0, 0.0, 0.1), &[0.0; 6]),
        Err(KinematicsError::OutsideMobility)
    );
    assert!(matches!(
        tool_loads(&m, &Pose::new(0.0, 0.0, 3.0, 0.0, 0.0, 0.0), &[0.0; 6]),
        Err(KinematicsError::Unreachable { .. })
    ));
    assert_eq!(
        tool_loads(&m, &Pose::new(f64::INFINITY, 0.0, 0.4, 0.0, 0.0, 0.0), &[0.0; 6]),
        Err(KinematicsError::NonFinite)
    );
    // No load, no reaction.
    let zero = tool_loads(&m, &home, &[0.0; 6]).unwrap();
    assert!(zero.drives.iter().all(|d| *d == 0.0), "{zero:?}");
}
