//! The tilts' loss of vertical force, priced in their own programmes (`optimal.tilt_loss_weight`). A platform
//! tilted by `theta_x` and `theta_y` sees gravity's vertical share fall by `l = g (1 - cos theta_x cos theta_y)`,
//! about `g theta^2 / 2`: 0.6 m/s^2 at 20 deg, twice the otoliths' vertical threshold, and a false heave cue
//! wherever the vehicle's own vertical force is the other way. The per-axis programmes are linear in the angle and
//! do not see it. Each horizontal programme prices `w l^2` on its own angle, as a quadratic about its last plan
//! (its angles from where that plan has reached, the other axis's likewise), a price that changes each sample:
//! Newton's, `w (l'^2 + l l'')` on `(theta - theta0)^2` with the gradient `2 w l l'`. Gauss-Newton's (without
//! `l l''`) is not enough: with the other axis tilted `l` stays large as this one's angle and `l'` go to zero, and
//! its quadratic's centre, `theta0 - l / l'`, runs off to either side of zero, a sign flip each sample (on the laps
//! a roll rate of 0.46 rad/s back and forth). With `l l''` the price near zero is a plain one on the angle,
//! `w l g theta^2`: the more the other tilt has lost, the dearer this one. The plan moves little from one sample
//! to the next, so each sample's quadratic is about a near neighbour of its answer.
//!
//! The same price keeps the plan (`optimal.plan_weight`): `c (theta_k - theta0_k)^2` at each step about the last
//! plan's angles shifted on by the sample. Without it each sample's plan answers that sample's noise held over
//! the horizon (on the laps, 5 % of the force: a tilt target that moves 1.6 deg from sample to sample), its first
//! step's rate turning one way and the next sample's the other: a pitch or roll rate past the canals' threshold
//! in episodes of one or two samples, false wherever the vehicle's own small rate is of the other sign.

use ringpod_core::cueing::G;

use super::{Axis, Optimal, Z};

/// The angle's place among a horizontal axis's outputs ([`super::model::horizontal`]).
pub const ANGLE: usize = 4;

impl Optimal {
    /// The price on horizontal axis `i`'s angle at each step of the horizon (steps of `h` seconds): its weight and
    /// the angle it pulls towards ([`super::qp::AxisQp::solve`]); none on z or with both weights at zero. The
    /// loss's price, and the plan's consistency: `c (theta_k - theta0_k)^2` about the last plan shifted on by the
    /// sample (`optimal.plan_weight`), so that a plan that turned one way at the last sample does not turn the
    /// other at this one for want of a reason (the two quadratics on one angle are one: their weights summed about
    /// their weighted centre).
    pub(super) fn angle_price(&self, i: usize, h: f64) -> Vec<(f64, f64)> {
        let o = &self.config.optimal;
        let (w, c) = (o.tilt_loss_weight, o.plan_weight);
        if i == Z || (w == 0.0 && c == 0.0) {
            return Vec::new();
        }
        let n = self.axes[i].qp.steps();
        let mine = self.axes[i].shifted_angles(h, n);
        let other = self.axes[1 - i].shifted_angles(h, n);
        mine.iter()
            .zip(&other)
            .map(|(&a, &b)| {
                let loss = if w == 0.0 { (0.0, 0.0) } else { newton(w, a, b) };
                kept(loss, c, a)
            })
            .collect()
    }
}

/// The price `(weight, centre)` with the plan's consistency `c (theta - planned)^2` added: one quadratic, the
/// weights summed about their weighted centre (the price as it was without it).
fn kept((weight, centre): (f64, f64), c: f64, planned: f64) -> (f64, f64) {
    if c == 0.0 {
        return (weight, centre);
    }
    let sum = weight + c;
    (sum, (weight * centre + c * planned) / sum)
}

/// The cost `w l^2` of the loss `l` at angles `a` (this axis's) and `b` (the other's) as a price on this axis's
/// angle: `(weight, centre)` of `weight (theta - centre)^2`, its second-order expansion about `a` (none where it
/// has no curvature: level).
fn newton(w: f64, a: f64, b: f64) -> (f64, f64) {
    let loss = G * (1.0 - a.cos() * b.cos());
    let slope = G * a.sin() * b.cos();
    // Within the tilt limits (well under 90 deg) the curvature `l''` is positive.
    let curvature = (G * a.cos() * b.cos()).max(0.0);
    let weight = w * (slope * slope + loss * curvature);
    if weight <= 0.0 {
        return (0.0, 0.0);
    }
    (weight, a - w * loss * slope / weight)
}

