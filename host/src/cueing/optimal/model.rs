//! The optimal cueing's models, one per platform axis: the platform's motion (position, velocity, and on x and
//! y the tilt whose share of gravity is a specific force) feeding the rider's perception, as continuous
//! state-space, discretised by zero-order hold (exact for inputs held over a step, which is what the programme
//! plans and what one sample applies).
//!
//! The axes are decoupled: x is surge with the pitch that cues it, y sway with roll, z heave. That is honest to
//! the linearised model (`sin(tilt) = tilt`, each tilt cueing one force) and keeps each programme small.

use nalgebra::{DMatrix, DVector};
use ringpod_core::cueing::filter::Section;
use ringpod_core::cueing::perception::{canal_sections, otolith_section};
use ringpod_core::cueing::G;

/// A linear system `x' = A x + B u`, `y = C x + D u`.
#[derive(Debug, Clone)]
pub struct Linear {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input matrix.
    pub b: DMatrix<f64>,
    /// Output matrix.
    pub c: DMatrix<f64>,
    /// Feed-through.
    pub d: DMatrix<f64>,
}

/// A linear system discretised at one step: `x+ = A x + B u`, `y+ = C x+ + D u`.
#[derive(Debug, Clone)]
pub struct Discrete {
    /// State transition.
    pub a: DMatrix<f64>,
    /// Input to state.
    pub b: DMatrix<f64>,
}

impl Linear {
    /// States, inputs, outputs.
    pub fn dims(&self) -> (usize, usize, usize) {
        (self.a.nrows(), self.b.ncols(), self.c.nrows())
    }

    /// Zero-order hold at `h` seconds: `exp([[A, B], [0, 0]] h)` holds both matrices.
    pub fn discretise(&self, h: f64) -> Discrete {
        let (n, m, _) = self.dims();
        let mut aug = DMatrix::zeros(n + m, n + m);
        aug.view_mut((0, 0), (n, n)).copy_from(&(&self.a * h));
        aug.view_mut((0, n), (n, m)).copy_from(&(&self.b * h));
        let e = aug.exp();
        Discrete {
            a: e.view((0, 0), (n, n)).into_owned(),
            b: e.view((0, n), (n, m)).into_owned(),
        }
    }

    /// The outputs at a state and input.
    pub fn output(&self, x: &DVector<f64>, u: &DVector<f64>) -> DVector<f64> {
        &self.c * x + &self.d * u
    }
}

/// A second-order section in controllable canonical form: `(A, B, C, D)` for one input and one output.
fn section(s: &Section<f64>) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, f64) {
    let [b2, b1, b0] = s.b;
    let [a1, a0] = s.a;
    (
        DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -a0, -a1]),
        DMatrix::from_row_slice(2, 1, &[0.0, 1.0]),
        DMatrix::from_row_slice(1, 2, &[b0 - b2 * a0, b1 - b2 * a1]),
        b2,
    )
}

/// The rider's perception of one axis: specific force (and on x, y the angular rate) in, perceived out. States:
/// the otolith's two, then the canal's three (its slow section's two, its lead's one). Inputs `[f, w]`, outputs
/// `[f^, w^]`; without rotation, the otolith alone (`[f]` to `[f^]`).
pub fn perception(rotation: bool) -> Linear {
    let (oa, ob, oc, od) = section(&otolith_section::<f64>());
    if !rotation {
        return Linear {
            a: oa,
            b: ob,
            c: oc,
            d: DMatrix::from_element(1, 1, od),
        };
    }
    let (slow, lead) = canal_sections::<f64>();
    let (sa, sb, sc, sd) = section(&slow);
    // The lead, first order: x' = -al x + v, y = (b0 - b1 al) x + b1 v, v the slow section's output.
    let (al, lb1, lb0) = (lead.a[0], lead.b[1], lead.b[2]);
    let mut a = DMatrix::zeros(5, 5);
    a.view_mut((0, 0), (2, 2)).copy_from(&oa);
    a.view_mut((2, 2), (2, 2)).copy_from(&sa);
    // x3' = -al x3 + sc x_slow + sd w.
    a[(4, 4)] = -al;
    a[(4, 2)] = sc[(0, 0)];
    a[(4, 3)] = sc[(0, 1)];
    let mut b = DMatrix::zeros(5, 2);
    b.view_mut((0, 0), (2, 1)).copy_from(&ob);
    b.view_mut((2, 1), (2, 1)).copy_from(&sb);
    b[(4, 1)] = sd;
    let mut c = DMatrix::zeros(2, 5);
    c.view_mut((0, 0), (1, 2)).copy_from(&oc);
    // w^ = (b0 - b1 al) x3 + b1 (sc x_slow + sd w).
    c[(1, 4)] = lb0 - lb1 * al;
    c[(1, 2)] = lb1 * sc[(0, 0)];
    c[(1, 3)] = lb1 * sc[(0, 1)];
    let mut d = DMatrix::zeros(2, 2);
    d[(0, 0)] = od;
    d[(1, 1)] = lb1 * sd;
    Linear { a, b, c, d }
}

/// The outputs of a horizontal axis's model, in order.
pub const HORIZONTAL_OUTPUTS: usize = 5;
/// The outputs of the vertical axis's model, in order.
pub const VERTICAL_OUTPUTS: usize = 3;

