//! The Cueing panel's controls as the page builds them: the core's list of washout parameters
//! ([`ringpod_core::cueing::schema::PARAMS`]) with each per-axis key spread over its axes, every control with the
//! path of its value in the parameters' JSON, its channel, label, unit, and its range or its few values.

use ringpod_core::cueing::schema::{Param, Values, CHANNELS, PARAMS};
use serde_json::{json, Value};

/// One control per value, in the order the panel shows them: channel by channel ([`CHANNELS`]), within a channel
/// axis by axis (tilt coordination's x, then its y), then in the order of the parameters.
pub fn fields() -> Value {
    let mut all: Vec<((usize, usize), Value)> = PARAMS.iter().flat_map(controls).collect();
    all.sort_by_key(|(place, _)| *place);
    Value::Array(all.into_iter().map(|(_, field)| field).collect())
}

/// A parameter's controls: one per axis of a per-axis key, one for a single value; each with its place (its
/// channel's, its axis's).
fn controls(p: &Param) -> Vec<((usize, usize), Value)> {
    let at = |channel: &str| CHANNELS.iter().position(|c| *c == channel).unwrap_or(CHANNELS.len());
    if p.axes.is_empty() {
        let channel = p.channels.first().copied().unwrap_or("");
        return vec![(
            (at(channel), 0),
            field(p, path(p.key, None), channel, p.name.to_owned()),
        )];
    }
    p.axes
        .iter()
        .zip(p.channels)
        .enumerate()
        .map(|(i, (axis, channel))| {
            // An axis named as its channel (surge in surge) goes without saying; tilt's x and y share theirs.
            let label = if axis == channel {
                p.name.to_owned()
            } else {
                format!("{axis}: {}", p.name)
            };
            let mut f = field(p, path(p.key, Some(i)), channel, label);
            // The axis as the core's check names it in an error (`tilt_scale (x)`), for the page to say which.
            f["axis"] = json!(axis.split(' ').next().unwrap_or(axis));
            ((at(channel), i), f)
        })
        .collect()
}

/// The path of a value in the parameters' JSON: `tilt_low_pass.omega` of axis 1 is `["tilt_low_pass", 1, "omega"]`;
/// in the `optimal` table the list is the second part: `optimal.force_weight` of axis 1 is
/// `["optimal", "force_weight", 1]`.
fn path(key: &str, axis: Option<usize>) -> Vec<Value> {
    let list = if key.starts_with("optimal.") { 2 } else { 1 };
    let mut path: Vec<Value> = key.split('.').map(|p| json!(p)).collect();
    if let Some(i) = axis {
        path.insert(list.min(path.len()), json!(i));
    }
    path
}

fn field(p: &Param, at: Vec<Value>, channel: &str, label: String) -> Value {
    let mut f = json!({ "path": at, "key": p.key, "channel": channel, "label": label, "unit": p.unit });
    match p.values {
        Values::Range(min, max) => {
            f["min"] = json!(min);
            f["max"] = json!(max);
        }
        Values::Words(words) => f["choices"] = json!(words),
        Values::Numbers(numbers) => f["choices"] = json!(numbers),
    }
    if let Some((key, value, initial)) = p.only_with {
        let initial = match p.values {
            // A whole number stays one in JSON (a window of 5.0 is no `u8`).
            Values::Numbers(_) => json!(initial as u16),
            _ => json!(initial),
        };
        f["only_with"] = json!({ "path": path(key, None), "value": value, "initial": initial });
    }
    f
}

#[cfg(test)]
mod tests {
    use ringpod_core::cueing::{CueConfig, Smoothing};
    use serde_json::{json, Value};

    use super::fields;

    /// The parameters checked as the panel's are: read by their types, then by the core's ranges.
    fn cue_config(config: &Value) -> Result<CueConfig, String> {
        let config: CueConfig = serde_json::from_value(config.clone()).map_err(|e| e.to_string())?;
        config.validate().map_err(|e| e.to_string())?;
        Ok(config)
    }

    /// The parameters' JSON with each kind of smoothing: together they hold every key there is.
    fn configs() -> Vec<Value> {
        [
            Smoothing::Off,
            Smoothing::Median { window: 5 },
            Smoothing::LowPass {
                corner_hz: 8.0,
                order: 2,
            },
        ]
        .into_iter()
        .map(|smoothing| {
            serde_json::to_value(CueConfig {
                smoothing,
                ..CueConfig::default()
            })
            .unwrap()
        })
        .collect()
    }

    /// Every path to a number, a word or a flag in `v`.
    fn leaves(v: &Value, here: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
        match v {
            Value::Object(map) => map.iter().for_each(|(k, v)| {
                here.push(json!(k));
                leaves(v, here, out);
                here.pop();
            }),
            Value::Array(list) => list.iter().enumerate().for_each(|(i, v)| {
                here.push(json!(i));
                leaves(v, here, out);
                here.pop();
            }),
            _ => out.push(here.clone()),
        }
    }

