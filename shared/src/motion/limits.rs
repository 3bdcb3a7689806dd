//! Velocity and acceleration limits, and the per-axis tracker that enforces them.

/// Limits per pose axis (`x, y, z` in m/s and m/s^2; `alpha, beta, gamma` in rad/s and rad/s^2) and per actuator
/// (rad/s or m/s, and per second squared).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotionLimits {
    /// Pose velocity limit per axis.
    pub pose_velocity: [f32; 6],
    /// Pose acceleration limit per axis.
    pub pose_acceleration: [f32; 6],
    /// Actuator velocity limit per axis (the stepper's top step rate divided by its steps per unit).
    pub actuator_velocity: [f32; 6],
    /// Actuator acceleration limit per axis.
    pub actuator_acceleration: [f32; 6],
}

impl MotionLimits {
    /// The 1:20 trainer model: 0.05 m/s (spec table), 1.9 rad/s of yaw (its test motion) and 1 rad/s of tilt;
    /// accelerations of 1 m/s^2 and 20 rad/s^2 let the 50 Hz vibration tests run at small amplitude. Actuators:
    /// 2 rad/s on the carriages (8 k steps/s) and 0.06 m/s on the linear actuators (96 k steps/s), inside the
    /// 100 k steps/s the step generator sustains.
    pub const TRAINER_MODEL: MotionLimits = MotionLimits {
        pose_velocity: [0.05, 0.05, 0.05, 1.0, 1.0, 1.9],
        pose_acceleration: [1.0, 1.0, 1.0, 20.0, 20.0, 20.0],
        actuator_velocity: [2.4, 2.4, 2.4, 2.4, 0.06, 0.06],
        actuator_acceleration: [60.0, 60.0, 60.0, 60.0, 1.5, 1.5],
    };
}

/// One axis following a reference under a velocity and an acceleration limit, in discrete time.
///
/// The speed it commands toward the reference is never more than it can brake from before reaching it:
/// decelerating by `a * dt` a tick from speed `v` covers `v (v / (a dt) + 1) dt / 2`, so the largest speed that still
/// stops within the remaining error `e` is `a dt (sqrt(1/4 + 2 e / (a dt^2)) - 1/2)`. A reference that stops is
/// therefore reached without overshoot.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisTracker {
    /// Current speed (units/s).
    pub velocity: f32,
}

impl AxisTracker {
    /// Speed for the next tick toward `error` (reference minus position), limited by `vmax` and `amax`.
    pub fn step(&mut self, error: f32, dt: f32, vmax: f32, amax: f32) -> f32 {
        let adt = amax * dt;
        let stop = if adt > 0.0 {
            adt * (libm::sqrtf(0.25 + 2.0 * libm::fabsf(error) / (adt * dt)) - 0.5)
        } else {
            0.0
        };
        let reach = libm::fabsf(error) / dt;
        let wanted = libm::copysignf(reach.min(stop).min(vmax), error);
        self.velocity = wanted.clamp(self.velocity - adt, self.velocity + adt);
        self.velocity
    }

    /// Speed for the next tick when braking to rest at `amax`.
    pub fn brake(&mut self, dt: f32, amax: f32) -> f32 {
        let adt = amax * dt;
        self.velocity = if libm::fabsf(self.velocity) <= adt {
            0.0
        } else {
            self.velocity - libm::copysignf(adt, self.velocity)
        };
        self.velocity
    }
}
