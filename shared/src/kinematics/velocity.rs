//! Velocity relations `A(p, q) * pdot = -B(p, q) * qdot` and singularity classification (KINEMATICS.md 3).

use nalgebra::{Matrix6, Vector6};

pub(crate) use super::lu::{rows_of, Lu6};
use super::{AxisKind, KinematicsError};
use crate::Real;

/// Singularity type at a configuration (Gosselin-Angeles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Singularity {
    /// Neither Jacobian is near singular.
    None,
    /// `det B ~ 0`: the platform loses a degree of freedom (workspace boundary).
    Type1,
    /// `det A ~ 0`: the platform gains uncontrolled mobility with the actuators locked.
    Type2,
    /// Both at once.
    Type3,
}

/// The Jacobians of the constraints at one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jacobians<T> {
    /// `A = dF/dp`, rows = constraints, columns = `(x, y, z, alpha, beta, gamma)`.
    pub a: Matrix6<T>,
    /// `B = dF/dq`, rows = constraints, columns = actuators.
    pub b: Matrix6<T>,
    /// Degrees of freedom; rows from `dof` on are auxiliary relations, pose columns from `dof` on are fixed.
    pub dof: usize,
    /// Characteristic length used to make angle columns commensurate with length columns.
    pub length: T,
    /// Kind of each actuator column.
    pub axes: [AxisKind; 6],
}

impl<T: Real> Jacobians<T> {
    /// `A` with its auxiliary rows replaced by "this fixed pose coordinate does not move": the square system whose
    /// solution is the platform's motion.
    pub(crate) fn a_closed(&self) -> Matrix6<T> {
        let mut a = self.a;
        for r in self.dof..6 {
            a.set_row(
                r,
                &nalgebra::RowVector6::from_fn(|_, c| if c == r { T::one() } else { T::zero() }),
            );
        }
        a
    }

    /// Actuator rates for pose rates: solves `B qdot = -A pdot`.
    pub fn actuator_rates(&self, pose_rates: &Vector6<T>) -> Result<Vector6<T>, KinematicsError> {
        let rhs = -(self.a * pose_rates);
        solve(&self.b, &rhs)
    }

    /// Pose rates for actuator rates: solves `A pdot = -B qdot` over the platform's degrees of freedom (auxiliary
    /// actuator rates are ignored; fixed pose coordinates get rate zero).
    pub fn pose_rates(&self, actuator_rates: &Vector6<T>) -> Result<Vector6<T>, KinematicsError> {
        let mut rhs = -(self.b * actuator_rates);
        for r in self.dof..6 {
            rhs[r] = T::zero();
        }
        solve(&self.a_closed(), &rhs)
    }

    /// Rows of `A` closed (see `a_closed`) with its angle columns divided by the characteristic length: the
    /// scale-free matrix of [`Jacobians::index_a`], and the system forward kinematics solves for `(dx, L dangle)`.
    pub(crate) fn a_closed_scaled(&self) -> [[T; 6]; 6] {
        let a = self.a_closed();
        core::array::from_fn(|r| core::array::from_fn(|c| if c < 3 { a[(r, c)] } else { a[(r, c)] / self.length }))
    }

    /// Type-2 index in `[0, 1]`: Hadamard's ratio of `A` (closed, angle columns divided by the characteristic
    /// length; see [`hadamard_ratio`]). 0 where the platform gains a freedom with the actuators locked: the rows of
    /// `A`, each with several entries, become dependent.
    pub fn index_a(&self) -> T {
        hadamard_ratio_in_place(&mut self.a_closed_scaled()).0
    }

