//! The pose the seat is in: forward kinematics of the steps the device counted, not the pose it was asked for.
//!
//! A device's telemetry carries its commanded pose and its step counts. When the motors cannot keep up (a fast yaw
//! on the ring's carriages: the step scheduler carries steps over), the counted steps lag the commanded pose by tens
//! of milliseconds, and whatever follows the seat (a record's followed pose, VR motion compensation, the workbench's
//! view) must show where it is. The host, not the board, solves the forward kinematics: the steps are already in every
//! sample, and the board's flash and cycles are kept for control. The solve is the core's, in `f32` as the board's
//! homing solves it, from the sample's commanded pose (a few milliseconds from the counted one, so Newton's method
//! converges in an iteration or two).
//!
//! Step counts are homed coordinates only once the device has homed: from the first sample of a state that implies
//! it (Ready, Running, Stopping) until homing or a jog starts again, the pose is solved from them, also through the
//! shutdown after a STOP, a fault and the power-down (the steps still say where the seat was left). Before that
//! (powering up, homing, jogging) where the seat is is not known from the steps, and the sample's pose becomes its
//! target, where the device is taking it: during homing the commanded pose is a placeholder that jumps when homing
//! finds the axes, and a record's derivatives or a VR view must not see that jump as motion.

use ringpod_core::controller::axis_scale;
use ringpod_core::kinematics::{Actuators, AxisKind, Mechanism, NewtonOptions, Pose, RingPlatform};
use ringpod_core::motion::{actuators_at_steps, AxisScale};
use ringpod_core::protocol::{RigRecord, Telemetry};
use ringpod_core::safety::State;

/// Solves each telemetry sample's pose from its counted steps.
#[derive(Debug, Clone)]
pub struct Followed {
    mechanism: RingPlatform<f32>,
    scales: [AxisScale; 6],
    axes: [AxisKind; 6],
    /// The actuators of the home pose: step 0 of every axis.
    at_zero: Actuators<f32>,
    /// Samples whose steps gave no pose (the solve failed): they kept the device's pose.
    pub unsolved: u64,
    /// Whether the counted steps are homed coordinates now.
    homed: bool,
}

impl Followed {
    /// For the platform and motors of the rig the device runs; `None` when its record gives no mechanism or scale
    /// (a device would not run such a record either).
    pub fn of(record: &RigRecord) -> Option<Self> {
        let geometry = record.geometry().ok()?;
        let mechanism = RingPlatform::<f32>::new(&geometry);
        let axes = mechanism.axes();
        let motors = &record.machine.axes;
        let mut scales = [AxisScale::MODEL_LINEAR; 6];
        for (a, scale) in scales.iter_mut().enumerate() {
            *scale = axis_scale(&motors[a], axes[a])?;
        }
        let home = Pose::from_array(record.home.map(|v| v as f32));
        let at_zero = mechanism.inverse(&home).ok()?;
        Some(Self {
            mechanism,
            scales,
            axes,
            at_zero,
            unsolved: 0,
            homed: false,
        })
    }

    /// The pose the sample's counted steps put the platform in.
    fn pose(&self, sample: &Telemetry) -> Option<Pose<f32>> {
        let q = actuators_at_steps(&self.scales, &self.axes, &self.at_zero, &sample.steps);
        let solved = self.mechanism.forward(&q, &sample.pose, &NewtonOptions::default());
        solved.ok().map(|s| s.pose)
    }

    /// Replaces the sample's pose by the counted one where the steps are homed coordinates (its target before).
    pub fn apply(&mut self, sample: &mut Telemetry) {
        match sample.state {
            State::Ready | State::Running | State::Stopping => self.homed = true,
            State::Homing | State::Jogging => self.homed = false,
            _ => {}
        }
        if !self.homed {
            sample.pose = sample.target;
            return;
        }
        match self.pose(sample) {
            Some(pose) => sample.pose = pose,
            None => self.unsolved += 1,
        }
    }
}

#[cfg(test)]
mod tests;
