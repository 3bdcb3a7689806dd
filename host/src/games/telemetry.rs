//! The telemetry formats ringpod reads (`stream --telemetry-udp`, `cue --capture`): its own text line, a game's
//! packet, or whichever game's format the first datagram is; and the text line's parser.

use clap::builder::PossibleValue;
use ringpod_core::cueing::Telemetry;

use super::{Format, LapPosition, Sample};

/// The telemetry formats `stream --telemetry-udp` reads: a text line, a game's own format, or whichever of the
/// games' formats the first readable datagram is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TelemetryFormat {
    /// One text line `t ax ay az wx wy wz` (or without `t`: the arrival time), separated by spaces, commas or
    /// semicolons; the units and axes of `ringpod cue`.
    Text,
    /// A game's own packet.
    Game(Format),
    /// The first datagram that one of the games' formats recognises names the format for the rest of the run.
    Auto,
}

impl TelemetryFormat {
    const ALL: [TelemetryFormat; 9] = [
        TelemetryFormat::Text,
        TelemetryFormat::Game(Format::Outsim),
        TelemetryFormat::Game(Format::Outsim2),
        TelemetryFormat::Game(Format::Beamng),
        TelemetryFormat::Game(Format::Codemasters),
        TelemetryFormat::Game(Format::F1),
        TelemetryFormat::Game(Format::Forza),
        TelemetryFormat::Game(Format::Xplane),
        TelemetryFormat::Auto,
    ];

    /// Whether a reader of this format may read `OutSimPack2` packets, and so takes `OutSim Opts`.
    pub fn reads_outsim2(self) -> bool {
        matches!(self, TelemetryFormat::Game(Format::Outsim2) | TelemetryFormat::Auto)
    }
}

impl clap::ValueEnum for TelemetryFormat {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(match self {
            TelemetryFormat::Text => PossibleValue::new("text")
                .help("`[t] ax ay az wx wy wz` or `t ax ay az wx wy wz lap`, the units of `ringpod cue`"),
            TelemetryFormat::Auto => {
                PossibleValue::new("auto").help("the first game format recognised, said on stderr")
            }
            TelemetryFormat::Game(f) => PossibleValue::new(f.name()).help(f.games()),
        })
    }
}

/// Six or seven numbers separated by spaces, commas or semicolons.
pub fn numbers(bytes: &[u8]) -> Result<Vec<f64>, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not text".to_string())?;
    text.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|s| !s.is_empty())
        // A word of the datagram, cut: a datagram can be 64 KiB of one word.
        .map(|s| {
            s.parse::<f64>()
                .map_err(|e| format!("`{}`: {e}", crate::input::unreadable::cut(s, 40)))
        })
        .collect()
}

/// Parses a text telemetry datagram: `[t] ax ay az wx wy wz`, or `t ax ay az wx wy wz lap` with the distance along
/// the lap (any unit that grows along it and falls back at the line: what a capture of a game that gives one holds,
/// and what a script of one's own can send for the lap preview).
pub fn parse_telemetry(bytes: &[u8]) -> Result<Sample, String> {
    let v = numbers(bytes)?;
    let (t, v, lap) = match v.len() {
        8 => (Some(v[0]), &v[1..7], Some(v[7])),
        7 => (Some(v[0]), &v[1..], None),
        6 => (None, &v[..], None),
        n => return Err(format!("expected 6, 7 or 8 numbers, got {n}")),
    };
    // A time that is not a time would become the reference of every later sample's interval, and a value that is
    // not finite would reach the filters on a first sample: both are unreadable.
    if t.is_some_and(|t| !t.is_finite() || t.abs() > crate::input::table::MAX_TIME_S) {
        return Err(format!(
            "its time is not a time (a finite number of seconds, at most {} either way)",
            crate::input::numbers::readable(crate::input::table::MAX_TIME_S)
        ));
    }
    if v.iter().chain(&lap).any(|x| !x.is_finite()) {
        return Err("a value is not finite".into());
    }
    Ok(Sample {
        time: t,
        telemetry: Telemetry {
            force: [v[0], v[1], v[2]],
            rate: [v[3], v[4], v[5]],
        },
        lap: lap.map(LapPosition::Along),
    })
}
