//! `ringpod stream`: poses from a file, a built-in motion or UDP datagrams to the controller.
//!
//! Every pose is limited into the envelope on the host first, by the core's own `motion::envelope::limit` in `f64` with
//! the device's margins, so that a board sees few setpoints it has to limit itself; the device limits what is left
//! and refuses only garbage. The run ends with a stop, a wait for rest and a report whose outcome and exit code say
//! whether the input was followed.

pub mod command;
pub mod datagram;
mod feed;
mod loads;
mod prepare;
pub mod record;
mod report;
mod session;
mod source;

use std::collections::{BTreeMap, VecDeque};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::EnvelopeMargins;
use ringpod_core::protocol::{MotionSettings, RigSource, Settings, SettingsKind, Status};
use ringpod_core::safety::{FaultReason, State};

pub use loads::{check_loads, platform as loads_platform};
use prepare::{prepare, telemetry_rate};
pub use report::{CaptureReport, DatagramReport, LimitedReport, RecordReport, Report};
use session::{Stop, StreamError, Streamer, NO_AUX};
pub use source::{motion_pose, read_csv, Amplitude, Axis, Motion, Sine, Source, UdpSource};

pub use crate::input::table::InputError;
use crate::link::client::{Client, ClientError, Transport};
use crate::stream::record::Recorder;

/// Exit codes of `ringpod stream` (the most serious applies).
pub mod exit {
    /// Every input pose was followed (limited ones included).
    pub const FOLLOWED: u8 = 0;
    /// The stream could not start: no device, bad options, the device not ready.
    pub const NOT_STARTED: u8 = 1;
    /// Input lines or datagrams could not be read (never sent); everything readable was followed.
    pub const INPUT_ERRORS: u8 = 3;
    /// The device refused setpoints (not finite, a gross jump, out of order).
    pub const REFUSED: u8 = 4;
    /// The device stopped streaming by itself or latched a fault.
    pub const DEVICE_STOPPED: u8 = 5;
    /// The link to the device was lost.
    pub const TRANSPORT_LOST: u8 = 6;
    /// Everything was followed but `--record` (or `--capture`) could not write its file.
    pub const RECORD_FAILED: u8 = 7;
    /// Interrupted (Ctrl-C).
    pub const INTERRUPTED: u8 = 130;
}

/// Stream settings.
pub struct Options {
    /// Home even if the device is homed already.
    pub home: bool,
    /// Limit poses into the envelope on the host before sending them (the device limits what is left).
    pub host_limits: bool,
    /// No progress bar.
    pub quiet: bool,
    /// Keep the device's telemetry on for someone watching (the workbench); a record turns it on anyway.
    pub telemetry: bool,
    /// The device's telemetry rate for this run (Hz, its `stream.telemetry_hz`; set back afterwards), so that a
    /// record can be taken at the control rate; `None` keeps the device's.
    pub telemetry_hz: Option<u16>,
}

/// A ring platform and its home pose.
#[derive(Debug, Clone, Copy)]
struct Platform {
    /// Its geometry.
    geometry: ringpod_core::kinematics::RingGeometry,
    /// Its home pose.
    home: [f64; 6],
}

/// What the device limits with and where it leads in, as the device says: its rig (geometry and home pose), its
/// envelope margins, stream timeout and pose limits. The host limits into exactly these, so that what it sends
/// passes there, whatever rig and settings the device runs.
struct DeviceEnvelope {
    platform: Platform,
    margins: EnvelopeMargins,
    stream_timeout: Duration,
    limits: MotionSettings,
}

impl<'a, T: Transport> Streamer<'a, T> {
    /// A run on the device's envelope, its counts from zero against the device's status before it (`baseline`).
    fn new(
        client: &'a mut Client<T>,
        interrupted: &'a dyn Fn() -> bool,
        bar: ProgressBar,
        envelope: DeviceEnvelope,
        host_limits: bool,
        baseline: Status,
        recorder: Option<Recorder>,
    ) -> Self {
        let DeviceEnvelope {
            platform,
            margins,
            stream_timeout,
            limits,
        } = envelope;
        Self {
            client,
            interrupted,
            bar,
            mechanism: RingPlatform::new(&platform.geometry),
            margins,
            host_limits,
            limits,
            stream_timeout,
            centre: Pose::from_array(platform.home),
            last_sent: baseline.pose.cast(),
            clock_us: 0,
            seq: 0,
            baseline,
            sent_all: 0,
            applied_all: 0,
            rejected_all: 0,
            device_limited: 0,
            input_sent: 0,
            input_applied: 0,
            lead_in: 0,
            settle: 0,
            washout: 0,
            restarts: 0,
            rejected: BTreeMap::new(),
            refusals: Vec::new(),
            limited: LimitedReport::default(),
            last_applied: None,
            in_flight: VecDeque::new(),
            refused_in_a_row: 0,
            last_refusal: None,
            recorder,
            record_error: None,
        }
    }
}

