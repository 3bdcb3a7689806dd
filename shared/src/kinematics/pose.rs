//! Platform pose and actuator vectors (KINEMATICS.md section 1).

use nalgebra::{Matrix3, Vector3, Vector6};

use super::KinematicsError;
use crate::Real;

/// Pose of the platform frame in the base frame: position in metres, orientation in radians.
///
/// Orientation convention (KINEMATICS.md 1): `R = Rz(gamma) * Ry(beta) * Rx(alpha)`, i.e. rotate about X
/// by `alpha`, then about Y by `beta`, then about Z by `gamma`, then translate by `(x, y, z)`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Pose<T> {
    /// Surge: X of the platform centre (m).
    pub x: T,
    /// Sway: Y of the platform centre (m).
    pub y: T,
    /// Heave: Z of the platform centre above the ring plane (m).
    pub z: T,
    /// Roll about X (rad).
    pub alpha: T,
    /// Pitch about Y (rad).
    pub beta: T,
    /// Yaw about Z (rad); unbounded, only its value modulo a turn matters to the geometry.
    pub gamma: T,
}

impl<T: Real> Pose<T> {
    /// A pose from its six coordinates.
    pub const fn new(x: T, y: T, z: T, alpha: T, beta: T, gamma: T) -> Self {
        Self {
            x,
            y,
            z,
            alpha,
            beta,
            gamma,
        }
    }

    /// The pose as `[x, y, z, alpha, beta, gamma]`.
    pub fn to_array(&self) -> [T; 6] {
        [self.x, self.y, self.z, self.alpha, self.beta, self.gamma]
    }

    /// The pose from `[x, y, z, alpha, beta, gamma]`.
    pub fn from_array(v: [T; 6]) -> Self {
        let [x, y, z, alpha, beta, gamma] = v;
        Self {
            x,
            y,
            z,
            alpha,
            beta,
            gamma,
        }
    }

    /// The pose as a column vector, in the order of [`Pose::to_array`].
    pub fn to_vector(&self) -> Vector6<T> {
        Vector6::from(self.to_array())
    }

    /// The pose from a column vector.
    pub fn from_vector(v: &Vector6<T>) -> Self {
        Self::new(v[0], v[1], v[2], v[3], v[4], v[5])
    }

    /// Returns the pose, or [`KinematicsError::NonFinite`] when any coordinate is NaN or infinite.
    pub fn validated(self) -> Result<Self, KinematicsError> {
        if self.to_array().iter().all(|c| c.finite()) {
            Ok(self)
        } else {
            Err(KinematicsError::NonFinite)
        }
    }

    /// Platform position `(x, y, z)`.
    pub fn position(&self) -> Vector3<T> {
        Vector3::new(self.x, self.y, self.z)
    }

    /// Rotation matrix platform -> base, `Rz(gamma) Ry(beta) Rx(alpha)`, written out as in KINEMATICS.md 1.
    pub fn rotation(&self) -> Matrix3<T> {
        rotation(self.alpha, self.beta, self.gamma)
    }

    /// `dR/dalpha`, `dR/dbeta`, `dR/dgamma` of [`Pose::rotation`], written out (one set of sines and cosines).
    pub(crate) fn rotation_partials(&self) -> [Matrix3<T>; 3] {
        let (sa, ca) = self.alpha.sin_cos_();
        let (sb, cb) = self.beta.sin_cos_();
        let (sg, cg) = self.gamma.sin_cos_();
        let z = T::zero();
        [
            Matrix3::new(
                z,
                cg * sb * ca + sg * sa,
                sg * ca - cg * sa * sb,
                z,
                sg * sb * ca - cg * sa,
                -sg * sa * sb - cg * ca,
                z,
                cb * ca,
                -cb * sa,
            ),
            Matrix3::new(
                -cg * sb,
                cg * cb * sa,
                cg * ca * cb,
                -sg * sb,
                sg * cb * sa,
                sg * ca * cb,
                -cb,
                -sb * sa,
                -sb * ca,
            ),
            Matrix3::new(
                -sg * cb,
                -sg * sb * sa - cg * ca,
                cg * sa - sg * ca * sb,
                cg * cb,
                cg * sb * sa - sg * ca,
                cg * ca * sb + sg * sa,
                z,
                z,
                z,
            ),
        ]
    }

    /// Converts each coordinate to another scalar type.
    pub fn cast<U: Real>(&self) -> Pose<U> {
        Pose::from_array(self.to_array().map(|c| U::of(c.to_f64())))
    }
}

/// `Rz(gamma) * Ry(beta) * Rx(alpha)`.
pub(crate) fn rotation<T: Real>(alpha: T, beta: T, gamma: T) -> Matrix3<T> {
    let (sa, ca) = alpha.sin_cos_();
    let (sb, cb) = beta.sin_cos_();
    let (sg, cg) = gamma.sin_cos_();
    Matrix3::new(
        cg * cb,
        cg * sb * sa - sg * ca,
        sg * sa + cg * ca * sb,
        sg * cb,
        cg * ca + sg * sb * sa,
        sg * ca * sb - cg * sa,
        -sb,
        cb * sa,
        cb * ca,
    )
}

/// The six actuator coordinates of a mechanism, in its canonical order (radians or metres per axis).
///
/// Trainer: `[q1, q2, q3, q4, s3, s4]`; rotopod: `[q1..q6]`; tool carrier: `[q1..q6]` of KINEMATICS.md 2.3.
/// Ring-carriage angles that come out of inverse kinematics lie in `(-pi, pi]`; the multi-turn position of a
/// carriage is kept by [`super::MultiTurn`].
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Actuators<T>(pub [T; 6]);

impl<T: Real> Actuators<T> {
    /// The six values.
    pub fn as_array(&self) -> &[T; 6] {
        &self.0
    }

    /// As a column vector.
    pub fn to_vector(&self) -> Vector6<T> {
        Vector6::from(self.0)
    }

    /// Returns the values, or [`KinematicsError::NonFinite`] when any is NaN or infinite.
    pub fn validated(self) -> Result<Self, KinematicsError> {
        if self.0.iter().all(|c| c.finite()) {
            Ok(self)
        } else {
            Err(KinematicsError::NonFinite)
        }
    }

    /// Converts each value to another scalar type.
    pub fn cast<U: Real>(&self) -> Actuators<U> {
        Actuators(self.0.map(|c| U::of(c.to_f64())))
    }
}
