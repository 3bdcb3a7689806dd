//! What a stream reports at its end (`--report-json`), and the names it gives the device's refusals.

use std::collections::BTreeMap;

use ringpod_core::motion::RejectReason;
use serde::Serialize;

use super::InputError;

/// How much was limited into the envelope.
#[derive(Debug, Default, Serialize)]
pub struct LimitedReport {
    /// Input poses the host limited before sending.
    pub host: u32,
    /// Setpoints the device limited (of those this run sent).
    pub device: u32,
    /// Per check that bound them (host and device).
    pub by_check: BTreeMap<String, u32>,
    /// The largest translation taken off a pose (mm).
    pub largest_mm: f64,
    /// The largest roll or pitch taken off a pose (deg).
    pub largest_deg: f64,
}

/// What came from a live source: UDP datagrams, or a game's shared memory (each new sample counted as a datagram).
#[derive(Debug, Default, Serialize)]
pub struct DatagramReport {
    /// Datagrams received from the source (shared memory: new samples, and new counters whose snapshot was refused).
    pub received: u32,
    /// Datagrams that did not parse (the first few of each kind also in `input_errors`).
    pub unreadable: u32,
    /// The unreadable datagrams by the kind of their reason (its numbers as `#`): they add up to `unreadable`.
    pub unreadable_by_kind: std::collections::BTreeMap<String, u64>,
    /// Telemetry: datagrams of the game without motion (F1's other packet types, Forza in its menus), skipped: not
    /// errors.
    pub skipped: u32,
    /// Datagrams from other senders than `--udp-from`, ignored.
    pub other_senders: u32,
    /// Datagrams that arrived before the platform was ready to follow them (while it powered up and homed): not
    /// read; the cueing starts at neutral on the first one after.
    pub before_ready: u32,
    /// Telemetry: pauses of more than a second after which the washout started again at neutral.
    pub telemetry_gaps: u32,
    /// Telemetry in `auto`: the format locked onto and the datagram at which (a format dropped after refusing many
    /// datagrams in a row is a lock to none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub telemetry_format_locks: Vec<crate::games::Lock>,
    /// Telemetry: changes of the `--cue-config` file that took effect while streaming (each blended in over a
    /// second).
    pub cue_reloads: u32,
    /// Telemetry: changes of the `--cue-config` file refused (a key out of range; the running configuration
    /// stayed).
    pub cue_refused: u32,
    /// Telemetry cued by the optimal cueing: samples planned, fallbacks (the axes that followed their last plan and
    /// those that took the classical washout's change), samples whose solves took longer than the budget (counted
    /// only), solve time p50/p99/max.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optimal: Option<crate::cueing::optimal::CountsReport>,
    /// Telemetry with the lap preview on: laps completed and kept, departures (each a fade of the preview),
    /// samples without a usable lap distance, time previewed and departed, and the state at the end (the lap,
    /// the lap it was matched to, the preview's share).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lap_preview: Option<crate::cueing::lap::Counts>,
    /// `--telemetry-shm`: the game, its mappings, and its samples, repeats, torn reads and stalls.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shared_memory: Option<super::live::ShmReport>,
    /// Telemetry: reads of the changed `--cue-config` file ignored as not yet whole (empty, cut short: not TOML,
    /// as an editor's truncate-then-write leaves it for a moment); read again at its next change.
    pub cue_ignored: u32,
}

