//! Velocity relations `A(p, q) * pdot = -B(p, q) * qdot` and singularity classification (KINEMATICS.md 3).

use nalgebra::{Matrix6, Vector6};

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
        self.b
            .lu()
            .solve(&rhs)
            .filter(all_finite)
            .ok_or(KinematicsError::Singular)
    }

    /// Pose rates for actuator rates: solves `A pdot = -B qdot` over the platform's degrees of freedom (auxiliary
    /// actuator rates are ignored; fixed pose coordinates get rate zero).
    pub fn pose_rates(&self, actuator_rates: &Vector6<T>) -> Result<Vector6<T>, KinematicsError> {
        let mut rhs = -(self.b * actuator_rates);
        for r in self.dof..6 {
            rhs[r] = T::zero();
        }
        self.a_closed()
            .lu()
            .solve(&rhs)
            .filter(all_finite)
            .ok_or(KinematicsError::Singular)
    }

    /// Scale-free singularity index of `A` in `[0, 1]` (0 = type-2 singular); see [`hadamard_ratio`].
    pub fn index_a(&self) -> T {
        let inv = T::one() / self.length;
        let mut a = self.a_closed();
        for c in 3..6 {
            a.column_mut(c).scale_mut(inv);
        }
        hadamard_ratio(&a)
    }

    /// Scale-free singularity index of `B` in `[0, 1]` (0 = type-1 singular).
    pub fn index_b(&self) -> T {
        let inv = T::one() / self.length;
        let mut b = self.b;
        for (c, kind) in self.axes.iter().enumerate() {
            if *kind != AxisKind::Linear {
                b.column_mut(c).scale_mut(inv);
            }
        }
        hadamard_ratio(&b)
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

fn all_finite<T: Real>(v: &Vector6<T>) -> bool {
    v.iter().all(|c| c.finite())
}

/// `|det M| / prod_i |row_i|`: 1 for orthogonal rows, 0 for a singular matrix, unchanged by scaling any row.
///
/// Hadamard's inequality bounds `|det M|` by the product of the row norms, so the ratio is a scale-free
/// measure of how far the rows are from linear dependence. It costs one LU decomposition, unlike an inverse
/// condition number (an SVD), which matters inside a 1 kHz control tick on a Cortex-M4F.
pub fn hadamard_ratio<T: Real>(m: &Matrix6<T>) -> T {
    let mut norms = T::one();
    for r in 0..6 {
        let n = m.row(r).norm();
        if n == T::zero() || !n.finite() {
            return T::zero();
        }
        norms *= n;
    }
    let det = m.lu().determinant();
    if det.finite() {
        (det / norms).abs()
    } else {
        T::zero()
    }
}
