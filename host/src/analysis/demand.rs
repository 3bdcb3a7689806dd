//! `ringpod loads --input motion.csv`: the drive demand along a motion, by inverse dynamics, its peak per axis, and,
//! where the rig gives motor data, what each drive gives at the speed it turns and the least margin over the motion.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use plotters::style::colors::{BLUE, RED};
use ringpod_core::kinematics::{AxisKind, Mechanism, MotionState, MultiTurn, Payload, Pose, RingPlatform};
use serde::Serialize;

use crate::error::CliError;
use crate::input::table::{self, InputError};
use crate::out::plot::{self, Panel, Series, TimePlot};
use crate::out::Outcome;
use crate::out::EXIT_CHECK_FAILED;
use crate::rig::Drive;

/// What `loads --input` works on.
pub struct Job<'a> {
    /// Mechanism name for reports.
    pub name: &'a str,
    /// The platform.
    pub ring: &'a RingPlatform<f64>,
    /// Axis names in actuator order.
    pub names: &'a [String; 6],
    /// Each axis's drive, where known.
    pub drives: &'a [Option<Drive>; 6],
    /// The pose CSV.
    pub input: &'a Path,
    /// Moving mass (kg) at the geometry's centre of mass.
    pub mass: f64,
    /// Its inertia about the centre of mass, platform frame (kg m^2).
    pub inertia: [f64; 3],
    /// Where to draw demand against available, if anywhere.
    pub plot: Option<&'a Path>,
}

/// One axis's drive against the motion: the least margin and where it happens.
#[derive(Debug, Clone, Serialize)]
pub struct MarginJson {
    /// The drive, as the rig names it.
    pub motor: String,
    /// Least `available / demand` over the motion (below 1: the motion asks more than the motor gives, and an
    /// open-loop stepper loses steps there).
    pub margin: f64,
    /// When the least margin happens (s).
    pub margin_time_s: f64,
    /// Demand there (axis units).
    pub demand: f64,
    /// What the drive gives there at that speed (axis units).
    pub available: f64,
    /// The motor's speed there (rpm).
    pub motor_rpm: f64,
    /// Rows where the demand exceeds what the drive gives.
    pub rows_over: usize,
    /// When the demand first exceeds it (s), if it does.
    pub first_over_s: Option<f64>,
}

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
    /// Each axis's drive against the motion (null where the rig gives no motor data).
    drives: [Option<MarginJson>; 6],
    /// Every drive with motor data keeps up (margin >= 1 on every row).
    drives_keep_up: bool,
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

/// Makes a sampled angle continuous: each step is taken the short way round.
pub(crate) fn unwrap(angle: &mut [f64]) {
    use std::f64::consts::{PI, TAU};
    for i in 1..angle.len() {
        let step = (angle[i] - angle[i - 1] + PI).rem_euclid(TAU) - PI;
        angle[i] = angle[i - 1] + step;
    }
}

/// The demand along a motion, row by row (rows with a solution).
pub struct Profile {
    /// Time of each row (s).
    pub t: Vec<f64>,
    /// Input line of each row.
    pub line: Vec<usize>,
    /// Drive demand of each row, per axis (N m or N, signed).
    pub demand: Vec<[f64; 6]>,
    /// Axis speed of each row (rad/s or m/s), from the unwrapped IK.
    pub speed: Vec<[f64; 6]>,
    /// Statics at the first pose.
    pub at_rest: [f64; 6],
    /// Rows without a solution, and lines that could not be read.
    pub errors: Vec<InputError>,
    /// Rows read.
    pub rows: usize,
}

