//! Proving the slow checks instead of evaluating them: the control tick moves the platform a few micrometres, and the
//! joint-cone margin and the singularity index (half the cost of all six checks on the M4F) cannot change by more
//! than a bound computed from how far the joints moved since they were last evaluated.
//!
//! The bounds, for chain directions `u_i` (unit), carriages `B_i` on the ring of radius `Rr`, platform joints `A_i`
//! and the platform normal `n`, each compared with its value at the last full check:
//!
//! - Angles: two unit vectors a chord `c` apart are `2 asin(c / 2) <= (pi / 2) c` apart. A chain's angle to the base
//!   plane, `asin(u.z)`, changes by at most the angle `u` turned; its angle to the platform plane, `asin(u . n)`, by
//!   at most that plus the angle `n` turned. So the cone margin drops by at most
//!   `(pi / 2) max_i (|du_i| + |dn|)`.
//! - The singularity index is `|det W|` of the wrench matrix with unit rows (the Hadamard ratio). The determinant is
//!   linear in each row and, by Hadamard's inequality, a row's cofactor is at most the product of the other rows'
//!   norms, 1. Changing the rows one at a time, `|d index| <= sum_i |d w_i|` over the unit rows, and a unit row
//!   moves at most twice as far as the raw row `w = (u, B x u / Rr)` (whose norm is at least `|u| = 1`):
//!   `|d w| <= |du| + (|dB| + Rr |du|) / Rr = 2 |du| + |dB| / Rr`. A radial chain's tangent row
//!   `(v, A x v / Rr)` with `v = (-B_y, B_x, 0) / Rr` moves at most `|dB| / Rr + (|dA| + |A| |dB| / Rr) / Rr`.
//!
//! Each bound takes only differences of vectors IK and the fast checks compute anyway. While both margins stay
//! above their bounds (with [`SLACK`] for rounding), the checks pass and report those lower bounds; otherwise they
//! are evaluated, and the guard starts again from there. Tested against full evaluation on random walks
//! (`shared/tests/suite/guard.rs`).

use super::checks::{Configuration, SlowMargins};
use super::RingPlatform;
use crate::real::length;
use crate::Real;

/// Room kept for rounding: `f32` evaluations of the margins differ from the true values by a few 1e-7.
const SLACK: f64 = 1e-5;

/// Where the slow checks were last evaluated and what they gave, and the configuration being checked now (kept
/// here so that a control loop fills the same memory every tick instead of clearing a new one).
#[derive(Debug, Clone, Copy)]
pub struct SlowCheckGuard<T: Real> {
    /// The configuration of the pose being checked (`configs[current]`) and the one where the slow checks were
    /// last evaluated (the other, when `at` is set). Evaluating makes the checked configuration the reference by
    /// flipping `current`, where keeping one of each copied 348 bytes (a `memcpy` of about 150 instructions on
    /// the M4F, at a quarter of the ticks).
    pub(super) configs: [Configuration<T>; 2],
    pub(super) current: usize,
    at: Option<SlowMargins<T>>,
}

impl<T: Real> Default for SlowCheckGuard<T> {
    fn default() -> Self {
        Self {
            configs: [Configuration::zeroed(); 2],
            current: 0,
            at: None,
        }
    }
}

impl<T: Real> SlowCheckGuard<T> {
    /// The configuration of the pose being checked: what the next IK overwrites, so memory to work in between two
    /// guarded checks (the reference stays as it is).
    pub(super) fn checked(&mut self) -> &mut Configuration<T> {
        &mut self.configs[self.current & 1]
    }
}

impl<T: Real> RingPlatform<T> {
    /// The slow margins of the guard's current configuration: proved from its reference when the bounds allow,
    /// else evaluated (and the reference moved there). Returns whether they were evaluated.
    pub(super) fn slow_margins(&self, guard: &mut SlowCheckGuard<T>) -> (SlowMargins<T>, bool) {
        let [first, second] = &guard.configs;
        let (c, reference) = if guard.current & 1 == 0 {
            (first, second)
        } else {
            (second, first)
        };
        if let Some(slow) = &guard.at {
            if let Some(proved) = self.proved(reference, slow, c) {
                return (proved, false);
            }
        }
        let slow = SlowMargins {
            cones: self.cone_margin(c),
            index: self.singularity_of(c),
        };
        guard.at = Some(slow);
        guard.current ^= 1;
        (slow, true)
    }

