//! Envelope limiting: a setpoint outside the workspace becomes the pose nearest to it, on the ray from the middle
//! of the workspace, that passes every check with a margin.
//!
//! Motion-simulator software clamps each axis to the rig's limits, scaling the excursion from the neutral pose; a
//! ring platform's envelope is not a box (the trainer model holds each spec axis alone but less than half of the
//! combined extremes), so the clamp has to be the workspace checks themselves. The search runs on the ray from the
//! centre (the home pose) to the target in `x, y, z, alpha, beta`, with the target's yaw throughout: the ring turns
//! with the platform and the trainer's home pose passes at every yaw, so a limited stream keeps turning with its
//! source. A ray from the centre, not a segment from the last target: the last target of a limited stream lies on
//! the edge, and the segment from it to the next target outside leaves the workspace at once, so the platform
//! would stick where it first met the edge (and its yaw with it, since the workspace turns with the yaw). From the
//! centre, a continuous source gives a continuous limited path wherever the workspace is star-shaped about its
//! centre.
//!
//! The search is a short scan inward from the target for the first point that passes, then a bisection, with a
//! fixed number of IK + check evaluations, so its cost is bounded (one evaluation when the target is inside). It
//! returns the last point found to pass: a pose that passes, never one that does not.
//!
//! The margin keeps targets that far inside each check, so that the path the trackers take between two targets
//! (per axis, under acceleration limits, not exactly on the straight line) stays inside too. The host limits its
//! poses with the same code in `f64` before it sends them, so a board sees few setpoints to limit.

use crate::kinematics::{Actuators, Check, Mechanism, Pose, WorkspaceReport};
use crate::Real;

/// How much room each check must leave, in the unit of the check ([`Check::unit`]), in the order of [`Check::ALL`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvelopeMargins(pub [f32; 6]);

impl Default for EnvelopeMargins {
    /// 2 mm of reach and stroke, 1 degree of carriage spacing and of rod crossing, 0.5 degree of joint cone,
    /// 0.01 of singularity index, 2 mm of stability: about what the trackers' path deviates from the straight line
    /// between two targets at the trainer model's limits, with room.
    fn default() -> Self {
        const DEG: f32 = core::f32::consts::PI / 180.0;
        Self([0.002, DEG, DEG, 0.5 * DEG, 0.01, 0.002])
    }
}

impl EnvelopeMargins {
    /// The margin of one check.
    pub fn of(&self, check: Check) -> f32 {
        let i = Check::ALL.iter().position(|c| *c == check).unwrap_or(0);
        self.0[i]
    }

    /// The first check whose margin is below its required room (a check that does not apply passes), or `None`
    /// when the report passes them all. NaN never passes.
    pub fn first_short<T: Real>(&self, report: &WorkspaceReport<T>) -> Option<Check> {
        report.first_below(&self.room())
    }

    /// The margins in the scalar type of a mechanism.
    pub fn room<T: Real>(&self) -> [T; 6] {
        self.0.map(|m| T::of(f64::from(m)))
    }
}

/// The outcome of [`limit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limited<T> {
    /// The pose to command: the target itself when it passes.
    pub pose: Pose<T>,
    /// Its actuators (IK), when the pose was evaluated; `None` when it is the centre (at the target's yaw).
    pub actuators: Option<Actuators<T>>,
    /// The check that bound the target (the first check short of its margin at the nearest failing point found);
    /// `None` when the target passes.
    pub bound_by: Option<Check>,
    /// How far along `centre -> to` the pose is (1 when the target passes).
    pub fraction: T,
}

impl<T: Real> Limited<T> {
    /// Whether the target had to be limited.
    pub fn is_limited(&self) -> bool {
        self.bound_by.is_some()
    }
}

