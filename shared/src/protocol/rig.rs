//! A ring platform as it travels to a device and lives in its flash: the rig file's geometry (KINEMATICS.md 2.1 and
//! 2.2: ring radius, rod length, chains in actuator order, joint limits) and home pose, in the units of
//! `kinematics` (m, rad), `f64` as the host computes them, so that a rig file, its record on the wire and its record
//! in flash are the same numbers bit for bit; and the settings sections that describe the machine (motors, pose
//! limits, inputs, supply sequencing, homing: [`MachineSettings`]), as they travel on their own.

use crate::kinematics::presets::{Preset, PresetGeometry};
use crate::kinematics::{Chain, ChainKind, GeometryError, RingGeometry, RingLimits};

use super::{ConfigRefusal, MachineSettings};

/// Longest rig name kept (bytes of UTF-8).
pub const RIG_NAME_LEN: usize = 32;

/// A ring platform and where homing leaves it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RigRecord {
    /// Its name, UTF-8, padded with zeros (longer names are cut at a character boundary).
    pub name: [u8; RIG_NAME_LEN],
    /// Ring radius (m).
    pub ring_radius: f64,
    /// Rod length of the rod chains (m).
    pub rod_length: f64,
    /// The chains, counter-clockwise around the ring; the first `chain_count` are used.
    pub chains: [Chain; 6],
    /// Chains in use (3 to 6).
    pub chain_count: u8,
    /// Joint limits of the workspace checks.
    pub limits: RingLimits,
    /// Home pose `[x, y, z, alpha, beta, gamma]` (m, rad).
    pub home: [f64; 6],
    /// Its motors, pose limits, inputs, supply sequencing and homing.
    pub machine: MachineSettings,
}

impl RigRecord {
    /// The record of `geometry` homed at `home`, named `name` (cut to [`RIG_NAME_LEN`] bytes at a character
    /// boundary), with the sections of `machine`.
    pub fn new(name: &str, geometry: &RingGeometry, home: [f64; 6], machine: MachineSettings) -> Self {
        let mut chains = [Chain {
            kind: ChainKind::Radial,
            platform_point: [0.0; 3],
        }; 6];
        for (slot, c) in chains.iter_mut().zip(geometry.chains()) {
            *slot = *c;
        }
        let mut stored = [0u8; RIG_NAME_LEN];
        let mut end = name.len().min(RIG_NAME_LEN);
        while !name.is_char_boundary(end) {
            end -= 1;
        }
        stored[..end].copy_from_slice(&name.as_bytes()[..end]);
        Self {
            name: stored,
            ring_radius: geometry.ring_radius,
            rod_length: geometry.rod_length,
            chains,
            chain_count: geometry.chains().len() as u8,
            limits: geometry.limits,
            home,
            machine,
        }
    }

    /// The name.
    pub fn name(&self) -> &str {
        let len = self.name.iter().position(|b| *b == 0).unwrap_or(RIG_NAME_LEN);
        core::str::from_utf8(&self.name[..len]).unwrap_or("?")
    }

    /// The geometry, through every check of `RingGeometry::new`; named as the preset it restates, if it restates
    /// one exactly, and "rig" otherwise.
    pub fn geometry(&self) -> Result<RingGeometry, GeometryError> {
        let n = usize::from(self.chain_count).min(6);
        let geometry = RingGeometry::new("rig", self.ring_radius, self.rod_length, &self.chains[..n], self.limits)?;
        let preset = Preset::ALL.into_iter().find_map(|p| match p.geometry() {
            PresetGeometry::Ring(g) => {
                let mut renamed = *g;
                renamed.name = "rig";
                (renamed == geometry).then_some(*g)
            }
            _ => None,
        });
        Ok(preset.unwrap_or(geometry))
    }
}

/// Where the rig a device runs came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RigSource {
    /// Compiled into the firmware (nothing stored).
    #[default]
    Compiled,
    /// Restored from flash.
    Stored,
    /// A stored rig was refused by the checks, and why: the compiled-in rig runs.
    Refused(ConfigRefusal),
    /// The stored record could not be read (another record version, or damaged): the compiled-in rig runs.
    Unreadable,
}

impl core::fmt::Display for RigSource {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Compiled => f.write_str("compiled in"),
            Self::Stored => f.write_str("stored"),
            Self::Refused(why) => write!(f, "the stored rig was refused ({why}): the compiled-in rig runs"),
            Self::Unreadable => f.write_str("the stored rig could not be read: the compiled-in rig runs"),
        }
    }
}
