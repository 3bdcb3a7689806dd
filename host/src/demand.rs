//! `ringpod loads --input motion.csv`: the drive demand along a motion, by inverse dynamics, and its peak per axis.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use ringpod_core::kinematics::{AxisKind, Mechanism, MotionState, Payload, Pose, RingPlatform};
use serde::Serialize;

use crate::error::{CliError, EXIT_CHECK_FAILED};
use crate::kinematics::Outcome;
use crate::table::{self, InputError};

#[derive(Serialize)]
struct DemandJson<'a> {
    mechanism: &'a str,
    mass_kg: f64,
    inertia_kg_m2: [f64; 3],
    axes: &'a [String; 6],
    units: [&'static str; 6],
    /// Largest absolute demand of each axis over the motion, in the axes' units.
    peak_demand: [f64; 6],
    /// When each peak happens (s, the file's time).
    peak_time_s: [f64; 6],
    /// The drive at rest at the first pose (statics), for comparison.
    at_rest_first_pose: [f64; 6],
    rows: usize,
    /// Rows with no kinematic solution, and lines that could not be read.
    errors: Vec<InputError>,
}

/// Rates and accelerations of sampled values at sample `i`, by the three-point formulas for uneven spacing (the
/// end samples take their neighbour's).
fn derivatives(t: &[f64], v: &[f64], i: usize) -> (f64, f64) {
    let n = t.len();
    if n < 3 {
        return (0.0, 0.0);
    }
    let i = i.clamp(1, n - 2);
    let (h1, h2) = (t[i] - t[i - 1], t[i + 1] - t[i]);
    let (a, b, c) = (v[i - 1], v[i], v[i + 1]);
    let rate = -h2 / (h1 * (h1 + h2)) * a + (h2 - h1) / (h1 * h2) * b + h1 / (h2 * (h1 + h2)) * c;
    let accel = 2.0 * (a / (h1 * (h1 + h2)) - b / (h1 * h2) + c / (h2 * (h1 + h2)));
    (rate, accel)
}

/// Runs the command for a ring platform.
pub fn run(
    name: &str,
    ring: &RingPlatform<f64>,
    names: &[String; 6],
    input: &Path,
    mass: f64,
    inertia: [f64; 3],
    json: bool,
) -> Result<Outcome, CliError> {
    let bad = |reason: String| CliError::BadNumbers { what: "input", reason };
    let text = std::fs::read_to_string(input).map_err(|e| bad(format!("{}: {e}", input.display())))?;
    let columns = ["t", "x", "y", "z", "alpha", "beta", "gamma"];
    let (rows, mut errors) = table::read(&text, &columns).map_err(bad)?;
    if rows.len() < 3 {
        return Err(bad(format!("{} usable rows; a motion needs at least 3", rows.len())));
    }
    let times: Vec<f64> = rows.iter().map(|(_, r)| r[0]).collect();
    let series: Vec<Vec<f64>> = (0..6).map(|k| rows.iter().map(|(_, r)| r[k + 1]).collect()).collect();
    let payload = Payload {
        mass,
        inertia: Matrix3::from_diagonal(&Vector3::from(inertia)),
    };
    let axes = ring.axes();
    let units: [&'static str; 6] = std::array::from_fn(|i| if axes[i] == AxisKind::Linear { "N" } else { "N m" });
    let mut peak = [0.0f64; 6];
    let mut peak_time = [f64::NAN; 6];
    let mut at_rest = [f64::NAN; 6];
    for (i, (line, row)) in rows.iter().enumerate() {
        let pose = Pose::from_array(std::array::from_fn(|k| row[k + 1]));
        let mut rates = [0.0; 6];
        let mut accelerations = [0.0; 6];
        for k in 0..6 {
            (rates[k], accelerations[k]) = derivatives(&times, &series[k], i);
        }
        let state = MotionState {
            pose,
            rates,
            accelerations,
        };
        let demand = ring
            .inverse(&pose)
            .and_then(|q| Ok((q, ring.drive_demand(&state, &q, &payload)?)));
        match demand {
            Ok((q, d)) => {
                if i == 0 {
                    if let Ok(l) = ring.loads(&pose, &q, &ring.gravity_wrench(&pose, mass)) {
                        at_rest = l.drives;
                    }
                }
                for k in 0..6 {
                    if d.drives[k].abs() > peak[k] || peak_time[k].is_nan() {
                        peak[k] = d.drives[k].abs();
                        peak_time[k] = row[0];
                    }
                }
            }
            Err(e) => errors.push(InputError {
                line: *line,
                reason: e.to_string(),
            }),
        }
    }
    let code = if errors.is_empty() { 0 } else { EXIT_CHECK_FAILED };
    let text = if json {
        let out = DemandJson {
            mechanism: name,
            mass_kg: mass,
            inertia_kg_m2: inertia,
            axes: names,
            units,
            peak_demand: peak,
            peak_time_s: peak_time,
            at_rest_first_pose: at_rest,
            rows: rows.len(),
            errors,
        };
        serde_json::to_string_pretty(&out)? + "\n"
    } else {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{name} moving {mass} kg (inertia {inertia:?} kg m^2) along {} ({} rows): peak demand per axis",
            input.display(),
            rows.len()
        );
        for k in 0..6 {
            let _ = writeln!(
                t,
                "  {:<4} {:>10.4} {:<4} at t = {:.3} s   (at rest at the first pose {:.4})",
                names[k], peak[k], units[k], peak_time[k], at_rest[k]
            );
        }
        for e in &errors {
            let _ = writeln!(t, "  line {}: {}", e.line, e.reason);
        }
        t
    };
    Ok(Outcome { text, code })
}
