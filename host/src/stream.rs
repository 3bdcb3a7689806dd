//! `ringpod stream`: poses from a file, a built-in motion or UDP datagrams to the controller.
//!
//! Every pose is limited into the envelope on the host first, by the core's own [`envelope::limit`] in `f64` with
//! the device's margins, so that a board sees few setpoints it has to limit itself; the device limits what is left
//! and refuses only garbage. The run ends with a stop, a wait for rest and a report whose outcome and exit code say
//! whether the input was followed.

use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use ringpod_core::kinematics::presets::{Preset, PresetGeometry, TRAINER_MODEL_RANGES};
use ringpod_core::kinematics::{Check, Mechanism, Pose, RingPlatform};
use ringpod_core::motion::{envelope, Accepted, EnvelopeMargins, MotionLimits, RejectReason, Setpoint};
use ringpod_core::protocol::{HostMessage, RigSource, Settings, SettingsKind, Status};
use ringpod_core::safety::{FaultReason, State};
use serde::Serialize;

use crate::client::{setpoint_answer, Client, ClientError, Transport};
use crate::record::Recorder;

/// Setpoints sent ahead of their answers: 16 ms of a 1 kHz stream, far more than a USB or pty round trip.
const IN_FLIGHT: usize = 16;

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
    /// Everything was followed but `--record` could not write its file.
    pub const RECORD_FAILED: u8 = 7;
    /// Interrupted (Ctrl-C).
    pub const INTERRUPTED: u8 = 130;
}

/// Built-in motions (trainer-model ranges and the test motions of the physical model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Motion {
    /// All six axes at once within a third of their ranges, yaw turning at 0.5 rad/s.
    Demo,
    /// Vertical vibration sweep 1 -> 50 Hz, amplitude limited to stay inside the speed and acceleration limits.
    Vibration,
    /// Continuous yaw at 1.9 rad/s.
    Yaw,
    /// Heave sine, 10 mm at 0.5 Hz.
    Heave,
}

/// A pose of an input file: its line number, its time (s) and the pose.
pub type TimedPose = (usize, f64, Pose<f64>);

/// Where poses come from.
pub enum Source {
    /// A motion, sampled at `rate_hz` for `seconds` (generated as it is sent).
    Motion {
        /// Which.
        motion: Motion,
        /// How long (s).
        seconds: f64,
        /// Setpoints per second.
        rate_hz: f64,
    },
    /// Timed poses from a CSV file.
    Poses(Vec<TimedPose>),
    /// Poses from UDP datagrams, sent as they arrive.
    Udp(UdpSource),
}

/// A live source of poses: simulator software sending one datagram per pose or per telemetry sample.
pub struct UdpSource {
    /// The bound socket.
    pub socket: std::net::UdpSocket,
    /// What a datagram means.
    pub decoder: crate::datagram::Decoder,
    /// End after this long without a datagram.
    pub idle: Duration,
    /// Take datagrams from this address only.
    pub from: Option<std::net::IpAddr>,
}

pub use crate::table::InputError;

/// The columns of a pose file.
pub const POSE_COLUMNS: [&str; 7] = ["t", "x", "y", "z", "alpha", "beta", "gamma"];

/// Reads a pose file: `t,x,y,z,alpha,beta,gamma` named in its header in any order (seconds, metres, radians or
/// degrees; [`crate::table::read`]). NaN and infinity in a pose are passed on: the device refuses them with a
/// reason, which is the point.
pub fn read_csv(text: &str, degrees: bool) -> Result<(Vec<TimedPose>, Vec<InputError>), String> {
    let (rows, errors) = crate::table::read(text, &POSE_COLUMNS)?;
    let a = |x: f64| if degrees { x.to_radians() } else { x };
    let poses = rows
        .into_iter()
        .map(|(line, v)| (line, v[0], Pose::new(v[1], v[2], v[3], a(v[4]), a(v[5]), a(v[6]))))
        .collect();
    Ok((poses, errors))
}