    /// Type-1 index in `[0, 1]`: the smallest singular value of `B` (angle columns divided by the characteristic
    /// length) with each constraint row divided by the norm of the whole row `[A_i B_i]`. 0 where an actuator can
    /// move without moving the platform (the platform loses a freedom: the workspace boundary). For rod chains,
    /// whose `B` is diagonal, it is the smallest share any constraint has in its actuator.
    ///
    /// Not Hadamard's ratio of `B`: a rod chain's row of `B` has a single entry, so that ratio stays 1 however small
    /// `dF/dq` gets. Not a determinant of the normalised rows either: six healthy rows at 0.4 each make 0.004.
    pub fn index_b(&self) -> T {
        let a = self.a_closed_scaled();
        let mut rows = [[T::zero(); 6]; 6];
        for (r, row) in rows.iter_mut().enumerate() {
            let mut norm = T::zero();
            for c in 0..6 {
                row[c] = match self.axes[c] {
                    AxisKind::Linear => self.b[(r, c)],
                    AxisKind::Ring | AxisKind::Angle => self.b[(r, c)] / self.length,
                };
                norm += a[r][c] * a[r][c] + row[c] * row[c];
            }
            let norm = norm.sqrt_();
            if norm > T::zero() && norm.finite() {
                for v in row.iter_mut() {
                    *v /= norm;
                }
            }
        }
        smallest_singular_value(&rows)
    }

    /// Classifies the configuration: an index below `threshold` counts as singular.
    pub fn classify(&self, threshold: T) -> Singularity {
        match (self.index_b() < threshold, self.index_a() < threshold) {
            (false, false) => Singularity::None,
            (true, false) => Singularity::Type1,
            (false, true) => Singularity::Type2,
            (true, true) => Singularity::Type3,
        }
    }
}

/// The smallest singular value of rows of norm at most one (so at most 1); 0 when it cannot be found (entries not
/// finite, or the iteration does not converge). A measure of distance to singularity that a product over rows (a
/// determinant) is not: six healthy rows at 0.4 each make a determinant of 0.004.
fn smallest_singular_value<T: Real>(rows: &[[T; 6]; 6]) -> T {
    if !rows.iter().flatten().all(|v| v.finite()) {
        return T::zero();
    }
    let m = Matrix6::from_fn(|r, c| rows[r][c]);
    m.try_svd(false, false, T::of(T::EPS), 200)
        .map(|svd| svd.singular_values.iter().fold(T::one(), |s, v| s.min_(*v)))
        .filter(|s| s.finite())
        .unwrap_or(T::zero())
}

fn solve<T: Real>(m: &Matrix6<T>, rhs: &Vector6<T>) -> Result<Vector6<T>, KinematicsError> {
    Lu6::in_place(&mut rows_of(m))
        .solve(&(*rhs).into())
        .map(Vector6::from)
        .ok_or(KinematicsError::Singular)
}

/// `|det M| / prod_i |row_i|`: 1 for orthogonal rows, 0 for a singular matrix, unchanged by scaling any row.
///
/// Hadamard's inequality bounds `|det M|` by the product of the row norms, so the ratio is a scale-free
/// measure of how far the rows are from linear dependence. It costs one LU decomposition, unlike an inverse
/// condition number (an SVD), which matters inside a 1 kHz control tick on a Cortex-M4F.
pub fn hadamard_ratio<T: Real>(m: &Matrix6<T>) -> T {
    hadamard_ratio_in_place(&mut rows_of(m)).0
}

/// [`hadamard_ratio`] of the matrix given by its rows, and their decomposition (the rows become its factors;
/// forward kinematics goes on to solve with it).
pub(crate) fn hadamard_ratio_in_place<T: Real>(rows: &mut [[T; 6]; 6]) -> (T, Lu6<'_, T>) {
    let mut norms = T::one();
    for row in rows.iter() {
        let n = row.iter().fold(T::zero(), |s, v| s + *v * *v).sqrt_();
        norms *= n;
    }
    let lu = Lu6::in_place(rows);
    if norms == T::zero() || !norms.finite() {
        return (T::zero(), lu);
    }
    let det = lu.determinant();
    let ratio = if det.finite() { (det / norms).abs() } else { T::zero() };
    (ratio, lu)
}
