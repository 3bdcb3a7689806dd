//! Rig files as written: the TOML form's types, reading one (errors name the line) and writing one from a geometry.

use std::path::Path;

use ringpod_core::controller::{ConfigError, ControllerConfig};
use ringpod_core::kinematics::geometry::{Branch, Chain, ChainKind, ElbowBranch, RingGeometry, DEG};
use ringpod_core::protocol::{AxisSettings, HomingSettings, RigRecord, Settings};
use serde::{Deserialize, Serialize};

use super::{err, settings, DriveSpec, RigError};

/// A rig file as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigFile {
    /// Name for reports (1 to 32 characters).
    pub name: String,
    /// Ring radius (m).
    pub ring_radius: f64,
    /// Rod length of the rod chains (m).
    pub rod_length: f64,
    /// Home pose x, y, z (m), roll, pitch, yaw (rad): where homing leaves the platform; inside every check.
    #[serde(deserialize_with = "super::exact::array")]
    pub home: [f64; 6],
    /// The chains, counter-clockwise around the ring.
    pub chains: Vec<ChainSpec>,
    /// Joint limits (the source's by default).
    #[serde(default)]
    pub limits: LimitsSpec,
    /// Motion ranges around home that `ringpod rig check` measures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<SpecRanges>,
    /// Motor data per axis, for the drive margin of `ringpod loads --input` (optional).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub drives: Vec<DriveSpec>,
    /// Each motor's steps per unit and direction, in actuator order (optional: the trainer model's drives).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub axes: Vec<AxisSettings>,
    /// Pose and actuator limits (optional: the trainer model's pose limits, and each actuator its kind's on the
    /// trainer model's drives).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<settings::MotionSpec>,
    /// Input wiring (optional: switches to ground with pull-ups, a normally closed e-stop chain, 3 ms debouncing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<settings::InputsSpec>,
    /// Supply sensing and sequencing (optional: both supplies sensed, the firmware's default delays).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supervisor: Option<ringpod_core::safety::SupervisorConfig>,
    /// Every axis's home switch and its search, in the axis's units (optional: the trainer model's switches on
    /// this rig: index flags at the carriages' home angles, linear actuators' lower end switches 1 mm below the
    /// stroke).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub homing: Option<HomingSettings>,
    /// The spare stepper axes 7 and 8 (`[[spare]]`, at most two; optional: none fitted). A fitted axis takes the
    /// Black Pill's LOGIC_OK, POWER_OK and USART1 pins for its STEP and DIR, so `[supervisor]` must sense no supply.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spare: Vec<ringpod_core::motion::SpareAxisSettings>,
    /// VR motion compensation: the rig's centre of rotation (`stream --motion-compensation`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion_compensation: Option<crate::vr::CompensationSpec>,
}

/// One chain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChainSpec {
    /// Rod (one actuator: the carriage), radial (two: the carriage and the length) or elbow (two: the carriage and
    /// the shoulder angle).
    pub kind: KindSpec,
    /// Which of the two solutions a rod chain takes (rod chains only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub branch: Option<BranchSpec>,
    /// Elbow chains: the shoulder axis's distance from the ring axis, on the carriage's radius (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shoulder_radius: Option<f64>,
    /// Elbow chains: the shoulder axis's height above the ring plane (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shoulder_height: Option<f64>,
    /// Elbow chains: shoulder axis to elbow axis (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_arm: Option<f64>,
    /// Elbow chains: elbow axis to the platform joint (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forearm: Option<f64>,
    /// Elbow chains: which side of the shoulder-to-joint line the elbow is on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elbow: Option<ElbowSpec>,
    /// The platform joint in the platform frame (m).
    #[serde(deserialize_with = "super::exact::array")]
    pub platform_point: [f64; 3],
}

