//! `ringpod stream`: poses from a file, a built-in motion or UDP datagrams to the controller.
//!
//! Every pose is limited into the envelope on the host first, by the core's own `motion::envelope::limit` in `f64` with
//! the device's margins, so that a board sees few setpoints it has to limit itself; the device limits what is left
//! and refuses only garbage. The run ends with a stop, a wait for rest and a report whose outcome and exit code say
//! whether the input was followed. The run record it writes is drawn by `plot` (`record`), its pose's velocity and
//! acceleration by `plot --derivatives` (`derivatives`).

mod admit;
pub mod command;
pub mod datagram;
pub mod derivatives;
mod ending;
mod feed;
pub mod live;
mod loads;
mod prepare;
pub mod record;
mod repeats;
mod report;
mod session;
mod source;

use std::collections::{BTreeMap, VecDeque};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::EnvelopeMargins;
use ringpod_core::protocol::{MotionSettings, RigSource, Settings, SettingsKind, Status};

pub use loads::{check_loads, platform as loads_platform};
use prepare::{greet, prepare};
pub use report::{LimitedReport, Report};
use session::Streamer;
pub use session::NO_AUX;
pub use source::{motion_pose, read_csv, Amplitude, Axis, Motion, Sine, Source};

pub use crate::input::table::InputError;
use crate::link::client::{Client, ClientError, Transport};
use crate::out::console;
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
    /// A stop the device does not answer at the end (a stalled link) is given again every second until it does,
    /// for up to 30 s: the CLI's; the workbench keeps its STOP pending itself.
    pub resend_stop: bool,
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
    /// The device's gross-jump window (ms) and telemetry rate (Hz), from its stream settings.
    gross_jump_ms: u16,
    telemetry_hz: u16,
}

impl DeviceEnvelope {
    /// The rules an input pose must pass on this device.
    fn admission(&self) -> admit::Admission {
        admit::Admission::new(
            &self.platform.geometry,
            self.platform.home,
            self.margins,
            self.limits.pose_velocity,
            self.gross_jump_ms,
        )
    }
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
        let admission = envelope.admission();
        let DeviceEnvelope {
            platform,
            margins,
            stream_timeout,
            limits,
            ..
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
            unanswered: 0,
            device_limited: 0,
            input_sent: 0,
            input_applied: 0,
            lead_in: 0,
            settle: 0,
            washout: 0,
            interpolated: 0,
            restarts: 0,
            held: 0,
            held_s: 0.0,
            held_gaps: 0,
            admission,
            rejected: BTreeMap::new(),
            refusals: Vec::new(),
            limited: LimitedReport::default(),
            last_applied: None,
            in_flight: VecDeque::new(),
            refused_in_a_row: 0,
            last_refusal: None,
            refusal_lines: repeats::Repeats::default(),
            recorder,
            record_error: None,
        }
    }
}

fn device_envelope<T: Transport>(client: &mut Client<T>) -> Result<DeviceEnvelope, ClientError> {
    let (rig, source, _) = client.rig()?;
    if let RigSource::Refused(_) | RigSource::Unreadable = source {
        // The board runs its compiled-in rig: said before anything moves, not found out from the motion.
        console::err(&format!("warning: {source}"));
    }
    let geometry = rig
        .geometry()
        .map_err(|e| ClientError::Unexpected(format!("the device's rig does not check: {e}")))?;
    // From here on the run's telemetry (the record, motion compensation) carries the pose of the counted steps.
    client.followed = crate::link::followed::Followed::of(&rig);
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
        gross_jump_ms: stream.gross_jump_ms,
        telemetry_hz: stream.telemetry_hz,
    })
}

/// Streams a source and returns the report (also for runs that ended early: its outcome says how). `Err` only
/// when the stream could not start. Nothing moves before the input is checked: a pose file whose rows hold no pose
/// to lead in to is reported with the device as it was.
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
    greet(client)?;
    let envelope = device_envelope(client)?;
    if recorder.is_some() && options.telemetry_hz.unwrap_or(envelope.telemetry_hz) == 0 {
        return Err(ClientError::Unexpected(
            "the device's telemetry is off (stream.telemetry_hz 0): a record would have no rows; give --record-hz \
             or set the device's rate"
                .into(),
        ));
    }
    let mut input_errors = input_errors;
    let mut source = source;
    if let Source::Poses(poses) = &mut source {
        lead_rows(poses, &envelope.admission(), &mut input_errors);
        if poses.is_empty() {
            let status = client.status()?;
            let s = Streamer::new(
                client,
                interrupted,
                ProgressBar::hidden(),
                envelope,
                options.host_limits,
                status,
                None,
            );
            return Ok(ending::report(s, ending::unmoved(status), input_errors, None, None));
        }
    }
    let home = envelope.platform.home;
    if let Source::Live(live) = &mut source {
        let home = Pose::from_array(home);
        // The envelope's scan only for a decoder that cues (the optimal cueing plans in it); before anything moves,
        // so that a rig whose home no cueing can move about is refused with the platform as it was.
        let envelope = live
            .decoder
            .cues()
            .then(|| {
                let mechanism = ringpod_core::kinematics::RingPlatform::new(&envelope.platform.geometry);
                crate::cueing::engine::envelope(&mechanism, &home).map_err(|check| {
                    ClientError::Unexpected(format!(
                        "the device's home fails the {check} check (`ringpod check`): cueing moves the platform \
                         about its home, and no pose about it is inside the envelope"
                    ))
                })
            })
            .transpose()?;
        live.decoder.centre_on(home, envelope);
    }
    let (baseline, restore_hz) = prepare(
        client,
        options.home,
        recorder.is_some() || options.telemetry,
        options.telemetry_hz,
    )?;
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
    let (outcome, datagrams, capture) = feed::feed(&mut s, &mut source, fast, home, &limits, &mut input_errors);
    s.bar.finish_and_clear();
    let ending = ending::wind_down(&mut s, outcome, record_path, restore_hz, options);
    Ok(ending::report(s, ending, input_errors, datagrams, capture))
}

/// Drops a pose file's rows before the first one a stream can lead in to (garbage, or far outside the envelope:
/// [`admit::Admission::first`]), each an input error said with its line.
fn lead_rows(poses: &mut Vec<source::TimedPose>, admission: &admit::Admission, errors: &mut Vec<InputError>) {
    let refusals: Vec<(usize, String)> = poses
        .iter()
        .map_while(|(line, _, pose, _)| admission.first(pose).map(|why| (*line, why)))
        .collect();
    poses.drain(..refusals.len());
    for (line, reason) in refusals {
        console::err(&format!("line {line}: {reason}"));
        errors.push(InputError { line, reason });
    }
}

/// A bar of setpoints for a source of known length, a spinner for a live one (on stderr, hidden without a
/// terminal or with `--quiet`).
fn progress_bar(source: &Source, quiet: bool) -> ProgressBar {
    let total = match source {
        Source::Motion { seconds, rate_hz, .. } => (seconds * rate_hz).round() as u64 + 1,
        Source::Poses(p) => p.len() as u64,
        Source::Live(_) => 0,
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
