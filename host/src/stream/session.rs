//! One run of a stream: setpoints sent ahead of their answers, the host's limiting into the device's envelope, the
//! lead-in, settle and washout setpoints, and everything counted for the report.

use std::collections::{BTreeMap, VecDeque};
use std::time::Duration;

use indicatif::ProgressBar;
use ringpod_core::kinematics::{Check, Pose, RingPlatform};
use ringpod_core::motion::{envelope, Accepted, EnvelopeMargins, RejectReason, Setpoint, SpareTargets};
use ringpod_core::protocol::{HostMessage, MotionSettings, Status};
use ringpod_core::safety::{AuxLevels, State};

/// What a setpoint carries beside its pose: the auxiliary outputs it switches and the spare axes' targets (a pose
/// file's `aux1`, `aux2`, `axis7`, `axis8` columns); `None` leaves each as it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Columns {
    /// The auxiliary outputs.
    pub aux: AuxLevels,
    /// The spare axes 7 and 8, in each axis's unit.
    pub spare: SpareTargets,
}

/// A setpoint that leaves the auxiliary outputs and the spare axes as they are (every pose but a pose file's rows
/// with those columns).
pub const NO_AUX: Columns = Columns {
    aux: [None; 2],
    spare: [None; 2],
};

use super::repeats::Say;
use super::report::{reason_name, LimitedReport};
use super::InputError;
use crate::link::client::{setpoint_answer, Client, ClientError, Transport};
use crate::out::console;
use crate::stream::record::Recorder;

/// Setpoints sent ahead of their answers: 16 ms of a 1 kHz stream, far more than a USB or pty round trip.
const IN_FLIGHT: usize = 16;

/// How long the answers to setpoints in flight are waited for: through a device's hold-up (a board's flash erase
/// stalls it about 2 s, a busy machine stalls the simulator), which the device catches up by itself.
const HOLD_UP_PATIENCE: Duration = Duration::from_secs(5);

/// How long without an answer is a stalled link, said as it happens.
const STALLED: Duration = Duration::from_millis(500);

/// Why streaming ended early.
pub(super) enum Stop {
    /// The device stopped streaming or faulted: the reason.
    Device(String),
    /// Ctrl-C.
    Interrupted,
}

/// What a setpoint is for.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Kind {
    /// An input pose, with its line or datagram number.
    Input(Option<usize>),
    LeadIn,
    Settle,
    /// A telemetry source paused: the washout of a vehicle at rest.
    Washout,
    /// Between two rows of a file further apart than [`KEEP_ALIVE`]: the straight line between them.
    Interpolated,
    /// A pose source paused: its last pose again.
    Held,
}

/// The longest a stream goes without a setpoint while its input lasts: a file's rows further apart are joined by
/// interpolated setpoints this far apart, a paused live source's last pose is held at this rate. The device's
/// stream timeout (100 ms by default) is for a host that is gone, not for a pause in what it streams.
pub(super) const KEEP_ALIVE: Duration = Duration::from_millis(10);

/// The way from `a` to `b` on each pose axis, yaw the short way round (as the device measures a jump).
pub(super) fn way(a: &Pose<f64>, b: &Pose<f64>) -> [f64; 6] {
    let (a, b) = (a.to_array(), b.to_array());
    std::array::from_fn(|i| {
        let d = b[i] - a[i];
        if i == 5 {
            (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        } else {
            d
        }
    })
}

/// The pose `f` of the way from `a` along `way`.
fn along(a: &Pose<f64>, way: &[f64; 6], f: f64) -> Pose<f64> {
    let a = a.to_array();
    Pose::from_array(std::array::from_fn(|i| a[i] + way[i] * f))
}

/// One run: the client, the host's clock and envelope, and everything counted.
pub(super) struct Streamer<'a, T: Transport> {
    pub(super) client: &'a mut Client<T>,
    pub(super) interrupted: &'a dyn Fn() -> bool,
    pub(super) bar: ProgressBar,
    pub(super) mechanism: RingPlatform<f64>,
    pub(super) margins: EnvelopeMargins,
    pub(super) host_limits: bool,
    pub(super) limits: MotionSettings,
    pub(super) stream_timeout: Duration,
    /// The middle of the workspace, from which poses are limited (the home pose).
    pub(super) centre: Pose<f64>,
    /// The last pose sent (limited).
    pub(super) last_sent: Pose<f64>,
    pub(super) clock_us: u64,
    pub(super) seq: u32,
    pub(super) baseline: Status,
    // Counts.
    pub(super) sent_all: u32,
    pub(super) applied_all: u32,
    pub(super) rejected_all: u32,
    /// Setpoints whose answer was lost on the link (see `collect`).
    pub(super) unanswered: u32,
    pub(super) device_limited: u32,
    pub(super) input_sent: u32,
    pub(super) input_applied: u32,
    pub(super) lead_in: u32,
    pub(super) settle: u32,
    pub(super) washout: u32,
    pub(super) interpolated: u32,
    pub(super) restarts: u32,
    pub(super) held: u32,
    /// Seconds a paused live source's last pose was held, and the pauses.
    pub(super) held_s: f64,
    pub(super) held_gaps: u32,
    /// The rules an input pose must pass to be sent.
    pub(super) admission: super::admit::Admission,
    pub(super) rejected: BTreeMap<String, u32>,
    pub(super) refusals: Vec<InputError>,
    pub(super) limited: LimitedReport,
    pub(super) last_applied: Option<Pose<f64>>,
    /// Setpoints sent and not yet answered: request id, input line or datagram number, pose.
    pub(super) in_flight: VecDeque<(u32, Option<usize>, Pose<f64>)>,
    pub(super) refused_in_a_row: u32,
    pub(super) last_refusal: Option<String>,
    /// The refusals said on stderr: the first each on a line, then counted (a file of bad rows is thousands).
    pub(super) refusal_lines: super::repeats::Repeats,
    /// `--record`: the open file, and the first write error.
    pub(super) recorder: Option<Recorder>,
    pub(super) record_error: Option<String>,
}

