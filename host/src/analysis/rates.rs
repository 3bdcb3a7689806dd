//! `ringpod rates`: the velocity problem of the source's chapter 4 at a pose. Differentiating the constraint
//! equations `F(p, q) = 0` gives `A p' + B q' = 0` (Angeles and Gosselin's form, `A = dF/dp`, `B = dF/dq`): the
//! actuator rates for given pose rates (`q' = -B^-1 A p'`, the inverse problem), or the pose rates for given
//! actuator rates (`p' = -A^-1 B q'`, the direct problem), with the platform's angular velocity, `A`, `B` and the
//! condition number of each (a type 1 singularity makes `B` singular, a type 2 makes `A` singular).

use std::fmt::Write as _;

use nalgebra::{Matrix6, Vector6};
use ringpod_core::kinematics::{Mechanism, Pose};
use serde::Serialize;

use super::kinematics::{pose_arg, On};
use super::mechanism::Selected;
use crate::error::CliError;
use crate::input::numbers;
use crate::out::Outcome;

/// The rates given.
pub enum Given<'a> {
    /// `x', y', z', alpha', beta', gamma'` (m/s; rad/s, or deg/s with `--degrees`).
    PoseRates(&'a str),
    /// Six actuator rates (rad/s or m/s; deg/s for angles with `--degrees`).
    ActuatorRates(&'a str),
}

/// `rates`: the platform, the pose (the home pose when none) and the rates given.
pub struct Options<'a> {
    pub on: On<'a>,
    pub pose: Option<&'a str>,
    pub given: Given<'a>,
}

#[derive(Serialize)]
struct RatesJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    pose_rates: [f64; 6],
    actuator_rates: [f64; 6],
    /// The platform's angular velocity in base axes (rad/s, or deg/s).
    angular_velocity: [f64; 3],
    a: [[f64; 6]; 6],
    b: [[f64; 6]; 6],
    condition_a: Option<f64>,
    condition_b: Option<f64>,
}

/// The angular velocity (base axes) of a rotation `Rz(gamma) Ry(beta) Rx(alpha)` whose angles change at `rates`:
/// `gamma' z + beta' Rz(gamma) y + alpha' Rz(gamma) Ry(beta) x`.
pub fn angular_velocity(pose: &Pose<f64>, rates: [f64; 3]) -> [f64; 3] {
    let [da, db, dg] = rates;
    let (sb, cb) = pose.beta.sin_cos();
    let (sg, cg) = pose.gamma.sin_cos();
    [da * cg * cb - db * sg, da * sg * cb + db * cg, dg - da * sb]
}

/// The 2-norm condition number (largest over smallest singular value); `None` when the matrix is singular.
fn condition(m: &Matrix6<f64>) -> Option<f64> {
    let s = m.singular_values();
    let (max, min) = (s.max(), s.min());
    (min > max * 1e-14 && max > 0.0).then(|| max / min)
}

fn rows(m: &Matrix6<f64>) -> [[f64; 6]; 6] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
}

