//! Rig files: a ring platform of the builder's own, in TOML (the geometry and the names of KINEMATICS.md 2.1 and 2.2,
//! the elbow chains of dissertation ch. 5.1, joint limits, the home pose, the spec ranges), checked with an error
//! that names the key and says why.
//!
//! ```toml
//! name = "my-rig"
//! ring_radius = 0.286          # m
//! rod_length = 0.2             # m
//! home = [0, 0, 0.227, 0, 0, 0]
//!
//! [[chains]]                   # counter-clockwise around the ring, in actuator order
//! kind = "rod"
//! branch = "plus"
//! platform_point = [-0.06, -0.12, 0]
//!
//! [[chains]]
//! kind = "elbow"               # carriage, driven shoulder, upper arm, elbow, forearm, spherical joint
//! shoulder_radius = 0.258      # m from the ring axis, on the carriage's radius
//! shoulder_height = 0.017      # m above the ring plane
//! upper_arm = 0.105            # m, shoulder axis to elbow axis
//! forearm = 0.189              # m, elbow axis to the platform joint
//! elbow = "up"                 # or "down": the side of the shoulder-to-joint line the elbow is on
//! platform_point = [0.181, 0.160, 0]
//! ...
//! [limits]                     # optional; the source's joint limits by default
//! stroke = [0.160, 0.310]      # m, required with radial chains
//! shoulder_angle_deg = [100, 190]  # required with elbow chains: the shoulder's travel
//! elbow_angle_deg = [25, 155]  # interior angle at the elbow; 10..170 by default
//! carriage_spacing_deg = [12, 120]
//! base_cone_deg = 11
//! platform_cone_deg = 22
//! min_singularity_index = 0.01
//! centre_of_mass = [0, 0, 0.02]
//!
//! [spec]                       # optional; +- ranges around home that `rig check` measures
//! surge = 0.05
//! sway = 0.05
//! heave = 0.04
//! roll_deg = 20
//! pitch_deg = 20
//! ```

mod checks;
mod command;
mod coverage;
mod design;
pub mod drives;
pub mod error;
mod exact;
mod file;
pub mod homing;
mod settings;

pub use command::{check_command, design_command, export, preset, CommandError, UnknownMechanism};
pub use coverage::coverage;
pub use drives::{Drive, DriveSpec};
pub use error::RigError;
pub use file::{parse, read, BranchSpec, ChainSpec, ElbowSpec, KindSpec, RigFile};
pub use settings::InputsSpec;

use std::path::Path;

use ringpod_core::kinematics::geometry::RingGeometry;
use ringpod_core::kinematics::Pose;

/// A rig that can be analysed: a valid mechanism (lengths, chains and joints that make sense) with a home pose, spec
/// ranges and drives. Its home pose need not be inside every check, nor its axes homeable: that is [`Rig`]'s.
#[derive(Debug, Clone)]
pub struct Platform {
    /// The geometry.
    pub geometry: RingGeometry,
    /// The home pose (finite; where the analysis commands start).
    pub home: Pose<f64>,
    /// The spec ranges, if the file gives them (m and rad).
    pub ranges: Option<[f64; 5]>,
    /// Each axis's drive, where the file gives one.
    pub drives: [Option<Drive>; 6],
}

/// A rig that can be driven: a [`Platform`] whose home pose is inside every check and whose controller
/// configuration (homing plan included) the core accepts.
#[derive(Debug, Clone)]
pub struct Rig {
    /// The geometry.
    pub geometry: RingGeometry,
    /// The home pose.
    pub home: Pose<f64>,
    /// The spec ranges, if the file gives them (m and rad).
    pub ranges: Option<[f64; 5]>,
    /// Each axis's drive, where the file gives one.
    pub drives: [Option<Drive>; 6],
    /// What a device stores and runs: the geometry, home pose, axes, pose limits and inputs.
    pub record: ringpod_core::protocol::RigRecord,
    /// The point VR motion compensation reports the pose of (platform coordinates, m; the platform origin unless
    /// the file's `[motion_compensation]` says otherwise).
    pub centre_of_rotation: [f64; 3],
    /// The spare axes 7 and 8 (`[[spare]]`; none fitted without it), checked with the rig: a device takes them as
    /// a settings section beside the record, the simulator at its start.
    pub spare: [ringpod_core::motion::SpareAxisSettings; ringpod_core::motion::SPARE_AXES],
}

/// Reads and checks a rig file to drive it.
pub fn load(path: &Path) -> Result<Rig, RigError> {
    read(path)?.check().map_err(|e| e.in_file(path))
}

/// Reads a rig file to analyse it: only the mechanism must be valid.
pub fn load_platform(path: &Path) -> Result<Platform, RigError> {
    read(path)?.platform().map_err(|e| e.in_file(path))
}

impl RigFile {
    /// What `rig check` calls drivable: every rule of [`RigFile::check`], and homing that ends in `Ready` in the
    /// simulated machine.
    pub fn drivable(&self) -> Result<Rig, RigError> {
        let rig = self.check()?;
        homing::homing_time(&rig.record).map_err(|why| RigError::new("", format!("it does not home: {why}")))?;
        Ok(rig)
    }
}

fn err<T>(key: impl Into<String>, why: impl Into<String>) -> Result<T, RigError> {
    Err(RigError::new(key, why))
}

#[cfg(test)]
mod tests;