impl Axis {
    /// A horizontal axis's angle at the end of each of `steps` steps of `h` seconds from now, along its last
    /// plan from where it has reached (its age), from its present angle; the plan's last angle held past its end
    /// (and the present one before any plan).
    pub(super) fn shifted_angles(&self, h: f64, steps: usize) -> Vec<f64> {
        let rates: Vec<f64> = self.plan.as_slice().chunks_exact(3).map(|s| s[1] + s[2]).collect();
        // The plan's angle change from its start to `t` seconds into it.
        let along = |t: f64| {
            let whole = ((t / h + 1e-9) as usize).min(rates.len());
            let done: f64 = rates[..whole].iter().sum::<f64>() * h;
            done + rates.get(whole).map_or(0.0, |r| r * (t - whole as f64 * h).max(0.0))
        };
        let now = self.x[2] + self.x[3];
        let start = along(self.plan_age);
        (1..=steps)
            .map(|k| now + along(self.plan_age + k as f64 * h) - start)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{patient, ranges, tilting};
    use super::super::{X, Y};
    use super::*;
    use nalgebra::DVector;
    use ringpod_core::cueing::perception::{Perception, FORCE_THRESHOLD};
    use ringpod_core::cueing::{self, Telemetry};

    /// The expansion is the cost's own: its value's slope and curvature at the angle, by differences.
    #[test]
    fn the_price_is_the_costs_second_order_expansion() {
        let w = 7.0;
        let cost = |a: f64, b: f64| w * (G * (1.0 - a.cos() * b.cos())).powi(2);
        for (a, b) in [(0.3, 0.0), (-0.2, 0.25), (0.01, 0.3), (0.0, 0.3), (-0.35, -0.1)] {
            let (weight, centre) = newton(w, a, b);
            let e = 1e-4;
            let slope = (cost(a + e, b) - cost(a - e, b)) / (2.0 * e);
            let curvature = (cost(a + e, b) - 2.0 * cost(a, b) + cost(a - e, b)) / (e * e);
            assert!((2.0 * weight - curvature).abs() < 1e-4 * curvature.max(1.0), "{a} {b}");
            assert!(
                (2.0 * weight * (a - centre) - slope).abs() < 1e-5 * slope.abs().max(1.0),
                "{a} {b}"
            );
            // The centre lies between zero and the angle: the price never pulls past level.
            assert!(centre * a >= 0.0 && centre.abs() <= a.abs(), "{a} {b}: {centre}");
        }
        assert_eq!(newton(w, 0.0, 0.0), (0.0, 0.0));
    }

    #[test]
    fn the_angles_run_along_the_last_plan_from_where_it_has_reached() {
        let mut o = Optimal::new(patient(), &ranges().into()).unwrap();
        let a = &mut o.axes[X];
        a.x[2] = 0.1;
        // Two steps of 0.15 s at 0.2 and -0.1 rad/s (tilt and rotation rates summed), 0.05 s into the first.
        a.plan = DVector::from_vec(vec![0.0, 0.15, 0.05, 0.0, -0.1, 0.0]);
        a.plan_age = 0.05;
        let angles = a.shifted_angles(0.15, 3);
        let expected = [
            0.1 + 0.1 * 0.2 - 0.05 * 0.1,
            0.1 + 0.1 * 0.2 - 0.15 * 0.1,
            0.1 + 0.1 * 0.2 - 0.15 * 0.1,
        ];
        for (got, want) in angles.iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{angles:?}");
        }
        o.axes[Y].plan = DVector::zeros(0);
        assert_eq!(o.axes[Y].shifted_angles(0.15, 2), vec![0.0, 0.0]);
    }