impl ChainSpec {
    /// A chain of `kind` at `platform_point` with no other keys.
    fn bare(kind: KindSpec, platform_point: [f64; 3]) -> Self {
        Self {
            kind,
            branch: None,
            shoulder_radius: None,
            shoulder_height: None,
            upper_arm: None,
            forearm: None,
            elbow: None,
            platform_point,
        }
    }

    /// The keys only elbow chains take, with whether each is given.
    pub(super) fn elbow_keys(&self) -> [(&'static str, bool); 5] {
        [
            ("shoulder_radius", self.shoulder_radius.is_some()),
            ("shoulder_height", self.shoulder_height.is_some()),
            ("upper_arm", self.upper_arm.is_some()),
            ("forearm", self.forearm.is_some()),
            ("elbow", self.elbow.is_some()),
        ]
    }
}

/// `kind` of a chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KindSpec {
    /// Carriage, spherical joint, rod of fixed length.
    Rod,
    /// Carriage, revolute joint tangent to the ring, linear actuator in the radial plane.
    Radial,
    /// Carriage, driven shoulder revolute tangent to the ring, upper arm, elbow revolute, forearm (ch. 5.1).
    Elbow,
}

/// `elbow` of an elbow chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ElbowSpec {
    /// The elbow on the higher side of the shoulder-to-joint line (while the joint is nearer the ring axis than the
    /// shoulder; the assembly is kept beyond).
    Up,
    /// The elbow on the lower side.
    Down,
}

/// `branch` of a rod chain: `q = theta + phi` or `theta - phi`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BranchSpec {
    /// `q = theta + phi`.
    Plus,
    /// `q = theta - phi`.
    Minus,
}

/// `[limits]`: what the workspace checks enforce. Angles in degrees, as builders measure them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsSpec {
    /// Linear-actuator length range (m); required when there are radial chains.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "super::exact::option")]
    pub stroke: Option<[f64; 2]>,
    /// The travel of elbow chains' shoulders (deg, the angle from the horizontal toward the ring axis, up
    /// positive); required when there are elbow chains.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "super::exact::option")]
    pub shoulder_angle_deg: Option<[f64; 2]>,
    /// Allowed interior angle at elbow chains' elbows (deg, 0 folded, 180 stretched); 10 to 170 by default.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "super::exact::option")]
    pub elbow_angle_deg: Option<[f64; 2]>,
    /// Allowed central angle between neighbouring carriages (deg).
    #[serde(deserialize_with = "super::exact::array")]
    pub carriage_spacing_deg: [f64; 2],
    /// Least angle of a chain to the base plane (deg).
    pub base_cone_deg: f64,
    /// Least angle of a chain to the platform plane (deg).
    pub platform_cone_deg: f64,
    /// Least singularity index of the wrench matrix.
    pub min_singularity_index: f64,
    /// Centre of mass of platform and payload in the platform frame (m).
    #[serde(deserialize_with = "super::exact::array")]
    pub centre_of_mass: [f64; 3],
}

impl Default for LimitsSpec {
    /// The source's joint limits: spacing 12 to 120 deg, cones 11 and 22 deg, index 0.01, centre of mass at the
    /// platform's origin.
    fn default() -> Self {
        Self {
            stroke: None,
            shoulder_angle_deg: None,
            elbow_angle_deg: None,
            carriage_spacing_deg: [12.0, 120.0],
            base_cone_deg: 11.0,
            platform_cone_deg: 22.0,
            min_singularity_index: 0.01,
            centre_of_mass: [0.0; 3],
        }
    }
}

/// `[spec]`: motion ranges, each plus and minus around home; yaw is continuous.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecRanges {
    /// Surge (m).
    pub surge: f64,
    /// Sway (m).
    pub sway: f64,
    /// Heave (m).
    pub heave: f64,
    /// Roll (deg).
    pub roll_deg: f64,
    /// Pitch (deg).
    pub pitch_deg: f64,
}

impl SpecRanges {
    /// `[surge, sway, heave, roll, pitch]` in m and rad.
    pub fn si(&self) -> [f64; 5] {
        [
            self.surge,
            self.sway,
            self.heave,
            self.roll_deg * DEG,
            self.pitch_deg * DEG,
        ]
    }
}

