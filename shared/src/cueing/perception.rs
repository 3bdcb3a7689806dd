//! What a rider perceives: the vestibular models of motion cueing, used by the optimal cueing (its cost) and by
//! the bench (its score).
//!
//! The otoliths sense specific force, the semicircular canals angular velocity; both are linear models with the
//! parameters of Telban and Cardullo, *Motion Cueing Algorithm Development: Human-Centered Linear and Nonlinear
//! Approaches* (NASA CR-2005-213747), chapter 3, the otolith and semicircular-canal models and their parameter
//! table, which take the otolith from Young and Meiry (poles 0.19 and 1.5 rad/s, zero 0.076 rad/s) and the canal
//! from the torsion pendulum with adaptation:
//!
//! ```text
//! otolith:   f^ / f = K (tau_a s + 1) / ((tau_l s + 1)(tau_s s + 1))        tau_a 13.2 s, tau_l 5.33 s, tau_s 0.66 s
//! canal:     w^ / w = tau_a' tau_1 s^2 (tau_l' s + 1) / ((tau_a' s + 1)(tau_1 s + 1)(tau_2 s + 1))
//!                                                       tau_1 5.73 s, tau_2 0.005 s, tau_l' 0.06 s, tau_a' 80 s
//! ```
//!
//! The otolith's gain `K` is taken as 1 (the paper's 0.4 is an afferent firing-rate scale): the perceived force is
//! then in m/s^2, equal to a sustained stimulus, and the canal's mid-band gain is 1 by its form, so both compare
//! with the perception thresholds of Reid and Nahon's tables (0.17 m/s^2 on x and y, 0.28 m/s^2 on z; 3.0, 3.6
//! and 2.6 deg/s in roll, pitch and yaw), which are what a perceived error or a false cue is measured against.
//!
//! Discretised by the bilinear (Tustin) transform at each sample's own interval, as every washout filter is
//! ([`super::filter`]): the otolith is one second-order section, the canal a second-order high-pass (the two slow
//! poles over `s^2`) followed by a first-order lead-lag (the lead `tau_l'` over the fast pole `tau_2`).

use super::filter::{Biquad, Section};
use crate::Real;

/// Otolith time constants (s): the lead `tau_a`, the long `tau_l` and the short `tau_s`.
pub const OTOLITH_TAU: [f64; 3] = [13.2, 5.33, 0.66];
/// Semicircular-canal time constants (s): the long `tau_1`, the short `tau_2`, the lead `tau_l` and the
/// adaptation `tau_a`.
pub const CANAL_TAU: [f64; 4] = [5.73, 0.005, 0.06, 80.0];
/// Specific-force perception thresholds on x, y, z (m/s^2).
pub const FORCE_THRESHOLD: [f64; 3] = [0.17, 0.17, 0.28];
/// Angular-velocity perception thresholds in roll, pitch, yaw (deg/s).
pub const ROTATION_THRESHOLD_DEG: [f64; 3] = [3.0, 3.6, 2.6];

/// The otolith's section: `(tau_a s + 1) / ((tau_l s + 1)(tau_s s + 1))`, divided through by `tau_l tau_s`.
pub fn otolith_section<T: Real>() -> Section<T> {
    let [ta, tl, ts] = OTOLITH_TAU;
    let p = tl * ts;
    Section {
        b: [T::zero(), T::of(ta / p), T::of(1.0 / p)],
        a: [T::of((tl + ts) / p), T::of(1.0 / p)],
    }
}

/// The canal's two sections: `s^2 / ((s + 1/tau_a)(s + 1/tau_1))` and `(tau_l s + 1) / (tau_2 s + 1)` (first
/// order, `b[1] s + b[2]` over `s + a[0]`).
pub fn canal_sections<T: Real>() -> (Section<T>, Section<T>) {
    let [t1, t2, tl, ta] = CANAL_TAU;
    let slow = Section {
        b: [T::one(), T::zero(), T::zero()],
        a: [T::of(1.0 / ta + 1.0 / t1), T::of(1.0 / (ta * t1))],
    };
    let lead = Section {
        b: [T::zero(), T::of(tl / t2), T::of(1.0 / t2)],
        a: [T::of(1.0 / t2), T::zero()],
    };
    (slow, lead)
}

/// The perceived specific force and angular velocity of one rider, each axis its own model.
#[derive(Debug, Clone)]
pub struct Perception<T: Real> {
    otolith: [Biquad<T>; 3],
    canal: [(Biquad<T>, Biquad<T>); 3],
}

