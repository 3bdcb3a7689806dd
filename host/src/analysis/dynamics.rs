//! `ringpod dynamics`: a ring platform in paper 002's terms (pairs, link matrices, loops closed by Gauss-Newton)
//! moved along a built-in smooth motion about its home pose or a motion file's timed poses, and its equation of motion (Lagrange, the matrix
//! method's kinetic energy) giving the drive torques and forces, the energies and the drives' power; each drive
//! force is checked against the ring platform's own inverse dynamics (Newton-Euler of the payload and statics).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Matrix3;
use plotters::style::colors::{BLACK, BLUE, CYAN, GREEN, MAGENTA, RED};
use ringpod_core::kinematics::{Mechanism as _, MotionState, Payload, Pose, RingGeometry, RingPlatform};
use ringpod_core::screws::matrix::mechanism::MAX_VARIABLES;
use ringpod_core::screws::matrix::ring::ring_model;
use ringpod_core::screws::matrix::LoopError;

use crate::error::CliError;
use crate::out::plot::{self, Panel, Series, TimePlot};
use crate::out::{Outcome, EXIT_CHECK_FAILED};

/// What `dynamics` works on.
pub struct Options<'a> {
    /// Mechanism name for reports.
    pub name: &'a str,
    /// The geometry (rod and radial chains).
    pub geometry: &'a RingGeometry,
    /// The pose the motion swings about.
    pub home: [f64; 6],
    /// Payload mass (kg) at the geometry's centre of mass, and its principal inertia there (kg m^2).
    pub mass: f64,
    pub inertia: [f64; 3],
    /// Amplitude of the motion: metres on x, y, z and radians on the angles, each coordinate its own frequency.
    pub amplitude: f64,
    /// Duration and sample step (s).
    pub duration: f64,
    pub step: f64,
    /// Where to write the table (.csv) and the plot (.png or .svg), if anywhere.
    pub table: Option<&'a Path>,
    pub plot: Option<&'a Path>,
    /// A motion file's timed poses with their rates and accelerations, instead of the built-in motion.
    pub motion: Option<Vec<(f64, MotionState<f64>)>>,
}

impl Options<'_> {
    /// The motion's samples: the file's, or the built-in motion's every `step` over `duration`.
    fn samples(&self) -> Vec<(f64, MotionState<f64>)> {
        self.motion.clone().unwrap_or_else(|| {
            let n = (self.duration / self.step).floor() as usize;
            (0..=n)
                .map(|k| k as f64 * self.step)
                .map(|t| (t, motion(self, t)))
                .collect()
        })
    }
}

mod file;

pub use file::run_file;

/// Relative agreement with the ring platform's inverse dynamics that the command asks for.
pub const AGREEMENT: f64 = 1e-6;

const FREQUENCIES: [f64; 6] = [2.0, 3.1, 1.7, 2.6, 1.3, 2.2];
const SHAPE: [f64; 6] = [0.8, -0.6, 1.0, 1.2, -1.0, 1.6];

/// The built-in motion at `t`: coordinate `k` swings by `amplitude SHAPE_k sin(FREQUENCIES_k t)` about home.
fn motion(o: &Options, t: f64) -> MotionState<f64> {
    let a = |k: usize| o.amplitude * SHAPE[k];
    let w = FREQUENCIES;
    let at = |k: usize| o.home[k] + a(k) * (w[k] * t).sin();
    MotionState {
        pose: Pose::new(at(0), at(1), at(2), at(3), at(4), at(5)),
        rates: std::array::from_fn(|k| a(k) * w[k] * (w[k] * t).cos()),
        accelerations: std::array::from_fn(|k| -a(k) * w[k] * w[k] * (w[k] * t).sin()),
    }
}

/// One row of the table.
struct Row {
    t: f64,
    u: [f64; 6],
    ud: [f64; 6],
    udd: [f64; 6],
    forces: [f64; 6],
    kinetic: f64,
    potential: f64,
    power: f64,
}

