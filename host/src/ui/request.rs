//! What a page may ask of the device over the WebSocket, read strictly: one JSON object with the page's number for
//! the request (`id`), what to do (`do`) and that request's fields, nothing else.

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// What a page asks the device to do.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(tag = "do", rename_all = "snake_case", deny_unknown_fields)]
pub enum Request {
    Enable,
    Disable,
    Home,
    Start,
    Stop,
    Clear,
    /// The STOP button: ends a stream, cancels every request sent before it, stops whatever moves, powers down.
    Halt,
    /// Axis 1-6; degrees of ring for a carriage or of a shoulder, mm for a linear actuator.
    Jog {
        axis: u8,
        distance: f64,
    },
    Buzz {
        axis: u8,
    },
    /// To the home pose, then power down.
    Park,
    /// Spare axis 7 or 8 moved by `distance` in its own unit from where its counted steps are, the platform held.
    SpareJog {
        axis: u8,
        distance: f64,
    },
    /// Spare axis 7 or 8 to `value` in its own unit, the platform held.
    SpareTo {
        axis: u8,
        value: f64,
    },
    /// A built-in motion (`demo`, `heave`, `yaw`, `vibration`).
    Motion {
        motion: String,
        seconds: f64,
        rate_hz: f64,
    },
    /// A pose CSV: the text of a file the user picked in the page (`text`, named `name`), or without `text` the
    /// file `name` under the directory `ringpod ui --files` names.
    File {
        name: String,
        #[serde(default)]
        text: Option<String>,
        #[serde(default)]
        degrees: bool,
    },
    /// Poses (`holds = "poses"`), a game's telemetry (`holds = "telemetry"`, cued by the workbench's live
    /// cueing file) or a motion front end's pose strings (`holds = "strings"`, `format` the `--pose-format`
    /// template) on a UDP port of the address the workbench listens on.
    Udp {
        port: u16,
        holds: String,
        #[serde(default)]
        format: Option<String>,
        #[serde(default)]
        degrees: bool,
        /// Seconds without a datagram after which the session ends.
        #[serde(default = "default_idle")]
        idle: f64,
        /// Only datagrams from this sender's address count (as the CLI's `--from`).
        #[serde(default)]
        from: Option<std::net::IpAddr>,
        /// Live for Speed's `OutSim Opts` (hexadecimal), for `outsim2` or `auto` telemetry (as the CLI's
        /// `--outsim-opts`).
        #[serde(default)]
        outsim_opts: Option<String>,
        /// The lap preview for telemetry that carries a lap position (as the CLI's `--lap-preview`; on unless
        /// `false`).
        #[serde(default = "default_lap_preview")]
        lap_preview: bool,
    },
    /// A rig file's text, stored on the device (it must be `Off`), then the device restarted to run it.
    LoadRig {
        text: String,
    },
}

fn default_idle() -> f64 {
    30.0
}

fn default_lap_preview() -> bool {
    true
}

impl Request {
    /// Whether the request may still run after a STOP sent after it: only the STOP itself.
    pub fn is_halt(&self) -> bool {
        *self == Self::Halt
    }

    /// Whether the request runs a stream (one at a time: a second one asked before the first ends is refused).
    pub fn is_stream(&self) -> bool {
        matches!(
            self,
            Self::Motion { .. }
                | Self::File { .. }
                | Self::Udp { .. }
                | Self::Park
                | Self::SpareJog { .. }
                | Self::SpareTo { .. }
        )
    }
}

/// A request of one page (its connection number) with the number the page gave it, and the STOP generation it
/// was sent in: a later STOP cancels it.
pub struct Job {
    pub page: u64,
    pub id: u64,
    pub epoch: u64,
    pub request: Request,
}

/// Why a page's message is not a request: the words for its reply, and the number it gave (0 when none).
#[derive(Debug, PartialEq)]
pub struct Unreadable {
    pub id: u64,
    pub why: String,
}

/// A JSON value whose objects each give a key once. serde_json's `Value` keeps the last of a key given twice, so
/// that `{"do":"enable","do":"halt"}` would run the halt: a request that says two things is refused instead.
struct Unique(Value);

impl<'de> Deserialize<'de> for Unique {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueVisitor)
    }
}