/// What the rider perceives after a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Perceived<T> {
    /// Specific force on x, y, z (m/s^2), the constant `g` of a level rider at rest left out (the models see the
    /// change from rest, as a rider does).
    pub force: [T; 3],
    /// Angular velocity in roll, pitch, yaw (rad/s).
    pub rate: [T; 3],
}

impl<T: Real> Default for Perception<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> Perception<T> {
    /// A rider at rest.
    pub fn new() -> Self {
        let (slow, lead) = canal_sections::<T>();
        Self {
            otolith: core::array::from_fn(|_| Biquad::new(otolith_section())),
            canal: core::array::from_fn(|_| (Biquad::new(slow), Biquad::first_order(lead))),
        }
    }

    /// The first stimulus of a run: held as the last input, the models at rest (a drive that starts in a
    /// corner is perceived as starting there, as the washout's first sample is).
    pub fn begin(&mut self, force: [T; 3], rate: [T; 3]) {
        for (f, v) in self.otolith.iter_mut().zip(force) {
            f.settle(v);
        }
        for ((slow, lead), v) in self.canal.iter_mut().zip(rate) {
            // A sustained rate is not perceived (the canal's gain at rest is zero): settled on it, reading zero.
            slow.settle(v);
            lead.settle(T::zero());
        }
    }