/// `stream --check-loads`: the drive demand of a file's or built-in motion's poses on the trainer model, against
/// its drives, before anything moves.
pub fn check_loads(
    source: &Source,
    payload: &ringpod_core::kinematics::Payload<f64>,
) -> anyhow::Result<crate::demand::Preflight> {
    let PresetGeometry::Ring(geometry) = Preset::TrainerModel.geometry() else {
        anyhow::bail!("the trainer model is a ring platform");
    };
    let ring = RingPlatform::new(geometry);
    let drives = crate::rig::drives::check(&crate::rig::drives::of_preset(Preset::TrainerModel), &ring.axes())?;
    let rows: Vec<(usize, f64, Pose<f64>)> = match source {
        Source::Poses(p) => p.clone(),
        Source::Motion {
            motion,
            seconds,
            rate_hz,
        } => {
            let n = (seconds * rate_hz).round() as usize;
            (0..=n)
                .map(|k| {
                    let t = k as f64 / rate_hz;
                    (k + 1, t, motion_pose(*motion, t, Preset::TrainerModel.home()))
                })
                .collect()
        }
        Source::Udp(_) => anyhow::bail!("--check-loads needs the poses beforehand (--input or --motion)"),
    };
    crate::demand::preflight(&ring, &drives, &rows, payload).map_err(|e| anyhow::anyhow!("--check-loads: {e}"))
}

/// Pose of a built-in motion at time `t` (s) around `home`. Every motion stays inside the envelope at any time
/// and yaw (tested for 120 s each), so host limiting leaves it unchanged.
pub fn motion_pose(motion: Motion, t: f64, home: [f64; 6]) -> Pose<f64> {
    let mut p = home;
    let tau = std::f64::consts::TAU;
    let limits = MotionLimits::TRAINER_MODEL;
    match motion {
        Motion::Demo => {
            // A third of each range (the combined extremes of half the ranges leave the envelope at some yaws),
            // frequencies low enough for the 0.05 m/s and 1 rad/s limits; the motion starts at home and eases in
            // over the first two seconds.
            let ease = (t / 2.0).min(1.0);
            for (i, f) in [0.2, 0.15, 0.25, 0.3, 0.22].iter().enumerate() {
                p[i] += ease * TRAINER_MODEL_RANGES[i] / 3.0 * (tau * f * t).sin();
            }
            p[5] = (0.5 * t * ease).rem_euclid(tau);
        }
        Motion::Vibration => {
            // Sweep the frequency linearly from 1 to 50 Hz over 20 s; the amplitude is the largest that keeps the
            // speed and acceleration inside the limits at the current frequency, capped at 1 mm.
            let f = 1.0 + 49.0 * (t / 20.0).min(1.0);
            let w = tau * f;
            let amp = 0.001f64
                .min(0.8 * f64::from(limits.pose_velocity[2]) / w)
                .min(0.8 * f64::from(limits.pose_acceleration[2]) / (w * w));
            // Phase of the linear chirp: the integral of f over time.
            let s = t.min(20.0);
            let phase = tau * (s + 49.0 * s * s / 40.0 + 50.0 * (t - s));
            p[2] += amp * phase.sin();
        }
        Motion::Yaw => p[5] = (1.9 * t.min(1.0).powi(2) * 0.5 + 1.9 * (t - 1.0).max(0.0)).rem_euclid(tau),
        Motion::Heave => p[2] += 0.010 * (tau * 0.5 * t).sin(),
    }
    Pose::from_array(p)
}

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

/// What came over UDP.
#[derive(Debug, Default, Serialize)]
pub struct DatagramReport {
    /// Datagrams received from the source.
    pub received: u32,
    /// Datagrams that did not parse (also in `input_errors`).
    pub unreadable: u32,
    /// Datagrams from other senders than `--udp-from`, ignored.
    pub other_senders: u32,
    /// Times the source paused longer than the stream timeout and the stream was led in and started again.
    pub resumed: u32,
    /// Telemetry: pauses of more than a second after which the washout started again at neutral.
    pub telemetry_gaps: u32,
}