/// Inverse dynamics along the pose CSV at `input`.
pub fn profile(ring: &RingPlatform<f64>, input: &Path, payload: &Payload<f64>) -> Result<Profile, CliError> {
    let bad = |reason: String| CliError::bad("input", reason);
    let text = crate::input::files::read_text(input, crate::input::files::DATA_LIMIT)
        .map_err(|e| bad(format!("{}: {e}", input.display())))?;
    let columns = ["t", "x", "y", "z", "alpha", "beta", "gamma"];
    let in_file = |e: String| bad(format!("{}: {e}", input.display()));
    let (rows, errors) = table::read(&text, &columns).map_err(in_file)?;
    let rows: Vec<(usize, f64, Pose<f64>)> = rows
        .into_iter()
        .map(|(line, r)| (line, r[0], Pose::from_array(std::array::from_fn(|k| r[k + 1]))))
        .collect();
    let mut p = profile_of(ring, &rows, payload).map_err(in_file)?;
    if p.t.is_empty() {
        // No demand to report: a peak, a margin or "the drives keep up" of no row would say what was not found.
        let first = p
            .errors
            .first()
            .map(|e| format!(" (line {}: {})", e.line, e.reason))
            .unwrap_or_default();
        return Err(bad(format!(
            "{}: none of its {} rows is a pose the platform reaches{first}: nothing to compute",
            input.display(),
            p.rows
        )));
    }
    let mut all = errors;
    all.append(&mut p.errors);
    all.sort_by_key(|e| e.line);
    p.errors = all;
    Ok(p)
}

/// Inverse dynamics along timed poses `(line, t, pose)`, times rising.
pub fn profile_of(
    ring: &RingPlatform<f64>,
    rows: &[(usize, f64, Pose<f64>)],
    payload: &Payload<f64>,
) -> Result<Profile, String> {
    // A pose that is not a number has no demand and would poison the unwrapping and the differences of every row
    // after it: it is reported by its line and left out.
    let refused = |r: &(usize, f64, Pose<f64>)| crate::input::numbers::motion_row_refused(&r.2.to_array());
    let (rows, garbage): (Vec<_>, Vec<_>) = rows.iter().cloned().partition(|r| refused(r).is_none());
    let garbage: Vec<InputError> = garbage
        .into_iter()
        .map(|r| InputError {
            line: r.0,
            reason: format!("{}: left out", refused(&r).unwrap_or_default()),
        })
        .collect();
    let mut profile = profile_of_finite(ring, &rows, payload)?;
    // Rows read: the left-out ones too.
    profile.rows += garbage.len();
    profile.errors.extend(garbage);
    profile.errors.sort_by_key(|e| e.line);
    Ok(profile)
}

/// Timed poses `(line, t, pose)`, times rising, as motion states: rates and accelerations by three-point
/// differences, each angle taken the short way round from one sample to the next. At least three rows.
pub fn motion_states(rows: &[(usize, f64, Pose<f64>)]) -> Result<Vec<MotionState<f64>>, String> {
    if rows.len() < 3 {
        return Err(format!("{} usable rows; a motion needs at least 3", rows.len()));
    }
    if let Some(w) = rows
        .windows(2)
        .find(|w| w[1].1.partial_cmp(&w[0].1) != Some(std::cmp::Ordering::Greater))
    {
        return Err(format!("line {}: time does not increase", w[1].0));
    }
    let times: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let mut series: Vec<Vec<f64>> = (0..6)
        .map(|k| rows.iter().map(|r| r.2.to_array()[k]).collect())
        .collect();
    // An angle that jumps by more than half a turn between two samples wrapped (a yaw written in [0, 2 pi)); the
    // motion is the short way round.
    for angle in &mut series[3..] {
        unwrap(angle);
    }
    Ok((0..rows.len())
        .map(|i| {
            let d: [(f64, f64); 6] = std::array::from_fn(|k| derivatives(&times, &series[k], i));
            MotionState {
                pose: rows[i].2,
                rates: d.map(|(rate, _)| rate),
                accelerations: d.map(|(_, acceleration)| acceleration),
            }
        })
        .collect())
}

fn profile_of_finite(
    ring: &RingPlatform<f64>,
    rows: &[(usize, f64, Pose<f64>)],
    payload: &Payload<f64>,
) -> Result<Profile, String> {
    let states = motion_states(rows)?;
    let axes = ring.axes();
    let mut out = Profile {
        t: Vec::new(),
        line: Vec::new(),
        demand: Vec::new(),
        speed: Vec::new(),
        at_rest: [f64::NAN; 6],
        errors: Vec::new(),
        rows: rows.len(),
    };
    let mut position: Option<MultiTurn<f64>> = None;
    let mut positions: Vec<[f64; 6]> = Vec::new();
    for (&(line, t, pose), state) in rows.iter().zip(&states) {
        let demand = ring
            .inverse(&pose)
            .and_then(|q| Ok((q, ring.drive_demand(state, &q, payload)?)));
        match demand {
            Ok((q, d)) => {
                if out.t.is_empty() {
                    let gravity = ring.gravity_wrench(&pose, payload.mass);
                    if let Ok(l) = ring.loads(&pose, &q, &gravity) {
                        out.at_rest = l.drives;
                    }
                }
                let p = position.get_or_insert_with(|| MultiTurn::new(q));
                p.follow(&q, &axes);
                positions.push(std::array::from_fn(|k| p.total(k)));
                out.t.push(t);
                out.line.push(line);
                out.demand.push(d.drives);
            }
            Err(e) => out.errors.push(InputError {
                line,
                reason: e.to_string(),
            }),
        }
    }
    let columns: Vec<Vec<f64>> = (0..6).map(|k| positions.iter().map(|q| q[k]).collect()).collect();
    out.speed = (0..out.t.len())
        .map(|i| std::array::from_fn(|k| derivatives(&out.t, &columns[k], i).0))
        .collect();
    Ok(out)
}

