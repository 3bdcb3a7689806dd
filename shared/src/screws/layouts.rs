//! The chains of each mechanism as [`Chain`]s of pairs for the structural analysis of [`super::structure`]: the
//! ring platforms' rod and radial chains at a pose, the tool carrier's three chains at a pose, and the source's
//! three single-chain examples of chapter 5.1 (figs. 5.1 to 5.3) at its coordinates.

use nalgebra::{Vector3, Vector6};

use super::structure::{Chain, Pair, StructureError};
use crate::kinematics::{ChainKind, KinematicsError, Mechanism, Pose, RingPlatform, ToolCarrier};

/// Why a mechanism's chains could not be laid out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LayoutError {
    /// The pose has no inverse kinematics.
    Kinematics(KinematicsError),
    /// A chain could not be built.
    Structure(StructureError),
}

impl From<KinematicsError> for LayoutError {
    fn from(e: KinematicsError) -> Self {
        LayoutError::Kinematics(e)
    }
}

impl From<StructureError> for LayoutError {
    fn from(e: StructureError) -> Self {
        LayoutError::Structure(e)
    }
}

/// Up to six chains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chains {
    chains: [Option<Chain>; 6],
    count: usize,
}

impl Chains {
    fn push(&mut self, chain: Chain) -> Result<(), StructureError> {
        *self.chains.get_mut(self.count).ok_or(StructureError::TooManyJoints)? = Some(chain);
        self.count += 1;
        Ok(())
    }

    /// The chains in order.
    pub fn iter(&self) -> impl Iterator<Item = &Chain> {
        self.chains.iter().flatten()
    }

    /// How many chains.
    pub fn len(&self) -> usize {
        self.count
    }