fn device_envelope<T: Transport>(client: &mut Client<T>) -> Result<DeviceEnvelope, ClientError> {
    let (rig, source, _) = client.rig()?;
    if let RigSource::Refused(_) | RigSource::Unreadable = source {
        // The board runs its compiled-in rig: said before anything moves, not found out from the motion.
        eprintln!("warning: {source}");
    }
    let geometry = rig
        .geometry()
        .map_err(|e| ClientError::Unexpected(format!("the device's rig does not check: {e}")))?;
    let (Settings::Stream(stream), _) = client.settings(SettingsKind::Stream)? else {
        return Err(ClientError::Unexpected(
            "the device answered with another section".into(),
        ));
    };
    // f32 on the device: 1e-6 of each unit more, so a pose the host passed passes there too.
    let margins = EnvelopeMargins(stream.margins.map(|m| m + 1e-6));
    let timeout_ms = stream.timeout_ms;
    // The running rig's pose limits (a live section: what the device limits to now).
    let limits = rig.machine.motion;
    Ok(DeviceEnvelope {
        platform: Platform {
            geometry,
            home: rig.home,
        },
        margins,
        stream_timeout: Duration::from_secs_f64(f64::from(timeout_ms) / 1000.0),
        limits,
    })
}

/// Streams a source and returns the report (also for runs that ended early: its outcome says how). `Err` only
/// when the stream could not start.
pub fn run<T: Transport>(
    client: &mut Client<T>,
    source: Source,
    input_errors: Vec<InputError>,
    options: &Options,
    fast: bool,
    interrupted: &dyn Fn() -> bool,
    recorder: Option<(Recorder, String)>,
) -> Result<Report, ClientError> {
    let (recorder, record_path) = match recorder {
        Some((r, path)) => (Some(r), Some(path)),
        None => (None, None),
    };
    let (baseline, restore_hz) = prepare(
        client,
        options.home,
        recorder.is_some() || options.telemetry,
        options.telemetry_hz,
    )?;
    let envelope = device_envelope(client)?;
    let home = envelope.platform.home;
    let mut source = source;
    if let Source::Udp(udp) = &mut source {
        udp.decoder.centre_on(Pose::from_array(home));
    }
    let bar = progress_bar(&source, options.quiet);
    let limits = envelope.limits;
    let mut s = Streamer::new(
        client,
        interrupted,
        bar,
        envelope,
        options.host_limits,
        baseline,
        recorder,
    );
    let mut input_errors = input_errors;
    let (outcome, datagrams, capture) = feed(&mut s, &mut source, fast, home, &limits, &mut input_errors);
    s.bar.finish_and_clear();
    // Stop, and wait for rest (also after Ctrl-C or a device that stopped by itself).
    let (stop, transport) = match outcome {
        Ok(()) => (None, None),
        Err(StreamError::Stop(stop)) => (Some(stop), None),
        Err(StreamError::Client(e)) => (None, Some(e)),
    };
    let status = if transport.is_none() {
        stop_and_rest(&mut s)
    } else {
        None
    };
    // The samples of the stop and the ramp to rest.
    let _ = s.record();
    let mut record = record_path.map(|path| record_report(&mut s, path));
    // The device's own telemetry rate back (a board stores it): after the record has taken its last samples.
    let rate_error = match restore_hz {
        Some(before) if transport.is_none() => telemetry_rate(s.client, before).err(),
        _ => None,
    };
    if let (Some(r), Some(e)) = (record.as_mut(), rate_error) {
        r.error
            .get_or_insert(format!("the device's telemetry rate was not set back: {e}"));
    }
    if let Some(r) = record.as_mut() {
        r.telemetry_hz = options.telemetry_hz;
    }
    let (status, transport) = match (status, transport) {
        (Some(st), None) => (Some(st), None),
        (None, None) => (None, Some("the device did not answer after the stop".to_string())),
        (_, Some(e)) => (None, Some(e.to_string())),
    };
    let refused: u32 = s.rejected.values().sum();
    let (outcome, reason, code) = verdict(transport, stop.as_ref(), refused, &input_errors, s.input_sent);
    let counts_agree = status.as_ref().is_some_and(|st| {
        let b = &s.baseline;
        st.applied.wrapping_sub(b.applied) == s.applied_all
            && st.rejected.total().wrapping_sub(b.rejected.total()) == s.rejected_all
            && st.limited.count.wrapping_sub(b.limited.count) == s.device_limited
            && s.sent_all == s.applied_all + s.rejected_all
    });
    s.limited.device = s.device_limited;
    Ok(Report {
        outcome,
        reason,
        exit_code: code,
        state: status.as_ref().map_or("unknown".into(), |st| format!("{:?}", st.state)),
        setpoints_sent: s.input_sent,
        setpoints_applied: s.input_applied,
        limited: s.limited,
        rejected: s.rejected,
        refusals: s.refusals,
        lead_in_sent: s.lead_in,
        settle_sent: s.settle,
        washout_sent: s.washout,
        restarts: s.restarts,
        final_steps: status.as_ref().map_or([0; 6], |st| st.steps),
        faults: s.client.faults.iter().map(|f: &FaultReason| f.to_string()).collect(),
        input_errors,
        datagrams,
        last_applied_pose: s.last_applied.map(|p| p.to_array()),
        counts_agree,
        record,
        capture,
    })
}

