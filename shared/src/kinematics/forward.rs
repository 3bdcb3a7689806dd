//! Forward kinematics by Newton-Raphson iteration on `F(p, q) = 0` (KINEMATICS.md 3).

use nalgebra::Vector6;

use super::velocity::hadamard_ratio_in_place;
use super::{Actuators, KinematicsError, Mechanism, Pose};
use crate::Real;

/// Settings of the Newton iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions<T> {
    /// Iterations before giving up with [`KinematicsError::NoConvergence`].
    pub max_iterations: u8,
    /// Converged when the step (lengths divided by the characteristic length, angles in rad) and the residual
    /// (divided by the characteristic length squared) are both below this.
    pub tolerance: T,
    /// Stop with [`KinematicsError::NearSingularity`] when the scale-free index of `A` falls below this.
    pub min_singularity_index: T,
}

impl<T: Real> Default for NewtonOptions<T> {
    /// 30 iterations; tolerance a few hundred ulps of the scalar (about 1e-13 for f64, 5e-5 for f32); index 1e-6.
    fn default() -> Self {
        Self {
            max_iterations: 30,
            tolerance: T::of(T::EPS * 400.0),
            min_singularity_index: T::of(1e-6),
        }
    }
}

/// A converged forward solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForwardSolution<T> {
    /// The pose.
    pub pose: Pose<T>,
    /// Newton iterations used.
    pub iterations: u8,
    /// Largest scaled constraint residual at the solution.
    pub residual: T,
}

/// Newton iteration `p <- p - A^-1 F(p, q)` from `guess`, shared by every mechanism.
pub fn newton<T: Real, M: Mechanism<T>>(
    mechanism: &M,
    q: &Actuators<T>,
    guess: &Pose<T>,
    options: &NewtonOptions<T>,
) -> Result<ForwardSolution<T>, KinematicsError> {
    let q = q.validated()?;
    let mut p = guess.validated()?.to_vector();
    let dof = mechanism.dof();
    for r in dof..6 {
        p[r] = T::zero();
    }
    let length = mechanism.characteristic_length();
    let inv_len = T::one() / length;
    let inv_len2 = inv_len * inv_len;
    for iteration in 1..=options.max_iterations {
        let pose = Pose::from_vector(&p);
        let jac = mechanism.jacobians(&pose, &q);
        // One decomposition of the scale-free A gives both the singularity index and the step.
        let mut rows = jac.a_closed_scaled();
        let (index, lu) = hadamard_ratio_in_place(&mut rows);
        if index < options.min_singularity_index {
            return Err(KinematicsError::NearSingularity);
        }
        let mut f = mechanism.residuals(&pose, &q);
        for r in dof..6 {
            f[r] = T::zero();
        }
        // A dp = -F over the degrees of freedom (fixed coordinates closed by unit rows), solved for
        // (dx, dy, dz, L dalpha, L dbeta, L dgamma).
        let Some(y) = lu.solve(&(-f).into()) else {
            return Err(KinematicsError::NearSingularity);
        };
        let dp = Vector6::from_fn(|i, _| if i < 3 { y[i] } else { y[i] * inv_len });
        p += dp;
        let step = scaled_max(&dp, inv_len);
        if !p.iter().all(|c| c.finite()) {
            return Err(KinematicsError::NoConvergence { iterations: iteration });
        }
        if step <= options.tolerance {
            let pose = Pose::from_vector(&p);
            let res = mechanism.residuals(&pose, &q);
            let residual = res.iter().take(dof).fold(T::zero(), |m, r| m.max(r.abs() * inv_len2));
            if residual <= options.tolerance {
                // The auxiliary relations are not part of the iteration: they tell which assembly was found.
                let aux = res.iter().skip(dof).fold(T::zero(), |m, r| m.max(r.abs() * inv_len));
                if aux > options.tolerance.sqrt_() {
                    return Err(KinematicsError::OtherAssembly);
                }
                return Ok(ForwardSolution {
                    pose,
                    iterations: iteration,
                    residual,
                });
            }
        }
    }
    Err(KinematicsError::NoConvergence {
        iterations: options.max_iterations,
    })
}

/// Largest step component, lengths made relative to the characteristic length.
fn scaled_max<T: Real>(dp: &Vector6<T>, inv_len: T) -> T {
    dp.iter().enumerate().fold(T::zero(), |m, (i, d)| {
        m.max(if i < 3 { d.abs() * inv_len } else { d.abs() })
    })
}