    /// Lower bounds of the slow margins at `c` from those at the reference, if both still pass with them.
    fn proved(&self, r: &Configuration<T>, at: &SlowMargins<T>, c: &Configuration<T>) -> Option<SlowMargins<T>> {
        let quarter_turn = T::frac_pi_2();
        let inv_rr = T::one() / self.rr;
        let tilt = length(&(c.rotation.column(2) - r.rotation.column(2)));
        let mut turn = T::zero();
        let mut rows = T::zero();
        for i in 0..self.n {
            let du = length(&(c.dirs[i] - r.dirs[i]));
            let db = length(&(c.carriages[i] - r.carriages[i]));
            turn = turn.max_(du);
            if self.arms[i].is_some() {
                // The forearm's row `(u, E x u / Rr)` moves at most `|du| + (|dE| + |E| |du|) / Rr`.
                let de = length(&(c.bases[i] - r.bases[i]));
                rows += du + (de + length(&r.bases[i]) * du) * inv_rr;
            } else {
                rows += du + du + db * inv_rr;
            }
            if self.kinds[i].is_planar() {
                let da = length(&(c.joints[i] - r.joints[i]));
                let reach = length(&r.joints[i]) * inv_rr;
                rows += db * inv_rr + (da + reach * db) * inv_rr;
            }
        }
        let slack = T::of(SLACK);
        let cones = at.cones - quarter_turn * (turn + tilt) - slack;
        // Two for each unit row moving up to twice as far as its raw row.
        let index = at.index - (rows + rows) - slack;
        (cones >= T::zero() && index >= self.min_index).then_some(SlowMargins { cones, index })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    use super::*;
    use crate::kinematics::presets::{Preset, PresetGeometry};
    use crate::kinematics::{Actuators, Mechanism, Pose};

    /// A guard whose configuration being checked holds `value` in every entry: what IK does not overwrite, the
    /// checks would read.
    fn filled<T: Real>(value: f64) -> SlowCheckGuard<T> {
        let x = T::of(value);
        let v = Vector3::new(x, x, x);
        let c = Configuration {
            q: Actuators([x; 6]),
            rotation: Matrix3::from_element(x),
            joints: [v; 6],
            carriages: [v; 6],
            bases: [v; 6],
            dirs: [v; 6],
            reach: x,
        };
        SlowCheckGuard {
            configs: [c; 2],
            current: 0,
            at: None,
        }
    }

    /// Every ring preset's mechanism in `f32` and `f64` at a pose `offset` (in units of the ring radius and of a
    /// radian) from its home: the checks in a reused configuration filled with NaN, with a huge value and with the
    /// last pose's configuration give what they give in a new one, whichever room stops them.
    fn compare<T: Real>(offset: &[f64; 6]) {
        let rooms: [[T; 6]; 3] = [
            [T::of(-1e9); 6],
            [T::zero(); 6],
            crate::motion::EnvelopeMargins::default().room(),
        ];
        for preset in Preset::ALL {
            let PresetGeometry::Ring(g) = preset.geometry() else {
                continue;
            };
            let m = RingPlatform::<T>::new(g);
            let rr = g.ring_radius;
            let home = preset.home();
            let pose = Pose::from_array(super::super::away_from(&home, offset, rr).map(T::of));
            let home = Pose::from_array(home.map(T::of));
            let mut used = SlowCheckGuard::<T>::default();
            let _ = m.inverse_within_in(&home, &rooms[0], &mut used);
            for room in &rooms {
                let fresh = m.inverse_within(&pose, room);
                for guard in [&mut filled(f64::NAN), &mut filled(1e30), &mut used] {
                    assert_eq!(
                        m.inverse_within_in(&pose, room, guard),
                        fresh,
                        "{} at {pose:?}",
                        preset.name()
                    );
                }
            }
            // Working in the guard leaves its reference alone: the next guarded check proves what it would have.
            let mut guard = SlowCheckGuard::<T>::default();
            let _ = m.inverse_guarded(&home, &mut guard);
            let mut untouched = guard;
            let _ = m.inverse_within_in(&pose, &rooms[0], &mut guard);
            assert_eq!(
                m.inverse_guarded(&home, &mut guard),
                m.inverse_guarded(&home, &mut untouched)
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3_000))]
        #[test]
        fn a_reused_configuration_checks_as_a_new_one(
            t in prop::array::uniform3(-0.5f64..0.5),
            r in prop::array::uniform3(-0.8f64..0.8),
        ) {
            let offset = [t[0], t[1], t[2] * 0.5, r[0], r[1], r[2] * 4.0];
            compare::<f32>(&offset);
            compare::<f64>(&offset);
        }
    }
}
