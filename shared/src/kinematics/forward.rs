//! Forward kinematics by Newton-Raphson iteration on `F(p, q) = 0` (KINEMATICS.md 3).

use nalgebra::Vector6;

use super::velocity::hadamard_ratio_in_place;
use super::{Actuators, AxisKind, KinematicsError, Mechanism, Pose};
use crate::real::wrap_pi;
use crate::Real;

/// Settings of the Newton iteration, and what a solution must satisfy to be returned.
///
/// Newton's method converges to *a* solution of `F(p, q) = 0`; the actuators of a parallel platform have several
/// (assembly modes, chain branches), and near a type-2 singularity two of them meet. A converged pose is therefore
/// returned only when it is the platform's: near the guess, away from a type-2 singularity, its own IK giving back
/// the actuators, and (by default) inside every workspace check. Anything else is an error that says which.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions<T> {
    /// Iterations before giving up with [`KinematicsError::NoConvergence`].
    pub max_iterations: u8,
    /// Converged when the step (lengths divided by the characteristic length, angles in rad) and the residual
    /// (divided by the characteristic length squared) are both below this.
    pub tolerance: T,
    /// A solution whose type-2 index ([`super::Jacobians::index_a`], what `check` classifies with) is below this is
    /// refused with [`KinematicsError::NearSingularity`]: there, neighbouring solutions meet.
    pub min_singularity_index: T,
    /// A solution further than this from the guess is refused with [`KinematicsError::FarFromGuess`]: the largest of
    /// the translation divided by the characteristic length and the rotation angles (rad).
    pub max_distance: T,
    /// Refuse a solution that fails a workspace check ([`KinematicsError::Outside`]).
    pub inside: bool,
}

impl<T: Real> Default for NewtonOptions<T> {
    /// 30 iterations; tolerance a few hundred ulps of the scalar (about 1e-13 for f64, 5e-5 for f32); type-2 index
    /// 0.01 (as `check`); half a characteristic length or half a radian from the guess; inside every check.
    fn default() -> Self {
        Self {
            max_iterations: 30,
            tolerance: T::of(T::EPS * 400.0),
            min_singularity_index: T::of(0.01),
            max_distance: T::of(0.5),
            inside: true,
        }
    }
}

/// How far from [`start_from_home`] a solution may be: the start knows only the yaw, so the platform may be a whole
/// tilt range away from it (one characteristic length, one radian).
pub const FROM_HOME_DISTANCE: f64 = 1.0;

