//! The Rig panel's form over a rig file: every value the form shows, with its group and label as shown, the unit
//! it is shown in (lengths in mm, angles in deg, whatever the file's own unit) and the range the rig module's
//! checks and the core's allow; and the form's values read back into a rig file, each refusal naming the field as
//! shown with its unit and range. The file keeps its own units: the page converts by each field's `scale`.

use serde::Serialize;
use serde_json::Value;

use crate::rig::{KindSpec, RigError, RigFile};

/// Radians to degrees.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// One value of the form.
#[derive(Debug, Clone, Serialize)]
pub struct Field {
    /// Where the value is in the rig file's JSON: `chains[2].shoulder_radius`, `home[3]`.
    pub path: String,
    /// The group it is shown in: `Geometry`, `Chain 3`, `Axis 5`.
    pub group: String,
    /// Its name in the group: `ring radius`, `platform joint`.
    pub label: &'static str,
    /// The element of a list (`x`, `min`), if it is one.
    pub part: Option<&'static str>,
    /// The unit shown (`mm`, `deg`, `mm/s`, `ms`; empty for none).
    pub unit: &'static str,
    /// Shown value = file value x scale.
    pub scale: f64,
    /// `number`, `integer`, `text`, `choice` or `bool`.
    pub kind: &'static str,
    /// The words a `choice` takes.
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub choices: &'static [&'static str],
    /// The range allowed, in the shown unit (`None`: any finite number).
    pub range: Option<Range>,
}

/// A range in the shown unit: `min` and `max` included unless said.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Range {
    pub min: f64,
    pub max: Option<f64>,
    /// The minimum itself is out (a length is more than 0).
    pub above: bool,
    /// The maximum itself is out (a cone angle is below 90 deg).
    pub below: bool,
}

const POSITIVE: Range = Range {
    min: 0.0,
    max: None,
    above: true,
    below: false,
};
const NOT_NEGATIVE: Range = Range {
    min: 0.0,
    max: None,
    above: false,
    below: false,
};
const fn within(min: f64, max: f64) -> Range {
    Range {
        min,
        max: Some(max),
        above: false,
        below: false,
    }
}

impl Range {
    fn holds(&self, v: f64) -> bool {
        let low = if self.above { v > self.min } else { v >= self.min };
        let high = match self.max {
            Some(m) if self.below => v < m,
            Some(m) => v <= m,
            None => true,
        };
        v.is_finite() && low && high
    }

    /// The range in words: `more than 0 mm`, `0 to 90 deg (90 itself excluded)`.
    pub fn text(&self, unit: &str) -> String {
        let u = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        match self.max {
            None if self.above => format!("more than {}{u}", self.min),
            None => format!("{}{u} or more", self.min),
            Some(m) if self.below => format!("{} to {m}{u}, {m} itself excluded", self.min),
            Some(m) => format!("{} to {m}{u}", self.min),
        }
    }
}

impl Field {
    /// The field as the form names it: `Chain 3 · shoulder radius (mm)`.
    pub fn shown(&self) -> String {
        let part = self.part.map(|p| format!(" {p}")).unwrap_or_default();
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" ({})", self.unit)
        };
        format!("{} · {}{part}{unit}", self.group, self.label)
    }
}

/// An axis's unit: carriages and shoulders turn (rad in the file, deg shown), radial lengths slide (m, mm shown).
#[derive(Clone, Copy)]
enum Motion {
    Turns,
    Slides,
}

impl Motion {
    fn unit(self, per_s: u8) -> (&'static str, f64) {
        match (self, per_s) {
            (Motion::Turns, 0) => ("deg", DEG),
            (Motion::Turns, 1) => ("deg/s", DEG),
            (Motion::Turns, _) => ("deg/s²", DEG),
            (Motion::Slides, 0) => ("mm", 1e3),
            (Motion::Slides, 1) => ("mm/s", 1e3),
            (Motion::Slides, _) => ("mm/s²", 1e3),
        }
    }
}