/// The end-of-run report (`--report-json`).
#[derive(Debug, Serialize)]
pub struct Report {
    /// `followed`, `input_errors`, `refused`, `device_stopped`, `transport_lost` or `interrupted`.
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
    /// Times a gap in the input longer than the stream timeout let the platform come to rest and the stream was
    /// started again.
    pub restarts: u32,
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
    /// The device's counters for this run agree with the host's, and every setpoint sent was answered.
    pub counts_agree: bool,
    /// `--record`: rows written (a row per telemetry sample), or why the record failed.
    pub record: Option<RecordReport>,
}

/// What `--record` wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RecordReport {
    /// The file.
    pub path: String,
    /// Rows written.
    pub rows: u64,
    /// Telemetry samples the client dropped before they were written (none unless the host fell behind).
    pub dropped: u64,
    /// Why the file could not be written, if it could not.
    pub error: Option<String>,
}

/// Stream settings.
pub struct Options {
    /// Home even if the device is homed already.
    pub home: bool,
    /// Limit poses into the envelope on the host before sending them (the device limits what is left).
    pub host_limits: bool,
    /// No progress bar.
    pub quiet: bool,
}

/// A ring platform and its home pose.
#[derive(Debug, Clone, Copy)]
struct Platform {
    /// Its geometry.
    geometry: ringpod_core::kinematics::RingGeometry,
    /// Its home pose.
    home: [f64; 6],
}

fn reason_name(r: RejectReason) -> String {
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

/// Why streaming ended early.
enum Stop {
    /// The device stopped streaming or faulted: the reason.
    Device(String),
    /// Ctrl-C.
    Interrupted,
}

/// What a setpoint is for.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// An input pose, with its line or datagram number.
    Input(Option<usize>),
    LeadIn,
    Settle,
    /// A telemetry source paused: the washout of a vehicle at rest.
    Washout,
}

/// One run: the client, the host's clock and envelope, and everything counted.
struct Streamer<'a, T: Transport> {
    client: &'a mut Client<T>,
    interrupted: &'a dyn Fn() -> bool,
    bar: ProgressBar,
    mechanism: RingPlatform<f64>,
    margins: EnvelopeMargins,
    host_limits: bool,
    limits: MotionLimits,
    stream_timeout: Duration,
    /// The middle of the workspace, from which poses are limited (the home pose).
    centre: Pose<f64>,
    /// The last pose sent (limited).
    last_sent: Pose<f64>,
    clock_us: u64,
    seq: u32,
    baseline: Status,
    // Counts.
    sent_all: u32,
    applied_all: u32,
    rejected_all: u32,
    device_limited: u32,
    input_sent: u32,
    input_applied: u32,
    lead_in: u32,
    settle: u32,
    washout: u32,
    restarts: u32,
    rejected: BTreeMap<String, u32>,
    refusals: Vec<InputError>,
    limited: LimitedReport,
    last_applied: Option<Pose<f64>>,
    /// Setpoints sent and not yet answered: request id, input line or datagram number, pose.
    in_flight: VecDeque<(u32, Option<usize>, Pose<f64>)>,
    refused_in_a_row: u32,
    last_refusal: Option<String>,
    /// `--record`: the open file, and the first write error.
    recorder: Option<Recorder>,
    record_error: Option<String>,
}

impl<'a, T: Transport> Streamer<'a, T> {
    /// Takes the telemetry that has arrived: written to the record with the pose sent last, or dropped when
    /// nothing records (so the client's queue stays empty).
    fn record(&mut self) -> Result<(), ClientError> {
        let samples = self.client.take_telemetry()?;
        if let (Some(r), None) = (self.recorder.as_mut(), &self.record_error) {
            for t in &samples {
                if let Err(e) = r.write(&self.last_sent, t) {
                    self.record_error = Some(e.to_string());
                    break;
                }
            }
        }
        Ok(())
    }