/// Where to start forward kinematics without a known pose: the home pose turned by the yaw the ring carriages show.
/// Use it with [`NewtonOptions::max_distance`] at [`FROM_HOME_DISTANCE`].
///
/// A ring platform's yaw turns every carriage by about the same angle, so the circular mean of the carriage angles'
/// differences from their home values is the yaw to a few degrees (tilt and translation move carriages in opposite
/// directions around the ring, which the mean cancels). Started at home yaw instead, Newton often lands on a far
/// solution (a 2026 check: 70 of 143 poses inside the checks came back wrong). Mechanisms without ring axes start at
/// home.
pub fn start_from_home<T: Real, M: Mechanism<T>>(mechanism: &M, q: &Actuators<T>, home: &Pose<T>) -> Pose<T> {
    let (Ok(q_home), Ok(q)) = (mechanism.inverse(home), q.validated()) else {
        return *home;
    };
    let (mut s, mut c) = (T::zero(), T::zero());
    for (i, kind) in mechanism.axes().iter().enumerate() {
        if *kind == AxisKind::Ring {
            let (si, ci) = wrap_pi(q.0[i] - q_home.0[i]).sin_cos_();
            s += si;
            c += ci;
        }
    }
    if s == T::zero() && c == T::zero() {
        return *home;
    }
    Pose {
        gamma: home.gamma + s.atan2_(c),
        ..*home
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
    let guess = Pose::from_vector(&p);
    for iteration in 1..=options.max_iterations {
        let pose = Pose::from_vector(&p);
        let jac = mechanism.jacobians(&pose, &q);
        // One decomposition of the scale-free A gives the step and a guard against dividing by (nearly) zero; the
        // solution's distance from a type-2 singularity is judged once it has converged.
        let mut rows = jac.a_closed_scaled();
        let (index, lu) = hadamard_ratio_in_place(&mut rows);
        if index < T::of(1e-12) {
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
            let pose = normalised(&Pose::from_vector(&p), &guess);
            let res = mechanism.residuals(&pose, &q);
            let residual = res.iter().take(dof).fold(T::zero(), |m, r| m.max(r.abs() * inv_len2));
            if residual <= options.tolerance {
                // The auxiliary relations are not part of the iteration: they tell which assembly was found.
                let aux = res.iter().skip(dof).fold(T::zero(), |m, r| m.max(r.abs() * inv_len));
                if aux > options.tolerance.sqrt_() {
                    return Err(KinematicsError::OtherAssembly);
                }
                // The type-2 index of the last iteration's Jacobian: its pose is within the tolerance of the solution,
                // far closer than the index changes by at its threshold, and a second Jacobian would cost as much
                // as an iteration.
                if index < options.min_singularity_index {
                    return Err(KinematicsError::NearSingularity);
                }
                accept(mechanism, &pose, &q, &guess, options)?;
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

/// Roll and pitch within `(-pi, pi]`, yaw within half a turn of the guess's (yaw is continuous).
fn normalised<T: Real>(pose: &Pose<T>, guess: &Pose<T>) -> Pose<T> {
    Pose {
        alpha: wrap_pi(pose.alpha),
        beta: wrap_pi(pose.beta),
        gamma: guess.gamma + wrap_pi(pose.gamma - guess.gamma),
        ..*pose
    }
}

/// Whether a converged pose is the platform's: near the guess, the actuators' own branches, inside the workspace
/// (see [`NewtonOptions`]; the type-2 index is judged by the caller).
fn accept<T: Real, M: Mechanism<T>>(
    mechanism: &M,
    pose: &Pose<T>,
    q: &Actuators<T>,
    guess: &Pose<T>,
    options: &NewtonOptions<T>,
) -> Result<(), KinematicsError> {
    let inv_len = T::one() / mechanism.characteristic_length();
    let (a, g) = (pose.to_array(), guess.to_array());
    let distance = (0..6).fold(T::zero(), |m, i| {
        let d = if i < 3 {
            (a[i] - g[i]).abs() * inv_len
        } else {
            // A guess a whole turn off names the same orientation.
            wrap_pi(a[i] - g[i]).abs()
        };
        m.max(d)
    });
    if distance > options.max_distance || !distance.finite() {
        return Err(KinematicsError::FarFromGuess);
    }
    // The checks only when they are asked for: without them IK alone gives the same actuators or the same error
    // (`properties.rs`), for a quarter of the cost on the M4F.
    let (back, outside) = if options.inside {
        let (back, report) = mechanism.inverse_checked(pose)?;
        (back, report.first_failure())
    } else {
        (mechanism.inverse(pose)?, None)
    };
    let dof = mechanism.dof();
    let axes = mechanism.axes();
    let tolerance = options.tolerance.sqrt_();
    for ((b, a), axis) in back.0.iter().zip(&q.0).zip(&axes).take(dof) {
        let d = match axis {
            AxisKind::Ring => wrap_pi(*b - *a),
            AxisKind::Linear => (*b - *a) * inv_len,
            AxisKind::Angle => *b - *a,
        };
        if d.abs() > tolerance || !d.finite() {
            return Err(KinematicsError::OtherBranch);
        }
    }
    match outside {
        Some(check) => Err(KinematicsError::Outside(check)),
        None => Ok(()),
    }
}

/// Largest step component, lengths made relative to the characteristic length.
fn scaled_max<T: Real>(dp: &Vector6<T>, inv_len: T) -> T {
    dp.iter().enumerate().fold(T::zero(), |m, (i, d)| {
        m.max(if i < 3 { d.abs() * inv_len } else { d.abs() })
    })
}
