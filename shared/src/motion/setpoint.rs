//! What the pipeline takes from the host and answers: a setpoint, the reasons it refuses garbage, how it limited
//! what it took, and the counters of both.

use crate::kinematics::{Check, Pose};
use crate::safety::AuxLevels;

use super::spare::SpareTargets;

/// A pose setpoint from the host.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Setpoint {
    /// Sequence number, increasing by one per setpoint (wrapping).
    pub seq: u32,
    /// Host time stamp (us); the interval between setpoints is taken from it.
    pub time_us: u64,
    /// The pose.
    pub pose: Pose<f32>,
    /// The auxiliary outputs this setpoint switches when it is taken (a pose file's `aux1`, `aux2` columns); `None`
    /// leaves an output as it is. Two bytes on the wire without them.
    pub aux: AuxLevels,
    /// Targets of the spare axes 7 and 8 (a pose file's `axis7`, `axis8` columns, in each axis's unit); `None`
    /// keeps an axis's target. Two bytes on the wire without them.
    pub spare: SpareTargets,
}

/// Why a setpoint was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum RejectReason {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// No IK solution (the controller's own moves; a streamed setpoint is limited instead).
    Unreachable,
    /// Further from the previous setpoint than the platform travels at its velocity limits in the jump window: a
    /// broken source. `outside` names the first check the pose fails as well, if it does.
    GrossJump {
        /// The first workspace check the pose fails (zero margin), `Check::Reach` when it has no IK.
        outside: Option<Check>,
    },
    /// Its sequence number or time stamp is not newer than the last accepted one.
    Stale,
    /// The controller is not streaming (not started, stopping, or after a stream loss).
    NotStreaming,
}

/// How many setpoints were rejected, per reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct RejectCounters {
    /// [`RejectReason::NonFinite`].
    pub non_finite: u32,
    /// [`RejectReason::Unreachable`].
    pub unreachable: u32,
    /// [`RejectReason::GrossJump`].
    pub gross_jump: u32,
    /// [`RejectReason::Stale`].
    pub stale: u32,
    /// [`RejectReason::NotStreaming`].
    pub not_streaming: u32,
}

impl RejectCounters {
    pub(super) fn count(&mut self, reason: RejectReason) {
        let c = match reason {
            RejectReason::NonFinite => &mut self.non_finite,
            RejectReason::Unreachable => &mut self.unreachable,
            RejectReason::GrossJump { .. } => &mut self.gross_jump,
            RejectReason::Stale => &mut self.stale,
            RejectReason::NotStreaming => &mut self.not_streaming,
        };
        *c = c.saturating_add(1);
    }

    /// Total of all reasons.
    pub fn total(&self) -> u32 {
        [
            self.non_finite,
            self.unreachable,
            self.gross_jump,
            self.stale,
            self.not_streaming,
        ]
        .iter()
        .fold(0u32, |a, b| a.saturating_add(*b))
    }
}

/// Setpoints limited into the envelope: how many, by which check, and the largest correction.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct LimitCounters {
    /// Setpoints limited (each is also counted as applied).
    pub count: u32,
    /// Per check that bound them, in the order of [`Check::ALL`].
    pub by_check: [u32; 6],
    /// The largest translation taken off a setpoint (m).
    pub largest_translation: f32,
    /// The largest roll or pitch taken off a setpoint (rad).
    pub largest_rotation: f32,
    /// Ticks on which the trackers' path met the edge of the workspace and only part of the step was taken (the
    /// pose decelerates faster than its limit there: staying inside comes first).
    pub edge_ticks: u32,
    /// Ticks on which the actuators' speed or acceleration limits slowed the whole pose step. They take precedence
    /// over the pose acceleration limits (a stepper past its limits loses steps), so on these ticks the pose may
    /// decelerate faster than its limit.
    pub actuator_ticks: u32,
}

impl LimitCounters {
    pub(super) fn count(&mut self, limit: &LimitReport) {
        self.count = self.count.saturating_add(1);
        let i = Check::ALL.iter().position(|c| *c == limit.check).unwrap_or(0);
        self.by_check[i] = self.by_check[i].saturating_add(1);
        self.largest_translation = self.largest_translation.max(limit.translation);
        self.largest_rotation = self.largest_rotation.max(limit.rotation);
    }
}

/// How a setpoint was limited (the answer to a limited setpoint).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LimitReport {
    /// The check that bound it.
    pub check: Check,
    /// Translation taken off (m).
    pub translation: f32,
    /// Roll or pitch taken off, the larger (rad).
    pub rotation: f32,
}

/// What became of an accepted setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Accepted {
    /// Followed as it was.
    Applied,
    /// Limited into the envelope.
    Limited(LimitReport),
}

impl core::fmt::Display for RejectReason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFinite => f.write_str("a coordinate is not a number"),
            Self::Unreachable => f.write_str("no inverse kinematics solution"),
            Self::GrossJump { outside: None } => f.write_str("a gross jump from the previous setpoint"),
            Self::GrossJump { outside: Some(c) } => {
                write!(
                    f,
                    "a gross jump from the previous setpoint, outside the {} check",
                    c.name()
                )
            }
            Self::Stale => f.write_str("not newer than the last setpoint"),
            Self::NotStreaming => f.write_str("the controller is not streaming"),
        }
    }
}
