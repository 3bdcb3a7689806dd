//! The tool carrier (KINEMATICS.md 2.3) as screw chains, and the loads of a tool wrench by paper 003's projection
//! method: drive torques and forces, the X guide's bearing load and the passive joints' loads.
//!
//! The worked position problem gives the carrier's equations, not its joints; this is the joint layout they imply
//! (every twist about the base origin, `R = Rx(alpha) Ry(beta)`, frame centre `C0 = P + L1 R e_z`, frame pivots
//! `A2, A3 = C0 +- (b/2) R e_y`):
//! - carriage chain: the X guide `P_x` (drive `q1`), cross slides `P_y`, `P_z`, the roll bearing `R_x` at `C0`, and
//!   the pitch drive `R_beta` about `R e_y` through `C0` (drive `q5`). Five joints: its one constraint is the
//!   couple that stops the frame turning about its third axis (no yaw).
//! - each dyad: base pivot `R_x` at `B` (`D`) (drive `q2`; `q4`), elbow `R_x` (driven on the B side: the `q3`
//!   drive, acting between `L2` and `L3`; free on the D side), a slider `P_x` (the frame pivot moves along X with
//!   the carriage while the dyad stays in its plane), and a spherical joint at `A2` (`A3`). Six joints: no
//!   constraint.
//!
//! Five drives and one constraint: six wrenches, statically determinate.

use nalgebra::{Vector3, Vector6};

use super::chains::{solve, ChainReactions, Joint};
use crate::kinematics::geometry::ToolGeometry;
use crate::kinematics::{KinematicsError, Mechanism, Pose, ToolCarrier};

/// The loads of a tool wrench on the tool carrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolLoads {
    /// Drives: `q1` X carriage (N), `q2` base pivot B (N m), the elbow drive of the B dyad (N m, `L3` against
    /// `L2`), `q4` base pivot D (N m), `q5` pitch (N m). Positive along each joint's positive motion.
    pub drives: [f64; 5],
    /// Force the X guide's bearings carry (N, base frame; its X part is the `q1` drive's).
    pub guide_force: [f64; 3],
    /// Moment the X guide's bearings carry, about the frame centre (N m).
    pub guide_moment: [f64; 3],
    /// Force through each frame pivot's spherical joint, `A2` then `A3` (N): the dyads are two-force members.
    pub pivot_forces: [[f64; 3]; 2],
    /// The carriage chain's constraint couple (N m): what stops the frame turning about its third axis.
    pub constraint_couple: [f64; 3],
    /// The same by the projection method (`W_C^+ P`): bounded near actuation singularities, where the unprojected
    /// value grows without bound.
    pub constraint_couple_projected: [f64; 3],
}

fn revolute(u: Vector3<f64>, at: Vector3<f64>, actuated: bool) -> Joint {
    let m = at.cross(&u);
    Joint {
        twist: Vector6::new(u.x, u.y, u.z, m.x, m.y, m.z),
        actuated,
    }
}

fn prismatic(u: Vector3<f64>, actuated: bool) -> Joint {
    Joint {
        twist: Vector6::new(0.0, 0.0, 0.0, u.x, u.y, u.z),
        actuated,
    }
}

/// The carrier's chains at a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolChains {
    /// X guide, cross slides, roll bearing, pitch drive.
    pub carriage: [Joint; 5],
    /// The B dyad, then the D dyad: base pivot, elbow, slider, spherical joint (three revolutes).
    pub dyads: [[Joint; 6]; 2],
    /// The frame centre `C0`.
    pub centre: Vector3<f64>,
}

/// The chains' joints at a pose (IK solved for the elbows).
pub fn chains(carrier: &ToolCarrier<f64>, pose: &Pose<f64>) -> Result<ToolChains, KinematicsError> {
    let q = carrier.inverse(pose)?.0;
    let g: &ToolGeometry = carrier.geometry();
    let (sa, ca) = libm::sincos(pose.alpha);
    let (sb, cb) = libm::sincos(pose.beta);
    let p = Vector3::new(pose.x, pose.y, pose.z);
    let ez = Vector3::new(sb, -sa * cb, ca * cb);
    let ey = Vector3::new(0.0, ca, sa);
    let centre = p + ez * g.l1;
    let ex = Vector3::x();
    let pivot = |side: f64| centre + ey * (side * g.b / 2.0);
    let dyad = |base: [f64; 3], angle: f64, at: Vector3<f64>, elbow_driven: bool| -> [Joint; 6] {
        let base = Vector3::from(base);
        let elbow = base + Vector3::new(0.0, libm::cos(angle), libm::sin(angle)) * g.l2;
        [
            revolute(ex, base, true),
            revolute(ex, elbow, elbow_driven),
            prismatic(ex, false),
            revolute(ex, at, false),
            revolute(Vector3::y(), at, false),
            revolute(Vector3::z(), at, false),
        ]
    };
    Ok(ToolChains {
        carriage: [
            prismatic(ex, true),
            prismatic(Vector3::y(), false),
            prismatic(Vector3::z(), false),
            revolute(ex, centre, false),
            revolute(ey, centre, true),
        ],
        dyads: [
            dyad(g.pivot_b, q[1], pivot(1.0), true),
            dyad(g.pivot_d, q[3], pivot(-1.0), false),
        ],
        centre,
    })
}

fn split(w: &Vector6<f64>) -> (Vector3<f64>, Vector3<f64>) {
    (Vector3::new(w[0], w[1], w[2]), Vector3::new(w[3], w[4], w[5]))
}

/// The loads of the wrench `[force; moment]` (N, N m, base frame) applied to the tool at its point (the pose's
/// position). Errors: no IK solution, or a pose where the wrenches do not span (a singularity).
pub fn tool_loads(
    carrier: &ToolCarrier<f64>,
    pose: &Pose<f64>,
    wrench: &[f64; 6],
) -> Result<ToolLoads, KinematicsError> {
    if !wrench.iter().all(|v| v.is_finite()) {
        return Err(KinematicsError::NonFinite);
    }
    let c = chains(carrier, pose)?;
    let p = Vector3::new(pose.x, pose.y, pose.z);
    let (f, m) = (
        Vector3::new(wrench[0], wrench[1], wrench[2]),
        Vector3::new(wrench[3], wrench[4], wrench[5]),
    );
    // The chains hold the applied wrench: they exert its opposite, about the origin.
    let m_o = m + p.cross(&f);
    let held = -Vector6::new(f.x, f.y, f.z, m_o.x, m_o.y, m_o.z);
    let r: ChainReactions = solve(&[&c.carriage, &c.dyads[0], &c.dyads[1]], &held).ok_or(KinematicsError::Singular)?;
    // Actuated joints in order: q1, q5 (carriage chain), q2, elbow (B dyad), q4 (D dyad).
    let a = r.actuators;
    let (force, moment_o) = split(&r.chain_wrenches[0]);
    let guide_moment = moment_o - c.centre.cross(&force);
    let (pb, _) = split(&r.chain_wrenches[1]);
    let (pd, _) = split(&r.chain_wrenches[2]);
    let (_, couple) = split(&r.constraint_loads[0]);
    let (_, couple_projected) = split(&r.constraint_loads_projected[0]);
    Ok(ToolLoads {
        drives: [a[0], a[2], a[3], a[4], a[1]],
        guide_force: force.into(),
        guide_moment: guide_moment.into(),
        pivot_forces: [pb.into(), pd.into()],
        constraint_couple: couple.into(),
        constraint_couple_projected: couple_projected.into(),
    })
}
