//! The tilt's loss of vertical force, given to the heave. A platform tilted by `theta_x` and `theta_y` sees
//! gravity's vertical share fall by `g (1 - cos theta_x cos theta_y)` (0.6 m/s^2 at 20 deg, twice the otoliths'
//! vertical threshold), but each axis plans on its own, so neither the tilt's programmes nor the heave's price it.
//! The heave plans last, after both tilts: it is given their plans' loss over its horizon as a known disturbance
//! of its perceived force (the reference raised by the loss's perceived response), and its own state carries the
//! loss the platform has. A heave cannot hold a sustained force (the otoliths' gain at rest is 1), so what it
//! does is move the loss in time: it falls while the tilt comes in and is caught as the loss grows.

use nalgebra::{DMatrix, DVector};
use ringpod_core::cueing::G;

use super::model::{vertical, Discrete, Linear};
use super::{tilt, Axis, Optimal, X, Y, Z};

/// The vertical force a platform tilted by `x` and `y` (rad) loses (m/s^2).
pub fn loss(x: f64, y: f64) -> f64 {
    G * (1.0 - x.cos() * y.cos())
}

/// The vertical model's response to the loss: the loss enters the rider's perception as the heave's
/// acceleration does, with the other sign, and moves no position.
fn loss_model() -> Linear {
    let m = vertical();
    let mut b = -&m.b;
    b[(1, 0)] = 0.0;
    let mut d = -&m.d;
    d[(1, 0)] = 0.0;
    d[(2, 0)] = 0.0;
    Linear { b, d, ..m }
}

/// The loss's effect on the heave: its model discretised at the plan's step and at the last sample's interval.
#[derive(Debug, Clone)]
pub struct Loss {
    model: Linear,
    at_h: Discrete,
    at_dt: Option<(f64, DMatrix<f64>)>,
}

impl Loss {
    /// For plans of steps of `h` seconds.
    pub fn new(h: f64) -> Self {
        let model = loss_model();
        Self {
            at_h: model.discretise(h),
            model,
            at_dt: None,
        }
    }

    /// The heave's perceived force, step by step over the horizon, that the loss `losses` (one a step, held over
    /// it) makes from rest: what the heave's own force must make up.
    pub fn perceived(&self, losses: &[f64]) -> Vec<f64> {
        let n = self.at_h.a.nrows();
        let mut x = DVector::zeros(n);
        losses
            .iter()
            .map(|&l| {
                let u = DVector::from_element(1, l);
                x = &self.at_h.a * &x + &self.at_h.b * &u;
                self.model.output(&x, &u)[0]
            })
            .collect()
    }

    /// Carries the loss `l` over a sample of `dt` into the heave's state (its perception's part).
    pub fn carry(&mut self, x: &mut DVector<f64>, l: f64, dt: f64) {
        if self.at_dt.as_ref().is_none_or(|(d, _)| *d != dt) {
            self.at_dt = Some((dt, self.model.discretise(dt).b));
        }
        if let Some((_, b)) = &self.at_dt {
            *x += b * l;
        }
    }
}

impl Optimal {
    /// Gives the heave the tilts' loss of vertical force `g (1 - cos x cos y)` to make up (this module), within
    /// the room the tilts leave it, or not (the default). Measured on the laps (the book's Optimal cueing): the
    /// heave's perceived error and false cues fall, the tilts' force error rises by more (the heave's motion
    /// takes room from the tilt in the shared envelope).
    pub fn give_heave_the_tilt_loss(&mut self, on: bool) {
        self.loss = on.then(|| Loss::new(self.config.optimal.step_s));
    }

    /// The tilts' loss of vertical force as the heave perceives it over its horizon (from rest, each step's loss
    /// at the middle of both tilts' planned angles from `before`, their angles as the sample began), and over
    /// this sample (at the middle of its angles); none where the heave is not given it.
    pub(super) fn tilt_loss(&self, before: [f64; 2], h: f64) -> Option<(Vec<f64>, f64)> {
        let loss = self.loss.as_ref()?;
        let n = self.axes[Z].qp.steps();
        let [ax, ay] = [X, Y].map(|i| self.axes[i].planned_angles(before[i], h, n));
        let losses: Vec<f64> = ax.iter().zip(&ay).map(|(x, y)| self::loss(*x, *y)).collect();
        let [x, y] = [X, Y].map(|i| 0.5 * (before[i] + self.axes[i].x[2] + self.axes[i].x[3]));
        Some((loss.perceived(&losses), self::loss(x, y)))
    }

    /// The heave's room beside the tilts' planned angles, where it is given their loss and the rig is known (a
    /// heave that makes up the loss at its range's edge beside a full tilt is cut by the limiter, the tilt with it).
    pub(super) fn heave_room(&mut self, h: f64, yaw: f64, dt: f64) {
        let (Some(t), Some(_)) = (self.tilt.as_mut(), &self.loss) else {
            return;
        };
        let share = self.config.optimal.envelope_share;
        let base = (self.ranges[Z].0 * share, self.ranges[Z].1 * share);
        let (lo, hi) = t.heave_bound_over(&self.axes, base, h, yaw, dt);
        self.axes[Z].qp.set_state_bound(tilt::HEAVE_BOUND, lo, hi);
    }
}

impl Axis {
    /// A horizontal axis's angle over its last plan's steps of `h` seconds from `angle` (the angle as the plan
    /// began), at each step's middle; `steps` of them, the last angle held past the plan's end.
    pub(super) fn planned_angles(&self, angle: f64, h: f64, steps: usize) -> Vec<f64> {
        let mut a = angle;
        let mut rates = self.plan.as_slice().chunks_exact(3).map(|s| s[1] + s[2]);
        (0..steps)
            .map(|_| {
                let r = rates.next().unwrap_or(0.0);
                let mid = a + 0.5 * h * r;
                a += h * r;
                mid
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A held loss is perceived, settled, as a fall of the vertical force by as much; the position does not move.
    #[test]
    fn a_held_loss_is_perceived_as_a_fall_of_the_vertical_force() {
        let l = loss(0.3, 0.2);
        assert!((l - G * (1.0 - 0.3f64.cos() * 0.2f64.cos())).abs() < 1e-12 && l > 0.0);
        let mut loss = Loss::new(0.15);
        let perceived = loss.perceived(&vec![l; 400]);
        assert!((perceived[399] + l).abs() < 1e-3, "{}", perceived[399]);
        let mut x = DVector::zeros(4);
        let a = vertical().discretise(0.01).a;
        for _ in 0..6000 {
            x = &a * &x;
            loss.carry(&mut x, l, 0.01);
        }
        assert_eq!((x[0], x[1]), (0.0, 0.0));
        let settled = vertical().output(&x, &DVector::zeros(1))[0] - l * vertical().d[(0, 0)];
        assert!((settled + l).abs() < 1e-3, "{settled}");
    }
}
