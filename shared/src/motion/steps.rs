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
            let offset = self.offsets[i];
            // A count and an offset within i32 (every position of the trainer model: 2^31 steps are kilometres of
            // stroke or thousands of carriage turns) negate and add exactly in i64, where nothing can saturate:
            // plain operations, about half the instructions of the saturating ones on the M4F. The general way
            // gives the same value for them.
            match (i32::try_from(raw), i32::try_from(offset)) {
                (Ok(r), Ok(o)) => {
                    let r = i64::from(r);
                    (if s.invert { -r } else { r }) + i64::from(o)
                }
                _ => {
                    let signed = if s.invert { raw.saturating_neg() } else { raw };
                    signed.saturating_add(offset)
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every count saturating, the form the i32 path replaced for counts and offsets within i32.
    fn saturating(c: &StepConverter, q: &MultiTurn<f32>) -> [i64; 6] {
        core::array::from_fn(|i| {
            let s = &c.scales[i];
            let raw = match c.axes[i] {
                AxisKind::Ring => q.ring_steps(i, s.steps_per_turn),
                AxisKind::Linear | AxisKind::Angle => (q.within.0[i] * s.steps_per_unit).round_to_i64(),
            };
            let signed = if s.invert { raw.saturating_neg() } else { raw };
            signed.saturating_add(c.offsets[i])
        })
    }

    /// Offsets near zero, near the ends of i32 and of i64: both paths and the switch between them.
    fn offset() -> impl Strategy<Value = i64> {
        prop_oneof![
            -100_000i64..100_000,
            (i64::from(i32::MIN) - 2)..(i64::from(i32::MIN) + 2),
            (i64::from(i32::MAX) - 2)..(i64::from(i32::MAX) + 2),
            (i64::MAX - 3)..=i64::MAX,
            i64::MIN..(i64::MIN + 3),
            any::<i64>(),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(5_000))]

        #[test]
        fn counts_within_i32_add_as_the_saturating_form(
            turns in prop::array::uniform6(any::<i32>()),
            within in prop::array::uniform6(prop_oneof![-4.0f32..4.0, -3e9f32..3e9, any::<f32>()]),
            offsets in prop::array::uniform6(offset()),
            per_turn in prop_oneof![1i64..100_000, any::<i64>()],
            per_unit in prop_oneof![1.0f32..1e5, 1e5f32..1e12],
            invert in prop::array::uniform6(any::<bool>()),
        ) {
            let axes = [AxisKind::Ring, AxisKind::Ring, AxisKind::Ring, AxisKind::Linear, AxisKind::Linear, AxisKind::Angle];
            let mut c = StepConverter::new(
                core::array::from_fn(|i| AxisScale { steps_per_turn: per_turn, steps_per_unit: per_unit, invert: invert[i] }),
                axes,
            );
            c.offsets = offsets;
            let q = MultiTurn { turns, within: Actuators(within) };
            prop_assert_eq!(c.to_steps(&q), saturating(&c, &q));
        }
    }
}
