//! A preset's mechanism behind one type, so each command is written once for every geometry.

use nalgebra::Vector6;
use ringpod_core::kinematics::presets::{Preset, PresetGeometry};
use ringpod_core::kinematics::{
    Actuators, AxisKind, ChainKind, Jacobians, KinematicsError, Mechanism, Pose, RingPlatform, ToolCarrier,
    WorkspaceReport,
};

use crate::error::CliError;
use crate::rig::Drive;

/// The mechanism of a preset, in f64 for analysis.
pub enum AnyMechanism {
    /// Trainer or rotopod.
    Ring(Box<RingPlatform<f64>>),
    /// Tool carrier.
    Tool(Box<ToolCarrier<f64>>),
}

/// The geometry a command works on: a preset by name, or a rig file.
pub struct Selected {
    /// Its name, for reports.
    pub name: String,
    /// Its home pose.
    pub home: [f64; 6],
    /// The mechanism.
    pub mechanism: AnyMechanism,
    /// Each axis's drive, where the rig file or the preset gives one.
    pub drives: [Option<Drive>; 6],
}

impl Selected {
    /// The rig file if one is given, else the preset named.
    pub fn of(mechanism: &str, geometry: Option<&std::path::Path>) -> Result<Self, CliError> {
        match geometry {
            Some(path) => {
                let rig = crate::rig::load_platform(path)?;
                Ok(Self {
                    name: rig.geometry.name.to_owned(),
                    home: rig.home.to_array(),
                    mechanism: AnyMechanism::Ring(Box::new(RingPlatform::new(&rig.geometry))),
                    drives: rig.drives,
                })
            }
            None => {
                let (preset, m) = AnyMechanism::by_name(mechanism)?;
                let drives = crate::rig::drives::check(&crate::rig::drives::of_preset(preset), &m.axes())?;
                Ok(Self {
                    name: preset.name().to_owned(),
                    home: preset.home(),
                    mechanism: m,
                    drives,
                })
            }
        }
    }
}

impl AnyMechanism {
    /// The mechanism of a preset name.
    pub fn by_name(name: &str) -> Result<(Preset, Self), CliError> {
        let preset = Preset::from_name(name).ok_or_else(|| crate::rig::UnknownMechanism(name.to_owned()))?;
        let m = match preset.geometry() {
            PresetGeometry::Ring(g) => AnyMechanism::Ring(Box::new(RingPlatform::new(g))),
            PresetGeometry::Tool(g) => AnyMechanism::Tool(Box::new(ToolCarrier::new(g))),
        };
        Ok((preset, m))
    }

    /// Actuator names in the canonical order: `q<chain>` for carriage angles, `s<chain>` for radial lengths and
    /// then for elbow chains' shoulder angles (a chain has one or the other).
    pub fn axis_names(&self) -> [String; 6] {
        match self {
            AnyMechanism::Ring(r) => {
                let chains = r.geometry().chains();
                let mut names: Vec<String> = (1..=chains.len()).map(|i| format!("q{i}")).collect();
                let second = |radial: bool| {
                    chains
                        .iter()
                        .enumerate()
                        .filter(move |(_, c)| (c.kind == ChainKind::Radial) == radial && c.kind.is_planar())
                        .map(|(i, _)| format!("s{}", i + 1))
                };
                names.extend(second(true).chain(second(false)));
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
