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