/// The end-of-run report (`--report-json`).
#[derive(Debug, Serialize)]
pub struct Report {
    /// `followed`, `input_errors`, `refused`, `device_stopped`, `transport_lost`, `interrupted` or
    /// `output_failed` (standard output or error could not be written: the run ended as a stop does).
    pub outcome: &'static str,
    /// Why the run ended as it did, when not simply followed.
    pub reason: Option<String>,
    /// The exit code (see [`exit`]).
    pub exit_code: u8,
    /// Final device state.
    pub state: String,
    /// Input setpoints sent (lead-in and settle not included).
    pub setpoints_sent: u32,
    /// Of those, accepted by the device (limited ones included).
    pub setpoints_applied: u32,
    /// Limiting into the envelope.
    pub limited: LimitedReport,
    /// Of the input setpoints, refused by the device, by reason.
    pub rejected: BTreeMap<String, u32>,
    /// Each refused input setpoint: its line (or datagram number) and the reason.
    pub refusals: Vec<InputError>,
    /// Lead-in setpoints (from where the platform was to the first pose, and after each restart).
    pub lead_in_sent: u32,
    /// Settle setpoints (the last pose held at the end).
    pub settle_sent: u32,
    /// Telemetry: setpoints of the washout to neutral while the source paused.
    pub washout_sent: u32,
    /// Setpoints interpolated between a file's rows further apart than a quarter of the stream timeout (one every
    /// 10 ms), so that the stream lives through the gap.
    pub interpolated_sent: u32,
    /// Rows more than a minute apart (not one motion): the stream stopped, the platform rested, and was led in
    /// again at the next row.
    pub restarts: u32,
    /// A live pose source's last pose sent again while it paused (every 10 ms from half the stream timeout on).
    pub held_sent: u32,
    /// Seconds a live source's pauses were bridged (its last pose held, or telemetry washed out), from half the
    /// stream timeout into each pause.
    pub held_s: f64,
    /// The pauses of a live source that were bridged so.
    pub held_gaps: u32,
    /// Step position of each axis at the end.
    pub final_steps: [i64; 6],
    /// Faults the device reported.
    pub faults: Vec<String>,
    /// Input lines or datagrams that could not be used (never sent).
    pub input_errors: Vec<InputError>,
    /// UDP sources: what arrived.
    pub datagrams: Option<DatagramReport>,
    /// The last input pose the device accepted, as sent (after host limiting).
    pub last_applied_pose: Option<[f64; 6]>,
    /// Setpoints (of every kind) whose answer never came while a later request's did: the device answers in order,
    /// so the request or its answer was lost on the link. Not waited for; `counts_agree` is false when any was.
    pub setpoints_unanswered: u32,
    /// The device's counters for this run agree with the host's, and every setpoint sent was answered.
    pub counts_agree: bool,
    /// `--record`: rows written (a row per telemetry sample), or why the record failed.
    pub record: Option<RecordReport>,
    /// `--capture`: datagrams written, or why the capture failed.
    pub capture: Option<CaptureReport>,
}

/// What `--record` wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RecordReport {
    /// The file.
    pub path: String,
    /// Rows written.
    pub rows: u64,
    /// The telemetry rate the run asked of the device (`--record-hz`), if it asked one.
    pub telemetry_hz: Option<u16>,
    /// Telemetry samples the client dropped before they were written (none unless the host fell behind).
    pub dropped: u64,
    /// Rows whose counted steps gave no pose (forward kinematics failed): their followed pose is the device's own.
    pub unsolved: u64,
    /// Why the file could not be written, if it could not.
    pub error: Option<String>,
}

/// What `--capture` wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CaptureReport {
    /// The file.
    pub path: String,
    /// Datagrams written (every one that arrived on the socket, from any sender).
    pub packets: u64,
    /// Why the file could not be written, if it could not: the capture stops there, the stream goes on.
    pub error: Option<String>,
}

/// A refusal's name in the report.
pub(super) fn reason_name(r: RejectReason) -> String {
    match r {
        RejectReason::NonFinite => "non_finite".into(),
        RejectReason::Unreachable => "unreachable".into(),
        RejectReason::GrossJump { outside: None } => "gross_jump".into(),
        RejectReason::GrossJump { outside: Some(c) } => format!("gross_jump+outside:{}", c.name()),
        RejectReason::Stale => "stale".into(),
        RejectReason::NotStreaming => "not_streaming".into(),
        other => format!("{other:?}").to_lowercase(),
    }
}