/// The actuators in the controller's order: every carriage in chain order, then every radial length, then every
/// elbow chain's shoulder (`presets --export`'s header).
fn actuators(file: &RigFile) -> Vec<Motion> {
    let count = |k: KindSpec| file.chains.iter().filter(|c| c.kind == k).count();
    let mut all = vec![Motion::Turns; file.chains.len()];
    all.extend(std::iter::repeat_n(Motion::Slides, count(KindSpec::Radial)));
    all.extend(std::iter::repeat_n(Motion::Turns, count(KindSpec::Elbow)));
    all
}

const XYZ: [&str; 3] = ["x", "y", "z"];
const POSE: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];
const MIN_MAX: [&str; 2] = ["min", "max"];

/// A number's field.
fn number(group: String, label: &'static str, part: Option<&'static str>, (unit, scale): (&'static str, f64)) -> Field {
    Field {
        path: String::new(),
        group,
        label,
        part,
        unit,
        scale,
        kind: "number",
        choices: &[],
        range: None,
    }
}

fn ranged(mut f: Field, range: Range) -> Field {
    f.range = Some(range);
    f
}

fn choice(group: String, label: &'static str, choices: &'static [&'static str]) -> Field {
    Field {
        kind: "choice",
        choices,
        ..number(group, label, None, ("", 1.0))
    }
}

fn of_kind(kind: &'static str, f: Field) -> Field {
    Field { kind, ..f }
}

/// The field of the value at `generic` (the path with its indices taken out: `chains[].platform_point[]`) and
/// `at` (those indices); none for a value the form does not show (kept as the file has it).
fn describe(generic: &str, at: &[usize], motions: &[Motion]) -> Option<Field> {
    const MM: (&str, f64) = ("mm", 1e3);
    const DEG_: (&str, f64) = ("deg", 1.0);
    let i = at.first().copied().unwrap_or(0);
    let j = at.get(1).copied().unwrap_or(0);
    let g = |s: &str| s.to_owned();
    let chain = || format!("Chain {}", i + 1);
    Some(match generic {
        "name" => ranged(
            of_kind("text", number(g("Rig"), "name", None, ("", 1.0))),
            within(1.0, 32.0),
        ),
        "ring_radius" => ranged(number(g("Geometry"), "ring radius", None, MM), POSITIVE),
        "rod_length" => ranged(number(g("Geometry"), "rod length", None, MM), POSITIVE),
        "home[]" => number(
            g("Home pose"),
            if i < 3 { "position" } else { "angle" },
            Some(POSE[i % 6]),
            pose(i, 0),
        ),
        "chains[].kind" => choice(chain(), "kind", &["rod", "radial", "elbow"]),
        "chains[].branch" => choice(chain(), "branch", &["plus", "minus"]),
        "chains[].elbow" => choice(chain(), "elbow", &["up", "down"]),
        "chains[].shoulder_radius" => ranged(number(chain(), "shoulder radius", None, MM), POSITIVE),
        "chains[].shoulder_height" => number(chain(), "shoulder height", None, MM),
        "chains[].upper_arm" => ranged(number(chain(), "upper arm", None, MM), POSITIVE),
        "chains[].forearm" => ranged(number(chain(), "forearm", None, MM), POSITIVE),
        "chains[].platform_point[]" => number(chain(), "platform joint", Some(XYZ[j % 3]), MM),
        "limits.stroke[]" => ranged(number(g("Limits"), "stroke", Some(MIN_MAX[i % 2]), MM), NOT_NEGATIVE),
        "limits.shoulder_angle_deg[]" => number(g("Limits"), "shoulder travel", Some(MIN_MAX[i % 2]), DEG_),
        "limits.elbow_angle_deg[]" => ranged(
            number(g("Limits"), "elbow angle", Some(MIN_MAX[i % 2]), DEG_),
            within(0.0, 180.0),
        ),
        "limits.carriage_spacing_deg[]" => ranged(
            number(g("Limits"), "carriage spacing", Some(MIN_MAX[i % 2]), DEG_),
            within(0.0, 360.0),
        ),
        "limits.base_cone_deg" => ranged(
            number(g("Limits"), "least angle of a link to the base", None, DEG_),
            Range {
                below: true,
                ..within(0.0, 90.0)
            },
        ),
        "limits.platform_cone_deg" => ranged(
            number(g("Limits"), "least angle of a link to the platform", None, DEG_),
            Range {
                below: true,
                ..within(0.0, 90.0)
            },
        ),
        "limits.min_singularity_index" => ranged(
            number(g("Limits"), "least singularity index", None, ("", 1.0)),
            Range {
                below: true,
                ..within(0.0, 1.0)
            },
        ),
        "limits.centre_of_mass[]" => number(g("Limits"), "centre of mass", Some(XYZ[i % 3]), MM),
        "spec.surge" | "spec.sway" | "spec.heave" => ranged(
            number(g("Spec ranges (±)"), spec_label(generic), None, MM),
            within(0.0, 1e6),
        ),
        "spec.roll_deg" | "spec.pitch_deg" => ranged(
            number(g("Spec ranges (±)"), spec_label(generic), None, DEG_),
            within(0.0, 360.0),
        ),
        _ => return machine(generic, i, motions),
    })
}

/// The unit of pose axis `k` (x, y, z slide; roll, pitch, yaw turn).
fn pose(k: usize, per_s: u8) -> (&'static str, f64) {
    if k < 3 {
        Motion::Slides.unit(per_s)
    } else {
        Motion::Turns.unit(per_s)
    }
}

/// [`describe`] of the controller's sections: each axis's steps, speeds and homing in its own unit, the pose
/// limits, the inputs and the supervisor.
fn machine(generic: &str, i: usize, motions: &[Motion]) -> Option<Field> {
    let g = |s: &str| s.to_owned();
    let axis = || format!("Axis {}", i + 1);
    let motion = |k: usize| motions.get(k).copied().unwrap_or(Motion::Turns);
    let ms = |label| {
        ranged(
            of_kind("integer", number(g("Supervisor"), label, None, ("ms", 1.0))),
            within(0.0, 60000.0),
        )
    };
    Some(match generic {
        "axes[].steps_per_unit" => {
            let (unit, scale) = match motion(i) {
                Motion::Turns => ("steps/deg", 1.0 / DEG),
                Motion::Slides => ("steps/mm", 1e-3),
            };
            ranged(number(axis(), "steps", None, (unit, scale)), POSITIVE)
        }
        "axes[].reverse" => of_kind("bool", number(axis(), "reversed", None, ("", 1.0))),
        "motion.pose_velocity[]" => ranged(
            number(g("Motion"), "pose speed", Some(POSE[i % 6]), pose(i, 1)),
            POSITIVE,
        ),
        "motion.pose_acceleration[]" => ranged(
            number(g("Motion"), "pose acceleration", Some(POSE[i % 6]), pose(i, 2)),
            POSITIVE,
        ),
        "motion.actuator_velocity[]" => ranged(number(axis(), "speed", None, motion(i).unit(1)), POSITIVE),
        "motion.actuator_acceleration[]" => ranged(number(axis(), "acceleration", None, motion(i).unit(2)), POSITIVE),
        "inputs.debounce_ms" => ranged(
            of_kind("integer", number(g("Inputs"), "debounce", None, ("ms", 1.0))),
            within(1.0, 50.0),
        ),
        "supervisor.logic_sense" => of_kind("bool", number(g("Supervisor"), "logic supply sensed", None, ("", 1.0))),
        "supervisor.power_sense" => of_kind("bool", number(g("Supervisor"), "motor supply sensed", None, ("", 1.0))),
        "supervisor.logic_settle_ms" => ms("logic supply settles"),
        "supervisor.power_settle_ms" => ms("motor supply settles"),
        "supervisor.supply_timeout_ms" => ms("supply timeout"),
        "supervisor.driver_off_ms" => ms("drivers off after"),
        "supervisor.discharge_ms" => ms("discharge"),
        "homing.axes[].toward" => choice(axis(), "homes toward", &["plus", "minus"]),
        "homing.axes[].switch" => number(axis(), "home switch at", None, motion(i).unit(0)),
        "homing.axes[].search" => ranged(number(axis(), "search travel", None, motion(i).unit(0)), POSITIVE),
        "homing.axes[].backoff" => ranged(number(axis(), "back-off", None, motion(i).unit(0)), POSITIVE),
        "homing.axes[].fast" => ranged(number(axis(), "search speed", None, motion(i).unit(1)), POSITIVE),
        "homing.axes[].slow" => ranged(number(axis(), "approach speed", None, motion(i).unit(1)), POSITIVE),
        _ => return None,
    })
}

fn spec_label(generic: &str) -> &'static str {
    match generic {
        "spec.surge" => "surge",
        "spec.sway" => "sway",
        "spec.heave" => "heave",
        "spec.roll_deg" => "roll",
        _ => "pitch",
    }
}

/// Every value of `file` the form shows, in the file's order (with `describe`'s indices spelled out).
pub fn fields(file: &RigFile) -> Vec<Field> {
    let motions = actuators(file);
    // toml's table keeps the order of the file's keys (serde_json's map sorts them).
    let value = toml::Value::try_from(file).unwrap_or(toml::Value::Boolean(false));
    let mut all = Vec::new();
    walk(
        &value,
        &mut String::new(),
        &mut String::new(),
        &mut Vec::new(),
        &motions,
        &mut all,
    );
    all
}

fn walk(
    v: &toml::Value,
    path: &mut String,
    generic: &mut String,
    at: &mut Vec<usize>,
    m: &[Motion],
    all: &mut Vec<Field>,
) {
    match v {
        toml::Value::Table(o) => {
            for (k, inner) in o {
                let (p, g) = (path.len(), generic.len());
                let dot = if path.is_empty() { "" } else { "." };
                path.push_str(&format!("{dot}{k}"));
                generic.push_str(&format!("{dot}{k}"));
                walk(inner, path, generic, at, m, all);
                path.truncate(p);
                generic.truncate(g);
            }
        }
        toml::Value::Array(a) => {
            for (i, inner) in a.iter().enumerate() {
                let (p, g) = (path.len(), generic.len());
                path.push_str(&format!("[{i}]"));
                generic.push_str("[]");
                at.push(i);
                walk(inner, path, generic, at, m, all);
                at.pop();
                path.truncate(p);
                generic.truncate(g);
            }
        }
        _ => {
            if let Some(mut f) = describe(generic, at, m) {
                f.path = path.clone();
                all.push(f);
            }
        }
    }
}

/// The form's values as a rig file: each of a type the file does not take, each key the file does not have, each
/// number outside its range, refused by its key with the value and range in the unit shown ([`shown`] names the
/// field). What the rig module's checks say beyond that (the home pose outside a check, a chain too few) is theirs.
#[cfg(test)]
pub fn read(value: &Value) -> Result<RigFile, RigError> {
    let file = typed(value)?;
    in_range(&fields(&file), value)?;
    Ok(file)
}

/// The form's values as a rig file, each of a type the file does not take and each key it does not have refused
/// by its key.
pub fn typed(value: &Value) -> Result<RigFile, RigError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let key = e.path().to_string();
        RigError::new(if key == "." { String::new() } else { key }, e.into_inner().to_string())
    })
}