    /// Lets `dt` pass on the device's clock, in slices so that Ctrl-C is seen within 50 ms.
    fn elapse(&mut self, dt: Duration) -> Result<(), Stop> {
        let mut left = dt;
        while !left.is_zero() {
            if (self.interrupted)() {
                return Err(Stop::Interrupted);
            }
            let slice = left.min(Duration::from_millis(50));
            self.client.transport().elapse(slice);
            left -= slice;
            // A lost transport shows at the next request; the record only misses what it could not read.
            let _ = self.record();
        }
        self.clock_us = self.clock_us.saturating_add((dt.as_micros() as u64).max(1));
        Ok(())
    }

    /// Limits a pose into the envelope (host side, f64) on the ray from the centre, as the device does.
    fn limit(&mut self, pose: Pose<f64>) -> Pose<f64> {
        if !self.host_limits || !pose.to_array().iter().all(|c| c.is_finite()) {
            // Garbage goes to the device as it is, to be refused with its reason.
            return pose;
        }
        let limited = envelope::limit(&self.mechanism, &self.centre, &pose, &self.margins, 16);
        if let Some(check) = limited.bound_by {
            let (mm, rad) = envelope::correction(&pose, &limited.pose);
            self.limited.host += 1;
            self.count_limit(check, mm, rad);
        }
        limited.pose
    }

    fn count_limit(&mut self, check: Check, translation_m: f64, rotation_rad: f64) {
        *self.limited.by_check.entry(check.name().to_string()).or_default() += 1;
        self.limited.largest_mm = self.limited.largest_mm.max(translation_m * 1e3);
        self.limited.largest_deg = self.limited.largest_deg.max(rotation_rad.to_degrees());
    }

    /// Sends one setpoint without waiting for its answer (a round trip per setpoint would cap the rate at one
    /// per round trip: 1 kHz needs them in flight), then counts the answers that have arrived, waiting while more
    /// than [`IN_FLIGHT`] are outstanding. A device that stops streaming ends the run.
    fn send(&mut self, pose: Pose<f64>, kind: Kind) -> Result<(), StreamError> {
        self.seq = self.seq.wrapping_add(1);
        self.sent_all += 1;
        if let Kind::Input(_) = kind {
            self.input_sent += 1;
        }
        let id = self.client.send(HostMessage::Setpoint(Setpoint {
            seq: self.seq,
            time_us: self.clock_us,
            pose: pose.cast(),
        }))?;
        if pose.to_array().iter().all(|c| c.is_finite()) {
            self.last_sent = pose;
        }
        let number = match kind {
            Kind::Input(line) => Some(line.unwrap_or(self.input_sent as usize)),
            _ => None,
        };
        self.in_flight.push_back((id, number, pose));
        self.collect(IN_FLIGHT)
    }

    /// Counts the answers to setpoints in flight, in order, until at most `keep` are outstanding.
    fn collect(&mut self, keep: usize) -> Result<(), StreamError> {
        let step = Duration::from_micros(200);
        let mut waited = Duration::ZERO;
        while let Some(&(id, number, pose)) = self.in_flight.front() {
            let Some(answer) = self.client.take_response(id)? else {
                if self.in_flight.len() <= keep {
                    break;
                }
                if waited >= self.client.timeout {
                    return Err(ClientError::Timeout(self.client.timeout).into());
                }
                self.client.transport().elapse(step);
                waited += step;
                continue;
            };
            self.in_flight.pop_front();
            self.answered(setpoint_answer(answer)?, number, pose)?;
        }
        self.record()?;
        if let Some(f) = self.client.faults.last() {
            return Err(StreamError::Stop(Stop::Device(format!(
                "the device latched a fault: {f}"
            ))));
        }
        Ok(())
    }