    /// One stimulus at the end of `dt` seconds: the specific force less the `g` of rest (m/s^2) and the angular
    /// velocity (rad/s); returns what is perceived.
    pub fn step(&mut self, force: [T; 3], rate: [T; 3], dt: T) -> Perceived<T> {
        Perceived {
            force: core::array::from_fn(|i| self.otolith[i].step(force[i], dt)),
            rate: core::array::from_fn(|i| {
                let (slow, lead) = &mut self.canal[i];
                let w = slow.step(rate[i], dt);
                lead.step(w, dt)
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The response to `sin(w t)` after the transient: amplitude and phase (rad) by correlation over whole periods.
    fn measured(mut step: impl FnMut(f64, f64) -> f64, w: f64) -> (f64, f64) {
        let period = core::f64::consts::TAU / w;
        let dt = (period / 2000.0).min(0.001);
        // Settle for ten of the slowest time constants (80 s adaptation), then correlate over 4 periods.
        let settle = 800.0_f64.max(20.0 * period);
        let n = (settle / dt) as usize;
        for k in 1..=n {
            step(libm::sin(w * k as f64 * dt), dt);
        }
        let m = (4.0 * period / dt).round() as usize;
        let (mut s, mut c) = (0.0, 0.0);
        for k in 1..=m {
            let t = (n + k) as f64 * dt;
            let y = step(libm::sin(w * t), dt);
            s += y * libm::sin(w * t);
            c += y * libm::cos(w * t);
        }
        let (s, c) = (2.0 * s / m as f64, 2.0 * c / m as f64);
        (libm::hypot(s, c), libm::atan2(c, s))
    }

    /// Gain and phase of the otolith model at `w` rad/s, from its transfer function.
    fn otolith_h(w: f64) -> (f64, f64) {
        let [ta, tl, ts] = OTOLITH_TAU;
        let g = libm::hypot(1.0, ta * w) / (libm::hypot(1.0, tl * w) * libm::hypot(1.0, ts * w));
        (g, libm::atan(ta * w) - libm::atan(tl * w) - libm::atan(ts * w))
    }

    #[test]
    fn the_otoliths_frequency_response_is_the_papers() {
        // Gain 1 at rest; a lead between the zero (0.076 rad/s) and the poles (0.19, 1.5 rad/s): gain above 1
        // mid-band and falling past 1.5 rad/s. Reference values from the transfer function.
        for (w, gain, phase_deg) in [(0.1, 1.458, 21.02), (1.0, 2.037, -27.13), (10.0, 0.371, -80.74)] {
            let (g, p) = otolith_h(w);
            assert!(
                (g - gain).abs() < 2e-3 && (p.to_degrees() - phase_deg).abs() < 0.05,
                "{w}: {g} {p}"
            );
            let mut m = Perception::<f64>::new();
            let (mg, mp) = measured(|u, dt| m.step([u, 0.0, 0.0], [0.0; 3], dt).force[0], w);
            assert!((mg - g).abs() < 2e-3 * g, "gain at {w} rad/s: {mg} vs {g}");
            assert!(
                (mp - p).abs() < 0.01,
                "phase at {w} rad/s: {} vs {}",
                mp.to_degrees(),
                p.to_degrees()
            );
        }
    }

    #[test]
    fn the_canals_frequency_response_is_the_papers() {
        let [t1, t2, tl, ta] = CANAL_TAU;
        // Mid-band (between 1/tau_1 and 1/tau_l) the canal reads angular velocity nearly one to one; below it
        // the cupula's restoring force takes the gain away (a phase lead towards 90 deg), above it the lead
        // tau_l' raises the gain.
        for w in [0.05, 1.0, 20.0] {
            let g = ta * t1 * w * w * libm::hypot(1.0, tl * w)
                / (libm::hypot(1.0, ta * w) * libm::hypot(1.0, t1 * w) * libm::hypot(1.0, t2 * w));
            let p = core::f64::consts::PI + libm::atan(tl * w)
                - libm::atan(ta * w)
                - libm::atan(t1 * w)
                - libm::atan(t2 * w);
            let mut m = Perception::<f64>::new();
            let (mg, mp) = measured(|u, dt| m.step([0.0; 3], [0.0, u, 0.0], dt).rate[1], w);
            assert!((mg - g).abs() < 3e-3 * g, "gain at {w} rad/s: {mg} vs {g}");
            let wrap = |a: f64| libm::remainder(a, core::f64::consts::TAU);
            assert!(
                wrap(mp - p).abs() < 0.01,
                "phase at {w} rad/s: {} vs {}",
                mp.to_degrees(),
                p.to_degrees()
            );
            if w == 1.0 {
                assert!(
                    (g - 0.987).abs() < 2e-3 && (wrap(p).to_degrees() - 13.76).abs() < 0.05,
                    "{g} {p}"
                );
            }
        }
    }

    #[test]
    fn a_force_step_overshoots_then_settles_as_the_model_says() {
        // Step response: 1 + c_l e^(-t/tau_l) + c_s e^(-t/tau_s), c_l = (tau_a - tau_l)/(tau_l - tau_s),
        // c_s = (tau_a - tau_s)/(tau_s - tau_l): the perceived force overshoots to about twice the stimulus near
        // 1.9 s, then settles on it (the otolith's lead).
        let [ta, tl, ts] = OTOLITH_TAU;
        let (cl, cs) = ((ta - tl) / (tl - ts), (ta - ts) / (ts - tl));
        let want = |t: f64| 1.0 + cl * libm::exp(-t / tl) + cs * libm::exp(-t / ts);
        let mut m = Perception::<f64>::new();
        m.begin([0.0; 3], [0.0; 3]);
        let dt = 0.01;
        let mut peak = (0.0, 0.0);
        for k in 1..=6000 {
            let t = f64::from(k) * dt;
            let y = m.step([1.0, 0.0, 0.0], [0.0; 3], dt).force[0];
            // The input jumps within the first interval, which the trapezoid takes as a ramp: compare from 0.1 s.
            if t >= 0.1 {
                assert!((y - want(t - dt / 2.0)).abs() < 2e-3, "{t}: {y} vs {}", want(t));
            }
            if y > peak.1 {
                peak = (t, y);
            }
        }
        assert!((peak.0 - 1.92).abs() < 0.05 && (peak.1 - 2.03).abs() < 0.01, "{peak:?}");
    }

    #[test]
    fn a_rate_step_is_felt_then_fades_and_reverses() {
        // A step of angular velocity: felt at once (one to one), fading with the cupula's 5.73 s, and reversed
        // by the adaptation (the after-sensation of a turn held long) before it returns to rest.
        let mut m = Perception::<f64>::new();
        let dt = 0.005;
        let at = |m: &mut Perception<f64>, from: usize, to: usize| {
            let mut y = 0.0;
            for _ in from..to {
                y = m.step([0.0; 3], [0.1, 0.0, 0.0], dt).rate[0];
            }
            y
        };
        let early = at(&mut m, 0, 20);
        assert!((early - 0.1).abs() < 0.005, "{early}");
        let later = at(&mut m, 20, 1146);
        // At tau_1 (5.73 s) the cupula's part is e^-1 of the stimulus, less the adaptation's beginning.
        assert!((0.030..0.037).contains(&later), "{later}");
        let long = at(&mut m, 1146, 8000);
        assert!(
            long < -0.001,
            "the adaptation reverses the sensation of a sustained rate: {long}"
        );
    }

    #[test]
    fn a_drive_begun_in_a_sustained_corner_perceives_it_steadily() {
        let mut m = Perception::<f64>::new();
        m.begin([3.0, -2.0, 0.5], [0.2, 0.0, 0.0]);
        let p = m.step([3.0, -2.0, 0.5], [0.2, 0.0, 0.0], 0.01);
        assert!(
            (p.force[0] - 3.0).abs() < 1e-9 && (p.force[1] + 2.0).abs() < 1e-9,
            "{p:?}"
        );
        assert!(p.rate[0].abs() < 1e-9, "{p:?}");
    }
}
