//! Kinematics of parallel platforms on a circular guide (KINEMATICS.md).
//!
//! Every mechanism implements [`Mechanism`]: inverse kinematics (pose -> six actuators), the constraint
//! residuals `F(p, q)` and their Jacobians `A = dF/dp`, `B = dF/dq` (section 3), forward kinematics by Newton
//! iteration on `F(p, q) = 0` (a provided method), and the workspace checks of section 4 with margins.

mod error;
pub mod forward;
pub mod geometry;
mod lu;
mod multiturn;
mod pose;
pub mod presets;
mod ring;
mod tool;
pub mod velocity;
pub mod workspace;

pub use error::{KinematicsError, Reach};
pub use forward::{start_from_home, ForwardSolution, NewtonOptions, FROM_HOME_DISTANCE};
pub use geometry::{
    Branch, Chain, ChainKind, Elbow, ElbowBranch, GeometryError, RingGeometry, RingLimits, ToolGeometry,
};
pub use multiturn::MultiTurn;
pub use pose::{Actuators, Pose};
pub use ring::{
    ActuatorLoads, BodyMotion, Loaded, MotionState, Payload, RingPlatform, SlowCheckGuard, TipOver, TipOverError,
    GRAVITY,
};
pub use tool::ToolCarrier;
pub use velocity::{Jacobians, Singularity};
pub use workspace::{Check, WorkspaceReport};

use nalgebra::Vector6;

use crate::Real;

/// What an actuator coordinate measures, which decides how it is unwrapped and converted to steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum AxisKind {
    /// A carriage angle on the ring (rad): multi-turn, unwrapped to the branch nearest the previous value.
    Ring,
    /// A length (m).
    Linear,
    /// A bounded joint angle (rad), never unwrapped.
    Angle,
}

/// A parallel mechanism: pose <-> six actuator coordinates.
///
/// Implementations never panic: every input class that has no answer returns a [`KinematicsError`].
pub trait Mechanism<T: Real> {
    /// What [`Mechanism::inverse_guarded`] remembers between calls (`()` for a mechanism that proves nothing).
    type Guard: Default + Clone + Copy + core::fmt::Debug;

    /// Degrees of freedom of the platform: 6, or 5 for the tool carrier whose yaw is fixed at zero.
    /// Pose coordinates from index `dof()` on are held at zero; actuators from index `dof()` on are auxiliary
    /// (they follow the pose and are not inputs of the forward kinematics).
    fn dof(&self) -> usize;

    /// What each of the six actuator coordinates measures.
    fn axes(&self) -> [AxisKind; 6];

    /// A length typical of the mechanism (ring radius, link length): it makes residuals, Jacobian columns and
    /// singularity indices scale-free.
    fn characteristic_length(&self) -> T;

    /// Inverse kinematics: the six actuator coordinates that put the platform at `pose`.
    fn inverse(&self, pose: &Pose<T>) -> Result<Actuators<T>, KinematicsError>;

    /// Constraint residuals `F(p, q)` (zero when `q` and `pose` belong together); rows from `dof()` on are the
    /// auxiliary relations.
    fn residuals(&self, pose: &Pose<T>, q: &Actuators<T>) -> Vector6<T>;

    /// The velocity Jacobians `A = dF/dp` and `B = dF/dq` at a pose and its actuators.
    fn jacobians(&self, pose: &Pose<T>, q: &Actuators<T>) -> Jacobians<T>;

    /// Every workspace check of KINEMATICS.md 4 with its margin, for a pose and the actuators of its IK.
    fn workspace(&self, pose: &Pose<T>, q: &Actuators<T>) -> WorkspaceReport<T>;

    /// Forward kinematics: the pose that the actuators `q` put the platform in, found by Newton iteration on
    /// `F(p, q) = 0` from `guess` (normally the last known pose).
    fn forward(
        &self,
        q: &Actuators<T>,
        guess: &Pose<T>,
        options: &NewtonOptions<T>,
    ) -> Result<ForwardSolution<T>, KinematicsError>
    where
        Self: Sized,
    {
        forward::newton(self, q, guess, options)
    }

    /// IK, then every workspace check: the actuators and the report, or the reason there is no solution.
    fn inverse_checked(&self, pose: &Pose<T>) -> Result<(Actuators<T>, WorkspaceReport<T>), KinematicsError> {
        let q = self.inverse(pose)?;
        Ok((q, self.workspace(pose, &q)))
    }

    /// IK and the workspace checks, in the order of [`Check::ALL`], against the room each must leave: the actuators
    /// when every check leaves it, else the first check short of it ([`Check::Reach`] when the pose has no IK).
    /// What [`WorkspaceReport::first_below`] finds in [`Mechanism::inverse_checked`]'s report, which the default
    /// evaluates; a mechanism may stop at the first check short of its room (the envelope search's points outside
    /// need no more).
    fn inverse_within(&self, pose: &Pose<T>, room: &[T; 6]) -> Result<Actuators<T>, Check> {
        match self.inverse_checked(pose) {
            Ok((q, report)) => report.first_below(room).map_or(Ok(q), Err),
            Err(_) => Err(Check::Reach),
        }
    }

    /// [`Mechanism::inverse_within`] with the memory of `guard` to work in: a mechanism may evaluate the checks in
    /// the configuration `guard` keeps for the pose being checked, which its IK overwrites, instead of clearing a
    /// new one per call (the envelope search evaluates up to eight poses a setpoint). The slow checks' reference in
    /// `guard` is left as it is, so [`Mechanism::inverse_guarded`] proves exactly what it would have. The default
    /// ignores `guard`.
    fn inverse_within_in(&self, pose: &Pose<T>, room: &[T; 6], guard: &mut Self::Guard) -> Result<Actuators<T>, Check> {
        let _ = guard;
        self.inverse_within(pose, room)
    }

    /// [`Mechanism::inverse_checked`] for a sequence of nearby poses (a control loop's): checks that change slowly
    /// may be proved from where `guard` last evaluated them instead of evaluated again. Every check still passes
    /// exactly when it would have; a proved margin is reported as its lower bound. The default evaluates everything.
    fn inverse_guarded(
        &self,
        pose: &Pose<T>,
        guard: &mut Self::Guard,
    ) -> Result<(Actuators<T>, WorkspaceReport<T>), KinematicsError> {
        let _ = guard;
        self.inverse_checked(pose)
    }
}