struct UniqueVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueVisitor {
    type Value = Unique;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Unique, E> {
        Ok(Unique(Value::Bool(v)))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Unique, E> {
        Ok(Unique(v.into()))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Unique, E> {
        Ok(Unique(v.into()))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Unique, E> {
        Ok(Unique(v.into()))
    }
    fn visit_str<E>(self, v: &str) -> Result<Unique, E> {
        Ok(Unique(Value::String(v.to_owned())))
    }
    fn visit_unit<E>(self) -> Result<Unique, E> {
        Ok(Unique(Value::Null))
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Unique, A::Error> {
        let mut all = Vec::new();
        while let Some(Unique(v)) = seq.next_element()? {
            all.push(v);
        }
        Ok(Unique(Value::Array(all)))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Unique, A::Error> {
        let mut object = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(serde::de::Error::custom(format!("the key `{key}` is given twice")));
            }
            let Unique(v) = map.next_value()?;
            object.insert(key, v);
        }
        Ok(Unique(Value::Object(object)))
    }
}

/// Reads a page's message. Every command refuses a field it does not have, by name (serde's `deny_unknown_fields`
/// does not reach the commands without fields of an internally tagged enum, so the keys are compared here too).
pub fn parse(text: &str) -> Result<(u64, Request), Unreadable> {
    let unreadable = |id: u64, why: String| Unreadable { id, why };
    let mut object = match serde_json::from_str::<Unique>(text) {
        Ok(Unique(Value::Object(o))) => o,
        Ok(_) => return Err(unreadable(0, "a request is a JSON object".into())),
        Err(e) if e.is_data() => return Err(unreadable(0, format!("not a request: {e}"))),
        Err(e) => return Err(unreadable(0, format!("not JSON: {e}"))),
    };
    let id = match object.remove("id") {
        Some(v) => v
            .as_u64()
            .ok_or_else(|| unreadable(0, "`id` is a whole number".into()))?,
        None => return Err(unreadable(0, "a request has an `id`".into())),
    };
    let given: Vec<String> = object.keys().cloned().collect();
    let request: Request =
        serde_json::from_value(Value::Object(object)).map_err(|e| unreadable(id, format!("not a request: {e}")))?;
    // The request's own fields, defaults included: a key beyond them is refused.
    let known = serde_json::to_value(&request).map_err(|e| unreadable(id, e.to_string()))?;
    if let Some(extra) = given.iter().find(|k| known.get(k.as_str()).is_none()) {
        let what = known["do"].as_str().unwrap_or("?");
        return Err(unreadable(
            id,
            format!("not a request: `{what}` has no field `{extra}`"),
        ));
    }
    Ok((id, request))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_read_with_their_numbers_and_defaults() {
        assert_eq!(parse(r#"{"id":3,"do":"halt"}"#), Ok((3, Request::Halt)));
        let (_, file) = parse(r#"{"id":5,"do":"file","name":"a.csv","text":"t,x\n"}"#).unwrap();
        assert!(matches!(file, Request::File { text: Some(_), .. }), "{file:?}");
        let (id, udp) = parse(r#"{"id":4,"do":"udp","port":4444,"holds":"poses"}"#).unwrap();
        assert_eq!(id, 4);
        assert_eq!(
            udp,
            Request::Udp {
                port: 4444,
                holds: "poses".into(),
                format: None,
                degrees: false,
                idle: 30.0,
                from: None,
                outsim_opts: None,
                lap_preview: true,
            }
        );
    }

    #[test]
    fn an_unknown_field_is_refused_by_every_command() {
        for (text, extra) in [
            (r#"{"id":1,"do":"enable","axis":2}"#, "axis"),
            (r#"{"id":1,"do":"halt","now":true}"#, "now"),
            (r#"{"id":1,"do":"park","to":"home"}"#, "to"),
            (r#"{"id":1,"do":"jog","axis":1,"distance":1,"speed":9}"#, "speed"),
            (r#"{"id":1,"do":"file","name":"a","path":"/etc/shadow"}"#, "path"),
            (
                r#"{"id":1,"do":"udp","port":1,"holds":"poses","bind":"0.0.0.0"}"#,
                "bind",
            ),
        ] {
            let e = parse(text).unwrap_err();
            assert_eq!(e.id, 1, "{text}");
            assert!(e.why.contains(extra), "{text}: {}", e.why);
        }
    }

    #[test]
    fn garbage_is_refused_with_a_reason() {
        for text in [
            "",
            "[]",
            "3",
            r#"{"do":"halt"}"#,
            r#"{"id":-1,"do":"halt"}"#,
            r#"{"id":1,"do":"fly"}"#,
        ] {
            let e = parse(text).unwrap_err();
            assert!(!e.why.is_empty(), "{text}");
        }
        assert_eq!(parse(r#"{"id":7,"do":"fly"}"#).unwrap_err().id, 7);
    }

    #[test]
    fn a_key_given_twice_is_refused_at_any_depth() {
        for (text, key) in [
            (r#"{"id":1,"do":"enable","do":"halt"}"#, "do"),
            (r#"{"id":1,"id":2,"do":"halt"}"#, "id"),
            (r#"{"id":1,"do":"jog","axis":1,"distance":1,"distance":90}"#, "distance"),
            (r#"{"id":1,"do":"file","name":"a","text":"x","name":"b"}"#, "name"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(
                e.why.contains(&format!("the key `{key}` is given twice")),
                "{text}: {}",
                e.why
            );
        }
        // Keys in nested values are checked too, and the same key in two objects is not a repeat.
        let nested = serde_json::from_str::<Unique>(r#"{"a":{"b":1,"b":2}}"#).map(|_| ());
        assert!(nested.unwrap_err().to_string().contains("`b` is given twice"));
        let fine = serde_json::from_str::<Unique>(r#"[{"b":1},{"b":2.5,"c":[null,true,-3,"s"]}]"#).unwrap();
        assert_eq!(fine.0, serde_json::json!([{"b":1},{"b":2.5,"c":[null,true,-3,"s"]}]));
    }
}