    fn set(config: &mut Value, path: &[Value], value: Value) {
        let mut v = config;
        for p in path {
            v = match p {
                Value::String(k) => &mut v[k.as_str()],
                _ => &mut v[p.as_u64().unwrap() as usize],
            };
        }
        *v = value;
    }

    /// The configuration a control is read in: the one whose smoothing has the kind it needs.
    fn config_for(field: &Value) -> Value {
        let all = configs();
        let kind = field["only_with"]["value"].as_str().unwrap_or("off");
        all.into_iter().find(|c| c["smoothing"]["kind"] == kind).unwrap()
    }

    /// A new key of the washout cannot be forgotten by the panel: every value of the parameters has a control,
    /// and every control a value.
    #[test]
    fn every_cueing_key_has_a_control_and_every_control_a_key() {
        let fields = fields();
        let paths: Vec<Vec<Value>> = fields
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["path"].as_array().unwrap().clone())
            .collect();
        let mut values = Vec::new();
        for config in configs() {
            leaves(&config, &mut Vec::new(), &mut values);
        }
        for v in &values {
            assert!(paths.contains(v), "no control for {v:?}");
        }
        for p in &paths {
            assert!(values.contains(p), "a control for no value: {p:?}");
        }
        let unique: std::collections::HashSet<String> = paths.iter().map(|p| format!("{p:?}")).collect();
        assert_eq!(unique.len(), paths.len(), "one control per value");
        for f in fields.as_array().unwrap() {
            assert!(f["channel"].as_str().is_some_and(|c| !c.is_empty()), "{f}");
            assert!(f.get("min").is_some() || f.get("choices").is_some(), "{f}");
        }
    }

    /// The ranges and values the panel offers are the ones the core's check enforces: each end of a range and
    /// each choice is taken (a choice with the values it brings, at their starting values, as the page sets them),
    /// a step beyond either end is refused naming the key.
    #[test]
    fn each_control_offers_what_the_check_takes() {
        let all = fields();
        for f in all.as_array().unwrap() {
            let path = f["path"].as_array().unwrap();
            let key = f["key"].as_str().unwrap().split('.').next().unwrap();
            let with = |value: Value| {
                let mut config = config_for(f);
                for g in all
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|g| g["only_with"]["path"] == f["path"])
                {
                    let (table, leaf) = g["path"].as_array().unwrap().split_at(1);
                    let table = config[table[0].as_str().unwrap()].as_object_mut().unwrap();
                    let leaf = leaf[0].as_str().unwrap();
                    table.remove(leaf);
                    if g["only_with"]["value"] == value {
                        table.insert(leaf.to_owned(), g["only_with"]["initial"].clone());
                    }
                }
                set(&mut config, path, value);
                cue_config(&config)
            };
            if let Some(choices) = f["choices"].as_array() {
                for c in choices {
                    assert!(with(c.clone()).is_ok(), "{f}: {c}");
                }
                let beyond = match &choices[0] {
                    Value::String(_) => json!("sideways"),
                    _ => json!(choices.iter().filter_map(Value::as_u64).max().unwrap() + 1),
                };
                assert!(with(beyond).is_err(), "{f}");
                continue;
            }
            let (min, max) = (f["min"].as_f64().unwrap(), f["max"].as_f64().unwrap());
            let step = (max - min) * 1e-6;
            assert!(with(json!(min)).is_ok(), "{f}: {min}");
            assert!(with(json!(max)).is_ok(), "{f}: {max}");
            for beyond in [min - step, max + step] {
                let e = with(json!(beyond)).unwrap_err();
                assert!(e.contains(key), "{f}: {beyond}: {e}");
            }
        }
    }

    /// Grouped by channel in reading order, each with its unit; a choice of a few values is a list to pick from.
    #[test]
    fn controls_are_grouped_by_channel_with_their_units() {
        let fields = fields();
        let fields = fields.as_array().unwrap();
        let channels: Vec<&str> = fields.iter().map(|f| f["channel"].as_str().unwrap()).collect();
        let mut order = channels.clone();
        order.dedup();
        assert_eq!(
            order,
            ringpod_core::cueing::schema::CHANNELS.to_vec(),
            "each channel once, in order"
        );
        let find = |path: Value| fields.iter().find(|f| f["path"] == path).unwrap();
        let surge_limit = find(json!(["translation_limit", 0]));
        assert_eq!(
            (surge_limit["channel"].as_str(), surge_limit["unit"].as_str()),
            (Some("surge"), Some("m/s²"))
        );
        assert_eq!(find(json!(["tilt_limit_deg", 1]))["label"], "y (roll): tilt limit");
        assert_eq!(find(json!(["yaw"]))["choices"], json!(["heading", "washout"]));
        assert_eq!(find(json!(["smoothing", "order"]))["only_with"]["initial"], json!(2));
    }
}
