//! Checking a rig file into what can be analysed ([`Platform`]) or driven ([`Rig`]): every key in turn, each error
//! naming it.

use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::geometry::{Branch, Chain, ChainKind, Elbow, ElbowBranch, RingGeometry, RingLimits, DEG};
use ringpod_core::kinematics::{Mechanism, Pose, RingPlatform};

use super::{drives, err, BranchSpec, ChainSpec, ElbowSpec, KindSpec, Platform, Rig, RigError, RigFile};

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
fn finite<const N: usize>(key: &str, v: &[f64; N]) -> Result<(), RigError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => err(key, format!("value {} is not a finite number", i + 1)),
        None => Ok(()),
    }
}

/// The largest translation range a `[spec]` may ask for (m).
const MAX_SPEC_TRAVEL: f64 = 1e3;

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
                // A kilometre of travel, a whole turn: past any platform, where the number is a broken one.
                let limit = |i: usize| {
                    if i < 3 {
                        MAX_SPEC_TRAVEL
                    } else {
                        crate::input::numbers::MAX_TILT
                    }
                };
                if let Some(i) = (0..5).find(|&i| !(si[i].is_finite() && (0.0..=limit(i)).contains(&si[i]))) {
                    let most = if i < 3 { "1000 m" } else { "360 deg" };
                    return err(
                        format!("spec.{}", names[i]),
                        format!("a range is a finite number from 0 to {most}"),
                    );
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
        // A finite number far beyond any pose (a yaw of 1e300) is out of range, not "NaN or infinite" as the
        // kinematics, overflowing on it, would say. After the geometry's own checks: its scale is the ring's.
        if let Err(e) = crate::input::numbers::pose_in_range("home", &self.home, self.ring_radius) {
            return err("home", e.reason);
        }
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
        let centre_of_rotation = match &self.motion_compensation {
            Some(m) => m
                .checked()
                .map_err(|why| super::RigError::new("motion_compensation.centre_of_rotation", why))?,
            None => [0.0; 3],
        };
        let spare = match self.spare_section(&record)? {
            ringpod_core::protocol::Settings::Spare(axes) => axes,
            _ => [ringpod_core::motion::SpareAxisSettings::NONE; ringpod_core::motion::SPARE_AXES],
        };
        Ok(Rig {
            geometry,
            home,
            ranges,
            drives,
            record,
            centre_of_rotation,
            spare,
        })
    }

    /// The geometry of the file, every key checked but the home pose.
    pub fn geometry(&self) -> Result<RingGeometry, RigError> {
        if self.name.is_empty() || self.name.chars().count() > 32 {
            return err("name", "between 1 and 32 characters");
        }
        // A name is printed in reports and stored on the device: a line break or a control character would break
        // the lines it is printed in.
        if self.name.chars().any(char::is_control) {
            return err("name", "no line breaks, tabs or other control characters");
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
        if elbows == 0 {
            if let Some(key) = [
                ("limits.shoulder_angle_deg", self.limits.shoulder_angle_deg.is_some()),
                ("limits.elbow_angle_deg", self.limits.elbow_angle_deg.is_some()),
            ]
            .iter()
            .find_map(|(k, given)| given.then_some(*k))
            {
                return err(key, "only elbow chains have it (this rig has none)");
            }
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
            (Some(_), 0) => return err("limits.stroke", "only radial chains have a stroke (this rig has none)"),
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
}
