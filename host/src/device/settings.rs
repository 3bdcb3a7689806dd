//! `ringpod device config`: the device's settings sections as JSON, by the field names of the rig file's sections,
//! and a change of one value by its path (`stream.timeout_ms`, `axes.1.reverse`, `motion.pose_velocity.2`): the
//! section is read, the value replaced, the section checked here as a typed value and sent whole; the device checks
//! it with the rest of its configuration and says why when it refuses.

use ringpod_core::protocol::{Settings, SettingsKind};
use serde_json::Value;

use crate::link::client::{Client, Transport};
use crate::rig::InputsSpec;

/// A section's value as JSON: its fields, the inputs by their names, every `f32` by its shortest decimal.
fn to_json(settings: &Settings) -> anyhow::Result<Value> {
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
    };
    tidy(&mut value);
    Ok(value)
}

/// The section `kind` from its JSON value (every field, no others).
fn from_json(kind: SettingsKind, value: Value) -> anyhow::Result<Settings> {
    let bad = |e: serde_json::Error| anyhow::anyhow!("{}: {e}", kind.name());
    Ok(match kind {
        SettingsKind::Stream => Settings::Stream(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Control => Settings::Control(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Motion => Settings::Motion(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Inputs => {
            let spec: InputsSpec = serde_json::from_value(value).map_err(bad)?;
            Settings::Inputs(spec.config().map_err(|e| anyhow::anyhow!("{e}"))?)
        }
        SettingsKind::Axes => Settings::Axes(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Homing => Settings::Homing(serde_json::from_value(value).map_err(bad)?),
        SettingsKind::Supervisor => Settings::Supervisor(serde_json::from_value(value).map_err(bad)?),
    })
}

/// The section a path starts with.
fn kind(name: &str) -> anyhow::Result<SettingsKind> {
    SettingsKind::ALL.into_iter().find(|k| k.name() == name).ok_or_else(|| {
        let names: Vec<&str> = SettingsKind::ALL.iter().map(|k| k.name()).collect();
        anyhow::anyhow!("no section {name:?}; sections: {}", names.join(", "))
    })
}

/// The value at `path` (object keys and array indices) inside `value`.
fn at<'a>(value: &'a mut Value, path: &[&str], whole: &str) -> anyhow::Result<&'a mut Value> {
    let Some((first, rest)) = path.split_first() else {
        return Ok(value);
    };
    let next = match value {
        Value::Object(map) => map.get_mut(*first),
        Value::Array(items) => first.parse::<usize>().ok().and_then(|i| items.get_mut(i)),
        _ => None,
    };
    let Some(next) = next else {
        anyhow::bail!("{whole}: no {first:?} there");
    };
    at(next, rest, whole)
}

/// A section as reported: its value, whether it is live, and whether the next start runs something else.
fn report(settings: &Settings, pending: bool) -> anyhow::Result<Value> {
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
pub fn run<T: Transport>(client: &mut Client<T>, args: &[String]) -> anyhow::Result<Value> {
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
                return report(&settings, pending);
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
                anyhow::bail!("{path}: give a value's path in its section, as stream.timeout_ms or axes.1.reverse");
            }
            let kind = kind(parts[0])?;
            let (settings, _) = client.settings(kind)?;
            let mut value = to_json(&settings)?;
            let new = serde_json::from_str(text).unwrap_or_else(|_| Value::String((*text).to_owned()));
            *at(&mut value, &parts[1..], path)? = new;
            let changed = from_json(kind, value).map_err(|e| anyhow::anyhow!("{path} = {text}: {e}"))?;
            client.set_settings(changed)?;
            let (back, pending) = client.settings(kind)?;
            report(&back, pending)
        }
        _ => anyhow::bail!("usage: ringpod device config [get SECTION[.PATH] | set SECTION.PATH VALUE]"),
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
        assert!(
            from_json(SettingsKind::Stream, stream).is_err(),
            "an unknown field is refused"
        );
    }
}