    /// No chains.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// A ring platform's chains at a pose (its IK places the carriages), in chain order:
/// - rod chain: the carriage (revolute about the ring axis Z through the centre, driven), the spherical pair at
///   the carriage `B`, the pin-spherical pair at the platform joint `A` (along the platform's X' and Y');
/// - radial chain: the carriage (driven), the revolute at `B` along the ring's tangent, the prismatic pair along
///   `B -> A` (driven; the source's screw is `B -> A` itself), the spherical pair at `A`;
/// - elbow chain (fig. 5.2): the carriage (driven), the shoulder revolute along the ring's tangent at the shoulder
///   `S` (driven), the elbow revolute parallel to it at the elbow `E`, the spherical pair at `A` (wrenches oriented
///   along the forearm `E -> A`).
pub fn ring_chains(platform: &RingPlatform<f64>, pose: &Pose<f64>) -> Result<Chains, LayoutError> {
    let q = platform.inverse(pose)?.0;
    let geometry = platform.geometry();
    let rr = geometry.ring_radius;
    let joints = platform.joints(pose);
    let rotation = pose.rotation();
    let mut out = Chains {
        chains: [None; 6],
        count: 0,
    };
    // Shoulder angles follow the carriages and the radial lengths.
    let chains = geometry.chains();
    let mut shoulder_axis = chains.len() + chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
    for (i, c) in chains.iter().enumerate() {
        let (qi, a) = (q[i], joints[i]);
        let (s, co) = libm::sincos(qi);
        let b = Vector3::new(rr * co, rr * s, 0.0);
        if let ChainKind::Elbow(e) = c.kind {
            let shoulder = Vector3::new(e.shoulder_radius * co, e.shoulder_radius * s, e.shoulder_height);
            let (ss, cs) = libm::sincos(q.get(shoulder_axis).copied().unwrap_or(0.0));
            shoulder_axis += 1;
            let elbow = shoulder + (Vector3::new(-co, -s, 0.0) * cs + Vector3::z() * ss) * e.upper_arm;
            let tangent = Vector3::new(-s, co, 0.0);
            let chain = Chain::new(elbow, a)?
                .revolute(Vector3::z(), Vector3::zeros(), true)?
                .revolute(tangent, shoulder, true)?
                .revolute(tangent, elbow, false)?
                .spherical(a)?;
            out.push(chain)?;
            continue;
        }
        let carriage = Chain::new(b, a)?.revolute(Vector3::z(), Vector3::zeros(), true)?;
        let chain = match c.kind {
            ChainKind::Rod(_) => carriage
                .spherical(b)?
                .pin_spherical(a, [rotation * Vector3::x(), rotation * Vector3::y()])?,
            ChainKind::Radial | ChainKind::Elbow(_) => carriage
                .revolute(Vector3::new(-s, co, 0.0), b, false)?
                .prismatic(a - b, (a - b).norm(), true)?
                .spherical(a)?,
        };
        out.push(chain)?;
    }
    Ok(out)
}

/// The tool carrier's chains at a pose (the joint layout of [`super::tool`]): the carriage chain (X guide driven,
/// cross slides, roll bearing, pitch driven), then the B dyad (base pivot and elbow driven, slider, spherical pair
/// at the frame pivot `A2`) and the D dyad (base pivot driven; `A3`).
pub fn tool_chains(carrier: &ToolCarrier<f64>, pose: &Pose<f64>) -> Result<Chains, LayoutError> {
    let c = super::tool::chains(carrier, pose)?;
    let g = carrier.geometry();
    let ey = Vector3::new(0.0, libm::cos(pose.alpha), libm::sin(pose.alpha));
    let mut out = Chains {
        chains: [None; 6],
        count: 0,
    };
    let twist = |j: &super::chains::Joint| -> [Vector6<f64>; 1] { [j.twist] };
    let mut carriage = Chain::new(Vector3::zeros(), c.centre)?;
    for (j, pair) in c.carriage.iter().zip([
        Pair::Prismatic,
        Pair::Prismatic,
        Pair::Prismatic,
        Pair::Revolute,
        Pair::Revolute,
    ]) {
        carriage = carriage.pair(pair, &twist(j), j.actuated, 1.0)?;
    }
    out.push(carriage)?;
    for (dyad, (base, side)) in c.dyads.iter().zip([(g.pivot_b, 1.0), (g.pivot_d, -1.0)]) {
        let a = c.centre + ey * (side * g.b / 2.0);
        let mut chain = Chain::new(Vector3::from(base), a)?;
        for (j, pair) in dyad[..3].iter().zip([Pair::Revolute, Pair::Revolute, Pair::Prismatic]) {
            chain = chain.pair(pair, &twist(j), j.actuated, 1.0)?;
        }
        let sphere = [dyad[3].twist, dyad[4].twist, dyad[5].twist];
        out.push(chain.pair(Pair::Spherical, &sphere, false, 1.0)?)?;
    }
    Ok(out)
}

/// The source's single-chain examples of chapter 5.1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Figure {
    /// Fig. 5.1, the rotopod's chain (carriage, spherical pair at `B`, pin-spherical pair at `A`) with
    /// `A = (0.5, 0.2, 1)`: determinant -0.2.
    Fig5_1,
    /// Fig. 5.1 as the source shows it first, `A = (0.5, 0, 1)` in a plane with the ring axis and `B`:
    /// determinant 0 (a type 1 singularity).
    Fig5_1Singular,
    /// Fig. 5.2: carriage, revolutes along Y at `B` (the second drive) and at `C = (0.5, 0, 0)` (the source's row
    /// `E3 = (0, 1, 0, 0, 0, 0.5)`: below `A` at the carriage's height), spherical pair at `A = (0.5, 0, 1)`:
    /// determinant -0.25.
    Fig5_2,
    /// Fig. 5.3: carriage, revolute along Y at `B`, prismatic pair along `B -> A` (driven), spherical pair at
    /// `A = (0.5, 0, 1)`: determinant 0.625 with the prismatic screw written as `B -> A` (the source's form), 0.559
    /// with it unit.
    Fig5_3,
}

impl Figure {
    /// The source's carriage joint `B`.
    pub const B: [f64; 3] = [1.0, 0.0, 0.0];

    /// The platform joint `A` the source takes.
    pub fn a(self) -> [f64; 3] {
        match self {
            Figure::Fig5_1 => [0.5, 0.2, 1.0],
            _ => [0.5, 0.0, 1.0],
        }
    }

    /// The determinant the source prints (its form, see [`super::structure`]).
    pub fn published(self) -> f64 {
        match self {
            Figure::Fig5_1 => -0.2,
            Figure::Fig5_1Singular => 0.0,
            Figure::Fig5_2 => -0.25,
            Figure::Fig5_3 => 0.625,
        }
    }

    /// The chain at the source's coordinates.
    pub fn chain(self) -> Result<Chain, StructureError> {
        let b = Vector3::from(Self::B);
        let a = Vector3::from(self.a());
        let carriage = Chain::new(b, a)?.revolute(Vector3::z(), Vector3::zeros(), true)?;
        match self {
            Figure::Fig5_1 | Figure::Fig5_1Singular => {
                carriage.spherical(b)?.pin_spherical(a, [Vector3::x(), Vector3::y()])
            }
            Figure::Fig5_2 => carriage
                .revolute(Vector3::y(), b, true)?
                .revolute(Vector3::y(), Vector3::new(a.x, a.y, b.z), false)?
                .spherical(a),
            Figure::Fig5_3 => carriage
                .revolute(Vector3::y(), b, false)?
                .prismatic(a - b, (a - b).norm(), true)?
                .spherical(a),
        }
    }
}
