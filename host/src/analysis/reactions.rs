//! `ringpod reactions`: the loads of a tool wrench on a mechanism of fewer than six degrees of freedom (the tool
//! carrier), by paper 003's projection method: drives, the X guide's bearing load, the dyads' pivot forces and
//! the constraint couple.

use std::fmt::Write as _;

use ringpod_core::screws::tool::{tool_loads, ToolLoads};
use serde::Serialize;

use crate::analysis::kinematics::{pose_arg, On, Outcome};
use crate::analysis::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::input::numbers;

#[derive(Serialize)]
struct ReactionsJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    /// The wrench on the tool at its point: force (N), moment (N m), base frame.
    wrench: [f64; 6],
    /// Drive names, in the order of `drives`.
    drive_names: [&'static str; 5],
    /// Drive force (N) or torque (N m), positive along the joint's positive motion.
    drives: [f64; 5],
    /// Force (N) and moment about the frame centre (N m) the X guide's bearings carry.
    guide_force: [f64; 3],
    guide_moment: [f64; 3],
    /// Force through the frame pivots A2 and A3 (N).
    pivot_forces: [[f64; 3]; 2],
    /// The carriage chain's constraint couple (N m), unprojected and by projection.
    constraint_couple: [f64; 3],
    constraint_couple_projected: [f64; 3],
}

const DRIVES: [&str; 5] = [
    "q1 X carriage",
    "q2 pivot B",
    "elbow B (L3 on L2)",
    "q4 pivot D",
    "q5 pitch",
];
const UNITS: [&str; 5] = ["N", "N m", "N m", "N m", "N m"];

/// `reactions` at `pose` (default: the home pose) under `wrench` (`fx,fy,fz,mx,my,mz`).
pub fn run(common: &On, pose: Option<&str>, wrench: &str) -> Result<Outcome, CliError> {
    let selected = Selected::of(common.mechanism, common.geometry)?;
    let AnyMechanism::Tool(carrier) = &selected.mechanism else {
        return Err(CliError::bad(
            "mechanism",
            "a ring platform has six degrees of freedom and no constraint reactions: its drive loads are \
                     `ringpod loads`"
                .into(),
        ));
    };
    let pose = pose_arg(
        common,
        selected.home,
        ringpod_core::kinematics::Mechanism::characteristic_length(carrier.as_ref()),
        pose,
        "pose",
    )?;
    let wrench = numbers::six("wrench", wrench)?;
    if let Some(i) = wrench.iter().position(|v| !(v.is_finite() && v.abs() <= 1e9)) {
        return Err(CliError::bad(
            "wrench",
            format!("value {} is not a finite number of at most 1e9", i + 1),
        ));
    }
    let l: ToolLoads = tool_loads(carrier, &pose, &wrench)?;
    let text = if common.json {
        serde_json::to_string_pretty(&ReactionsJson {
            mechanism: &selected.name,
            pose: pose.to_array(),
            wrench,
            drive_names: DRIVES,
            drives: l.drives,
            guide_force: l.guide_force,
            guide_moment: l.guide_moment,
            pivot_forces: l.pivot_forces,
            constraint_couple: l.constraint_couple,
            constraint_couple_projected: l.constraint_couple_projected,
        })? + "\n"
    } else {
        let mut t = String::new();
        let v = |a: [f64; 3]| format!("[{:9.4}, {:9.4}, {:9.4}]", a[0], a[1], a[2]);
        let _ = writeln!(
            t,
            "{}: tool wrench {wrench:?} (N, N m) at the tool point",
            selected.name
        );
        for k in 0..5 {
            let _ = writeln!(t, "  drive {:<20} {:>10.4} {}", DRIVES[k], l.drives[k], UNITS[k]);
        }
        let _ = writeln!(t, "  X guide force        {} N", v(l.guide_force));
        let _ = writeln!(
            t,
            "  X guide moment       {} N m (about the frame centre)",
            v(l.guide_moment)
        );
        let _ = writeln!(t, "  pivot A2 force       {} N", v(l.pivot_forces[0]));
        let _ = writeln!(t, "  pivot A3 force       {} N", v(l.pivot_forces[1]));
        let _ = writeln!(
            t,
            "  constraint couple    {} N m (projected {})",
            v(l.constraint_couple),
            v(l.constraint_couple_projected)
        );
        t
    };
    Ok(Outcome::ok(text))
}
