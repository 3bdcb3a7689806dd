//! `ringpod device config`: the device's settings sections as JSON, by the field names of the rig file's sections,
//! and a change of one value by its path (`stream.timeout_ms`, `axes.1.reverse`, `motion.pose_velocity.2`): the
//! section is read, the value replaced, the section checked here as a typed value and sent whole; the device checks
//! it with the rest of its configuration and says why when it refuses.

use ringpod_core::protocol::{Settings, SettingsKind};
use serde_json::Value;

use crate::link::client::{Client, ClientError, Transport};
use crate::rig::{InputsSpec, RigError};

/// Why `device config` could not do what it was asked.
#[derive(Debug, thiserror::Error)]
pub enum ConfigCommandError {
    /// The words are none of the forms.
    #[error("usage: ringpod device config [get SECTION[.PATH] | set SECTION.PATH VALUE]")]
    Usage,
    /// A set names a section but no value in it.
    #[error("{0}: give a value's path in its section, as stream.timeout_ms or axes.1.reverse")]
    NoPath(String),
    /// No section of that name.
    #[error("no section {name:?}; sections: {}", SettingsKind::ALL.map(|k| k.name()).join(", "))]
    NoSection {
        /// The name given.
        name: String,
    },
    /// The path leads nowhere in its section.
    #[error("{path}: no {key:?} there")]
    NoKey {
        /// The whole path.
        path: String,
        /// The first key not found.
        key: String,
    },
    /// The changed section is not a section of its kind (a wrong type or an unknown field).
    #[error("{}{section}: {reason}", change.as_ref().map_or(String::new(), |c| format!("{c}: ")))]
    Section {
        /// The change that made it (`path = value`), when one did (`device config set`).
        change: Option<String>,
        /// The section.
        section: &'static str,
        /// What serde found.
        reason: serde_json::Error,
    },
    /// The inputs section names an input there is not.
    #[error("{0}")]
    Inputs(#[from] RigError),
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// A section could not be written as JSON.
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
}

/// A section's value as JSON: its fields, the inputs by their names, every `f32` by its shortest decimal.
fn to_json(settings: &Settings) -> Result<Value, serde_json::Error> {
    fn tidy(v: &mut Value) {
        match v {
            Value::Number(n) if n.is_f64() => {
                let written = n.as_f64().map(crate::input::numbers::as_written);
                if let Some(short) = written.and_then(serde_json::Number::from_f64) {
                    *n = short;
                }
            }
            Value::Array(a) => a.iter_mut().for_each(tidy),
            Value::Object(o) => o.iter_mut().for_each(|(_, v)| tidy(v)),
            _ => {}
        }
    }
    let mut value = match settings {
        Settings::Stream(s) => serde_json::to_value(s)?,
        Settings::Control(s) => serde_json::to_value(s)?,
        Settings::Motion(s) => serde_json::to_value(s)?,
        Settings::Inputs(s) => serde_json::to_value(InputsSpec::of(s))?,
        Settings::Axes(s) => serde_json::to_value(s)?,
        Settings::Homing(s) => serde_json::to_value(s)?,
        Settings::Supervisor(s) => serde_json::to_value(s)?,
        Settings::Spare(s) => serde_json::to_value(s)?,
    };
    tidy(&mut value);
    Ok(value)
}

/// The section `kind` from its JSON value (every field, no others).
fn from_json(kind: SettingsKind, value: Value) -> Result<Settings, ConfigCommandError> {
    let bad = |reason| ConfigCommandError::Section {
        change: None,
        section: kind.name(),
        reason,
    };
    Ok(match kind {
        SettingsKind::Stream => Settings::Stream(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Control => Settings::Control(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Motion => Settings::Motion(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Inputs => {
            let spec: InputsSpec = serde_json::from_value(value).map_err(bad)?;
            Settings::Inputs(spec.config()?)
        }
        SettingsKind::Axes => Settings::Axes(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Homing => Settings::Homing(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Supervisor => Settings::Supervisor(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Spare => Settings::Spare(serde_json::from_value(value).map_err(bad)?),
    })
}

/// The section a path starts with.
fn kind(name: &str) -> Result<SettingsKind, ConfigCommandError> {
    SettingsKind::ALL
        .into_iter()
        .find(|k| k.name() == name)
        .ok_or_else(|| ConfigCommandError::NoSection { name: name.to_owned() })
}

/// The value at `path` (object keys and array indices) inside `value`.
fn at<'a>(value: &'a mut Value, path: &[&str], whole: &str) -> Result<&'a mut Value, ConfigCommandError> {
    let Some((first, rest)) = path.split_first() else {
        return Ok(value);
    };
    let next = match value {
        Value::Object(map) => map.get_mut(*first),
        Value::Array(items) => first.parse::<usize>().ok().and_then(|i| items.get_mut(i)),
        _ => None,
    };
    let Some(next) = next else {
        return Err(ConfigCommandError::NoKey {
            path: whole.to_owned(),
            key: (*first).to_owned(),
        });
    };
    at(next, rest, whole)
}

/// A section as reported: its value, whether it is live, and whether the next start runs something else.
fn report(settings: &Settings, pending: bool) -> Result<Value, serde_json::Error> {
    let kind = settings.kind();
    Ok(serde_json::json!({
        "section": kind.name(),
        "live": kind.is_live(),
        "pending": pending,
        "value": to_json(settings)?,
    }))
}

/// `device config`: every section; `device config get SECTION[.PATH]`; `device config set SECTION.PATH VALUE`
/// (VALUE is JSON: `250`, `true`, `"direct"`, `[1, 2]`; a bare word is a string). Prints JSON; a set prints the
/// section read back from the device.
pub fn run<T: Transport>(client: &mut Client<T>, args: &[String]) -> Result<Value, ConfigCommandError> {
    let words: Vec<&str> = args.iter().map(String::as_str).collect();
    match words.as_slice() {
        [] => {
            let mut all = serde_json::Map::new();
            let mut pending = Vec::new();
            for kind in SettingsKind::ALL {
                let (settings, p) = client.settings(kind)?;
                all.insert(kind.name().to_owned(), to_json(&settings)?);
                if p {
                    pending.push(kind.name());
                }
            }
            all.insert("pending".to_owned(), serde_json::json!(pending));
            Ok(Value::Object(all))
        }
        ["get", path] => {
            let parts: Vec<&str> = path.split('.').collect();
            let (settings, pending) = client.settings(kind(parts[0])?)?;
            if parts.len() == 1 {
                return Ok(report(&settings, pending)?);
            }
            let mut value = to_json(&settings)?;
            let found = at(&mut value, &parts[1..], path)?.clone();
            Ok(
                serde_json::json!({ "key": path, "value": found, "live": settings.kind().is_live(), "pending": pending }),
            )
        }
        ["set", path, text] => {
            let parts: Vec<&str> = path.split('.').collect();
            if parts.len() < 2 {
                return Err(ConfigCommandError::NoPath((*path).to_owned()));
            }
            let kind = kind(parts[0])?;
            let (settings, _) = client.settings(kind)?;
            let mut value = to_json(&settings)?;
            let new = serde_json::from_str(text).unwrap_or_else(|_| Value::String((*text).to_owned()));
            *at(&mut value, &parts[1..], path)? = new;
            let changed = from_json(kind, value).map_err(|e| match e {
                ConfigCommandError::Section { section, reason, .. } => ConfigCommandError::Section {
                    change: Some(format!("{path} = {text}")),
                    section,
                    reason,
                },
                other => other,
            })?;
            client.set_settings(changed)?;
            let (back, pending) = client.settings(kind)?;
            Ok(report(&back, pending)?)
        }
        _ => Err(ConfigCommandError::Usage),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::controller::ControllerConfig;

    /// Every section of the trainer model goes to JSON by the rig file's names and comes back to the same value.
    #[test]
    fn every_section_round_trips_through_json() {
        let config = ControllerConfig::trainer_model();
        for kind in SettingsKind::ALL {
            let settings = config.settings(kind);
            let json = to_json(&settings).unwrap();
            assert_eq!(from_json(kind, json).unwrap(), settings, "{kind:?}");
        }
        let inputs = to_json(&config.settings(SettingsKind::Inputs)).unwrap();
        assert!(inputs["active_low"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!("home1")));
        let motion = to_json(&config.settings(SettingsKind::Motion)).unwrap().to_string();
        assert!(!motion.contains("0000000"), "shortest decimals: {motion}");
    }

    #[test]
    fn paths_name_what_is_not_there() {
        let config = ControllerConfig::trainer_model();
        let mut value = to_json(&config.settings(SettingsKind::Axes)).unwrap();
        assert_eq!(
            at(&mut value, &["1", "reverse"], "axes.1.reverse").unwrap(),
            &Value::Bool(false)
        );
        let e = at(&mut value, &["6", "reverse"], "axes.6.reverse").unwrap_err();
        assert!(e.to_string().contains("\"6\""), "{e}");
        let mut stream = to_json(&config.settings(SettingsKind::Stream)).unwrap();
        stream["timeout"] = serde_json::json!(5);
        let e = from_json(SettingsKind::Stream, stream).expect_err("an unknown field is refused");
        // Read back from a device, the section names itself; after a set, the change comes first.
        assert!(matches!(e, ConfigCommandError::Section { change: None, .. }), "{e:?}");
        assert!(e.to_string().starts_with("stream: "), "{e}");
        let ConfigCommandError::Section { section, reason, .. } = e else {
            unreachable!()
        };
        let set = ConfigCommandError::Section {
            change: Some("stream.timeout = 5".into()),
            section,
            reason,
        };
        assert!(set.to_string().starts_with("stream.timeout = 5: stream: "), "{set}");
    }
}