impl ChainSpec {
    /// The chain as a rig file writes it.
    fn of(c: &Chain) -> Self {
        match c.kind {
            ChainKind::Rod(b) => Self {
                branch: Some(match b {
                    Branch::Plus => BranchSpec::Plus,
                    Branch::Minus => BranchSpec::Minus,
                }),
                ..Self::bare(KindSpec::Rod, c.platform_point)
            },
            ChainKind::Radial => Self::bare(KindSpec::Radial, c.platform_point),
            ChainKind::Elbow(e) => Self {
                shoulder_radius: Some(e.shoulder_radius),
                shoulder_height: Some(e.shoulder_height),
                upper_arm: Some(e.upper_arm),
                forearm: Some(e.forearm),
                elbow: Some(match e.branch {
                    ElbowBranch::Up => ElbowSpec::Up,
                    ElbowBranch::Down => ElbowSpec::Down,
                }),
                ..Self::bare(KindSpec::Elbow, c.platform_point)
            },
        }
    }
}

/// Reads a rig file without checking it (a design template need not be a valid rig yet).
pub fn read(path: &Path) -> Result<RigFile, RigError> {
    let text = crate::input::files::read_text(path, crate::input::files::CONFIG_LIMIT)
        .or_else(|e| err(path.display().to_string(), e))?;
    parse(&text).map_err(|e| e.in_file(path))
}

/// A rig file's text, read but not checked (the workbench's editor checks as the user types).
pub fn parse(text: &str) -> Result<RigFile, RigError> {
    toml::from_str(text).or_else(|e| {
        // toml names the line; keep its words, and name the key written on that line.
        err(
            key_at(text, e.span()).unwrap_or_default(),
            e.message().trim().to_owned() + &span_of(text, e.span()),
        )
    })
}

/// The key of the `key = value` line where `span` starts, if it is one.
fn key_at(text: &str, span: Option<std::ops::Range<usize>>) -> Option<String> {
    let start = span?.start.min(text.len());
    let line = text[..start].rsplit('\n').next()?;
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    let bare = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.';
    (!key.is_empty() && key.chars().all(bare)).then(|| key.to_owned())
}

fn span_of(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    span.map(|s| format!(" (line {})", text[..s.start.min(text.len())].matches('\n').count() + 1))
        .unwrap_or_default()
}

/// Radians to degrees as a person writes them: 120, not 119.99999999999999.
fn degrees(rad: f64) -> f64 {
    (rad / DEG * 1e9).round() / 1e9
}

impl RigFile {
    /// The rig file of a geometry (what `ringpod presets --export` writes).
    pub fn of(geometry: &RingGeometry, home: [f64; 6], ranges: Option<[f64; 5]>, drives: Vec<DriveSpec>) -> Self {
        let l = &geometry.limits;
        let has_radial = geometry.chains().iter().any(|c| c.kind == ChainKind::Radial);
        let arm = geometry.chains().iter().find_map(|c| match c.kind {
            ChainKind::Elbow(e) => Some(e),
            _ => None,
        });
        Self {
            name: geometry.name.to_owned(),
            ring_radius: geometry.ring_radius,
            rod_length: geometry.rod_length,
            home,
            chains: geometry.chains().iter().map(ChainSpec::of).collect(),
            limits: LimitsSpec {
                stroke: has_radial.then_some(l.stroke),
                shoulder_angle_deg: arm.map(|e| e.shoulder_angle.map(degrees)),
                elbow_angle_deg: arm.map(|e| e.elbow_angle.map(degrees)),
                carriage_spacing_deg: l.carriage_spacing.map(degrees),
                base_cone_deg: degrees(l.base_cone),
                platform_cone_deg: degrees(l.platform_cone),
                min_singularity_index: l.min_singularity_index,
                centre_of_mass: l.centre_of_mass,
            },
            spec: ranges.map(|r| SpecRanges {
                surge: r[0],
                sway: r[1],
                heave: r[2],
                roll_deg: degrees(r[3]),
                pitch_deg: degrees(r[4]),
            }),
            drives,
            axes: Vec::new(),
            motion: None,
            inputs: None,
            supervisor: None,
            homing: None,
            spare: Vec::new(),
            motion_compensation: None,
        }
    }