/// The least margin of one drive over a profile's axis `k`.
fn margin(drive: &Drive, p: &Profile, k: usize) -> MarginJson {
    let mut worst = MarginJson {
        motor: drive.motor.clone(),
        margin: f64::INFINITY,
        margin_time_s: f64::NAN,
        demand: 0.0,
        available: drive.available(0.0),
        motor_rpm: 0.0,
        rows_over: 0,
        first_over_s: None,
    };
    for i in 0..p.t.len() {
        let (demand, speed) = (p.demand[i][k].abs(), p.speed[i][k]);
        let available = drive.available(speed);
        let ratio = if demand > 0.0 {
            available / demand
        } else {
            f64::INFINITY
        };
        if ratio < 1.0 {
            worst.rows_over += 1;
            worst.first_over_s.get_or_insert(p.t[i]);
        }
        if ratio < worst.margin || worst.margin_time_s.is_nan() {
            worst = MarginJson {
                margin: ratio,
                margin_time_s: p.t[i],
                demand,
                available,
                motor_rpm: drive.motor_rpm(speed),
                ..worst
            };
        }
    }
    worst
}

/// What `stream --check-loads` found before anything moved.
pub struct Preflight {
    /// Every drive with motor data keeps up along the whole motion.
    pub keeps_up: bool,
    /// A line per axis with motor data, and the poses that have no solution (the stream limits those).
    pub text: String,
}

/// `stream --check-loads`: where a motion would ask more of the drives than they give, before anything moves.
pub fn preflight(
    ring: &RingPlatform<f64>,
    drives: &[Option<Drive>; 6],
    rows: &[(usize, f64, Pose<f64>)],
    payload: &Payload<f64>,
) -> Result<Preflight, String> {
    let p = profile_of(ring, rows, payload)?;
    let axes = ring.axes();
    let mut text = String::new();
    let mut keeps_up = true;
    for (k, drive) in drives.iter().enumerate() {
        let Some(drive) = drive else { continue };
        let unit = if axes[k] == AxisKind::Linear { "N" } else { "N m" };
        let m = margin(drive, &p, k);
        let axis = k + 1;
        match m.first_over_s {
            Some(first) => {
                keeps_up = false;
                let _ = writeln!(
                    text,
                    "axis {axis}: over its drive from t = {first:.3} s, {} of {} poses; worst at t = {:.3} s: needs \
                     {:.4} {unit}, {} gives {:.4} at {:.0} rpm (margin {:.3})",
                    m.rows_over,
                    p.t.len(),
                    m.margin_time_s,
                    m.demand,
                    m.motor,
                    m.available,
                    m.motor_rpm,
                    m.margin
                );
            }
            None => {
                let _ = writeln!(
                    text,
                    "axis {axis}: keeps up (least margin {:.3} at t = {:.3} s)",
                    m.margin, m.margin_time_s
                );
            }
        }
    }
    if drives.iter().all(Option::is_none) {
        text += "no motor data for this geometry: nothing to check against\n";
    }
    if !p.errors.is_empty() {
        let _ = writeln!(
            text,
            "{} poses have no solution and were left out (the stream limits them into the envelope)",
            p.errors.len()
        );
    }
    Ok(Preflight { keeps_up, text })
}

