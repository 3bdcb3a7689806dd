//! Conversion between actuator positions and motor steps.

use crate::kinematics::{Actuators, AxisKind, MultiTurn};
use crate::Real;

/// How one axis's motor relates to its actuator coordinate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AxisScale {
    /// Ring axes: motor steps per carriage revolution (an integer, so whole turns convert exactly).
    pub steps_per_turn: i64,
    /// Other axes: motor steps per metre or per radian.
    pub steps_per_unit: f32,
    /// The motor turns the other way (swap DIR).
    pub invert: bool,
}

impl AxisScale {
    /// Steps per unit of the actuator coordinate (per radian for ring axes).
    pub fn per_unit(&self, kind: AxisKind) -> f32 {
        match kind {
            AxisKind::Ring => self.steps_per_turn as f32 / core::f32::consts::TAU,
            AxisKind::Linear | AxisKind::Angle => self.steps_per_unit,
        }
    }
}

/// Actuator positions to motor step positions: scale, direction, and the homing offsets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepConverter {
    /// Per axis.
    pub scales: [AxisScale; 6],
    /// What each axis measures.
    pub axes: [AxisKind; 6],
    /// Motor step position of actuator value zero, set by homing.
    pub offsets: [i64; 6],
}

impl StepConverter {
    /// A converter with zero offsets.
    pub fn new(scales: [AxisScale; 6], axes: [AxisKind; 6]) -> Self {
        Self {
            scales,
            axes,
            offsets: [0; 6],
        }
    }

    /// Motor step position of every axis for actuator positions `q` (ring axes multi-turn, exact in whole turns).
    pub fn to_steps(&self, q: &MultiTurn<f32>) -> [i64; 6] {
        core::array::from_fn(|i| {
            let s = &self.scales[i];
            let raw = match self.axes[i] {
                AxisKind::Ring => q.ring_steps(i, s.steps_per_turn),
                AxisKind::Linear | AxisKind::Angle => (q.within.0[i] * s.steps_per_unit).round_to_i64(),
            };
            let signed = if s.invert { raw.saturating_neg() } else { raw };
            signed.saturating_add(self.offsets[i])
        })
    }

    /// Sets the offset of `axis` so that actuator value `value` is at motor position `steps` (homing).
    pub fn set_home(&mut self, axis: usize, value: &MultiTurn<f32>, steps: i64) {
        if axis < 6 {
            self.offsets[axis] = 0;
            let at = self.to_steps(value)[axis];
            self.offsets[axis] = steps.saturating_sub(at);
        }
    }
}

/// The actuator positions that motor step positions stand for in homed coordinates, where step 0 of every axis is
/// its value in `at_zero` (the actuators of the home pose): the inverse of [`StepConverter::to_steps`] after homing,
/// to within a step's rounding. Ring axes count whole carriage turns, so a value may lie beyond one turn.
pub fn actuators_at_steps(
    scales: &[AxisScale; 6],
    axes: &[AxisKind; 6],
    at_zero: &Actuators<f32>,
    position: &[i64; 6],
) -> Actuators<f32> {
    Actuators(core::array::from_fn(|a| {
        let scale = &scales[a];
        let per_unit = scale.per_unit(axes[a]) * if scale.invert { -1.0 } else { 1.0 };
        at_zero.0[a] + position[a] as f32 / per_unit
    }))
}