    /// Counts one answer; `number` is an input setpoint's line or datagram number (`None`: lead-in or settle).
    fn answered(
        &mut self,
        answer: Result<Accepted, RejectReason>,
        number: Option<usize>,
        pose: Pose<f64>,
    ) -> Result<(), StreamError> {
        match answer {
            Ok(accepted) => {
                self.applied_all += 1;
                self.refused_in_a_row = 0;
                if let Accepted::Limited(r) = accepted {
                    self.device_limited += 1;
                    self.count_limit(r.check, f64::from(r.translation), f64::from(r.rotation));
                }
                if number.is_some() {
                    self.input_applied += 1;
                    self.last_applied = Some(pose);
                }
            }
            Err(reason) => {
                self.rejected_all += 1;
                let name = reason_name(reason);
                if let Some(number) = number {
                    *self.rejected.entry(name.clone()).or_default() += 1;
                    self.bar
                        .suspend(|| eprintln!("line {number}: refused by the device: {name}"));
                    self.refusals.push(InputError {
                        line: number,
                        reason: name.clone(),
                    });
                }
                if reason == RejectReason::NotStreaming {
                    let status = self.client.status()?;
                    let fault = self
                        .client
                        .faults
                        .last()
                        .map_or(String::new(), |f| format!(": fault {f}"));
                    let before = match &self.last_refusal {
                        Some(last) if self.refused_in_a_row > 0 => format!(
                            ", after {} refused setpoints in a row (the last: {last})",
                            self.refused_in_a_row
                        ),
                        _ => String::new(),
                    };
                    return Err(StreamError::Stop(Stop::Device(format!(
                        "the device stopped streaming ({:?}){fault}{before}",
                        status.state
                    ))));
                }
                self.refused_in_a_row += 1;
                self.last_refusal = Some(name);
            }
        }
        Ok(())
    }