/// Why the matrix method has no answer, in words.
fn describe(e: LoopError) -> &'static str {
    match e {
        LoopError::Shape => "the mechanism has a chain the matrix-method model does not describe (an elbow chain)",
        LoopError::Singular => "the drives do not determine the platform here (a singular or unreachable pose)",
        LoopError::NoConvergence => "the loops did not close from the previous point (the motion jumps)",
        LoopError::NonFinite => "a value is not finite",
    }
}

fn fail(e: LoopError, t: f64) -> CliError {
    CliError::Dynamics(format!("at t = {t} s: {}", describe(e)))
}

fn unreachable(e: impl std::fmt::Display, t: f64) -> CliError {
    CliError::Dynamics(format!("at t = {t} s: {e}"))
}

/// Runs the motion; the outcome's code is [`EXIT_CHECK_FAILED`] when a drive force differs from the ring
/// platform's inverse dynamics by more than [`AGREEMENT`] of the largest.
pub fn run(o: &Options) -> Result<Outcome, CliError> {
    let ring = RingPlatform::<f64>::new(o.geometry);
    let inertia = Matrix3::from_diagonal(&o.inertia.into());
    let samples = o.samples();
    let first = samples.first().map_or_else(|| motion(o, 0.0).pose, |(_, s)| s.pose);
    let rm = ring_model(o.geometry, &first, o.mass, &inertia).map_err(|e| fail(e, 0.0))?;
    let payload = Payload { mass: o.mass, inertia };
    let drives = rm.model.mechanism.drives().len();
    let mut guess: [f64; MAX_VARIABLES] = rm.q;
    let (mut rows, mut worst, mut largest) = (Vec::new(), 0.0f64, 0.0f64);
    for (t, s) in samples {
        let q = ring.inverse(&s.pose).map_err(|e| unreachable(e, t))?;
        let closed = rm.model.closed(&guess, &q.0[..drives]).map_err(|e| fail(e, t))?;
        let f = rm.model.mechanism.frames(&closed).map_err(|e| fail(e, t))?;
        let (ud, udd) = rm.drive_motion(&f, &ring, &s).map_err(|e| fail(e, t))?;
        let solved = rm
            .model
            .solve_point(&closed, &q.0[..drives], &ud[..drives], &udd[..drives])
            .map_err(|e| fail(e, t))?;
        let expected = ring
            .drive_demand(&s, &q, &payload)
            .map_err(|e| unreachable(e, t))?
            .drives;
        for (got, want) in solved.forces.iter().zip(&expected).take(drives) {
            worst = worst.max((got - want).abs());
            largest = largest.max(want.abs());
        }
        let e = rm.model.energy(&solved.frames, &solved.state);
        let power = solved.forces.iter().zip(&ud).map(|(f, v)| f * v).sum();
        rows.push(Row {
            t,
            u: q.0,
            ud,
            udd,
            forces: solved.forces,
            kinetic: e.kinetic,
            potential: e.gravity + e.springs,
            power,
        });
        guess = closed;
    }
    let relative = if largest > 0.0 { worst / largest } else { worst };
    let mut out = report(o.name, &rows, drives, o.table, o.plot)?;
    let _ = writeln!(
        out.text,
        "against the ring platform's inverse dynamics: largest difference {relative:.3e} of the largest drive force"
    );
    out.code = if relative <= AGREEMENT { 0 } else { EXIT_CHECK_FAILED };
    Ok(out)
}