    /// The file as TOML text, every number as written: the device's `f32` values by their shortest decimal (0.05,
    /// not 0.05000000074505806), keys in the order of the types.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        fn tidy(v: &mut toml::Value) {
            match v {
                toml::Value::Float(f) => *f = crate::input::numbers::as_written(*f),
                toml::Value::Array(a) => a.iter_mut().for_each(tidy),
                toml::Value::Table(t) => t.iter_mut().for_each(|(_, v)| tidy(v)),
                _ => {}
            }
        }
        let mut value = toml::Value::try_from(self)?;
        tidy(&mut value);
        toml::to_string(&value)
    }
}
impl RigFile {
    /// The record a device stores: geometry and home pose with the file's sections (or the defaults), checked by
    /// the controller's own code; each error names its key.
    pub(super) fn record(&self, record: RigRecord) -> Result<RigRecord, RigError> {
        let mut record = record;
        record.geometry().or_else(|e| err("rig", e.to_string()))?;
        if !self.axes.is_empty() && self.axes.len() != 6 {
            return err(
                "axes",
                format!("{} entries: one per actuator (6), or none", self.axes.len()),
            );
        }
        for (slot, axis) in record.machine.axes.iter_mut().zip(&self.axes) {
            *slot = *axis;
        }
        if let Some(m) = &self.motion {
            record.machine.motion = m.settings(&record.machine.motion);
        }
        if let Some(spec) = &self.inputs {
            record.machine.inputs = spec.config()?;
        }
        if let Some(s) = self.supervisor {
            record.machine.supervisor = s;
        }
        if let Some(h) = &self.homing {
            record.machine.homing = *h;
        }
        // The device's checks are the only ones: a field out of range is named by the core, by the file's key.
        ControllerConfig::from_record(&record).map_err(|e| match e {
            ConfigError::Value(field) => RigError::new(field.to_string(), format!("must be {}", field.must())),
            other => RigError::new("rig", format!("the controller cannot drive it: {other}")),
        })?;
        Ok(record)
    }

    /// The spare axes' section of the file (none fitted without `[[spare]]`), checked with the rig it comes with:
    /// each fitted axis's ranges and the pins it takes (the error names the key).
    pub fn spare_section(&self, record: &RigRecord) -> Result<Settings, RigError> {
        use ringpod_core::motion::{SpareAxisSettings, SPARE_AXES};
        if self.spare.len() > SPARE_AXES {
            return Err(RigError::new("spare", "at most two axes (7 and 8)"));
        }
        let mut axes = [SpareAxisSettings::NONE; SPARE_AXES];
        axes[..self.spare.len()].copy_from_slice(&self.spare);
        let section = Settings::Spare(axes);
        let named = |e: ConfigError| match e {
            ConfigError::Value(field) => RigError::new(field.to_string(), format!("must be {}", field.must())),
            other => RigError::new("spare", format!("the controller cannot drive it: {other}")),
        };
        let mut config = ControllerConfig::from_record(record).map_err(named)?;
        config.apply(&section).and_then(|()| config.validate()).map_err(named)?;
        Ok(section)
    }

    /// This file with the sections of `record` written out (what `device rig show` prints).
    pub fn with_sections(mut self, record: &RigRecord) -> Self {
        let m = &record.machine;
        self.axes = m.axes.to_vec();
        self.motion = Some(settings::MotionSpec::of(&m.motion));
        self.inputs = Some(settings::InputsSpec::of(&m.inputs));
        self.supervisor = Some(m.supervisor);
        self.homing = Some(m.homing);
        self
    }
}
