//! Errors of the kinematics.

use core::fmt;

/// Why a chain cannot reach a pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Reach {
    /// The platform joint is at or beyond the rod length above or below the ring plane (`|Az| >= L`).
    Height,
    /// The rod's horizontal reach cannot span from the ring to the joint's projection (acos argument out of `[-1, 1]`).
    Ring,
    /// The platform joint is on the ring axis, where the carriage angle is undefined.
    Centre,
    /// A planar dyad cannot close: the pivot distance is out of `[|L2 - L3|, L2 + L3]` (the tool carrier's dyads;
    /// an elbow chain's arm, shoulder to platform joint, out of `[|upper_arm - forearm|, upper_arm + forearm]`).
    Dyad,
}

/// Why a kinematics computation has no answer.
///
/// Aligned to four bytes: in a `Result` beside `f32` arrays its byte-sized fields otherwise put the payload at an
/// odd offset, and moving that result out is a byte-wise `memcpy` call on the M4F (measured in the control tick).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
#[repr(align(4))]
pub enum KinematicsError {
    /// An input (pose, actuators, guess) has a NaN or infinite coordinate.
    NonFinite,
    /// Chain `chain` (0-based) cannot reach the pose.
    Unreachable {
        /// 0-based chain index.
        chain: u8,
        /// Which condition failed.
        reason: Reach,
    },
    /// The pose asks for motion along a coordinate the mechanism does not have (tool carrier yaw).
    OutsideMobility,
    /// The Jacobian needed for the computation is singular (velocities undefined).
    Singular,
    /// Forward kinematics came within the configured margin of a type-2 singularity.
    NearSingularity,
    /// Forward kinematics converged to an assembly that the auxiliary actuators contradict (the tool carrier's
    /// other four-bar assembly): the guess was too far from the platform's real pose.
    OtherAssembly,
    /// Forward kinematics did not converge within the configured number of iterations.
    NoConvergence {
        /// Iterations run.
        iterations: u8,
    },
    /// Forward kinematics converged to a pose further from the guess than the configured distance: another
    /// solution of the same actuators, not the platform's (the guess was too far off).
    FarFromGuess,
    /// Forward kinematics converged to a pose whose own inverse kinematics gives other actuators (another branch
    /// of a chain: the guess was on the wrong side of a type-1 boundary).
    OtherBranch,
    /// Forward kinematics converged to a pose that fails a workspace check: not a pose the platform can be in.
    Outside(crate::kinematics::Check),
}

impl fmt::Display for Reach {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Height => "the joint is beyond rod length from the ring plane",
            Self::Ring => "the rod cannot span from the ring to the joint",
            Self::Centre => "the joint is on the ring axis",
            Self::Dyad => "the dyad cannot close",
        })
    }
}

impl fmt::Display for KinematicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => f.write_str("input has a NaN or infinite coordinate"),
            Self::Unreachable { chain, reason } => write!(f, "unreachable: chain {} ({reason})", chain + 1),
            Self::OutsideMobility => f.write_str("the mechanism cannot move along that coordinate"),
            Self::Singular => f.write_str("singular Jacobian"),
            Self::NearSingularity => f.write_str("too close to a type-2 singularity"),
            Self::OtherAssembly => f.write_str("converged to another assembly than the auxiliary actuators show"),
            Self::NoConvergence { iterations } => write!(f, "no convergence after {iterations} iterations"),
            Self::FarFromGuess => f.write_str("converged too far from the guess (another solution of the actuators)"),
            Self::OtherBranch => f.write_str("converged to a pose whose chains take other branches than the actuators"),
            Self::Outside(check) => write!(f, "converged to a pose outside the workspace ({check} fails)"),
        }
    }
}

impl core::error::Error for KinematicsError {}
