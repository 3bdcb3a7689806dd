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

mod command;
mod coverage;
mod design;
pub mod device;
pub mod drives;
pub mod error;
mod settings;

pub use command::{check_command, design_command, export, preset};
pub use coverage::coverage;
pub use drives::{Drive, DriveSpec};
pub use error::RigError;
pub use settings::InputsSpec;

use std::path::Path;

use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::geometry::{Branch, Chain, ChainKind, Elbow, ElbowBranch, RingGeometry, RingLimits, DEG};
use ringpod_core::kinematics::{Mechanism, Pose, RingPlatform};
use ringpod_core::protocol::{AxisSettings, HomingSettings};
use serde::{Deserialize, Serialize};

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
    fn elbow_keys(&self) -> [(&'static str, bool); 5] {
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
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stroke: Option<[f64; 2]>,
    /// The travel of elbow chains' shoulders (deg, the angle from the horizontal toward the ring axis, up
    /// positive); required when there are elbow chains.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shoulder_angle_deg: Option<[f64; 2]>,
    /// Allowed interior angle at elbow chains' elbows (deg, 0 folded, 180 stretched); 10 to 170 by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elbow_angle_deg: Option<[f64; 2]>,
    /// Allowed central angle between neighbouring carriages (deg).
    pub carriage_spacing_deg: [f64; 2],
    /// Least angle of a chain to the base plane (deg).
    pub base_cone_deg: f64,
    /// Least angle of a chain to the platform plane (deg).
    pub platform_cone_deg: f64,
    /// Least singularity index of the wrench matrix.
    pub min_singularity_index: f64,
    /// Centre of mass of platform and payload in the platform frame (m).
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

fn err<T>(key: impl Into<String>, why: impl Into<String>) -> Result<T, RigError> {
    Err(RigError::new(key, why))
}

/// `limits.elbow_angle_deg` when a file does not give it: 10 degrees short of folded and of stretched, where the
/// arm's Jacobian is singular.
const DEFAULT_ELBOW_ANGLE_DEG: [f64; 2] = [10.0, 170.0];

/// The arm of elbow chain `i`, each key checked; the joint limits are `[limits]`'s (rad), the shoulders' travel
/// given (checked by the caller otherwise).
fn elbow_of(c: &ChainSpec, i: usize, shoulder: Option<[f64; 2]>, elbow_angle: [f64; 2]) -> Result<Elbow, RigError> {
    let key = |k: &str| format!("chains[{i}].{k}");
    let need =
        |k: &str, v: Option<f64>| v.ok_or_else(|| RigError::new(key(k), format!("an elbow chain takes `{k}` (m)")));
    let shoulder_radius = need("shoulder_radius", c.shoulder_radius)?;
    let shoulder_height = need("shoulder_height", c.shoulder_height)?;
    let upper_arm = need("upper_arm", c.upper_arm)?;
    let forearm = need("forearm", c.forearm)?;
    for (k, v) in [
        ("shoulder_radius", shoulder_radius),
        ("upper_arm", upper_arm),
        ("forearm", forearm),
    ] {
        positive(&key(k), v)?;
    }
    if !shoulder_height.is_finite() {
        return err(
            key("shoulder_height"),
            format!("{shoulder_height} is not a finite height (m)"),
        );
    }
    let branch = match c.elbow {
        Some(ElbowSpec::Up) => ElbowBranch::Up,
        Some(ElbowSpec::Down) => ElbowBranch::Down,
        None => return err(key("elbow"), "an elbow chain takes \"up\" or \"down\""),
    };
    Ok(Elbow {
        shoulder_radius,
        shoulder_height,
        upper_arm,
        forearm,
        branch,
        // Without a travel the count of actuators or the travel's own error comes first.
        shoulder_angle: shoulder.unwrap_or([0.0, 1.0]),
        elbow_angle,
    })
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
}

/// Reads and checks a rig file to drive it.
pub fn load(path: &Path) -> Result<Rig, RigError> {
    read(path)?.check().map_err(|e| e.in_file(path))
}

/// Reads a rig file to analyse it: only the mechanism must be valid.
pub fn load_platform(path: &Path) -> Result<Platform, RigError> {
    read(path)?.platform().map_err(|e| e.in_file(path))
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
        // toml names the key and the line; keep its words.
        err("", e.message().trim().to_owned() + &span_of(text, e.span()))
    })
}