    /// Starts the stream (the device must be `Ready`) and leads the platform from where it is to `first` at a
    /// quarter of the speed limits, at 100 Hz. Returns `first` as limited.
    fn start_and_lead_in(&mut self, first: Pose<f64>) -> Result<Pose<f64>, StreamError> {
        self.collect(0)?;
        let status = self.client.wait_for(Duration::from_secs(10), |s| {
            !matches!(s.state, State::Running | State::Stopping)
        })?;
        if status.state != State::Ready {
            return Err(StreamError::Stop(Stop::Device(format!(
                "the device is in {:?}, not ready to stream",
                status.state
            ))));
        }
        self.client.start()?;
        let now = status.pose.cast::<f64>();
        self.last_sent = now;
        let first = self.limit(first);
        let (a, b) = (now.to_array(), first.to_array());
        // The way from here to the first pose; yaw the short way round.
        let way: [f64; 6] = std::array::from_fn(|i| {
            let d = b[i] - a[i];
            if i == 5 {
                (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
            } else {
                d
            }
        });
        let seconds = (0..6).fold(0.0f64, |m, i| {
            m.max(way[i].abs() / (0.25 * f64::from(self.limits.pose_velocity[i])))
        });
        let n = (seconds * 100.0).ceil() as usize;
        for k in 1..=n {
            let f = k as f64 / n as f64;
            let pose = Pose::from_array(std::array::from_fn(|i| a[i] + way[i] * f));
            self.elapse(Duration::from_millis(10))?;
            let pose = self.limit(pose);
            self.send(pose, Kind::LeadIn)?;
            self.lead_in += 1;
        }
        // The first pose follows the lead-in by one of its intervals.
        self.elapse(Duration::from_millis(10))?;
        Ok(first)
    }

    /// Holds the last pose until the platform has arrived there (the device's commanded pose equals its target),
    /// at least 250 ms and at most 10 s: a platform slowed by its limits can be far behind its source when the
    /// source ends, and stopping before it arrives would leave it wherever braking ends.
    fn settle(&mut self) -> Result<(), StreamError> {
        let last = self.last_sent;
        for k in 1..=1000u32 {
            self.elapse(Duration::from_millis(10))?;
            self.send(last, Kind::Settle)?;
            self.settle += 1;
            if k >= 25 && k % 5 == 0 {
                self.collect(0)?;
                let s = self.client.status()?;
                let (p, t) = (s.pose.to_array(), s.target.to_array());
                let arrived = (0..6).all(|i| {
                    let d = t[i] - p[i];
                    let d = if i == 5 { d.sin().atan2(d.cos()) } else { d };
                    d.abs() <= 2e-6
                });
                if arrived {
                    break;
                }
            }
        }
        Ok(())
    }

    /// Streams timed poses (a file or a motion): each at its own time; a gap longer than the stream timeout
    /// lets the platform come to rest, and the stream is led in and started again at the next pose.
    fn timed(
        &mut self,
        poses: &mut dyn Iterator<Item = (Option<usize>, f64, Pose<f64>)>,
        fast: bool,
    ) -> Result<(), StreamError> {
        let mut last_t: Option<f64> = None;
        for (line, t, pose) in poses {
            if (self.interrupted)() {
                return Err(StreamError::Stop(Stop::Interrupted));
            }
            let gap = last_t.map_or(0.0, |l| (t - l).max(0.0));
            let pose = match last_t {
                None => self.start_and_lead_in(pose)?,
                Some(_) if gap > self.stream_timeout.as_secs_f64() => {
                    // The device brakes to rest by itself; nothing happens after that, so a fast run does not
                    // compute the rest of the gap.
                    let wait = if fast { gap.min(3.0) } else { gap };
                    self.elapse(Duration::from_secs_f64(wait))?;
                    self.restarts += 1;
                    self.bar
                        .suspend(|| eprintln!("{gap:.3} s gap in the input: the platform rests, then leads in again"));
                    self.start_and_lead_in(pose)?
                }
                Some(_) => {
                    self.elapse(Duration::from_secs_f64(gap))?;
                    self.limit(pose)
                }
            };
            last_t = Some(t);
            self.send(pose, Kind::Input(line))?;
            self.bar.inc(1);
        }
        if last_t.is_some() {
            self.settle()?;
        }
        self.collect(0)
    }

    /// Streams datagrams as they arrive: the platform waits where it is for the first one, leads in and starts;
    /// a pause longer than the stream timeout brakes it to rest, and the next datagram leads in and starts again;
    /// `idle` without a datagram ends the session.
    fn live(
        &mut self,
        source: &mut UdpSource,
        report: &mut DatagramReport,
        errors: &mut Vec<InputError>,
    ) -> Result<(), StreamError> {
        source
            .socket
            .set_read_timeout(Some(Duration::from_millis(1)))
            .map_err(ClientError::Io)?;
        self.bar.suspend(|| {
            eprintln!(
                "streaming: send datagrams to {}",
                source.socket.local_addr().map_or("?".into(), |a| a.to_string())
            )
        });
        // The largest UDP payload: no datagram is ever cut.
        let mut buf = vec![0u8; 65_536];
        let mut wall = Instant::now();
        let mut last_datagram = Instant::now();
        let mut last_idle = Instant::now();
        let mut streaming = false;
        loop {
            if (self.interrupted)() {
                return Err(StreamError::Stop(Stop::Interrupted));
            }
            let got = source.socket.recv_from(&mut buf);
            let now = Instant::now();
            self.elapse(now - wall)?;
            wall = now;
            let (n, from) = match got {
                Ok(got) => got,
                // A signal (Ctrl-C) interrupts the wait: nothing arrived, and the loop then sees the flag.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    let quiet = now - last_datagram;
                    // Telemetry that pauses washes out: the vehicle at rest, through the washout, every 10 ms
                    // from half the stream timeout on, so the platform glides back to neutral.
                    if streaming && quiet > self.stream_timeout / 2 && now - last_idle >= Duration::from_millis(10) {
                        let dt = (now - last_idle).min(Duration::from_millis(20)).as_secs_f64();
                        last_idle = now;
                        if let Some(pose) = source.decoder.idle(dt, now) {
                            let pose = self.limit(pose);
                            self.send(pose, Kind::Washout)?;
                            self.washout += 1;
                            continue;
                        }
                    }
                    if streaming && quiet > self.stream_timeout && !source.decoder.washes_out() {
                        // The source paused (a game's menu): the device brakes to rest by itself.
                        streaming = false;
                        if self.last_applied.is_some() {
                            self.bar.suspend(|| eprintln!("the source paused: the platform rests"));
                        }
                    }
                    if quiet >= source.idle {
                        return self.collect(0);
                    }
                    continue;
                }
                Err(e) => return Err(ClientError::Io(e).into()),
            };
            if source.from.is_some_and(|ip| ip != from.ip()) {
                report.other_senders += 1;
                continue;
            }
            last_datagram = now;
            last_idle = now;
            report.received += 1;
            let number = report.received as usize;
            let pose = match source.decoder.decode(&buf[..n], now) {
                Ok(pose) => pose,
                Err(reason) => {
                    report.unreadable += 1;
                    self.bar.suspend(|| eprintln!("datagram {number}: {reason}"));
                    errors.push(InputError { line: number, reason });
                    continue;
                }
            };
            let pose = if streaming {
                self.limit(pose)
            } else {
                if self.last_applied.is_some() {
                    report.resumed += 1;
                }
                streaming = true;
                self.start_and_lead_in(pose)?
            };
            self.send(pose, Kind::Input(Some(number)))?;
            self.bar.inc(1);
            // The lead-in let its own time pass: the device's clock is already there.
            wall = Instant::now();
        }
    }
}

