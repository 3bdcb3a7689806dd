//! Velocity and acceleration limits, and the per-axis tracker that enforces them.

use crate::Real;

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

/// One axis following a reference under a velocity and an acceleration limit, in discrete time.
///
/// The speed it commands toward the reference is never more than it can brake from, a tick at a time, before the
/// point where the reference stops (see [`AxisTracker::step`] for the exact discrete bound): a reference that stops
/// is reached without overshoot.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisTracker {
    /// Current speed (units/s).
    pub velocity: f32,
}

impl AxisTracker {
    /// Speed for the next tick toward `error` (reference minus position), limited by `vmax` and `amax`, never
    /// faster than it can brake from within `stop_distance` (the distance to where the reference will stop).
    pub fn step(&mut self, error: f32, stop_distance: f32, dt: f32, vmax: f32, amax: f32) -> f32 {
        let adt = amax * dt;
        let d = libm::fabsf(stop_distance);
        // An axis with no error is not sent anywhere (the speed it asks for is 0, whatever `stop` is, since `stop`
        // is never negative): the braking bound, a root and two divisions, is left out for it.
        let stop = if adt > 0.0 && error != 0.0 {
            // Braking from v covers dt (v + (v - a dt) + ... ) down to the last positive speed. With n whole braking
            // steps (n a dt <= v < (n + 1) a dt) that is dt (n + 1) (v - n a dt / 2), so the fastest speed that stops
            // within d is d / ((n + 1) dt) + n a dt / 2; the continuous estimate picks n.
            let k = crate::real::sqrtf(0.25 + 2.0 * d / (adt * dt)) - 0.5;
            // floor of a non-negative value: a truncating conversion (one VCVT on the M4F; libm's floorf works on
            // the bits); from 2^23 on every f32 is a whole number already.
            let k = k.max_(0.0);
            let n = if k < 8_388_608.0 { (k as i32) as f32 } else { k };
            (d / ((n + 1.0) * dt) + n * adt * 0.5).min_((n + 1.0) * adt)
        } else {
            0.0
        };
        let reach = libm::fabsf(error) / dt;
        let wanted = libm::copysignf(reach.min_(stop).min_(vmax), error);
        // Not f32::clamp: it asserts its bounds are ordered, a panic path (adt is never negative here).
        self.velocity = wanted.max_(self.velocity - adt).min_(self.velocity + adt);
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The step with the braking bound taken for every axis: what the step, which leaves the bound out for an
    /// axis with no error, must give bit for bit.
    fn always_bounded(v: f32, error: f32, stop_distance: f32, dt: f32, vmax: f32, amax: f32) -> f32 {
        let adt = amax * dt;
        let d = libm::fabsf(stop_distance);
        let stop = if adt > 0.0 {
            let k = crate::real::sqrtf(0.25 + 2.0 * d / (adt * dt)) - 0.5;
            let k = k.max_(0.0);
            let n = if k < 8_388_608.0 { (k as i32) as f32 } else { k };
            (d / ((n + 1.0) * dt) + n * adt * 0.5).min_((n + 1.0) * adt)
        } else {
            0.0
        };
        let reach = libm::fabsf(error) / dt;
        let wanted = libm::copysignf(reach.min_(stop).min_(vmax), error);
        wanted.max_(v - adt).min_(v + adt)
    }

    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn an_axis_without_error_gets_the_speed_the_bound_would_give(
            v in prop_oneof![Just(0.0f32), -2.0f32..2.0, any::<f32>()],
            error in prop_oneof![Just(0.0f32), Just(-0.0f32), -1.0f32..1.0, any::<f32>()],
            stop_distance in prop_oneof![Just(0.0f32), -1.0f32..1.0, any::<f32>()],
            dt in prop_oneof![Just(0.001f32), Just(0.0005f32), 0.0f32..0.1],
            vmax in prop_oneof![0.0f32..10.0, any::<f32>()],
            amax in prop_oneof![Just(0.0f32), 0.0f32..100.0, any::<f32>()],
        ) {
            let mut t = AxisTracker { velocity: v };
            let got = t.step(error, stop_distance, dt, vmax, amax);
            let want = always_bounded(v, error, stop_distance, dt, vmax, amax);
            prop_assert!(same(got, want) && same(t.velocity, want), "{got:e} {want:e}");
        }
    }
}
