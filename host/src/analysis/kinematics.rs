//! `presets`, `ik`, `check`, `fk`: the kinematics questions, answered as text or JSON.

use std::fmt::Write;

use ringpod_core::kinematics::presets::Preset;
use ringpod_core::kinematics::{
    start_from_home, AxisKind, KinematicsError, Mechanism, NewtonOptions, Pose, Singularity, WorkspaceReport,
    FROM_HOME_DISTANCE,
};
use serde::Serialize;

use crate::analysis::branches::{self, Assembly};
use crate::analysis::mechanism::{AnyMechanism, Selected};
use crate::analysis::units::Units;
use crate::error::CliError;
use crate::input::numbers;
pub use crate::out::Outcome;
use crate::out::EXIT_CHECK_FAILED;

/// What every analysis command is asked about: the platform (a preset by name, or a rig file) and how to answer.
pub struct On<'a> {
    /// A preset's name (used when no rig file is given).
    pub mechanism: &'a str,
    /// A rig file, instead of the preset.
    pub geometry: Option<&'a std::path::Path>,
    /// Angles in degrees, on input and output.
    pub degrees: bool,
    /// One JSON object instead of text.
    pub json: bool,
}

/// `fk`: the actuator values and how to search.
pub struct FkOptions<'a> {
    /// The platform.
    pub on: On<'a>,
    /// Six actuator values, comma-separated.
    pub actuators: &'a str,
    /// A pose to start from (default: the home pose).
    pub guess: Option<&'a str>,
    /// Newton iterations at most.
    pub max_iterations: u8,
    /// Accept a solution outside the workspace checks.
    pub anywhere: bool,
    /// The tool carrier's dyad assemblies (`All` is refused: FK answers for one).
    pub assembly: Option<Assembly>,
}

/// `loads`: statics at a pose, or inverse dynamics along a motion file.
pub struct LoadsOptions<'a> {
    /// The platform.
    pub on: On<'a>,
    /// The pose (default: the home pose).
    pub pose: Option<&'a str>,
    /// The payload (kg).
    pub mass: f64,
    /// A motion file (pose CSV): the demand along it.
    pub input: Option<&'a std::path::Path>,
    /// With `input`: the payload's inertia Ixx,Iyy,Izz.
    pub inertia: Option<&'a str>,
    /// With `input`: a picture of demand against what the drives give.
    pub plot: Option<&'a std::path::Path>,
}

#[derive(Serialize)]
struct PresetJson {
    name: &'static str,
    description: &'static str,
    home: [f64; 6],
}

pub fn presets(json: bool) -> Result<Outcome, CliError> {
    if json {
        let list: Vec<_> = Preset::ALL
            .iter()
            .map(|p| PresetJson {
                name: p.name(),
                description: p.description(),
                home: p.home(),
            })
            .collect();
        return Ok(Outcome::ok(serde_json::to_string_pretty(&list)? + "\n"));
    }
    let mut text = String::new();
    for p in Preset::ALL {
        let _ = writeln!(text, "{:<14} {}", p.name(), p.description());
        let h = p.home();
        let _ = writeln!(text, "{:<14} home pose {:?}", "", h);
    }
    Ok(Outcome::ok(text))
}

#[derive(Serialize)]
struct CheckJson {
    name: &'static str,
    /// None: the check does not apply to this mechanism.
    margin: Option<f64>,
    unit: &'static str,
    pass: bool,
}

/// `ik`'s and `check`'s answer: written as JSON, or read out by [`ik_text`].
#[derive(Serialize)]
struct IkJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    axes: &'a [String; 6],
    units: [&'static str; 6],
    actuators: [f64; 6],
    checks: Vec<CheckJson>,
    singularity_index: f64,
    singularity: &'static str,
    all_pass: bool,
    /// The tool carrier's dyad assemblies (B side, D side).
    #[serde(skip_serializing_if = "Option::is_none")]
    branches: Option<[&'static str; 2]>,
}

fn checks_json(report: &WorkspaceReport<f64>, units: &Units) -> Vec<CheckJson> {
    report
        .iter()
        .map(|(c, m)| CheckJson {
            name: c.name(),
            margin: m.map(|m| units.margin_out(c, m)),
            unit: units.margin_unit(c),
            pass: report.passes(c),
        })
        .collect()
}

fn singularity_name(s: Singularity) -> &'static str {
    match s {
        Singularity::None => "none",
        Singularity::Type1 => "type 1 (actuators lose a direction)",
        Singularity::Type2 => "type 2 (platform gains mobility)",
        Singularity::Type3 => "type 3 (both)",
    }
}