/// A bar of setpoints for a source of known length, a spinner for a live one (on stderr, hidden without a
/// terminal or with `--quiet`).
fn progress_bar(source: &Source, quiet: bool) -> ProgressBar {
    let total = match source {
        Source::Motion { seconds, rate_hz, .. } => (seconds * rate_hz).round() as u64 + 1,
        Source::Poses(p) => p.len() as u64,
        Source::Udp(_) => 0,
    };
    let bar = if quiet {
        ProgressBar::hidden()
    } else if total > 0 {
        ProgressBar::new(total)
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} setpoints {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Sends the source's poses: timed ones (a motion, a file) on their clock, a live source as it arrives; a live
/// source's datagram counts and capture come back with the outcome.
fn feed<T: Transport>(
    s: &mut Streamer<'_, T>,
    source: &mut Source,
    fast: bool,
    home: [f64; 6],
    limits: &MotionSettings,
    input_errors: &mut Vec<InputError>,
) -> (Result<(), StreamError>, Option<DatagramReport>, Option<CaptureReport>) {
    match source {
        Source::Motion {
            motion,
            sine,
            seconds,
            rate_hz,
        } => {
            let (motion, sine, seconds, rate_hz) = (*motion, *sine, *seconds, *rate_hz);
            if let Some(sine) = &sine {
                eprintln!("{}", sine.describe(limits));
            }
            let n = (seconds * rate_hz).round() as u64;
            let mut poses = (0..=n).map(|k| {
                let t = k as f64 / rate_hz;
                (None, t, motion_pose(motion, sine.as_ref(), t, home, limits), NO_AUX)
            });
            (s.timed(&mut poses, fast), None, None)
        }
        Source::Poses(p) => {
            let mut poses = p.iter().map(|(line, t, pose, aux)| (Some(*line), *t, *pose, *aux));
            (s.timed(&mut poses, fast), None, None)
        }
        Source::Udp(udp) => {
            let mut d = DatagramReport::default();
            let r = s.live(udp, &mut d, input_errors);
            d.telemetry_gaps = udp.decoder.gaps();
            (d.cue_reloads, d.cue_refused) = udp.decoder.reloads();
            let capture = udp.capture.take().map(|(writer, path)| {
                let (packets, error) = writer.finish();
                CaptureReport { path, packets, error }
            });
            (r, Some(d), capture)
        }
    }
}

/// Collects the answers still in flight (a device that stopped streaming has refused them), stops, and waits up
/// to 10 s for rest; the status at rest, or none when the device did not answer.
fn stop_and_rest<T: Transport>(s: &mut Streamer<'_, T>) -> Option<Status> {
    while !s.in_flight.is_empty() {
        if let Err(StreamError::Client(_)) = s.collect(0) {
            break;
        }
    }
    let _ = s.client.stop();
    // The wait for rest runs to its end even after a signal: the platform is brought to rest, then reported.
    let cancel = s.client.cancel.take();
    let status = s.client.wait_for(Duration::from_secs(10), |st| {
        !matches!(st.state, State::Running | State::Stopping)
    });
    s.client.cancel = cancel;
    status.ok()
}

/// What `--record` wrote: its rows, the samples dropped, and why it stopped writing, if it did.
fn record_report<T: Transport>(s: &mut Streamer<'_, T>, path: String) -> RecordReport {
    let dropped = s.client.telemetry_dropped;
    let (rows, error) = match (s.recorder.take(), s.record_error.take()) {
        (Some(r), None) => {
            let rows = r.rows;
            (rows, r.finish().err().map(|e| e.to_string()))
        }
        (r, e) => (r.map_or(0, |r| r.rows), e),
    };
    RecordReport {
        path,
        rows,
        telemetry_hz: None,
        dropped,
        error,
    }
}

/// The run's outcome, its reason and exit code: the most serious of a lost link, a device that stopped, a
/// signal, refusals, input errors, no input at all; else followed.
fn verdict(
    transport: Option<String>,
    stop: Option<&Stop>,
    refused: u32,
    input_errors: &[InputError],
    input_sent: u32,
) -> (&'static str, Option<String>, u8) {
    if let Some(t) = transport {
        ("transport_lost", Some(t), exit::TRANSPORT_LOST)
    } else if let Some(Stop::Device(why)) = stop {
        ("device_stopped", Some(why.clone()), exit::DEVICE_STOPPED)
    } else if let Some(Stop::Interrupted) = stop {
        (
            "interrupted",
            Some("interrupted (a signal, or STOP in the workbench)".to_string()),
            exit::INTERRUPTED,
        )
    } else if refused > 0 {
        (
            "refused",
            Some(format!("the device refused {refused} setpoints")),
            exit::REFUSED,
        )
    } else if !input_errors.is_empty() {
        (
            "input_errors",
            Some(format!("{} input lines could not be read", input_errors.len())),
            exit::INPUT_ERRORS,
        )
    } else if input_sent == 0 {
        (
            "input_errors",
            Some("no pose in the input".to_string()),
            exit::INPUT_ERRORS,
        )
    } else {
        ("followed", None, exit::FOLLOWED)
    }
}