fn span_of(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    span.map(|s| format!(" (line {})", text[..s.start.min(text.len())].matches('\n').count() + 1))
        .unwrap_or_default()
}

/// Radians to degrees as a person writes them: 120, not 119.99999999999999.
fn degrees(rad: f64) -> f64 {
    (rad / DEG * 1e9).round() / 1e9
}

fn finite<const N: usize>(key: &str, v: &[f64; N]) -> Result<(), RigError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => err(key, format!("value {} is not a finite number", i + 1)),
        None => Ok(()),
    }
}

fn positive(key: &str, v: f64) -> Result<(), RigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        err(key, format!("{v} is not a positive length (m)"))
    }
}

impl RigFile {
    /// The mechanism, spec ranges and drives: what analysis needs. Each error names its key.
    pub fn platform(&self) -> Result<Platform, RigError> {
        let geometry = self.geometry()?;
        let m = RingPlatform::<f64>::new(&geometry);
        let ranges = match &self.spec {
            Some(s) => {
                let si = s.si();
                let names = ["surge", "sway", "heave", "roll_deg", "pitch_deg"];
                if let Some(i) = si.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
                    return err(format!("spec.{}", names[i]), "a range is a finite number >= 0");
                }
                Some(si)
            }
            None => None,
        };
        let drives = drives::check(&self.drives, &m.axes())?;
        Ok(Platform {
            geometry,
            home: Pose::from_array(self.home),
            ranges,
            drives,
        })
    }

    /// Every rule the presets obey, and the controller's (the home pose inside every check, the homing plan, the
    /// step timing): each error names its key.
    pub fn check(&self) -> Result<Rig, RigError> {
        let Platform {
            geometry,
            home,
            ranges,
            drives,
        } = self.platform()?;
        let m = RingPlatform::<f64>::new(&geometry);
        match m.inverse_checked(&home) {
            Err(e) => return err("home", format!("has no solution: {e}")),
            Ok((_, report)) => {
                if let Some(check) = report.first_failure() {
                    let margin = report.margin(check).unwrap_or(0.0);
                    return err(
                        "home",
                        format!(
                            "fails the {check} check by {:.6} {} (home must be inside every check)",
                            -margin,
                            check.unit()
                        ),
                    );
                }
            }
        }
        let record = self.record(ControllerConfig::default_record(&self.name, &geometry, self.home))?;
        Ok(Rig {
            geometry,
            home,
            ranges,
            drives,
            record,
        })
    }

    /// The geometry of the file, every key checked but the home pose.
    pub fn geometry(&self) -> Result<RingGeometry, RigError> {
        if self.name.is_empty() || self.name.chars().count() > 32 {
            return err("name", "between 1 and 32 characters");
        }
        // The core's geometry carries a static name; a rig is loaded once per command.
        self.geometry_named(Box::leak(self.name.clone().into_boxed_str()))
    }

    /// [`RigFile::geometry`] under another name (a design search scores thousands of candidates whose home is not
    /// yet inside).
    pub fn geometry_named(&self, name: &'static str) -> Result<RingGeometry, RigError> {
        positive("ring_radius", self.ring_radius)?;
        positive("rod_length", self.rod_length)?;
        finite("home", &self.home)?;
        let n = self.chains.len();
        if !(3..=6).contains(&n) {
            return err("chains", format!("{n} chains; a ring platform has 3 to 6"));
        }
        let (shoulder, elbow_angle) = self.arm_limits()?;
        let mut chains = Vec::with_capacity(n);
        for (i, c) in self.chains.iter().enumerate() {
            let key = |k: &str| format!("chains[{i}].{k}");
            finite(&key("platform_point"), &c.platform_point)?;
            if c.kind != KindSpec::Elbow {
                if let Some((k, _)) = c.elbow_keys().into_iter().find(|(_, given)| *given) {
                    return err(key(k), "only elbow chains have it");
                }
            }
            let kind = match (c.kind, c.branch) {
                (KindSpec::Rod, Some(BranchSpec::Plus)) => ChainKind::Rod(Branch::Plus),
                (KindSpec::Rod, Some(BranchSpec::Minus)) => ChainKind::Rod(Branch::Minus),
                (KindSpec::Rod, None) => return err(key("branch"), "a rod chain takes \"plus\" or \"minus\""),
                (KindSpec::Radial | KindSpec::Elbow, Some(_)) => {
                    return err(
                        key("branch"),
                        "only rod chains have a branch (an elbow chain has `elbow`)",
                    )
                }
                (KindSpec::Radial, None) => ChainKind::Radial,
                (KindSpec::Elbow, None) => ChainKind::Elbow(elbow_of(c, i, shoulder, elbow_angle)?),
            };
            for (j, other) in self.chains[..i].iter().enumerate() {
                let d: f64 = (0..3)
                    .map(|k| (other.platform_point[k] - c.platform_point[k]).powi(2))
                    .sum();
                if d.sqrt() < 1e-9 {
                    return err(key("platform_point"), format!("the same point as chains[{j}]"));
                }
            }
            chains.push(Chain {
                kind,
                platform_point: c.platform_point,
            });
        }
        let radial = chains.iter().filter(|c| c.kind == ChainKind::Radial).count();
        let elbows = chains.iter().filter(|c| matches!(c.kind, ChainKind::Elbow(_))).count();
        if n + radial + elbows != 6 {
            return err(
                "chains",
                format!(
                    "{n} carriages, {radial} radial lengths and {elbows} shoulders make {} actuators; a ring \
                     platform drives six",
                    n + radial + elbows
                ),
            );
        }
        if elbows > 0 && shoulder.is_none() {
            return err(
                "limits.shoulder_angle_deg",
                "required with elbow chains: [min, max] of the shoulders' travel (deg)",
            );
        }
        let limits = self.limits(radial)?;
        // The core's own validation is the last word (it is what the firmware builds from).
        RingGeometry::new(name, self.ring_radius, self.rod_length, &chains, limits).or_else(|e| err("", e.to_string()))
    }

    /// The elbow chains' joint limits (rad): the shoulders' travel if given, and the elbow angle's range.
    fn arm_limits(&self) -> Result<(Option<[f64; 2]>, [f64; 2]), RigError> {
        let l = &self.limits;
        let shoulder = match l.shoulder_angle_deg {
            Some(s) => {
                finite("limits.shoulder_angle_deg", &s)?;
                if !(s[0] < s[1] && s[1] - s[0] <= 360.0) {
                    return err(
                        "limits.shoulder_angle_deg",
                        "[min, max] with min < max <= min + 360 (deg)",
                    );
                }
                Some(s.map(|v| v * DEG))
            }
            None => None,
        };
        let [lo, hi] = l.elbow_angle_deg.unwrap_or(DEFAULT_ELBOW_ANGLE_DEG);
        if !(lo >= 0.0 && lo < hi && hi <= 180.0) {
            return err("limits.elbow_angle_deg", "[min, max] with 0 <= min < max <= 180 (deg)");
        }
        Ok((shoulder, [lo * DEG, hi * DEG]))
    }

    fn limits(&self, radial: usize) -> Result<RingLimits, RigError> {
        let l = &self.limits;
        let stroke = match (l.stroke, radial) {
            (Some(s), _) => {
                finite("limits.stroke", &s)?;
                if !(s[0] >= 0.0 && s[0] < s[1]) {
                    return err("limits.stroke", "[min, max] with 0 <= min < max (m)");
                }
                s
            }
            (None, 0) => [0.0, 1.0],
            (None, _) => return err("limits.stroke", "required with radial chains: [min, max] length (m)"),
        };
        let [lo, hi] = l.carriage_spacing_deg;
        if !(lo >= 0.0 && lo < hi && hi <= 360.0) {
            return err(
                "limits.carriage_spacing_deg",
                "[min, max] with 0 <= min < max <= 360 (deg)",
            );
        }
        for (key, v) in [
            ("limits.base_cone_deg", l.base_cone_deg),
            ("limits.platform_cone_deg", l.platform_cone_deg),
        ] {
            if !(0.0..90.0).contains(&v) {
                return err(key, format!("{v} is not in [0, 90) deg"));
            }
        }
        if !(0.0..1.0).contains(&l.min_singularity_index) {
            return err("limits.min_singularity_index", "in [0, 1)");
        }
        finite("limits.centre_of_mass", &l.centre_of_mass)?;
        Ok(RingLimits {
            stroke,
            carriage_spacing: [lo * DEG, hi * DEG],
            base_cone: l.base_cone_deg * DEG,
            platform_cone: l.platform_cone_deg * DEG,
            min_singularity_index: l.min_singularity_index,
            centre_of_mass: l.centre_of_mass,
        })
    }

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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use ringpod_core::kinematics::presets::{self, Preset};
    use ringpod_core::kinematics::{NewtonOptions, FROM_HOME_DISTANCE};

    /// Uniform numbers in [-1, 1) from a fixed seed (an LCG: the same on every run).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    fn trainer_file() -> RigFile {
        RigFile::of(
            &presets::TRAINER_MODEL,
            Preset::TrainerModel.home(),
            Some(presets::TRAINER_MODEL_RANGES),
            drives::of_preset(Preset::TrainerModel),
        )
    }

    #[test]
    fn a_rig_file_round_trips_exactly() {
        let file = trainer_file();
        let text = file.to_toml().unwrap();
        let back: RigFile = toml::from_str(&text).unwrap();
        assert_eq!(back, file);
        assert_eq!(back.to_toml().unwrap(), text);
    }

    #[test]
    fn a_rig_restating_the_preset_drives_bit_identical_ik() {
        let rig = parse(&trainer_file().to_toml().unwrap())
            .and_then(|f| f.check())
            .unwrap();
        let (ours, preset) = (
            RingPlatform::<f64>::new(&rig.geometry),
            RingPlatform::<f64>::new(&presets::TRAINER_MODEL),
        );
        let (ours32, preset32) = (
            RingPlatform::<f32>::new(&rig.geometry),
            RingPlatform::<f32>::new(&presets::TRAINER_MODEL),
        );
        let mut uniform = uniform(5);
        for _ in 0..2_000 {
            let p = Pose::new(
                uniform() * 0.06,
                uniform() * 0.06,
                0.227 + uniform() * 0.05,
                uniform() * 0.4,
                uniform() * 0.4,
                uniform() * 4.0,
            );
            assert_eq!(ours.inverse(&p), preset.inverse(&p));
            assert_eq!(ours32.inverse(&p.cast()), preset32.inverse(&p.cast()));
        }
        assert_eq!(rig.home, Pose::from_array(Preset::TrainerModel.home()));
        assert_eq!(rig.ranges, Some(presets::TRAINER_MODEL_RANGES));
    }

    /// Each class of mistake, and the key its error names.
    #[test]
    fn every_invalid_class_names_its_key() {
        type Mistake = Box<dyn Fn(&mut RigFile)>;
        let cases: Vec<(&str, Mistake)> = vec![
            ("name", Box::new(|f| f.name.clear())),
            ("ring_radius", Box::new(|f| f.ring_radius = -0.2)),
            ("ring_radius", Box::new(|f| f.ring_radius = f64::NAN)),
            ("rod_length", Box::new(|f| f.rod_length = 0.0)),
            ("home", Box::new(|f| f.home[5] = f64::INFINITY)),
            ("home", Box::new(|f| f.home[2] = 0.9)),
            ("home", Box::new(|f| f.home[1] = 0.1)),
            ("chains", Box::new(|f| f.chains.truncate(2))),
            (
                "chains",
                Box::new(|f| {
                    f.chains[0].kind = KindSpec::Radial;
                    f.chains[0].branch = None;
                }),
            ),
            ("chains[0].branch", Box::new(|f| f.chains[0].kind = KindSpec::Radial)),
            ("chains[0].branch", Box::new(|f| f.chains[0].branch = None)),
            (
                "chains[2].branch",
                Box::new(|f| f.chains[2].branch = Some(BranchSpec::Plus)),
            ),
            (
                "chains[1].platform_point",
                Box::new(|f| f.chains[1].platform_point = f.chains[0].platform_point),
            ),
            (
                "chains[3].platform_point",
                Box::new(|f| f.chains[3].platform_point[0] = f64::NAN),
            ),
            ("limits.stroke", Box::new(|f| f.limits.stroke = None)),
            ("limits.stroke", Box::new(|f| f.limits.stroke = Some([0.3, 0.2]))),
            (
                "limits.carriage_spacing_deg",
                Box::new(|f| f.limits.carriage_spacing_deg = [120.0, 12.0]),
            ),
            ("limits.base_cone_deg", Box::new(|f| f.limits.base_cone_deg = 95.0)),
            (
                "limits.platform_cone_deg",
                Box::new(|f| f.limits.platform_cone_deg = -1.0),
            ),
            (
                "limits.min_singularity_index",
                Box::new(|f| f.limits.min_singularity_index = 1.5),
            ),
            (
                "limits.centre_of_mass",
                Box::new(|f| f.limits.centre_of_mass[2] = f64::NAN),
            ),
            ("spec.heave", Box::new(|f| f.spec.as_mut().unwrap().heave = -0.01)),
        ];
        for (key, break_it) in cases {
            let mut f = trainer_file();
            break_it(&mut f);
            let e = f.check().expect_err(key);
            assert_eq!(e.key, key, "{e}");
            assert!(!e.why.is_empty());
        }
        // Syntax and unknown keys: toml's message with the line.
        let e = parse("name = \"x\"\nring_radius = 0.3\nrod_lenght = 0.2\n").unwrap_err();
        assert!(e.why.contains("rod_lenght") && e.why.contains("line 3"), "{e}");
    }

    /// A rig file with elbow chains as a builder writes it (the README's example): the trainer model's rods and
    /// two arms of ch. 5.1 fig. 5.2.
    const ELBOW_RIG: &str = r#"