pub(crate) fn pose_arg(
    common: &On,
    home: [f64; 6],
    length: f64,
    text: Option<&str>,
    what: &'static str,
) -> Result<Pose<f64>, CliError> {
    let units = Units {
        degrees: common.degrees,
    };
    let pose = match text {
        Some(t) => units.pose_in(numbers::six(what, t)?),
        None => Pose::from_array(home),
    };
    numbers::pose_in_range(what, &pose.to_array(), length)?;
    Ok(pose)
}

/// `ik` and `check`: the actuators at a pose and its checks; `assembly` chooses the tool carrier's dyad branches.
pub fn ik(
    common: &On,
    pose: Option<&str>,
    assembly: Option<Assembly>,
    exit_on_failed_check: bool,
) -> Result<Outcome, CliError> {
    let units = Units {
        degrees: common.degrees,
    };
    let Selected {
        name,
        home,
        mechanism: m,
        ..
    } = Selected::of(common.mechanism, common.geometry)?;
    let pose = pose_arg(common, home, m.characteristic_length(), pose, "pose")?;
    if let (AnyMechanism::Tool(tool), Some(Assembly::All)) = (&m, assembly) {
        return Ok(Outcome::ok(branches::all(&name, tool, &pose, &units, common.json)?));
    }
    let m = branches::assembled(m, assembly)?;
    let assembled = match &m {
        AnyMechanism::Tool(tool) => Some(tool.branches().map(branches::name)),
        AnyMechanism::Ring(_) => None,
    };
    let (q, report) = m.inverse_checked(&pose).map_err(|reason| match (&m, reason) {
        (AnyMechanism::Ring(r), KinematicsError::Unreachable { .. }) => CliError::OutOfReach {
            reason,
            margin: r.reach_margin(&pose),
        },
        _ => CliError::Kinematics(reason),
    })?;
    let axes = m.axes();
    let names = m.axis_names();
    let actuators: [f64; 6] = std::array::from_fn(|i| units.axis_out(axes[i], q.0[i]));
    let singularity = m.jacobians(&pose, &q).classify(0.01);
    let code = if exit_on_failed_check && !report.all_pass() {
        EXIT_CHECK_FAILED
    } else {
        0
    };
    let answer = IkJson {
        mechanism: &name,
        pose: units.pose_out(&pose),
        axes: &names,
        units: std::array::from_fn(|i| units.axis_unit(axes[i])),
        actuators,
        checks: checks_json(&report, &units),
        singularity_index: report.singularity_index,
        singularity: singularity_name(singularity),
        all_pass: report.all_pass(),
        branches: assembled,
    };
    let text = if common.json {
        serde_json::to_string_pretty(&answer)? + "\n"
    } else {
        ik_text(&answer, units.angle_unit(), exit_on_failed_check)
    };
    Ok(Outcome { text, code })
}

/// `ik`'s and `check`'s answer as text: the pose, the actuators (`ik`), each check's margin, the singularity, and
/// for `check` the verdict.
fn ik_text(a: &IkJson, angle_unit: &str, check: bool) -> String {
    let mut t = String::new();
    let shown: Vec<String> = a.pose.iter().map(|v| format!("{v:.6}")).collect();
    let _ = writeln!(
        t,
        "{} at pose x,y,z,alpha,beta,gamma = {} (m, {angle_unit})",
        a.mechanism,
        shown.join(", "),
    );
    if let Some([b, d]) = a.branches {
        let _ = writeln!(t, "dyad branches: B side {b}, D side {d} (--branch all shows the four)");
    }
    if !check {
        for i in 0..6 {
            let _ = writeln!(t, "  {:<4} {:>14.9} {}", a.axes[i], a.actuators[i], a.units[i]);
        }
    }
    let _ = writeln!(t, "checks (margin > 0 is inside):");
    for c in &a.checks {
        let verdict = if c.pass { "ok  " } else { "FAIL" };
        match c.margin {
            Some(v) => {
                let _ = writeln!(t, "  {verdict} {:<17} {:>12.6} {}", c.name, v, c.unit);
            }
            None => {
                let _ = writeln!(t, "  n/a  {:<17}", c.name);
            }
        }
    }
    let _ = writeln!(t, "singularity index {:.4} ({})", a.singularity_index, a.singularity);
    if check {
        let verdict = if a.all_pass {
            "inside the workspace"
        } else {
            "OUTSIDE the workspace"
        };
        let _ = writeln!(t, "{verdict}");
    }
    t
}

#[derive(Serialize)]
struct FkJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    iterations: u8,
    residual: f64,
}