/// Writes the table and the plot where asked, and says the samples, the peaks and the energy balance.
fn report(
    name: &str,
    rows: &[Row],
    drives: usize,
    table_to: Option<&Path>,
    plot: Option<&Path>,
) -> Result<Outcome, CliError> {
    let done = balance(rows);
    let drift = rows
        .iter()
        .zip(&done)
        .map(|(r, (_, d))| (r.kinetic + r.potential - d).abs())
        .fold(0.0, f64::max);
    if let Some(path) = table_to {
        crate::out::file::write(path, table(rows, drives).as_bytes()).map_err(|e| CliError::file(path, e))?;
    }
    if let Some(path) = plot {
        draw(name, rows, drives, path).map_err(|e| CliError::Dynamics(e.to_string()))?;
    }
    let peak: Vec<String> = (0..drives)
        .map(|a| format!("{:.6}", rows.iter().map(|r| r.forces[a].abs()).fold(0.0, f64::max)))
        .collect();
    let duration = rows.last().map_or(0.0, |r| r.t);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{name}: {} samples over {duration} s, {drives} drives",
        rows.len()
    );
    let _ = writeln!(text, "peak drive force/torque: {}", peak.join(", "));
    let _ = writeln!(
        text,
        "energy balance: kinetic + potential minus (initial + the drives' work, trapezoid rule) at most {drift:.3e} J"
    );
    Ok(Outcome::ok(text))
}

fn table(rows: &[Row], drives: usize) -> String {
    let mut head = vec!["t".to_string()];
    for name in ["u", "ud", "udd", "force"] {
        head.extend((1..=drives).map(|a| format!("{name}{a}")));
    }
    head.extend(["kinetic", "potential", "power"].map(String::from));
    let mut out = head.join(",") + "\n";
    for r in rows {
        let mut cells = vec![r.t];
        for values in [&r.u, &r.ud, &r.udd, &r.forces] {
            cells.extend_from_slice(&values[..drives]);
        }
        cells.extend([r.kinetic, r.potential, r.power]);
        let line: Vec<String> = cells.iter().map(|v| format!("{v:.9e}")).collect();
        out += &(line.join(",") + "\n");
    }
    out
}

/// The drives' power is the rate of the total energy: the initial energy plus the drives' work (trapezoid rule) at
/// each row, to set beside the energy.
fn balance(rows: &[Row]) -> Vec<(f64, f64)> {
    let start = rows.first().map_or(0.0, |r| r.kinetic + r.potential);
    let mut work = 0.0;
    let mut out = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        if let Some(p) = k.checked_sub(1).and_then(|k| rows.get(k)) {
            work += (r.t - p.t) * (p.power + r.power) / 2.0;
        }
        out.push((r.t, start + work));
    }
    out
}

fn draw(name: &str, rows: &[Row], drives: usize, path: &Path) -> Result<(), plot::PlotError> {
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    let series = |name: &str, value: &dyn Fn(&Row) -> f64, colour| {
        Series::new(name, rows.iter().map(|r| (r.t, value(r))).collect(), colour)
    };
    let forces = (0..drives)
        .map(|a| series(&format!("drive {}", a + 1), &|r: &Row| r.forces[a], colours[a]))
        .collect();
    let done = balance(rows);
    let energy = vec![
        series("kinetic + potential", &|r: &Row| r.kinetic + r.potential, BLUE),
        Series::new("initial + drives' work", done, RED),
    ];
    let plot = TimePlot {
        title: format!("{name}: drive forces by paper 002's matrix method and Lagrange equation"),
        panels: vec![
            Panel {
                title: "drive torques / forces".into(),
                unit: "N m, N".into(),
                series: forces,
                events: Vec::new(),
            },
            Panel {
                title: "energy balance".into(),
                unit: "J".into(),
                series: energy,
                events: Vec::new(),
            },
        ],
    };
    plot::save(path, (1000, 900), &plot)
}

/// `dynamics` as asked on the command line.
pub struct Request<'a> {
    /// A preset's name (used when no rig file is given).
    pub mechanism: &'a str,
    /// A rig file, instead of the preset.
    pub geometry: Option<&'a Path>,
    /// Payload mass (kg) and principal inertia `Ixx,Iyy,Izz` (kg m^2) as typed.
    pub mass: f64,
    pub inertia: &'a str,
    /// The motion's amplitude, duration and step.
    pub amplitude: f64,
    pub duration: f64,
    pub step: f64,
    /// Where to write the table and the plot.
    pub table: Option<&'a Path>,
    pub plot: Option<&'a Path>,
    /// A mechanism file, instead of a ring platform.
    pub file: Option<&'a Path>,
    /// A motion file (`t,x,y,z,alpha,beta,gamma`), instead of the built-in motion.
    pub input: Option<&'a Path>,
}

