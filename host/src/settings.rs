//! Names of the device settings on the command line, and `ringpod device config`.

use ringpod_core::protocol::ConfigKey;

use crate::client::{Client, Transport};

/// The command-line name of a key: `tick-hz`, `pose-velocity.2`.
pub fn name(key: ConfigKey) -> String {
    match key {
        ConfigKey::StreamTimeoutMs => "stream-timeout-ms".into(),
        ConfigKey::GrossJumpMs => "gross-jump-ms".into(),
        ConfigKey::FollowDirect => "follow-direct".into(),
        ConfigKey::TickHz => "tick-hz".into(),
        ConfigKey::InputActiveLow => "input-active-low".into(),
        ConfigKey::DebounceMs => "debounce-ms".into(),
        ConfigKey::TelemetryHz => "telemetry-hz".into(),
        ConfigKey::PoseVelocity(a) => format!("pose-velocity.{a}"),
        ConfigKey::PoseAcceleration(a) => format!("pose-acceleration.{a}"),
        ConfigKey::StepsPerUnit(a) => format!("steps-per-unit.{a}"),
        ConfigKey::Reverse(a) => format!("reverse.{a}"),
        ConfigKey::EnvelopeMargin(c) => format!(
            "envelope-margin.{}",
            ringpod_core::kinematics::Check::ALL
                .get(usize::from(c))
                .map_or("?", |c| c.name())
        ),
    }
}

/// The key with this name.
pub fn parse(text: &str) -> anyhow::Result<ConfigKey> {
    ConfigKey::all().find(|k| name(*k) == text).ok_or_else(|| {
        let names: Vec<String> = ConfigKey::all().map(name).collect();
        anyhow::anyhow!("unknown setting {text:?}; settings: {}", names.join(", "))
    })
}

/// An `f32` setting as JSON, by its shortest decimal form (0.05, not 0.05000000074505806).
fn number(v: f32) -> serde_json::Value {
    serde_json::json!(v.to_string().parse::<f64>().unwrap_or(f64::from(v)))
}

/// `device config`, `device config get KEY`, `device config set KEY VALUE`: prints JSON (a set prints the value
/// read back from the device).
pub fn run<T: Transport>(client: &mut Client<T>, args: &[String]) -> anyhow::Result<serde_json::Value> {
    let words: Vec<&str> = args.iter().map(String::as_str).collect();
    match words.as_slice() {
        [] => {
            let mut all = serde_json::Map::new();
            for key in ConfigKey::all() {
                all.insert(name(key), number(client.get_config(key)?));
            }
            Ok(serde_json::Value::Object(all))
        }
        ["get", key] => {
            let key = parse(key)?;
            Ok(serde_json::json!({ "key": name(key), "value": number(client.get_config(key)?), "live": key.is_live() }))
        }
        ["set", key, value] => {
            let key = parse(key)?;
            let value: f32 = value.parse().map_err(|_| anyhow::anyhow!("not a number: {value:?}"))?;
            client.set_config(key, value)?;
            Ok(serde_json::json!({ "key": name(key), "value": number(client.get_config(key)?), "live": key.is_live() }))
        }
        _ => anyhow::bail!("usage: ringpod device config [get KEY | set KEY VALUE]"),
    }
}
