//! `ik --branch`: the tool carrier's dyad assemblies. Its closed form has two solutions per dyad (`q2, q4 = theta -+
//! kappa`, KINEMATICS.md 2.3; the source prints both, `q2` and `q2'`); a machine is built on one of them, so IK is
//! told which, or shows all four.

use std::fmt::Write;

use ringpod_core::kinematics::geometry::Branch;
use ringpod_core::kinematics::{Mechanism, Pose, ToolCarrier};
use serde::Serialize;

use crate::analysis::mechanism::AnyMechanism;
use crate::analysis::units::Units;
use crate::error::CliError;

/// Which assemblies `ik` solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Assembly {
    /// One: the B-side dyad's branch (for `q2`), then the D-side one's (for `q4`).
    One([Branch; 2]),
    /// All four.
    All,
}

/// The four assemblies, in the order `all` prints them.
const ASSEMBLIES: [[Branch; 2]; 4] = [
    [Branch::Minus, Branch::Minus],
    [Branch::Minus, Branch::Plus],
    [Branch::Plus, Branch::Minus],
    [Branch::Plus, Branch::Plus],
];

/// The branch's name on the command line: `minus` is `theta - kappa`, `plus` is `theta + kappa`.
pub fn name(b: Branch) -> &'static str {
    match b {
        Branch::Minus => "minus",
        Branch::Plus => "plus",
    }
}

fn branch(text: &str) -> Result<Branch, String> {
    match text.trim() {
        "minus" => Ok(Branch::Minus),
        "plus" => Ok(Branch::Plus),
        other => Err(format!("`{other}` is not a branch (minus or plus)")),
    }
}

/// Reads `--branch`: `all`, one branch for both dyads (`minus`, `plus`), or the B side's and the D side's
/// (`minus,plus`).
pub fn parse(text: &str) -> Result<Assembly, String> {
    if text.trim() == "all" {
        return Ok(Assembly::All);
    }
    let parts: Vec<&str> = text.split(',').collect();
    match parts.as_slice() {
        [one] => {
            let b = branch(one)?;
            Ok(Assembly::One([b, b]))
        }
        [b, d] => Ok(Assembly::One([branch(b)?, branch(d)?])),
        _ => Err("give `all`, one branch (minus or plus) or two (B side, D side: minus,plus)".into()),
    }
}

/// The mechanism on the assembly asked: the tool carrier rebuilt on `One`; refused for a ring platform (its rods'
/// branches are its geometry) and for `All` (the caller answers for one assembly).
pub(crate) fn assembled(m: AnyMechanism, assembly: Option<Assembly>) -> Result<AnyMechanism, CliError> {
    let refused = |reason: &str| CliError::bad("branch", reason.into());
    match (m, assembly) {
        (m, None) => Ok(m),
        (AnyMechanism::Tool(tool), Some(Assembly::One(b))) => Ok(AnyMechanism::Tool(Box::new(tool.with_branches(b)))),
        (AnyMechanism::Tool(_), Some(Assembly::All)) => Err(refused(
            "one assembly of the tool carrier's dyads here (minus, plus or B,D)",
        )),
        (AnyMechanism::Ring(_), Some(_)) => Err(refused(
            "chooses the tool carrier's dyad assemblies (tool5-ex); a ring platform's rod branches are its geometry's",
        )),
    }
}

#[derive(Serialize)]
struct AssemblyJson {
    branches: [&'static str; 2],
    actuators: [f64; 6],
    singularity_index: f64,
    first_failure: Option<&'static str>,
    all_pass: bool,
}

#[derive(Serialize)]
struct AllJson<'a> {
    mechanism: &'a str,
    pose: [f64; 6],
    axes: [String; 6],
    units: [&'static str; 6],
    assemblies: Vec<AssemblyJson>,
}

/// The four assemblies at a pose: each one's actuators and checks. The pose's reach does not depend on the
/// assembly (a dyad closes or not), so either all four solve or the error is the pose's.
pub(crate) fn all(
    name_of: &str,
    m: &ToolCarrier<f64>,
    pose: &Pose<f64>,
    units: &Units,
    json: bool,
) -> Result<String, CliError> {
    let axes = m.axes();
    let mut rows = Vec::with_capacity(4);
    for branches in ASSEMBLIES {
        let (q, report) = m.with_branches(branches).inverse_checked(pose)?;
        rows.push(AssemblyJson {
            branches: branches.map(name),
            actuators: std::array::from_fn(|i| units.axis_out(axes[i], q.0[i])),
            singularity_index: report.singularity_index,
            first_failure: report.first_failure().map(|c| c.name()),
            all_pass: report.all_pass(),
        });
    }
    if json {
        let out = AllJson {
            mechanism: name_of,
            pose: units.pose_out(pose),
            axes: std::array::from_fn(|i| format!("q{}", i + 1)),
            units: std::array::from_fn(|i| units.axis_unit(axes[i])),
            assemblies: rows,
        };
        return Ok(serde_json::to_string_pretty(&out)? + "\n");
    }
    let mut t = String::new();
    let shown: Vec<String> = units.pose_out(pose).iter().map(|v| format!("{v:.6}")).collect();
    let _ = writeln!(
        t,
        "{name_of} at pose x,y,z,alpha,beta,gamma = {} (m, {}): the four assemblies of its dyads",
        shown.join(", "),
        units.angle_unit()
    );
    let _ = writeln!(
        t,
        "  {:<6} {:<6} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}  checks",
        "B", "D", "q1", "q2", "q3", "q4", "q5", "q6"
    );
    let unit_row: Vec<String> = axes.iter().map(|a| format!("{:>12}", units.axis_unit(*a))).collect();
    let _ = writeln!(t, "  {:<13} {}", "", unit_row.join(" "));
    for row in &rows {
        let q: Vec<String> = row.actuators.iter().map(|v| format!("{v:>12.6}")).collect();
        let verdict = match row.first_failure {
            None => format!("all pass (index {:.4})", row.singularity_index),
            Some(check) => format!("FAIL {check} (index {:.4})", row.singularity_index),
        };
        let _ = writeln!(
            t,
            "  {:<6} {:<6} {}  {verdict}",
            row.branches[0],
            row.branches[1],
            q.join(" ")
        );
    }
    let _ = writeln!(
        t,
        "minus: theta - kappa, plus: theta + kappa (q2 from the B side's branch, q4 from the D side's)"
    );
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_every_form_and_refuses_others() {
        assert_eq!(parse("all"), Ok(Assembly::All));
        assert_eq!(parse("plus"), Ok(Assembly::One([Branch::Plus; 2])));
        assert_eq!(parse("minus,plus"), Ok(Assembly::One([Branch::Minus, Branch::Plus])));
        assert!(parse("up").is_err());
        assert!(parse("minus,plus,minus").is_err());
        assert!(parse("").is_err());
    }
}
