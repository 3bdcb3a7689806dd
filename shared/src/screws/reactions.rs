//! Paper 003's generalised reactions (SCREWS.md 2b): for a parallel mechanism of fewer than six degrees of freedom,
//! the actuator forces and the constraint reactions that hold a platform wrench, with the projection that keeps the
//! constraint reactions from blowing up at actuation singularities.
//!
//! Each chain's constraint wrenches are the wrenches reciprocal to all its joint twists (no work on any joint
//! motion); its actuation wrench is reciprocal to its passive joints and Euclid-orthogonal to its constraint
//! wrenches, scaled to unit work on the actuated joint, so its reaction is the actuator's torque or force. With the
//! actuation wrenches `W_A` and the constraint wrenches `W_C` (six in all), `[W_A | W_C] r = P`. Projected, the
//! actuation wrenches lose their part in the span of the constraint wrenches: `[N N^T W_A | W_C] r = P`. The
//! actuator reactions are unchanged; the constraint reactions become `W_C^+ P`, bounded where `W_C` is.

use nalgebra::{Matrix6, Vector6};

use super::reciprocal;
use crate::kinematics::velocity::Lu6;

/// `[a; b] -> [b; a]`: `t^T Delta w` is the reciprocal product.
fn swap_halves(w: &Vector6<f64>) -> Vector6<f64> {
    Vector6::new(w[3], w[4], w[5], w[0], w[1], w[2])
}

/// The unit vector spanning the null space of the matrix whose rows are `rows` (at most five; the smallest
/// singular direction), or `None` when the rows are not finite or the decomposition does not converge.
fn null_direction(rows: &[Vector6<f64>]) -> Option<Vector6<f64>> {
    if rows.len() > 5 || !rows.iter().flat_map(|r| r.iter()).all(|v| v.is_finite()) {
        return None;
    }
    let m = Matrix6::from_fn(|r, c| rows.get(r).map_or(0.0, |row| row[c]));
    let svd = m.try_svd(false, true, f64::EPSILON, 500)?;
    let v_t = svd.v_t?;
    let (k, _) =
        svd.singular_values.iter().enumerate().fold(
            (0, f64::INFINITY),
            |best, (i, s)| if *s < best.1 { (i, *s) } else { best },
        );
    Some(v_t.row(k).transpose())
}

/// The constraint wrench of a chain whose joints' twists leave one constraint (five joints): the wrench that does
/// no work on any of them, unit length, sign arbitrary.
pub fn constraint_wrench(twists: &[Vector6<f64>]) -> Option<Vector6<f64>> {
    let rows: heapless_rows::Rows = twists.iter().map(swap_halves).collect();
    null_direction(rows.as_slice())
}

/// The actuation wrench of a chain: no work on its passive joints, Euclid-orthogonal to its constraint wrench, and
/// unit work on its actuated joint (so its reaction is the actuator's torque or force).
pub fn actuation_wrench(
    actuated: &Vector6<f64>,
    passive: &[Vector6<f64>],
    constraint: &Vector6<f64>,
) -> Option<Vector6<f64>> {
    let mut rows: heapless_rows::Rows = passive.iter().map(swap_halves).collect();
    rows.push(*constraint)?;
    let w = null_direction(rows.as_slice())?;
    let work = reciprocal(actuated, &w);
    (work.abs() > f64::EPSILON).then(|| w / work)
}

/// Reactions of a platform wrench `p` (the wrench the chains exert on the platform), unprojected and projected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reactions {
    /// Actuator reactions (torques or forces), the same with and without projection.
    pub actuators: [f64; 6],
    /// Constraint reactions, unprojected: they grow without bound near actuation singularities.
    pub constraints: [f64; 6],
    /// Constraint reactions with the actuation wrenches projected out of the constraints' span: `W_C^+ P`.
    pub constraints_projected: [f64; 6],
}

/// Solves `[W_A | W_C] r = p` and its projected form for `n` actuation and `6 - n` constraint wrenches.
pub fn reactions(actuation: &[Vector6<f64>], constraints: &[Vector6<f64>], p: &Vector6<f64>) -> Option<Reactions> {
    let (n, k) = (actuation.len(), constraints.len());
    if n + k != 6 || k == 0 {
        return None;
    }
    let columns = |a: &[Vector6<f64>]| -> [[f64; 6]; 6] {
        core::array::from_fn(|r| core::array::from_fn(|c| if c < n { a[c][r] } else { constraints[c - n][r] }))
    };
    let solve = |rows: [[f64; 6]; 6]| {
        let mut rows = rows;
        Lu6::in_place(&mut rows).solve(&[p[0], p[1], p[2], p[3], p[4], p[5]])
    };
    let plain = solve(columns(actuation))?;
    // Projector onto the Euclidean complement of span(W_C): I - W_C (W_C^T W_C)^-1 W_C^T.
    let mut gram = [[0.0; 6]; 6];
    for (i, row) in gram.iter_mut().enumerate() {
        for (j, g) in row.iter_mut().enumerate() {
            *g = match (i < k, j < k) {
                (true, true) => constraints[i].dot(&constraints[j]),
                _ => f64::from(u8::from(i == j)),
            };
        }
    }
    let lu = Lu6::in_place(&mut gram);
    let project = |w: &Vector6<f64>| -> Option<Vector6<f64>> {
        let mut rhs = [0.0; 6];
        for (i, c) in constraints.iter().enumerate() {
            rhs[i] = c.dot(w);
        }
        let x = lu.solve(&rhs)?;
        Some(constraints.iter().enumerate().fold(*w, |acc, (i, c)| acc - c * x[i]))
    };
    let mut projected = [Vector6::zeros(); 6];
    for (slot, w) in projected.iter_mut().zip(actuation) {
        *slot = project(w)?;
    }
    let with_projection = solve(columns(&projected[..n]))?;
    let mut out = Reactions {
        actuators: [0.0; 6],
        constraints: [0.0; 6],
        constraints_projected: [0.0; 6],
    };
    out.actuators[..n].copy_from_slice(&plain[..n]);
    out.constraints[..k].copy_from_slice(&plain[n..]);
    out.constraints_projected[..k].copy_from_slice(&with_projection[n..]);
    Some(out)
}

/// A small fixed-capacity list of rows (at most six), so the module needs no allocator.
pub(super) mod heapless_rows {
    use nalgebra::Vector6;

    #[derive(Default)]
    pub struct Rows {
        rows: [Vector6<f64>; 6],
        len: usize,
    }

    impl Rows {
        pub fn push(&mut self, row: Vector6<f64>) -> Option<()> {
            let slot = self.rows.get_mut(self.len)?;
            *slot = row;
            self.len += 1;
            Some(())
        }

        pub fn as_slice(&self) -> &[Vector6<f64>] {
            &self.rows[..self.len]
        }
    }

    impl FromIterator<Vector6<f64>> for Rows {
        fn from_iter<I: IntoIterator<Item = Vector6<f64>>>(iter: I) -> Self {
            let mut rows = Rows::default();
            for row in iter.into_iter().take(6) {
                let _ = rows.push(row);
            }
            rows
        }
    }
}
