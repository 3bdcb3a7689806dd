//! A preset's mechanism behind one type, so each command is written once for every geometry.

use nalgebra::Vector6;
use ringpod_core::kinematics::presets::{Preset, PresetGeometry};
use ringpod_core::kinematics::{
    Actuators, AxisKind, ChainKind, Jacobians, KinematicsError, Mechanism, Pose, RingPlatform, ToolCarrier,
    WorkspaceReport,
};

use crate::error::CliError;

/// The mechanism of a preset, in f64 for analysis.
pub enum AnyMechanism {
    /// Trainer or rotopod.
    Ring(Box<RingPlatform<f64>>),
    /// Tool carrier.
    Tool(ToolCarrier<f64>),
}

impl AnyMechanism {
    /// The mechanism of a preset name.
    pub fn by_name(name: &str) -> Result<(Preset, Self), CliError> {
        let preset = Preset::from_name(name).ok_or_else(|| CliError::UnknownMechanism(name.to_owned()))?;
        let m = match preset.geometry() {
            PresetGeometry::Ring(g) => AnyMechanism::Ring(Box::new(RingPlatform::new(g))),
            PresetGeometry::Tool(g) => AnyMechanism::Tool(ToolCarrier::new(g)),
        };
        Ok((preset, m))
    }

    /// Actuator names in the canonical order: `q<chain>` for carriage angles, `s<chain>` for radial lengths.
    pub fn axis_names(&self) -> [String; 6] {
        match self {
            AnyMechanism::Ring(r) => {
                let chains = r.geometry().chains();
                let mut names: Vec<String> = (1..=chains.len()).map(|i| format!("q{i}")).collect();
                names.extend(
                    chains
                        .iter()
                        .enumerate()
                        .filter(|(_, c)| c.kind == ChainKind::Radial)
                        .map(|(i, _)| format!("s{}", i + 1)),
                );
                std::array::from_fn(|i| names.get(i).cloned().unwrap_or_default())
            }
            AnyMechanism::Tool(_) => std::array::from_fn(|i| format!("q{}", i + 1)),
        }
    }
}

macro_rules! delegate {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            AnyMechanism::Ring($m) => $e,
            AnyMechanism::Tool($m) => $e,
        }
    };
}

impl Mechanism<f64> for AnyMechanism {
    type Guard = ();

    fn dof(&self) -> usize {
        delegate!(self, m => m.dof())
    }
    fn axes(&self) -> [AxisKind; 6] {
        delegate!(self, m => m.axes())
    }
    fn characteristic_length(&self) -> f64 {
        delegate!(self, m => m.characteristic_length())
    }
    fn inverse(&self, pose: &Pose<f64>) -> Result<Actuators<f64>, KinematicsError> {
        delegate!(self, m => m.inverse(pose))
    }
    fn residuals(&self, pose: &Pose<f64>, q: &Actuators<f64>) -> Vector6<f64> {
        delegate!(self, m => m.residuals(pose, q))
    }
    fn jacobians(&self, pose: &Pose<f64>, q: &Actuators<f64>) -> Jacobians<f64> {
        delegate!(self, m => m.jacobians(pose, q))
    }
    fn workspace(&self, pose: &Pose<f64>, q: &Actuators<f64>) -> WorkspaceReport<f64> {
        delegate!(self, m => m.workspace(pose, q))
    }
    fn inverse_checked(&self, pose: &Pose<f64>) -> Result<(Actuators<f64>, WorkspaceReport<f64>), KinematicsError> {
        delegate!(self, m => m.inverse_checked(pose))
    }
}
