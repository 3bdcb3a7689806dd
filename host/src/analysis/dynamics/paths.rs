//! A mechanism file's forward dynamics (`dynamics --file --forward`: paper 002's equation of motion solved with the
//! loop equations, let go at rest from the sketch under constant drive forces) and the paths of its link points
//! (`--point`: eqs. 5 and 6, position `A_0i r`, velocity `W_i A_0i r`, and acceleration), with their tables and
//! plots.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Matrix4, Vector3, Vector4};
use plotters::style::colors::{BLACK, BLUE, CYAN, GREEN, MAGENTA, RED};
use ringpod_core::screws::matrix::inverse;
use ringpod_core::screws::matrix::mechanism::{Frames, MAX_DRIVES, MAX_VARIABLES};
use ringpod_core::screws::matrix::LoopError;

use super::file::{bad, in_words, Built};
use super::{balance, Row};
use crate::error::CliError;
use crate::out::plot::{self, Panel, Series, TimePlot};
use crate::out::Outcome;

/// What a mechanism file is asked beyond its drives' swing.
#[derive(Default)]
pub struct FileOptions<'a> {
    /// Forward dynamics under these constant drive forces (`F1,F2,...`; empty: zeros), instead of the swing.
    pub forward: Option<&'a str>,
    /// Points to follow: `LINK:X,Y,Z`, the point in the base at the sketch.
    pub points: &'a [String],
    /// Where to write the points' table (.csv) and plot (.png or .svg).
    pub paths: Option<&'a Path>,
    pub paths_plot: Option<&'a Path>,
}

/// A point of a link, as asked and in the link's frame.
pub struct Point {
    /// As typed (for the table and the plot).
    pub name: String,
    pub link: usize,
    /// In the link's frame.
    pub local: Vector3<f64>,
}

/// Each point's position, velocity and acceleration in the base at one sample.
pub type Traced = Vec<[Vector3<f64>; 3]>;

/// The points asked, each on its link's frame at the sketch.
pub fn points(specs: &[String], b: &Built) -> Result<Vec<Point>, CliError> {
    specs
        .iter()
        .map(|spec| {
            let refuse = |why: &str| bad(format!("point `{spec}`: {why}"));
            let (link, at) = spec.split_once(':').ok_or_else(|| refuse("written LINK:X,Y,Z"))?;
            let link = match b.links.get(link.trim()) {
                Some(&i) => i,
                None => return Err(refuse("the link names no pair (or `ground`)")),
            };
            let xyz: Vec<f64> = at
                .split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| refuse("X,Y,Z are three numbers"))?;
            let [x, y, z] = xyz[..] else {
                return Err(refuse("X,Y,Z are three numbers"));
            };
            if ![x, y, z].iter().all(|v| v.is_finite() && v.abs() <= 1e6) {
                return Err(refuse("X,Y,Z are finite, at most 1e6 m"));
            }
            let frame = b.frames.get(link).copied().unwrap_or_else(Matrix4::identity);
            let local = inverse(&frame) * Vector4::new(1.0, x, y, z);
            Ok(Point {
                name: spec.clone(),
                link,
                local: Vector3::new(local[1], local[2], local[3]),
            })
        })
        .collect()
}

/// The points at one sample (eqs. 5 and 6).
pub fn trace(
    b: &Built,
    points: &[Point],
    frames: &Frames,
    qd: &[f64; MAX_VARIABLES],
    qdd: &[f64; MAX_VARIABLES],
) -> Traced {
    points
        .iter()
        .map(|p| b.model.mechanism.point(frames, qd, qdd, p.link, &p.local))
        .collect()
}

/// The drive forces of `--force` (`F1,F2,...`, one per drive; empty: zeros).
fn forces(text: &str, drives: usize) -> Result<[f64; MAX_DRIVES], CliError> {
    let mut out = [0.0; MAX_DRIVES];
    if text.trim().is_empty() {
        return Ok(out);
    }
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| CliError::bad("force", format!("`{text}`: numbers separated by commas")))?;
    if values.len() != drives || !values.iter().all(|v| v.is_finite() && v.abs() <= 1e9) {
        return Err(CliError::bad(
            "force",
            format!("`{text}`: one finite force per drive ({drives}), at most 1e9 either way"),
        ));
    }
    out[..drives].copy_from_slice(&values);
    Ok(out)
}