name = "my-elbow-rig"
ring_radius = 0.286
rod_length = 0.312
home = [0, 0, 0.227, 0, 0, 0]

[[chains]]
kind = "rod"
branch = "plus"
platform_point = [-0.194, -0.031, 0]

[[chains]]
kind = "rod"
branch = "minus"
platform_point = [0.194, -0.031, 0]

[[chains]]
kind = "elbow"
shoulder_radius = 0.258
shoulder_height = 0.017
upper_arm = 0.105
forearm = 0.189
elbow = "up"
platform_point = [0.181, 0.160, 0]

[[chains]]
kind = "elbow"
shoulder_radius = 0.258
shoulder_height = 0.017
upper_arm = 0.105
forearm = 0.189
elbow = "up"
platform_point = [-0.181, 0.160, 0]

[limits]
shoulder_angle_deg = [100, 190]
elbow_angle_deg = [25, 155]
min_singularity_index = 0.02
centre_of_mass = [0, 0, 0.02]
"#;

    #[test]
    fn a_rig_file_with_elbow_chains_drives_the_preset_s_ik() {
        let rig = parse(ELBOW_RIG).and_then(|f| f.check()).unwrap();
        let m = RingPlatform::<f64>::new(&rig.geometry);
        let preset = RingPlatform::<f64>::new(&presets::TRAINER_ELBOW);
        assert_eq!(m.axes(), preset.axes());
        let mut uniform = uniform(9);
        for _ in 0..1_000 {
            let p = Pose::new(
                uniform() * 0.05,
                uniform() * 0.05,
                0.227 + uniform() * 0.04,
                uniform() * 0.3,
                uniform() * 0.3,
                uniform() * 4.0,
            );
            assert_eq!(m.inverse(&p), preset.inverse(&p));
        }
        // The preset's own file round-trips and restates the preset exactly.
        let file = RigFile::of(
            &presets::TRAINER_ELBOW,
            Preset::TrainerElbow.home(),
            Preset::TrainerElbow.spec_ranges(),
            drives::of_preset(Preset::TrainerElbow),
        );
        let text = file.to_toml().unwrap();
        let back = parse(&text).unwrap();
        assert_eq!(back, file);
        let rig = back.check().unwrap();
        let mut renamed = rig.geometry;
        renamed.name = presets::TRAINER_ELBOW.name;
        assert_eq!(renamed, presets::TRAINER_ELBOW);
        assert_eq!(rig.record.geometry().unwrap(), presets::TRAINER_ELBOW);
    }

    /// Each mistake in an elbow chain or its limits, and the key its error names.
    #[test]
    fn every_invalid_elbow_key_is_named() {
        type Mistake = Box<dyn Fn(&mut RigFile)>;
        let cases: Vec<(&str, Mistake)> = vec![
            (
                "chains[2].shoulder_radius",
                Box::new(|f| f.chains[2].shoulder_radius = None),
            ),
            (
                "chains[2].shoulder_radius",
                Box::new(|f| f.chains[2].shoulder_radius = Some(0.0)),
            ),
            (
                "chains[3].shoulder_height",
                Box::new(|f| f.chains[3].shoulder_height = None),
            ),
            (
                "chains[3].shoulder_height",
                Box::new(|f| f.chains[3].shoulder_height = Some(f64::INFINITY)),
            ),
            ("chains[2].upper_arm", Box::new(|f| f.chains[2].upper_arm = Some(-0.1))),
            ("chains[2].upper_arm", Box::new(|f| f.chains[2].upper_arm = None)),
            ("chains[3].forearm", Box::new(|f| f.chains[3].forearm = Some(f64::NAN))),
            ("chains[2].elbow", Box::new(|f| f.chains[2].elbow = None)),
            (
                "chains[2].branch",
                Box::new(|f| f.chains[2].branch = Some(BranchSpec::Plus)),
            ),
            ("chains[0].upper_arm", Box::new(|f| f.chains[0].upper_arm = Some(0.1))),
            (
                "chains[1].elbow",
                Box::new(|f| f.chains[1].elbow = Some(ElbowSpec::Down)),
            ),
            (
                "chains[2].shoulder_radius",
                Box::new(|f| {
                    f.chains[2].kind = KindSpec::Radial;
                    f.limits.stroke = Some([0.1, 0.3]);
                }),
            ),
            (
                "limits.shoulder_angle_deg",
                Box::new(|f| f.limits.shoulder_angle_deg = None),
            ),
            (
                "limits.shoulder_angle_deg",
                Box::new(|f| f.limits.shoulder_angle_deg = Some([190.0, 100.0])),
            ),
            (
                "limits.shoulder_angle_deg",
                Box::new(|f| f.limits.shoulder_angle_deg = Some([0.0, f64::NAN])),
            ),
            (
                "limits.elbow_angle_deg",
                Box::new(|f| f.limits.elbow_angle_deg = Some([0.0, 200.0])),
            ),
            (
                "limits.elbow_angle_deg",
                Box::new(|f| f.limits.elbow_angle_deg = Some([90.0, 90.0])),
            ),
            // Arms too short for the home pose, or the home pose outside the shoulders' travel.
            (
                "home",
                Box::new(|f| {
                    f.chains[2].upper_arm = Some(0.05);
                    f.chains[2].forearm = Some(0.05);
                }),
            ),
            ("home", Box::new(|f| f.limits.shoulder_angle_deg = Some([160.0, 190.0]))),
            (
                "chains",
                Box::new(|f| {
                    let mut extra = f.chains[2].clone();
                    extra.platform_point = [0.0, -0.2, 0.0];
                    f.chains.push(extra);
                }),
            ),
        ];
        for (key, break_it) in cases {
            let mut f = parse(ELBOW_RIG).unwrap();
            break_it(&mut f);
            let e = f.check().expect_err(key);
            assert_eq!(e.key, key, "{e}");
            assert!(!e.why.is_empty());
        }
        // A value or a key toml cannot take: its message names it and the line.
        let line_of = |what: &str| ELBOW_RIG[..ELBOW_RIG.find(what).unwrap()].matches('\n').count() + 1;
        let e = parse(&ELBOW_RIG.replacen("elbow = \"up\"", "elbow = \"sideways\"", 1)).unwrap_err();
        let line = format!("line {}", line_of("elbow = \"up\""));
        assert!(e.why.contains("sideways") && e.why.contains(&line), "{e}");
        let e = parse(&ELBOW_RIG.replacen("forearm = 0.189", "fore_arm = 0.189", 1)).unwrap_err();
        let line = format!("line {}", line_of("forearm = 0.189"));
        assert!(e.why.contains("fore_arm") && e.why.contains(&line), "{e}");
    }

    fn perturbed(factors: [f64; 10]) -> RigFile {
        let mut f = trainer_file();
        f.ring_radius *= factors[0];
        f.rod_length *= factors[1];
        for (i, c) in f.chains.iter_mut().enumerate() {
            c.platform_point[0] *= factors[2 + 2 * i];
            c.platform_point[1] *= factors[3 + 2 * i];
        }
        f
    }

    /// The random rigs below are not vacuous: most of them are valid and inside the checks at the tested poses.
    #[test]
    fn most_perturbed_rigs_are_valid() {
        let mut uniform = uniform(17);
        let valid = (0..200)
            .filter(|_| {
                perturbed(core::array::from_fn(|_| 1.0 + 0.05 * uniform()))
                    .check()
                    .is_ok()
            })
            .count();
        assert!(valid > 100, "{valid} of 200 valid");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        /// Rigs no preset describes (the model's dimensions each changed by up to 5 %): every one that is valid
        /// passes IK -> FK round trips from no guess at poses inside its checks.
        #[test]
        fn random_valid_rigs_round_trip(factors in prop::array::uniform10(0.95..1.05f64), offsets in prop::array::uniform6(-1.0..1.0f64)) {
            let Ok(rig) = perturbed(factors).check() else { return Ok(()) };
            let m = RingPlatform::<f64>::new(&rig.geometry);
            let h = rig.home.to_array();
            let p = Pose::new(h[0] + offsets[0] * 0.03, h[1] + offsets[1] * 0.03, h[2] + offsets[2] * 0.02,
                offsets[3] * 0.15, offsets[4] * 0.15, offsets[5] * 3.0);
            let Ok((q, report)) = m.inverse_checked(&p) else { return Ok(()) };
            if !report.all_pass() {
                return Ok(());
            }
            let options = NewtonOptions { max_distance: FROM_HOME_DISTANCE, ..NewtonOptions::default() };
            let start = ringpod_core::kinematics::start_from_home(&m, &q, &rig.home);
            match m.forward(&q, &start, &options) {
                Ok(fk) => {
                    let (a, b) = (fk.pose.to_array(), p.to_array());
                    prop_assert!((0..5).all(|i| (a[i] - b[i]).abs() < 1e-9), "{:?} vs {:?}", fk.pose, p);
                }
                // Refusing near a type-2 singularity is right; anything else is not.
                Err(e) => prop_assert_eq!(e, ringpod_core::kinematics::KinematicsError::NearSingularity),
            }
        }
    }
}