/// The point at `s` of the ray `centre -> to` in `x, y, z, alpha, beta`, with the target's yaw.
fn along<T: Real>(centre: &Pose<T>, to: &Pose<T>, s: T) -> Pose<T> {
    let (a, b) = (centre.to_array(), to.to_array());
    Pose::from_array(core::array::from_fn(|i| {
        if i == 5 {
            b[5]
        } else {
            a[i] + (b[i] - a[i]) * s
        }
    }))
}

/// Limits `to` into the envelope along the ray from `centre` (a pose in the middle of the workspace that passes
/// at every yaw: the home pose) with at most `evaluations` IK + check evaluations (at least one: the target).
/// Never returns a pose that fails a check's margin.
pub fn limit<T: Real, M: Mechanism<T>>(
    mechanism: &M,
    centre: &Pose<T>,
    to: &Pose<T>,
    margins: &EnvelopeMargins,
    evaluations: u8,
) -> Limited<T> {
    limit_in(mechanism, &mut M::Guard::default(), centre, to, margins, evaluations)
}

/// [`limit`] evaluating in the memory of a guard (see [`Mechanism::inverse_within_in`]): a control loop passes its
/// own, so that no evaluation clears a configuration of its own. The result is [`limit`]'s.
pub fn limit_in<T: Real, M: Mechanism<T>>(
    mechanism: &M,
    guard: &mut M::Guard,
    centre: &Pose<T>,
    to: &Pose<T>,
    margins: &EnvelopeMargins,
    evaluations: u8,
) -> Limited<T> {
    // Why a pose fails the envelope: no IK (the reach check; or the pose is not finite, which the caller refuses
    // first), or the first check short of its margin.
    let room = margins.room();
    let mut evaluate = |pose: &Pose<T>| mechanism.inverse_within_in(pose, &room, guard);
    let first = match evaluate(to) {
        Ok(q) => {
            return Limited {
                pose: *to,
                actuators: Some(q),
                bound_by: None,
                fraction: T::one(),
            }
        }
        Err(check) => check,
    };
    // The excursion may leave the workspace and come back along the ray (it need not be convex): scan inward
    // from the target in a few even steps for the first point that passes, so that the point found is the one
    // nearest the target; then bisect between it and the last point that failed.
    let budget = evaluations.max(1) - 1;
    let scan = (budget / 2).min(4);
    let (mut lo, mut hi) = (T::zero(), T::one());
    let mut best: Option<(Pose<T>, Actuators<T>)> = None;
    let mut bound_by = first;
    for k in (1..=scan).rev() {
        let s = T::of(f64::from(k) / f64::from(scan + 1));
        let pose = along(centre, to, s);
        match evaluate(&pose) {
            Ok(q) => {
                lo = s;
                best = Some((pose, q));
                break;
            }
            Err(check) => {
                hi = s;
                bound_by = check;
            }
        }
    }
    let half = T::of(0.5);
    for _ in 0..budget.saturating_sub(scan) {
        let mid = (lo + hi) * half;
        let pose = along(centre, to, mid);
        match evaluate(&pose) {
            Ok(q) => {
                lo = mid;
                best = Some((pose, q));
            }
            Err(check) => {
                hi = mid;
                bound_by = check;
            }
        }
    }
    match best {
        Some((pose, q)) => Limited {
            pose,
            actuators: Some(q),
            bound_by: Some(bound_by),
            fraction: lo,
        },
        // Nothing on the ray passed but the centre, which passes at every yaw.
        None => Limited {
            pose: along(centre, to, T::zero()),
            actuators: None,
            bound_by: Some(bound_by),
            fraction: T::zero(),
        },
    }
}

/// How far a limited pose is from what was asked: the translation (m) and the largest roll or pitch difference
/// (rad); yaw passes through and is never corrected.
pub fn correction<T: Real>(asked: &Pose<T>, limited: &Pose<T>) -> (T, T) {
    let (a, b) = (asked.to_array(), limited.to_array());
    let d: [T; 6] = core::array::from_fn(|i| a[i] - b[i]);
    let translation = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt_();
    let rotation = d[3].abs().max(d[4].abs());
    (translation, rotation)
}