/// A horizontal axis: states `[p, v, tilt, rotation, perception (5)]`, inputs `[a, tilt rate, rotation rate]`,
/// outputs `[f^, w^, p, v, angle]`. The tilt and the rotation are two parts of one platform angle: the tilt's
/// rate is held below the rotation threshold (tilt coordination, not felt as a rotation), the rotation's is not
/// (an onset cue, felt as the vehicle's own rotation). The specific force is `a + g angle`.
pub fn horizontal() -> Linear {
    let p = perception(true);
    let mut a = DMatrix::zeros(9, 9);
    a[(0, 1)] = 1.0;
    let mut b = DMatrix::zeros(9, 3);
    b[(1, 0)] = 1.0;
    b[(2, 1)] = 1.0;
    b[(3, 2)] = 1.0;
    // The perception's inputs: f = a + g (tilt + rotation), w = tilt rate + rotation rate.
    let mut feed_x = DMatrix::zeros(2, 9);
    feed_x[(0, 2)] = G;
    feed_x[(0, 3)] = G;
    let feed_u = DMatrix::from_row_slice(2, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 1.0]);
    a.view_mut((4, 4), (5, 5)).copy_from(&p.a);
    a.view_mut((4, 0), (5, 9)).add_assign_from(&(&p.b * &feed_x));
    b.view_mut((4, 0), (5, 3)).copy_from(&(&p.b * &feed_u));
    let mut c = DMatrix::zeros(HORIZONTAL_OUTPUTS, 9);
    let mut d = DMatrix::zeros(HORIZONTAL_OUTPUTS, 3);
    c.view_mut((0, 4), (2, 5)).copy_from(&p.c);
    c.view_mut((0, 0), (2, 9)).add_assign_from(&(&p.d * &feed_x));
    d.view_mut((0, 0), (2, 3)).copy_from(&(&p.d * &feed_u));
    c[(2, 0)] = 1.0;
    c[(3, 1)] = 1.0;
    c[(4, 2)] = 1.0;
    c[(4, 3)] = 1.0;
    Linear { a, b, c, d }
}

/// The vertical axis: states `[p, v, perception (2)]`, input `[a]`, outputs `[f^, p, v]`.
pub fn vertical() -> Linear {
    let p = perception(false);
    let mut a = DMatrix::zeros(4, 4);
    a[(0, 1)] = 1.0;
    a.view_mut((2, 2), (2, 2)).copy_from(&p.a);
    let mut b = DMatrix::zeros(4, 1);
    b[(1, 0)] = 1.0;
    b.view_mut((2, 0), (2, 1)).copy_from(&p.b);
    let mut c = DMatrix::zeros(VERTICAL_OUTPUTS, 4);
    c.view_mut((0, 2), (1, 2)).copy_from(&p.c);
    c[(1, 0)] = 1.0;
    c[(2, 1)] = 1.0;
    let d = DMatrix::from_row_slice(VERTICAL_OUTPUTS, 1, &[p.d[(0, 0)], 0.0, 0.0]);
    Linear { a, b, c, d }
}

trait AddAssignFrom {
    fn add_assign_from(&mut self, other: &DMatrix<f64>);
}

impl<V: nalgebra::StorageMut<f64, nalgebra::Dyn, nalgebra::Dyn>> AddAssignFrom
    for nalgebra::Matrix<f64, nalgebra::Dyn, nalgebra::Dyn, V>
{
    fn add_assign_from(&mut self, other: &DMatrix<f64>) {
        for j in 0..other.ncols() {
            for i in 0..other.nrows() {
                self[(i, j)] += other[(i, j)];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::cueing::perception::Perception;

    /// The state-space perception, held input over small steps, against the core's Tustin filters: the same
    /// transfer functions, so the same response to a smooth stimulus.
    #[test]
    fn the_state_space_perception_is_the_cores() {
        let p = perception(true);
        let h = 0.002;
        let d = p.discretise(h);
        let mut x = DVector::zeros(5);
        let mut core = Perception::<f64>::new();
        let mut worst: f64 = 0.0;
        for k in 1..=5000 {
            let t = f64::from(k) * h;
            let (f, w) = ((1.3 * t).sin() * 2.0, (0.7 * t).sin() * 0.3);
            // Hold the mid-interval value: second-order accurate, as the trapezoid is.
            let tm = t - h / 2.0;
            let u = DVector::from_vec(vec![(1.3 * tm).sin() * 2.0, (0.7 * tm).sin() * 0.3]);
            x = &d.a * &x + &d.b * &u;
            let y = p.output(&x, &DVector::from_vec(vec![f, w]));
            let c = core.step([f, 0.0, 0.0], [w, 0.0, 0.0], h);
            worst = worst.max((y[0] - c.force[0]).abs()).max((y[1] - c.rate[0]).abs());
        }
        assert!(worst < 2e-3, "{worst}");
    }

    /// A horizontal axis held tilted: the perceived force settles on `g` times the angle; a held acceleration
    /// moves the platform as `a t^2 / 2`.
    #[test]
    fn a_held_tilt_is_perceived_as_its_share_of_gravity() {
        let m = horizontal();
        let mut x = DVector::zeros(9);
        x[2] = 0.1;
        let d = m.discretise(0.1);
        let u = DVector::zeros(3);
        for _ in 0..400 {
            x = &d.a * &x + &d.b * &u;
        }
        let y = m.output(&x, &u);
        assert!(
            (y[0] - G * 0.1).abs() < 1e-3 && y[1].abs() < 1e-6 && (y[4] - 0.1).abs() < 1e-12,
            "{y}"
        );
        let mut x = DVector::zeros(9);
        let u = DVector::from_vec(vec![2.0, 0.0, 0.0]);
        let d = m.discretise(0.5);
        x = &d.a * &x + &d.b * &u;
        assert!((x[0] - 0.25).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12, "{x}");
    }
}