    /// Cornering held at 3 m/s^2 for 20 s, more than the tilt gives: unpriced, the roll stays at its bound (16.3
    /// deg) and the rider perceives the vertical force 0.42 m/s^2 low at the end, above the otoliths' 0.28 m/s^2
    /// threshold (a false heave cue where the road is level); priced at 50, the roll settles at 11.6 deg and the
    /// vertical error at 0.20 m/s^2, under it, while the lateral force is cued all the same, 0.7 times as much.
    #[test]
    fn a_priced_loss_keeps_a_held_corners_vertical_error_under_the_threshold() {
        let drive = |weight: f64| {
            let mut c = tilting();
            c.optimal.tilt_loss_weight = weight;
            let mut o = Optimal::new(c, &ranges().into()).unwrap();
            let level = |ay: f64| Telemetry {
                force: [0.0, ay, G],
                rate: [0.0; 3],
            };
            o.begin(&level(0.0)).unwrap();
            let dt = 0.02;
            let offsets: Vec<[f64; 6]> = (0..1000).map(|_| o.step(&level(3.0), dt, &[]).unwrap()).collect();
            let mut p = Perception::<f64>::new();
            p.begin([0.0; 3], [0.0; 3]);
            let mut perceived = [0.0; 3];
            for k in 1..offsets.len() - 1 {
                let second = |j: usize| (offsets[k + 1][j] - 2.0 * offsets[k][j] + offsets[k - 1][j]) / (dt * dt);
                let f = cueing::delivered([second(0), second(1), second(2)], offsets[k][3], offsets[k][4]);
                perceived = p.step([f[0], f[1], f[2] - G], [0.0; 3], dt).force;
            }
            (perceived, offsets[999][3])
        };
        let (unpriced, roll) = drive(0.0);
        let (priced, priced_roll) = drive(50.0);
        assert!(roll > 0.28, "rolled {roll}");
        assert!(-unpriced[2] > FORCE_THRESHOLD[2] + 0.1, "{unpriced:?}");
        assert!(-priced[2] < FORCE_THRESHOLD[2] - 0.05 && priced[2] < 0.0, "{priced:?}");
        assert!(
            priced_roll > 0.15 && priced_roll < roll - 0.05,
            "{priced_roll} against {roll}"
        );
        assert!(priced[1] > 0.6 * unpriced[1], "{priced:?} against {unpriced:?}");
    }

    /// Braking held at 2 m/s^2 with the laps' noise (5 % of the force, sample by sample): the plan solved from
    /// each noisy sample held chases the noise, its first step's tilt rate turning from one sample to the next,
    /// and the rider perceives a pitch rate past the canals' threshold in many short episodes where the vehicle
    /// has none. Kept close to the last plan (`plan_weight`), the pitch is perceived past the threshold less than
    /// half as long while the tilt cues the braking as much: 151 samples of 400 against 314, at a mean pitch of
    /// 0.169 rad (9.7 deg) either way.
    #[test]
    fn a_plan_kept_from_sample_to_sample_does_not_pitch_with_the_noise() {
        use ringpod_core::cueing::perception::ROTATION_THRESHOLD_DEG;
        let drive = |weight: f64| {
            let mut c = tilting();
            // `optimal-tilt-kept.toml`'s weights.
            c.optimal.tilt_loss_weight = 40.0;
            c.optimal.plan_weight = weight;
            let mut o = Optimal::new(c, &ranges().into()).unwrap();
            // A fixed sequence of uniform noise in -1..1 (a linear congruential generator): the same every run.
            let mut seed = 12345u64;
            let mut noise = move || {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            let braking = |ax: f64| Telemetry {
                force: [ax, 0.0, G],
                rate: [0.0; 3],
            };
            o.begin(&braking(0.0)).unwrap();
            let dt = 0.01;
            let pitch: Vec<f64> = (0..600)
                .map(|_| o.step(&braking(-2.0 * (1.0 + 0.087 * noise())), dt, &[]).unwrap()[4])
                .collect();
            let mut p = Perception::<f64>::new();
            p.begin([0.0; 3], [0.0; 3]);
            let threshold = ROTATION_THRESHOLD_DEG[1].to_radians();
            let mut past = 0;
            for k in 1..pitch.len() {
                let rate = p.step([0.0; 3], [0.0, (pitch[k] - pitch[k - 1]) / dt, 0.0], dt).rate[1];
                // From 2 s on: the braking's onset is a true cue, and the tilt has come in.
                past += usize::from(k >= 200 && rate.abs() > threshold);
            }
            let mean = pitch[200..].iter().sum::<f64>() / 400.0;
            (past, mean)
        };
        let (chasing, tilt) = drive(0.0);
        let (kept, kept_tilt) = drive(1000.0);
        assert!(tilt > 0.15, "pitched {tilt}");
        assert!(
            chasing > 250 && kept * 2 < chasing,
            "{kept} samples past the threshold kept, {chasing} not"
        );
        assert!((kept_tilt - tilt).abs() < 0.02 * tilt, "{kept_tilt} against {tilt}");
    }
}
