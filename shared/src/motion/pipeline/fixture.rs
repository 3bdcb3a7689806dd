//! What the parts' tests share: the trainer model at its home pose, as the controller builds it.

#![allow(clippy::panic)]

use super::{Pipeline, PipelineConfig};
use crate::kinematics::{presets, RingPlatform};
use crate::kinematics::{Mechanism, Pose};
use crate::motion::steps::AxisScale;
use crate::motion::steps::StepConverter;

/// The trainer model's home pose.
pub(super) const HOME: [f32; 6] = [0.0, 0.0, presets::TRAINER_MODEL_HOME_Z as f32, 0.0, 0.0, 0.0];

/// The trainer model's pipeline at home, holding (not streaming), with `config`.
pub(super) fn holding(config: PipelineConfig) -> Pipeline<RingPlatform<f32>> {
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let (c, l) = (AxisScale::MODEL_CARRIAGE, AxisScale::MODEL_LINEAR);
    let converter = StepConverter::new([c, c, c, c, l, l], m.axes());
    match Pipeline::new(m, config, converter, Pose::from_array(HOME)) {
        Ok(p) => p,
        Err(e) => panic!("home is reachable: {e:?}"),
    }
}

/// The default pipeline at home, streaming.
pub(super) fn streaming() -> Pipeline<RingPlatform<f32>> {
    let mut p = holding(PipelineConfig::default());
    p.start();
    p
}

/// Home moved by `by` on `axis`.
pub(super) fn home_plus(axis: usize, by: f32) -> Pose<f32> {
    let mut a = HOME;
    a[axis] += by;
    Pose::from_array(a)
}

/// Whether `pose` passes IK and every workspace check (evaluated in full, nothing proved from a guard).
pub(super) fn inside(p: &Pipeline<RingPlatform<f32>>, pose: &Pose<f32>) -> bool {
    p.mechanism()
        .inverse_checked(pose)
        .is_ok_and(|(_, report)| report.all_pass())
}