pub fn fk(args: &FkOptions) -> Result<Outcome, CliError> {
    let common = &args.on;
    let units = Units {
        degrees: common.degrees,
    };
    let Selected {
        name,
        home,
        mechanism: m,
        ..
    } = Selected::of(common.mechanism, common.geometry)?;
    let m = branches::assembled(m, args.assembly)?;
    let raw = numbers::six("actuators", args.actuators)?;
    let axes = m.axes();
    let q = ringpod_core::kinematics::Actuators(std::array::from_fn(|i| match axes[i] {
        AxisKind::Linear => raw[i],
        AxisKind::Ring | AxisKind::Angle => units.angle_in(raw[i]),
    }));
    let length = m.characteristic_length();
    for (i, v) in q.0.iter().enumerate() {
        let limit = match axes[i] {
            AxisKind::Linear => numbers::MAX_LENGTHS * length,
            AxisKind::Ring | AxisKind::Angle => numbers::MAX_TURNING,
        };
        if !v.is_finite() || v.abs() > limit {
            return Err(CliError::bad(
                "actuators",
                format!(
                    "value {} ({}) is out of range (at most {} either way)",
                    i + 1,
                    numbers::readable(*v),
                    numbers::readable(limit)
                ),
            ));
        }
    }
    // Without a guess: home turned by the yaw the carriages show, accepted within a tilt range of it.
    let (guess, max_distance) = match args.guess {
        Some(_) => (
            pose_arg(common, home, length, args.guess, "guess")?,
            NewtonOptions::<f64>::default().max_distance,
        ),
        None => (start_from_home(&m, &q, &Pose::from_array(home)), FROM_HOME_DISTANCE),
    };
    let options = NewtonOptions {
        max_iterations: args.max_iterations,
        max_distance,
        inside: !args.anywhere,
        ..NewtonOptions::default()
    };
    let sol = m.forward(&q, &guess, &options)?;
    let pose = units.pose_out(&sol.pose);
    let text = if common.json {
        let out = FkJson {
            mechanism: &name,
            pose,
            iterations: sol.iterations,
            residual: sol.residual,
        };
        serde_json::to_string_pretty(&out)? + "\n"
    } else {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{} pose ({} Newton iterations, residual {:.1e}):",
            name, sol.iterations, sol.residual
        );
        for (name, (v, unit)) in ["x", "y", "z", "alpha", "beta", "gamma"].iter().zip(pose.iter().zip([
            "m",
            "m",
            "m",
            units.angle_unit(),
            units.angle_unit(),
            units.angle_unit(),
        ])) {
            let _ = writeln!(t, "  {name:<6} {v:>14.9} {unit}");
        }
        t
    };
    Ok(Outcome::ok(text))
}

#[derive(Serialize)]
struct LoadsJson<'a> {
    mechanism: &'a str,
    mass_kg: f64,
    axes: &'a [String; 6],
    /// Carriage torque about the ring axis (N m) or linear-actuator force (N, positive = compression).
    drives: [f64; 6],
    units: [&'static str; 6],
    /// Force along each transmitted line (N), wrench-matrix row order.
    line_forces: [f64; 6],
}

pub fn loads(args: &LoadsOptions) -> Result<Outcome, CliError> {
    let common = &args.on;
    let Selected {
        name,
        home,
        mechanism: m,
        drives,
    } = Selected::of(common.mechanism, common.geometry)?;
    let AnyMechanism::Ring(ring) = &m else {
        return Err(CliError::bad("mechanism", "statics are for ring platforms".into()));
    };
    numbers::mass(args.mass)?;
    let names = m.axis_names();
    if let Some(input) = args.input {
        let inertia = numbers::inertia(args.inertia)?;
        let job = crate::analysis::demand::Job {
            name: &name,
            ring,
            names: &names,
            drives: &drives,
            input,
            mass: args.mass,
            inertia,
            plot: args.plot,
        };
        return crate::analysis::demand::run(&job, common.json);
    }
    let pose = pose_arg(common, home, m.characteristic_length(), args.pose, "pose")?;
    let q = m.inverse(&pose)?;
    let wrench = ring.gravity_wrench(&pose, args.mass);
    let l = ring.loads(&pose, &q, &wrench)?;
    let axes = m.axes();
    let units: [&'static str; 6] = std::array::from_fn(|i| if axes[i] == AxisKind::Linear { "N" } else { "N m" });
    let text = if common.json {
        let out = LoadsJson {
            mechanism: &name,
            mass_kg: args.mass,
            axes: &names,
            drives: l.drives,
            units,
            line_forces: l.line_forces,
        };
        serde_json::to_string_pretty(&out)? + "\n"
    } else {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{name} holding {} kg at its centre of mass:",
            crate::input::numbers::readable(args.mass)
        );
        for i in 0..6 {
            let _ = writeln!(t, "  {:<4} {:>12.4} {}", names[i], l.drives[i], units[i]);
        }
        t
    };
    Ok(Outcome::ok(text))
}