/// How a stream ended early.
enum StreamError {
    Stop(Stop),
    Client(ClientError),
}

impl From<ClientError> for StreamError {
    fn from(e: ClientError) -> Self {
        match e {
            ClientError::Interrupted => StreamError::Stop(Stop::Interrupted),
            other => StreamError::Client(other),
        }
    }
}

impl From<Stop> for StreamError {
    fn from(s: Stop) -> Self {
        StreamError::Stop(s)
    }
}

/// Brings the device to `Ready`: hello, power up, home if needed. Errors here mean the stream never started.
fn prepare<T: Transport>(client: &mut Client<T>, home: bool, telemetry: bool) -> Result<Status, ClientError> {
    let device = client.hello()?;
    if device.preset != Some(Preset::TrainerModel) {
        eprintln!(
            "note: the device drives {}",
            device.preset.map_or("a geometry of its own", |p| p.name())
        );
    }
    if telemetry {
        // From here on: the record covers powering up and homing too.
        client.telemetry(true)?;
    }
    let mut status = client.status()?;
    if matches!(status.state, State::Fault(..)) {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}: clear the fault first",
            status.state
        )));
    }
    if matches!(status.state, State::Running | State::Stopping) {
        client.stop()?;
        status = client.wait_for(Duration::from_secs(10), |s| !matches!(s.state, State::Stopping))?;
    }
    if status.state == State::Off {
        client.enable()?;
        status = client.wait_for(Duration::from_secs(5), |s| {
            matches!(s.state, State::PowerOn { settled: true } | State::Fault(..))
        })?;
    }
    if !status.homed || home {
        client.home()?;
        let homed = client.wait_for(Duration::from_secs(120), |s| {
            matches!(s.state, State::Ready | State::Fault(..))
        });
        status = match homed {
            Ok(s) => s,
            Err(e) => {
                // Ctrl-C or a timeout during homing: abort it before saying so.
                let _ = client.stop();
                return Err(e);
            }
        };
    }
    if status.state != State::Ready {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}, not ready",
            status.state
        )));
    }
    Ok(status)
}