/// Solves the velocity problem at the pose.
pub fn run(o: &Options) -> Result<Outcome, CliError> {
    let Selected {
        name, home, mechanism, ..
    } = Selected::of(o.on.mechanism, o.on.geometry)?;
    let pose = pose_arg(&o.on, home, mechanism.characteristic_length(), o.pose, "pose")?;
    let q = mechanism.inverse(&pose)?;
    let j = mechanism.jacobians(&pose, &q);
    let axes = mechanism.axes();
    // Angles in and out in degrees with --degrees: the rates are linear in them, so the same factor applies.
    let angle = if o.on.degrees { 1f64.to_degrees() } else { 1.0 };
    let is_angle = |i: usize, pose_axis: bool| {
        if pose_axis {
            i >= 3
        } else {
            axes[i] != ringpod_core::kinematics::AxisKind::Linear
        }
    };
    let to_si = |v: [f64; 6], pose_axis: bool| {
        Vector6::from_fn(|i, _| if is_angle(i, pose_axis) { v[i] / angle } else { v[i] })
    };
    let out = |v: &Vector6<f64>, pose_axis: bool| -> [f64; 6] {
        std::array::from_fn(|i| if is_angle(i, pose_axis) { v[i] * angle } else { v[i] })
    };
    let given = |what, text, pose_axis| -> Result<Vector6<f64>, CliError> {
        let v = to_si(numbers::six(what, text)?, pose_axis);
        let si: [f64; 6] = std::array::from_fn(|i| v[i]);
        numbers::rates_in_range(what, &si, |i| is_angle(i, pose_axis), mechanism.characteristic_length())?;
        Ok(v)
    };
    let (p_rates, q_rates) = match o.given {
        Given::PoseRates(text) => {
            let p = given("pose-rates", text, true)?;
            (p, j.actuator_rates(&p)?)
        }
        Given::ActuatorRates(text) => {
            let qd = given("actuator-rates", text, false)?;
            (j.pose_rates(&qd)?, qd)
        }
    };
    let omega = angular_velocity(&pose, [p_rates[3], p_rates[4], p_rates[5]]).map(|w| w * angle);
    let json = RatesJson {
        mechanism: &name,
        pose: {
            let v = pose.to_array();
            std::array::from_fn(|i| if i < 3 { v[i] } else { v[i] * angle })
        },
        pose_rates: out(&p_rates, true),
        actuator_rates: out(&q_rates, false),
        angular_velocity: omega,
        a: rows(&j.a),
        b: rows(&j.b),
        condition_a: condition(&j.a),
        condition_b: condition(&j.b),
    };
    if o.on.json {
        return Ok(Outcome::ok(serde_json::to_string_pretty(&json)? + "\n"));
    }
    Ok(Outcome::ok(text(&json, &mechanism.axis_names(), o.on.degrees)))
}

fn text(j: &RatesJson, names: &[String; 6], degrees: bool) -> String {
    let unit = if degrees { "deg" } else { "rad" };
    let list = |v: &[f64]| v.iter().map(|x| format!("{x:.6}")).collect::<Vec<_>>().join(", ");
    let mut t = String::new();
    let _ = writeln!(t, "{} at pose {} (m, {unit})", j.mechanism, list(&j.pose));
    let _ = writeln!(
        t,
        "pose rates x',y',z',alpha',beta',gamma' = {} (m/s, {unit}/s)",
        list(&j.pose_rates)
    );
    let _ = writeln!(
        t,
        "angular velocity (base axes) = {} ({unit}/s)",
        list(&j.angular_velocity)
    );
    let _ = writeln!(t, "actuator rates:");
    for (n, v) in names.iter().zip(j.actuator_rates) {
        let _ = writeln!(t, "  {n:<4} {v:>14.9}");
    }
    for (label, m, c) in [("A = dF/dp", &j.a, j.condition_a), ("B = dF/dq", &j.b, j.condition_b)] {
        let cond = c.map_or("singular".to_owned(), |c| format!("condition {c:.4}"));
        let _ = writeln!(t, "{label} ({cond}):");
        for row in m {
            let cells: Vec<String> = row.iter().map(|x| format!("{x:>11.5}")).collect();
            let _ = writeln!(t, "  {}", cells.join(" "));
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The angular velocity against the rotation's own derivative: `R' R^T` is the skew matrix of omega.
    #[test]
    fn angular_velocity_is_the_rotations_derivative() {
        let pose = Pose::new(0.0, 0.0, 0.2, 0.3, -0.4, 1.1);
        let rates = [0.7, -0.2, 0.5];
        let h = 1e-6;
        let at = |s: f64| {
            Pose::new(
                0.0,
                0.0,
                0.2,
                pose.alpha + s * rates[0],
                pose.beta + s * rates[1],
                pose.gamma + s * rates[2],
            )
            .rotation()
        };
        let dr = (at(h) - at(-h)) / (2.0 * h);
        let w = dr * pose.rotation().transpose();
        let want = [w[(2, 1)], w[(0, 2)], w[(1, 0)]];
        let got = angular_velocity(&pose, rates);
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-8, "{got:?} {want:?}");
        }
    }
}