/// A motion file's timed poses as motion states (rates and accelerations by differences, as `loads` takes
/// them); a line that cannot be read refuses the file, by its number.
fn motion_file(path: &Path) -> Result<Vec<(f64, MotionState<f64>)>, CliError> {
    let bad = |reason: String| CliError::bad("input", format!("{}: {reason}", path.display()));
    let text = crate::input::files::read_text(path, crate::input::files::DATA_LIMIT).map_err(bad)?;
    let columns = ["t", "x", "y", "z", "alpha", "beta", "gamma"];
    let (rows, errors) = crate::input::table::read(&text, &columns).map_err(bad)?;
    if let Some(e) = errors.first() {
        return Err(bad(format!("line {}: {}", e.line, e.reason)));
    }
    // As `loads` and `stream` take a motion: a row of garbage is no motion (1e300 gave forces of thousands).
    if let Some((line, why)) = rows.iter().find_map(|(line, r)| {
        crate::input::numbers::motion_row_refused(&std::array::from_fn(|k| r[k + 1])).map(|why| (line, why))
    }) {
        return Err(bad(format!("line {line}: {why}")));
    }
    let rows: Vec<(usize, f64, Pose<f64>)> = rows
        .into_iter()
        .map(|(line, r)| (line, r[0], Pose::from_array(std::array::from_fn(|k| r[k + 1]))))
        .collect();
    let states = super::demand::motion_states(&rows).map_err(bad)?;
    Ok(rows.iter().map(|r| r.1).zip(states).collect())
}

/// `dynamics` from its arguments: the mechanism selected, the numbers checked (a positive duration and step, a
/// finite amplitude, a mass and inertia as `loads` takes them).
pub fn command(args: &Request) -> Result<Outcome, CliError> {
    // Every file it reads and every one it writes: no output may be an input or another output.
    let inputs: Vec<&Path> = [args.file, args.input, args.geometry].into_iter().flatten().collect();
    let outputs: Vec<&Path> = [args.table, args.plot].into_iter().flatten().collect();
    crate::out::file::check_outputs(&outputs, &inputs).map_err(|(out, e)| CliError::file(out, e))?;
    if let Some(path) = args.file {
        return run_file(path, args.table, args.plot);
    }
    let selected = crate::analysis::mechanism::Selected::of(args.mechanism, args.geometry)?;
    let crate::analysis::mechanism::AnyMechanism::Ring(ring) = &selected.mechanism else {
        return Err(CliError::bad(
            "mechanism",
            "the matrix-method dynamics are for ring platforms".into(),
        ));
    };
    let positive = |what: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(CliError::bad(what, format!("{v} is not a positive number")))
        }
    };
    let step = positive("step", args.step)?;
    let duration = positive("duration", args.duration)?;
    if duration / step > 1e6 {
        return Err(CliError::bad(
            "step",
            format!("{step} s makes more than a million samples"),
        ));
    }
    if !args.amplitude.is_finite() || args.amplitude < 0.0 {
        return Err(CliError::bad(
            "amplitude",
            format!("{} is not a non-negative number", args.amplitude),
        ));
    }
    run(&Options {
        name: &selected.name,
        geometry: ring.geometry(),
        home: selected.home,
        mass: crate::input::numbers::mass(args.mass)?,
        inertia: crate::input::numbers::inertia(Some(args.inertia))?,
        amplitude: args.amplitude,
        duration,
        step,
        table: args.table,
        plot: args.plot,
        motion: args.input.map(motion_file).transpose()?,
    })
}