/// The device's envelope margins and stream timeout (the host limits with the same margins, a rounding more).
/// What the device limits with and where it leads in, as the device says: its rig (geometry and home pose), its
/// envelope margins, stream timeout and pose limits. The host limits into exactly these, so that what it sends
/// passes there, whatever rig and settings the device runs.
struct DeviceEnvelope {
    platform: Platform,
    margins: EnvelopeMargins,
    stream_timeout: Duration,
    limits: MotionLimits,
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
    let limits = MotionLimits {
        pose_velocity: rig.machine.motion.pose_velocity,
        pose_acceleration: rig.machine.motion.pose_acceleration,
        ..MotionLimits::TRAINER_MODEL
    };
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
    let baseline = prepare(client, options.home, recorder.is_some())?;
    let DeviceEnvelope {
        platform,
        margins,
        stream_timeout,
        limits,
    } = device_envelope(client)?;
    let geometry = &platform.geometry;
    let total = match &source {
        Source::Motion { seconds, rate_hz, .. } => (seconds * rate_hz).round() as u64 + 1,
        Source::Poses(p) => p.len() as u64,
        Source::Udp(_) => 0,
    };
    let bar = if options.quiet {
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
    let mut s = Streamer {
        client,
        interrupted,
        bar,
        mechanism: RingPlatform::new(geometry),
        margins,
        host_limits: options.host_limits,
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
    };
    let mut input_errors = input_errors;
    let mut datagrams = None;
    let home = platform.home;
    let mut source = source;
    let outcome = match &mut source {
        Source::Motion {
            motion,
            seconds,
            rate_hz,
        } => {
            let (motion, seconds, rate_hz) = (*motion, *seconds, *rate_hz);
            let n = (seconds * rate_hz).round() as u64;
            let mut poses = (0..=n).map(|k| {
                let t = k as f64 / rate_hz;
                (None, t, motion_pose(motion, t, home))
            });
            s.timed(&mut poses, fast)
        }
        Source::Poses(p) => {
            let mut poses = p.iter().map(|(line, t, pose)| (Some(*line), *t, *pose));
            s.timed(&mut poses, fast)
        }
        Source::Udp(udp) => {
            let mut d = DatagramReport::default();
            let r = s.live(udp, &mut d, &mut input_errors);
            d.telemetry_gaps = udp.decoder.gaps();
            datagrams = Some(d);
            r
        }
    };
    s.bar.finish_and_clear();
    // Stop, and wait for rest (also after Ctrl-C or a device that stopped by itself).
    let (stop, transport) = match outcome {
        Ok(()) => (None, None),
        Err(StreamError::Stop(stop)) => (Some(stop), None),
        Err(StreamError::Client(e)) => (None, Some(e)),
    };
    let status = if transport.is_none() {
        // The answers still in flight count too (a device that stopped streaming has refused them).
        while !s.in_flight.is_empty() {
            if let Err(StreamError::Client(_)) = s.collect(0) {
                break;
            }
        }
        let _ = s.client.stop();
        let cancel = s.client.cancel.take();
        let status = s.client.wait_for(Duration::from_secs(10), |st| {
            !matches!(st.state, State::Running | State::Stopping)
        });
        s.client.cancel = cancel;
        status.ok()
    } else {
        None
    };
    // The samples of the stop and the ramp to rest.
    let _ = s.record();
    let record = record_path.map(|path| {
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
            dropped,
            error,
        }
    });
    let (status, transport) = match (status, transport) {
        (Some(st), None) => (Some(st), None),
        (None, None) => (None, Some("the device did not answer after the stop".to_string())),
        (_, Some(e)) => (None, Some(e.to_string())),
    };
    let refused: u32 = s.rejected.values().sum();
    let (outcome, reason, code) = if let Some(t) = transport {
        ("transport_lost", Some(t), exit::TRANSPORT_LOST)
    } else if let Some(Stop::Device(why)) = &stop {
        ("device_stopped", Some(why.clone()), exit::DEVICE_STOPPED)
    } else if let Some(Stop::Interrupted) = &stop {
        (
            "interrupted",
            Some("interrupted (Ctrl-C)".to_string()),
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
    } else if s.input_sent == 0 {
        (
            "input_errors",
            Some("no pose in the input".to_string()),
            exit::INPUT_ERRORS,
        )
    } else {
        ("followed", None, exit::FOLLOWED)
    };
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
    })
}
