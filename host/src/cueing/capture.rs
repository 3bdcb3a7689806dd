//! `ringpod cue --input FILE.pcap`: a packet capture of a game's telemetry (`stream --capture`, tcpdump, Wireshark)
//! as the telemetry rows `cue` reads from a CSV, so a drive recorded once is cued again with other parameters.
//!
//! Each UDP datagram (to `--udp-port` only, when given) is decoded in `--telemetry-format` (`auto` when not given:
//! the format of the capture's first run of [`games::reader::LOCK_AFTER`] datagrams that one game's format recognises and
//! decodes, named in the summary with the packet the run starts at), `OutSimPack2` with `--outsim-opts` when
//! given. A row's time is the game's own time when its format
//! carries one, as the live path (`stream --telemetry-udp`) takes it, else the packet's capture time (from the first
//! datagram taken), the live path's arrival time. A datagram the format cannot read, or whose time is not after the
//! last one's, is an input error named by its packet number (as the live path counts an unreadable datagram);
//! packets that are not UDP, go to another port, are IP fragments or are cut short are skipped and counted, as are
//! the game's other packets (F1 sends session, lap data, ... to the motion packet's port: [`GAME_PACKETS`]).
//! A format that carries the lap position (F1, Forza, Codemasters: [`games::LapPosition`]) gives each row the lap
//! distance as its eighth value, made as the live path makes it ([`LapTrack`]), which `--preview lap` aligns by.

use std::collections::BTreeMap;

use serde::Serialize;

use super::lap_track::LapTrack;
use crate::games;
use crate::games::outsim2::Opts;
use crate::games::TelemetryFormat;
use crate::input::capture;
use crate::input::table::InputError;

/// What a capture held, in `cue`'s summary.
#[derive(Debug, Serialize)]
pub struct CaptureSummary {
    /// `pcap` or `pcapng`.
    pub file_format: &'static str,
    /// Packets in the file.
    pub packets: usize,
    /// UDP datagrams to the port (or any), decoded or not.
    pub datagrams: usize,
    /// The telemetry format they were read as (`auto` when none was recognised).
    pub telemetry_format: String,
    /// `auto`: the packet from which the format's run of datagrams started.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recognised_from_packet: Option<usize>,
    /// The UDP destination ports in the file and their datagrams (to choose `--udp-port` when there are several).
    pub ports: BTreeMap<u16, usize>,
    /// The senders of the datagrams taken (address and port) and their datagrams.
    pub senders: BTreeMap<String, usize>,
    /// Packets not taken, by why; among them the datagrams that are the game's other packets ([`GAME_PACKETS`]).
    pub skipped: BTreeMap<String, usize>,
}

/// Why a datagram of the game was not cued: another of its packet types (F1's session, lap data, ...) or the game
/// in its menus (Forza's `IsRaceOn` 0), which carry no motion. Not an error.
pub const GAME_PACKETS: &str = "the game's packets without motion (other types, menus)";

/// A telemetry row as `cue` reads it from a CSV: its packet number and `t ax ay az wx wy wz`.
pub type Row = (usize, Vec<f64>);

/// A sample's row at time `t`: `t ax ay az wx wy wz`, and the lap distance where the format carries the lap
/// position.
fn row(t: f64, sample: &games::Sample, track: &mut LapTrack) -> Vec<f64> {
    let [ax, ay, az] = sample.telemetry.force;
    let [wx, wy, wz] = sample.telemetry.rate;
    let mut row = vec![t, ax, ay, az, wx, wy, wz];
    if let Some(position) = sample.lap {
        row.push(track.distance(t, position));
    }
    row
}

/// The telemetry rows of a capture, the datagrams that could not be used, and what the capture held.
pub fn rows(
    bytes: &[u8],
    format: TelemetryFormat,
    port: Option<u16>,
    outsim_opts: Option<Opts>,
) -> Result<(Vec<Row>, Vec<InputError>, CaptureSummary), String> {
    let cap = capture::read(bytes)?;
    let mut summary = CaptureSummary {
        file_format: cap.format,
        packets: cap.packets,
        datagrams: 0,
        telemetry_format: String::new(),
        recognised_from_packet: None,
        ports: BTreeMap::new(),
        senders: BTreeMap::new(),
        skipped: cap.skipped,
    };
    let mut taken = Vec::new();
    for d in &cap.datagrams {
        *summary.ports.entry(d.to.port()).or_default() += 1;
        if port.is_some_and(|p| p != d.to.port()) {
            *summary.skipped.entry("UDP to another port".into()).or_default() += 1;
            continue;
        }
        summary.datagrams += 1;
        *summary.senders.entry(d.from.to_string()).or_default() += 1;
        taken.push(d);
    }
    // Offline, the whole capture is there: the format is chosen once, and every datagram read in it.
    let format = match format {
        TelemetryFormat::Auto => match games::detect(taken.iter().map(|d| d.payload.as_slice()), outsim_opts) {
            Some((f, i)) => {
                summary.recognised_from_packet = Some(taken[i].number);
                eprintln!(
                    "telemetry: the datagrams are {f} ({}), from packet {}",
                    f.games(),
                    taken[i].number
                );
                TelemetryFormat::Game(f)
            }
            None => TelemetryFormat::Auto,
        },
        named => named,
    };
    let mut reader = games::Reader::new(format, outsim_opts);
    let mut rows = Vec::new();
    let mut errors = Vec::new();
    let mut first: Option<std::time::Duration> = None;
    let mut last_t: Option<f64> = None;
    let mut track = LapTrack::default();
    for d in taken {
        let mut refuse = |reason: String| errors.push(InputError { line: d.number, reason });
        let sample = match reader.read(&d.payload) {
            Ok(Some(sample)) => sample,
            Ok(None) => {
                *summary.skipped.entry(GAME_PACKETS.into()).or_default() += 1;
                continue;
            }
            Err(reason) => {
                refuse(reason);
                continue;
            }
        };
        // Capture times need not rise (a capture merged from two interfaces, a clock set back).
        let t = match sample.time {
            Some(t) => t,
            None => match d.time.checked_sub(*first.get_or_insert(d.time)) {
                Some(since) => since.as_secs_f64(),
                None => {
                    refuse("its capture time is before the first datagram's".into());
                    continue;
                }
            },
        };
        if last_t.is_some_and(|l| t <= l) {
            refuse("its time is not after the last one's".into());
            continue;
        }
        last_t = Some(t);
        rows.push((d.number, row(t, &sample, &mut track)));
    }
    if cap.cut_short {
        errors.push(InputError {
            line: cap.packets + 1,
            reason: "the file ends in the middle of this packet (a capture cut off): the packets before it are cued"
                .into(),
        });
    }
    summary.telemetry_format = match format {
        TelemetryFormat::Text => "text".into(),
        TelemetryFormat::Game(f) => f.name().into(),
        TelemetryFormat::Auto => "auto".into(),
    };
    Ok((rows, errors, summary))
}

#[cfg(test)]
mod tests;