/// Every shown value of `value` inside its field's range.
pub fn in_range(fields: &[Field], value: &Value) -> Result<(), RigError> {
    let at = |path: &str| {
        path.split(['.', '[', ']'])
            .filter(|s| !s.is_empty())
            .try_fold(value, |v, k| match k.parse::<usize>() {
                Ok(i) => v.get(i),
                Err(_) => v.get(k),
            })
    };
    for f in fields {
        let (Some(range), Some(v)) = (f.range, at(&f.path)) else {
            continue;
        };
        let (shown, words) = match v {
            Value::String(s) => (s.chars().count() as f64, "characters"),
            _ => (v.as_f64().unwrap_or(f64::NAN) * f.scale, ""),
        };
        if !range.holds(shown) {
            let unit = if words.is_empty() { f.unit } else { words };
            let said = if words.is_empty() {
                format!("{} {unit}", tidy(shown))
            } else {
                format!("{shown} {unit}")
            };
            return Err(RigError::new(
                f.path.clone(),
                format!("{} is out of range: {}", said.trim_end(), range.text(unit)),
            ));
        }
    }
    Ok(())
}

/// A shown number without the noise of its conversion (120, not 119.99999999999999).
fn tidy(v: f64) -> f64 {
    if v.is_finite() && v != 0.0 {
        let digits = 9 - v.abs().log10().ceil() as i32;
        let k = 10f64.powi(digits.clamp(0, 15));
        (v * k).round() / k
    } else {
        v
    }
}