/// Forward dynamics from the sketch at rest under constant drive forces, by fourth-order Runge-Kutta over the
/// file's duration and step, the loops closed at every stage; each sample's energy, power and points.
pub fn forward(b: &Built, text: &str, points: &[Point]) -> Result<(Vec<Row>, Vec<Traced>), CliError> {
    let d = b.swing.len();
    let tau = forces(text, d)?;
    let mut u: [f64; MAX_DRIVES] = std::array::from_fn(|i| b.swing.get(i).map_or(0.0, |s| s.0));
    let mut ud = [0.0; MAX_DRIVES];
    let mut guess = b.q;
    let (mut rows, mut traced) = (Vec::new(), Vec::new());
    let n = (b.duration / b.step).floor() as usize;
    for k in 0..=n {
        let t = k as f64 * b.step;
        let fail = |e: LoopError| bad(format!("at t = {t} s: {}", in_words(e)));
        let (udd, state) = b
            .model
            .drive_accelerations(&guess, &u[..d], &ud[..d], &tau[..d])
            .map_err(fail)?;
        let frames = b.model.mechanism.frames(&state.q).map_err(fail)?;
        let qdd = b
            .model
            .mechanism
            .accelerations(&frames, &state.qd, &udd[..d])
            .map_err(fail)?;
        let e = b.model.energy(&frames, &state);
        let power = tau.iter().zip(&ud).map(|(f, v)| f * v).sum::<f64>() + b.model.element_power(&state);
        traced.push(trace(b, points, &frames, &state.qd, &qdd));
        rows.push(Row {
            t,
            u,
            ud,
            udd,
            forces: tau,
            kinetic: e.kinetic,
            potential: e.gravity + e.springs,
            power,
        });
        if k < n {
            let (u1, ud1, q1) = b.model.step(&state.q, &u, &ud, b.step, |_| tau).map_err(fail)?;
            (u, ud, guess) = (u1, ud1, q1);
        }
    }
    Ok((rows, traced))
}

/// Forward dynamics' text, table and plot: the drives' values and rates, and the energy balance.
pub fn forward_report(b: &Built, rows: &[Row], table: Option<&Path>, plot: Option<&Path>) -> Result<Outcome, CliError> {
    let d = b.swing.len();
    // The table and the energy balance as the swing's; the plot of the motion instead of the (constant) forces.
    let mut out = super::report(&b.name, rows, d, table, None)?;
    let last = rows.last().ok_or_else(|| bad("no samples".into()))?;
    let values: Vec<String> = (0..d).map(|a| format!("{:.6}", last.u[a])).collect();
    let rates: Vec<String> = (0..d).map(|a| format!("{:.6}", last.ud[a])).collect();
    let _ = writeln!(
        out.text,
        "forward dynamics from rest at the sketch under drive forces {:?}: at {} s the drives are at {} moving at {}",
        &last.forces[..d],
        last.t,
        values.join(", "),
        rates.join(", ")
    );
    if let Some(path) = plot {
        let series = |name: String, value: &dyn Fn(&Row) -> f64, colour| {
            Series::new(name, rows.iter().map(|r| (r.t, value(r))).collect(), colour)
        };
        let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
        let panel = |title: &str, unit: &str, series| Panel {
            title: title.into(),
            unit: unit.into(),
            series,
            events: Vec::new(),
        };
        let picture = TimePlot {
            title: format!("{}: forward dynamics by paper 002's Lagrange equation", b.name),
            panels: vec![
                panel(
                    "drive values",
                    "rad, m",
                    (0..d)
                        .map(|a| series(format!("drive {}", a + 1), &|r: &Row| r.u[a], colours[a]))
                        .collect(),
                ),
                panel(
                    "drive rates",
                    "rad/s, m/s",
                    (0..d)
                        .map(|a| series(format!("drive {}", a + 1), &|r: &Row| r.ud[a], colours[a]))
                        .collect(),
                ),
                panel(
                    "energy balance",
                    "J",
                    vec![
                        series("kinetic + potential".into(), &|r: &Row| r.kinetic + r.potential, BLUE),
                        Series::new("initial + drives' and elements' work", balance(rows), RED),
                    ],
                ),
            ],
        };
        plot::save(path, (1000, 1100), &picture).map_err(|e| CliError::Dynamics(e.to_string()))?;
    }
    Ok(out)
}