/// Runs the command for a ring platform.
pub fn run(job: &Job, json: bool) -> Result<Outcome, CliError> {
    let payload = Payload {
        mass: job.mass,
        inertia: Matrix3::from_diagonal(&Vector3::from(job.inertia)),
    };
    let p = profile(job.ring, job.input, &payload)?;
    let axes = job.ring.axes();
    let units: [&'static str; 6] = std::array::from_fn(|i| if axes[i] == AxisKind::Linear { "N" } else { "N m" });
    let mut peak = [0.0f64; 6];
    let mut peak_time = [f64::NAN; 6];
    for (i, d) in p.demand.iter().enumerate() {
        for k in 0..6 {
            if d[k].abs() > peak[k] || peak_time[k].is_nan() {
                peak[k] = d[k].abs();
                peak_time[k] = p.t[i];
            }
        }
    }
    let margins: [Option<MarginJson>; 6] = std::array::from_fn(|k| job.drives[k].as_ref().map(|d| margin(d, &p, k)));
    let keep_up = margins.iter().flatten().all(|m| m.rows_over == 0);
    if let Some(out) = job.plot {
        draw(job, &p, units, out).map_err(|e| CliError::bad("plot", e.to_string()))?;
    }
    let code = if p.errors.is_empty() && keep_up {
        0
    } else {
        EXIT_CHECK_FAILED
    };
    let text = if json {
        let out = DemandJson {
            mechanism: job.name,
            mass_kg: job.mass,
            inertia_kg_m2: job.inertia,
            axes: job.names,
            units,
            peak_demand: peak,
            peak_time_s: peak_time,
            at_rest_first_pose: p.at_rest,
            drives: margins,
            drives_keep_up: keep_up,
            rows: p.rows,
            errors: p.errors,
        };
        serde_json::to_string_pretty(&out)? + "\n"
    } else {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{} moving {} kg (inertia {:?} kg m^2) along {} ({} rows): peak demand per axis",
            job.name,
            crate::input::numbers::readable(job.mass),
            job.inertia,
            job.input.display(),
            p.rows
        );
        for k in 0..6 {
            let _ = writeln!(
                t,
                "  {:<4} {:>10.4} {:<4} at t = {:.3} s   (at rest at the first pose {:.4})",
                job.names[k], peak[k], units[k], peak_time[k], p.at_rest[k]
            );
        }
        if margins.iter().any(Option::is_some) {
            let _ = writeln!(
                t,
                "drives (least available / demand over the motion; below 1 loses steps):"
            );
            for (k, m) in margins.iter().enumerate() {
                let Some(m) = m else { continue };
                let _ = writeln!(
                    t,
                    "  {:<4} margin {:>7.3} at t = {:.3} s: needs {:.4} {}, gives {:.4} at {:.0} rpm; {} rows over   ({})",
                    job.names[k], m.margin, m.margin_time_s, m.demand, units[k], m.available, m.motor_rpm, m.rows_over, m.motor
                );
            }
            let _ = writeln!(
                t,
                "{}",
                if keep_up {
                    "the drives keep up with this motion"
                } else {
                    "the motion asks more than the drives give: exit 3"
                }
            );
        }
        for e in &p.errors {
            let _ = writeln!(t, "  line {}: {}", e.line, e.reason);
        }
        t
    };
    Ok(Outcome { text, code })
}

/// Each axis's demand against what its drive gives at the speed it turns.
fn draw(job: &Job, p: &Profile, units: [&str; 6], out: &Path) -> Result<(), plot::PlotError> {
    let panels = (0..6)
        .map(|k| {
            let mut series = vec![Series::new(
                "demand |torque or force|",
                p.t.iter().zip(&p.demand).map(|(t, d)| (*t, d[k].abs())).collect(),
                RED,
            )];
            if let Some(d) = &job.drives[k] {
                series.push(Series::new(
                    format!("available: {}", d.motor),
                    p.t.iter().zip(&p.speed).map(|(t, s)| (*t, d.available(s[k]))).collect(),
                    BLUE,
                ));
            }
            Panel {
                title: format!("axis {} ({})", job.names[k], units[k]),
                unit: units[k].to_owned(),
                series,
                events: Vec::new(),
            }
        })
        .collect();
    let plot = TimePlot {
        title: format!(
            "{}: drive demand for {} kg along {}",
            job.name,
            crate::input::numbers::readable(job.mass),
            job.input
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().into_owned())
        ),
        panels,
    };
    plot::save(out, (1000, 1300), &plot)
}

#[cfg(test)]
mod tests;