impl<'a, T: Transport> Streamer<'a, T> {
    /// Takes the telemetry that has arrived: written to the record with the pose sent last, or dropped when
    /// nothing records (so the client's queue stays empty).
    pub(super) fn record(&mut self) -> Result<(), ClientError> {
        let samples = self.client.take_telemetry()?;
        if let (Some(r), None) = (self.recorder.as_mut(), &self.record_error) {
            let written = samples
                .iter()
                .try_for_each(|t| r.write(&self.last_sent, t))
                .and_then(|()| r.flush());
            if let Err(e) = written {
                self.record_error = Some(e.to_string());
            }
        }
        Ok(())
    }

    /// Lets `dt` pass on the device's clock, in slices so that Ctrl-C is seen within 50 ms.
    pub(super) fn elapse(&mut self, dt: Duration) -> Result<(), Stop> {
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

    /// Lets `dt` that has already passed on the wall clock pass on the device's too, in one call: a live source's
    /// interval between two arrivals. In slices, a device tied to the wall clock would catch up with the first and
    /// then run the others ahead of it.
    pub(super) fn caught_up(&mut self, dt: Duration) -> Result<(), Stop> {
        if (self.interrupted)() {
            return Err(Stop::Interrupted);
        }
        self.client.transport().elapse(dt);
        let _ = self.record();
        self.clock_us = self.clock_us.saturating_add((dt.as_micros() as u64).max(1));
        Ok(())
    }

    /// Limits a pose into the envelope (host side, f64) on the ray from the centre, as the device does.
    pub(super) fn limit(&mut self, pose: Pose<f64>) -> Pose<f64> {
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

    pub(super) fn count_limit(&mut self, check: Check, translation_m: f64, rotation_rad: f64) {
        *self.limited.by_check.entry(check.name().to_string()).or_default() += 1;
        self.limited.largest_mm = self.limited.largest_mm.max(translation_m * 1e3);
        self.limited.largest_deg = self.limited.largest_deg.max(rotation_rad.to_degrees());
    }

    /// Sends one setpoint without waiting for its answer (a round trip per setpoint would cap the rate at one
    /// per round trip: 1 kHz needs them in flight), then counts the answers that have arrived, waiting while more
    /// than [`IN_FLIGHT`] are outstanding. A device that stops streaming ends the run.
    pub(super) fn send(&mut self, pose: Pose<f64>, kind: Kind, columns: Columns) -> Result<(), StreamError> {
        self.seq = self.seq.wrapping_add(1);
        self.sent_all += 1;
        if let Kind::Input(_) = kind {
            self.input_sent += 1;
        }
        let id = self.client.send(HostMessage::Setpoint(Setpoint {
            seq: self.seq,
            time_us: self.clock_us,
            pose: pose.cast(),
            aux: columns.aux,
            spare: columns.spare,
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
    pub(super) fn collect(&mut self, keep: usize) -> Result<(), StreamError> {
        let step = Duration::from_micros(200);
        let patience = self.client.timeout.max(crate::link::patience(HOLD_UP_PATIENCE));
        let mut waited = Duration::ZERO;
        let mut stalled = false;
        let stall = crate::link::patience(STALLED);
        while let Some(&(id, number, pose)) = self.in_flight.front() {
            let Some(answer) = self.client.take_response(id)? else {
                if self.client.answered_after(id) {
                    // Lost on the link: waiting would stall the stream for good. Counted and reported.
                    self.in_flight.pop_front();
                    self.unanswered += 1;
                    if self.unanswered == 1 {
                        self.bar.suspend(|| {
                            console::err(
                                "a setpoint's answer was lost on the link (the device answered a later request): \
                                 counted in the report, the stream goes on",
                            )
                        });
                    }
                    continue;
                }
                if !stalled && waited >= stall {
                    stalled = true;
                    self.bar.suspend(|| {
                        console::err(&format!(
                            "the link is stalled: no answer from the device for {stall:?} (the stream ends after {patience:?} without one)"
                        ))
                    });
                }
                if self.in_flight.len() <= keep {
                    break;
                }
                // A stopping signal ends the wait at once: the run's loop stops and the ending counts the rest.
                if self.client.cancelled() {
                    break;
                }
                if waited >= patience {
                    return Err(ClientError::Timeout(patience).into());
                }
                self.client.transport().elapse(step);
                waited += step;
                continue;
            };
            if stalled {
                stalled = false;
                let waited = waited.as_secs_f64();
                self.bar
                    .suspend(|| console::err(&format!("the link answered again after {waited:.1} s")));
            }
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
    pub(super) fn answered(
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
                    let line = match self.refusal_lines.note(std::time::Instant::now()) {
                        Say::Line => Some(format!("line {number}: refused by the device: {name}")),
                        Say::Count(n) => Some(format!(
                            "{n} more setpoints refused by the device (the last: line {number}, {name}); the \
                             report lists each"
                        )),
                        Say::Nothing => None,
                    };
                    if let Some(line) = line {
                        self.bar.suspend(|| console::err(&line));
                    }
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
    pub(super) fn start_and_lead_in(&mut self, first: Pose<f64>) -> Result<Pose<f64>, StreamError> {
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
        // Led in to the first pose as limited, also when the device is left to limit what is sent: the lead-in is
        // bounded by the envelope, and the first pose (admitted: limiting moves it by less than a gross jump)
        // follows it without one.
        let target = self.admission.limited(&first);
        let first = self.limit(first);
        let way = way(&now, &target);
        let seconds = (0..6).fold(0.0f64, |m, i| {
            m.max(way[i].abs() / (0.25 * f64::from(self.limits.pose_velocity[i])))
        });
        let n = (seconds * 100.0).ceil() as usize;
        for k in 1..=n {
            let pose = along(&now, &way, k as f64 / n as f64);
            self.elapse(Duration::from_millis(10))?;
            let pose = self.limit(pose);
            self.send(pose, Kind::LeadIn, NO_AUX)?;
            self.lead_in += 1;
        }
        // The first pose follows the lead-in by one of its intervals.
        self.elapse(Duration::from_millis(10))?;
        Ok(first)
    }

    /// Lets `dt` pass between two input poses as sent. Further apart than a quarter of the stream timeout, a
    /// setpoint every [`KEEP_ALIVE`] on the straight line from `from` to `to` (each limited as any pose): the
    /// stream lives through a gap of any length, and the platform moves as the rows, samples of a motion, describe
    /// it (the device interpolates the same line between two setpoints). `to` itself is the caller's to send.
    pub(super) fn between(&mut self, from: &Pose<f64>, to: &Pose<f64>, dt: f64) -> Result<(), StreamError> {
        let n = if dt <= self.stream_timeout.as_secs_f64() / 4.0 {
            1
        } else {
            (dt / KEEP_ALIVE.as_secs_f64()).ceil() as u64
        };
        let step = Duration::from_secs_f64(dt / n as f64);
        let way = way(from, to);
        // A row the device would refuse as a gross jump is not made one by interpolating towards it: the last
        // pose is held through the gap and the device judges the row.
        let jump = (0..6).any(|i| way[i].abs() > self.admission.window[i]);
        for k in 1..n {
            self.elapse(step)?;
            let f = if jump { 0.0 } else { k as f64 / n as f64 };
            let pose = self.limit(along(from, &way, f));
            self.send(pose, Kind::Interpolated, NO_AUX)?;
            self.interpolated += 1;
        }
        self.elapse(step)?;
        Ok(())
    }

    /// Holds the last pose until the platform has arrived there (the device's commanded pose equals its target
    /// and no longer moves), at least 250 ms and at most 10 s: a platform slowed by its limits can be far behind
    /// its source when the source ends, and stopping before it arrives would leave it wherever braking ends.
    ///
    /// Within 2 um (or 2 urad) of the target is not yet there: the trackers cover that in their last tick or two,
    /// and a stop then left the trainer model's linear actuators a step short of where the source ended (a step is
    /// 0.6 um). So the pose must also be the one of the check before, 50 ms earlier: the trackers are at rest.
    pub(super) fn settle(&mut self) -> Result<(), StreamError> {
        let last = self.last_sent;
        let mut before = None;
        for k in 1..=1000u32 {
            self.elapse(Duration::from_millis(10))?;
            self.send(last, Kind::Settle, NO_AUX)?;
            self.settle += 1;
            if k >= 25 && k % 5 == 0 {
                self.collect(0)?;
                let s = self.client.status()?;
                let (p, t) = (s.pose.to_array(), s.target.to_array());
                let near = (0..6).all(|i| {
                    let d = t[i] - p[i];
                    let d = if i == 5 { d.sin().atan2(d.cos()) } else { d };
                    d.abs() <= 2e-6
                });
                if near && before == Some(p) {
                    break;
                }
                before = Some(p);
            }
        }
        Ok(())
    }
}

/// How a stream ended early.
pub(super) enum StreamError {
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