/// The points' ranges in the text, and their table and plot where asked.
pub fn report(
    text: &mut String,
    name: &str,
    points: &[Point],
    rows: &[Row],
    traced: &[Traced],
    o: &FileOptions,
) -> Result<(), CliError> {
    for (k, p) in points.iter().enumerate() {
        let along = |c: usize| traced.iter().map(move |s| s[k][0][c]);
        let range = |c: usize| {
            let (lo, hi) = along(c).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
            format!("{lo:.6}..{hi:.6}")
        };
        let speed = traced.iter().map(|s| s[k][1].norm()).fold(0.0, f64::max);
        let _ = writeln!(
            text,
            "point {}: x {}, y {}, z {} m; peak speed {speed:.6} m/s",
            p.name,
            range(0),
            range(1),
            range(2)
        );
    }
    if let Some(path) = o.paths {
        let mut csv = String::from("t");
        for k in 1..=points.len() {
            for q in ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"] {
                let _ = write!(csv, ",p{k}_{q}");
            }
        }
        csv.push('\n');
        for (r, s) in rows.iter().zip(traced) {
            let _ = write!(csv, "{:.9e}", r.t);
            for v in s.iter().flat_map(|p| p.iter().flat_map(|v| v.iter())) {
                let _ = write!(csv, ",{v:.9e}");
            }
            csv.push('\n');
        }
        crate::out::file::write(path, csv.as_bytes()).map_err(|e| CliError::file(path, e))?;
    }
    if let Some(path) = o.paths_plot {
        let panels = points
            .iter()
            .enumerate()
            .map(|(k, p)| Panel {
                title: format!("point {}", p.name),
                unit: "m".into(),
                series: [("x", RED), ("y", GREEN), ("z", BLUE)]
                    .into_iter()
                    .enumerate()
                    .map(|(c, (axis, colour))| {
                        Series::new(
                            axis,
                            rows.iter().zip(traced).map(|(r, s)| (r.t, s[k][0][c])).collect(),
                            colour,
                        )
                    })
                    .collect(),
                events: Vec::new(),
            })
            .collect();
        let picture = TimePlot {
            title: format!("{name}: paths of link points (paper 002, eqs. 5-6)"),
            panels,
        };
        plot::save(path, (1000, 300 + 300 * points.len() as u32), &picture)
            .map_err(|e| CliError::Dynamics(e.to_string()))?;
    }
    Ok(())
}

/// `dynamics --file`: the file's mechanism along its drives' swing (inverse dynamics) or let go under constant
/// drive forces (`--forward`), its table, plot and energy, and the paths of the points asked.
pub fn run_file(path: &Path, table: Option<&Path>, plot: Option<&Path>, o: &FileOptions) -> Result<Outcome, CliError> {
    let b = super::file::read(path)?;
    let points = points(o.points, &b)?;
    let (rows, traced) = match o.forward {
        Some(forces) => forward(&b, forces, &points)?,
        None => swing(&b, &points)?,
    };
    let mut out = match o.forward {
        Some(_) => forward_report(&b, &rows, table, plot)?,
        None => super::report(&b.name, &rows, b.swing.len(), table, plot)?,
    };
    report(&mut out.text, &b.name, &points, &rows, &traced, o)?;
    Ok(out)
}

/// The drives' value, rate and acceleration at `t` (`k` 0, 1, 2) of their swing and steady rate.
fn drive_at(b: &Built, t: f64, k: usize) -> [f64; MAX_DRIVES] {
    std::array::from_fn(|i| match b.swing.get(i) {
        Some((u0, a, f, v)) => {
            let w = 2.0 * std::f64::consts::PI * f;
            let s = (w * t).sin();
            let c = (w * t).cos();
            [u0 + v * t + a * s, v + a * w * c, -a * w * w * s][k]
        }
        None => 0.0,
    })
}