/// A key of the rig module's error (`chains[2].upper_arm`, `home`, `axes[4].steps_per_unit`) as the form names it:
/// its field, or the group a whole list is shown in; the key itself when the form does not show it.
pub fn shown(key: &str, fields: &[Field]) -> String {
    if let Some(f) = fields.iter().find(|f| f.path == key) {
        return f.shown();
    }
    let under = |f: &&Field| {
        f.path
            .strip_prefix(key)
            .is_some_and(|rest| rest.starts_with(['[', '.']))
    };
    match fields.iter().find(under) {
        Some(f)
            if f.part.is_some()
                && fields
                    .iter()
                    .filter(under)
                    .all(|g| g.label == f.label && g.unit == f.unit) =>
        {
            let unit = if f.unit.is_empty() {
                String::new()
            } else {
                format!(" ({})", f.unit)
            };
            format!("{} · {}{unit}", f.group, f.label)
        }
        Some(f) if fields.iter().filter(under).all(|g| g.group == f.group) => f.group.clone(),
        Some(_) => key.to_owned(),
        // A key the file lacks (a chain's branch left out): named in the group of its neighbours.
        None => match key.rsplit_once('.') {
            Some((parent, last)) if !parent.is_empty() => match shown(parent, fields) {
                group if group != parent => format!("{group} · {}", last.replace('_', " ")),
                _ => key.to_owned(),
            },
            _ => key.to_owned(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn trainer() -> Value {
        let text = crate::rig::export("trainer-model").unwrap().text;
        serde_json::to_value(crate::rig::parse(&text).unwrap()).unwrap()
    }

    #[test]
    fn lengths_are_shown_in_mm_and_angles_in_deg() {
        let file = read(&trainer()).unwrap();
        let all = fields(&file);
        let f = |p: &str| all.iter().find(|f| f.path == p).unwrap_or_else(|| panic!("{p}"));
        assert_eq!((f("ring_radius").unit, f("ring_radius").scale), ("mm", 1e3));
        assert_eq!(f("ring_radius").shown(), "Geometry · ring radius (mm)");
        assert_eq!((f("home[4]").unit, f("home[4]").scale), ("deg", DEG));
        assert_eq!(
            f("chains[2].platform_point[1]").shown(),
            "Chain 3 · platform joint y (mm)"
        );
        assert_eq!(
            f("limits.carriage_spacing_deg[0]").scale,
            1.0,
            "the file's degrees stay degrees"
        );
        assert_eq!(f("chains[0].kind").choices, ["rod", "radial", "elbow"]);
        // Nothing without a unit that has one.
        assert!(all
            .iter()
            .all(|f| !f.unit.is_empty() || f.kind != "number" || f.label.contains("index")));
    }

    #[test]
    fn a_bad_value_is_named_as_shown_with_its_unit_and_range() {
        let mut v = trainer();
        v["ring_radius"] = json!(-0.005);
        let e = read(&v).unwrap_err();
        assert_eq!(
            shown(&e.key, &fields(&read(&trainer()).unwrap())),
            "Geometry · ring radius (mm)"
        );
        assert_eq!(e.why, "-5 mm is out of range: more than 0 mm");
        let mut v = trainer();
        v["limits"]["base_cone_deg"] = json!(90);
        let e = read(&v).unwrap_err();
        assert_eq!(e.why, "90 deg is out of range: 0 to 90 deg, 90 itself excluded");
        let mut v = trainer();
        v["ring_radius"] = json!("big");
        let e = read(&v).unwrap_err();
        assert_eq!(e.key, "ring_radius");
        assert!(e.why.contains("invalid type"), "{e}");
        let mut v = trainer();
        v["limits"]["colour"] = json!(1);
        let e = read(&v).unwrap_err();
        assert!(
            e.key.starts_with("limits") && e.why.contains("unknown field `colour`"),
            "{e:?}"
        );
    }

    #[test]
    fn the_checks_keys_are_said_as_the_form_shows_them() {
        let all = fields(&read(&trainer()).unwrap());
        assert_eq!(shown("chains[1].branch", &all), "Chain 2 · branch");
        assert_eq!(shown("home", &all), "Home pose");
        assert_eq!(shown("limits.stroke", &all), "Limits · stroke (mm)");
        assert_eq!(shown("drives[0].lead", &all), "drives[0].lead");
    }
}