/// Inverse dynamics along the drives' swing, and the points' positions, velocities and accelerations.
fn swing(b: &Built, points: &[Point]) -> Result<(Vec<Row>, Vec<Traced>), CliError> {
    let d = b.swing.len();
    let mut guess = b.q;
    let (mut rows, mut traced) = (Vec::new(), Vec::new());
    for k in 0..=(b.duration / b.step).floor() as usize {
        let t = k as f64 * b.step;
        let (u, ud, udd) = (drive_at(b, t, 0), drive_at(b, t, 1), drive_at(b, t, 2));
        let fail = |e: LoopError| bad(format!("at t = {t} s: {}", in_words(e)));
        let s = b
            .model
            .solve_point(&guess, &u[..d], &ud[..d], &udd[..d])
            .map_err(fail)?;
        let e = b.model.energy(&s.frames, &s.state);
        let power = s.forces.iter().zip(&ud).map(|(f, v)| f * v).sum::<f64>() + b.model.element_power(&s.state);
        traced.push(trace(b, points, &s.frames, &s.state.qd, &s.qdd));
        rows.push(Row {
            t,
            u,
            ud,
            udd,
            forces: s.forces,
            kinetic: e.kinetic,
            potential: e.gravity + e.springs,
            power,
        });
        guess = s.state.q;
    }
    Ok((rows, traced))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::super::file::parse;
    use super::*;

    const SWASH: &str = include_str!("../../../../docs/dynamics/swash-plate.toml");
    const SUSPENSION: &str = include_str!("../../../../docs/dynamics/front-suspension.toml");

    /// The swash plate's output angle for the shaft's angle theta: `-atan(tan 15 deg sin theta)` (the four axes meet
    /// at one point: a spherical four-bar; the sign is the fork's frame turning about +Z).
    fn swash_output(theta: f64) -> (f64, f64) {
        let t = 15f64.to_radians().tan();
        let psi = -(t * theta.sin()).atan();
        // d psi / d theta.
        let rate = -t * theta.cos() / (1.0 + t * t * theta.sin() * theta.sin());
        (psi, rate)
    }

    /// Around a whole turn of the shaft the loop closes on the closed form's output angle.
    #[test]
    fn the_swash_plate_follows_its_closed_form() {
        let b = parse(SWASH).unwrap();
        let mut guess = b.q;
        let mut widest: f64 = 0.0;
        for k in 0..=360 {
            let theta = (k as f64).to_radians();
            let q = b.model.closed(&guess, &[theta]).unwrap();
            let (psi, _) = swash_output(theta);
            assert!((q[3] - psi).abs() < 1e-9, "{k} deg: {} vs {psi}", q[3]);
            widest = widest.max(q[3].abs());
            guess = q;
        }
        assert!((widest - 15f64.to_radians()).abs() < 1e-9);
    }

    /// A link point's path and velocity along the swing (eqs. 5, 6): the output lever's tip 0.15 m out turns with
    /// the closed form's angle, `0.15 (-sin psi, cos psi, 0)`, at `psi' = dpsi/dtheta * omega`.
    #[test]
    fn a_link_points_path_and_velocity_match_the_closed_form() {
        let b = parse(SWASH).unwrap();
        let points = points(&["output:0,0.15,0".to_string()], &b).unwrap();
        let (rows, traced) = swing(&b, &points).unwrap();
        let omega = b.swing[0].3;
        assert_eq!(rows.len(), 201);
        for (r, s) in rows.iter().zip(&traced) {
            let (psi, dpsi) = swash_output(omega * r.t);
            let [at, velocity, _] = s[0];
            let want = Vector3::new(-0.15 * psi.sin(), 0.15 * psi.cos(), 0.0);
            assert!((at - want).norm() < 1e-9, "t = {}: {at:?} vs {want:?}", r.t);
            let want = Vector3::new(-psi.cos(), -psi.sin(), 0.0) * 0.15 * dpsi * omega;
            assert!((velocity - want).norm() < 1e-7, "t = {}: {velocity:?} vs {want:?}", r.t);
        }
    }

    /// Forward dynamics under a constant torque on the shaft, no spring, damper or change of height: every joule of
    /// the torque's work `tau (theta - theta_0)` is the kinetic energy, at every sample.
    #[test]
    fn forward_dynamics_turns_the_shafts_work_into_kinetic_energy() {
        let b = parse(SWASH).unwrap();
        let (rows, _) = forward(&b, "0.05", &[]).unwrap();
        let first = &rows[0];
        assert_eq!((first.kinetic, first.u[0], first.ud[0]), (0.0, 0.0, 0.0));
        let last = rows.last().unwrap();
        assert!(last.ud[0] > 10.0, "{}", last.ud[0]);
        for r in &rows {
            let work = 0.05 * (r.u[0] - first.u[0]);
            assert!((r.kinetic - work).abs() < 1e-7, "t = {}: {} vs {work}", r.t, r.kinetic);
            assert!((r.potential - first.potential).abs() < 1e-9);
        }
        // The drive forces' count is checked.
        let e = forward(&b, "0.05,1", &[])
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("one finite force per drive (1)"), "{e}");
        let e = forward(&b, "x", &[]).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("numbers separated by commas"), "{e}");
    }

    /// The front suspension closes at its sketch and along the bump its links stay rigid: the ball joints 0.3015 m
    /// apart on the upright, the tie rod 0.32 m from the rack, and the wheel centre rises and falls by the arm's
    /// 0.4 m x 0.08 rad.
    #[test]
    fn the_front_suspension_moves_its_wheel_with_rigid_links() {
        let b = parse(SUSPENSION).unwrap();
        let specs = [
            "upright:0,0.65,0.10",
            "upright:0,0.62,0.40",
            "upright:0.12,0.62,0.15",
            "upright:0,0.75,0.28",
        ];
        let points = points(&specs.map(String::from), &b).unwrap();
        let (_, traced) = swing(&b, &points).unwrap();
        let kingpin = (0.3f64 * 0.3 + 0.03 * 0.03).sqrt();
        let rack = Vector3::new(0.12, 0.30, 0.15);
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &traced {
            assert!(((s[0][0] - s[1][0]).norm() - kingpin).abs() < 1e-9);
            assert!(((s[2][0] - rack).norm() - 0.32).abs() < 1e-9);
            // The lower ball on its arm's circle about the pivot axis (along X through (0, 0.25, 0.10)).
            let arm = s[0][0] - Vector3::new(s[0][0].x, 0.25, 0.10);
            assert!((arm.norm() - 0.4).abs() < 1e-9 && s[0][0].x.abs() < 1e-9);
            low = low.min(s[3][0].z);
            high = high.max(s[3][0].z);
        }
        assert!((high - 0.28 - 0.4 * 0.08f64.sin()).abs() < 2e-3, "{high}");
        assert!((0.28 - low - 0.4 * 0.08f64.sin()).abs() < 2e-3, "{low}");
    }

    /// A spherical pair sketched at its gimbal lock is refused by its name, in the mechanism's words; points that are
    /// not `LINK:X,Y,Z` on a link of the file are refused.
    #[test]
    fn a_spherical_pair_at_its_gimbal_lock_and_bad_points_are_refused() {
        let locked = "at = [0.0, 1.5707963267948966, 0.0]";
        assert!(SUSPENSION.contains(locked));
        for at in ["at = [0.0, 0.0, 0.0]", "at = [0.3, 3.141592653589793, 0.0]", "at = []"] {
            let e = parse(&SUSPENSION.replacen(locked, at, 1))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(
                e.contains("pair `upright`: a spherical pair sketched at theta") && e.contains("gimbal lock"),
                "{e}"
            );
            assert!(!e.contains("platform"), "{e}");
        }
        let b = parse(SWASH).unwrap();
        for (spec, says) in [
            ("wheel:0,0,0", "names no pair"),
            ("output", "written LINK:X,Y,Z"),
            ("output:0,0", "three numbers"),
            ("output:0,x,0", "three numbers"),
            ("output:0,nan,0", "finite"),
        ] {
            let e = points(&[spec.to_string()], &b).err().map(|e| e.to_string());
            assert!(e.as_deref().unwrap_or_default().contains(says), "{spec}: {e:?}");
        }
    }
}
