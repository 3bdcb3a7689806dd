//! Feeding a run its poses: those known beforehand (a file, a motion) each at its own time, or a live source's (UDP
//! datagrams, a game's shared memory) as they arrive, with the washout while it pauses.

use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use ringpod_core::kinematics::Pose;

use ringpod_core::protocol::MotionSettings;

use super::live::{Arrival, LiveSource};
use super::report::{CaptureReport, DatagramReport};
use super::session::{Columns, Kind, Stop, StreamError, Streamer, KEEP_ALIVE, NO_AUX};
use super::{motion_pose, InputError, Source};
use crate::link::client::{ClientError, Transport};
use crate::out::console;

/// Rows further apart than this (s) are not samples of one motion: the platform rests between them.
const LONGEST_GAP: f64 = 60.0;

impl<T: Transport> Streamer<'_, T> {
    /// Stops the stream and lets the platform come to rest for a gap of `gap` seconds between two rows (a fast
    /// run does not compute more than 3 s of a device at rest).
    fn rest(&mut self, gap: f64, fast: bool) -> Result<(), StreamError> {
        self.collect(0)?;
        self.client.stop()?;
        let wait = if fast { gap.min(3.0) } else { gap };
        self.elapse(Duration::from_secs_f64(wait))?;
        self.restarts += 1;
        self.bar.suspend(|| {
            console::err(&format!(
                "{gap:.3} s between two rows: the stream stops, the platform rests, then leads in again"
            ))
        });
        Ok(())
    }

    /// Streams timed poses (a file or a motion): each at its own time, rows further apart than a quarter of the
    /// stream timeout joined by interpolated setpoints ([`Streamer::between`]); rows more than [`LONGEST_GAP`]
    /// apart are not one motion: the stream stops, the platform rests, and leads in again at the next row
    /// (`restarts`). Garbage is refused here, named and counted in `errors`, never sent; the pose a stream leads
    /// in to must be one it can.
    pub(super) fn timed(
        &mut self,
        poses: &mut dyn Iterator<Item = (Option<usize>, f64, Pose<f64>, Columns)>,
        fast: bool,
        errors: &mut Vec<InputError>,
    ) -> Result<(), StreamError> {
        // The last row sent: its time and its pose as sent.
        let mut last: Option<(f64, Pose<f64>)> = None;
        for (line, t, pose, aux) in poses {
            if (self.interrupted)() {
                return Err(StreamError::Stop(Stop::Interrupted));
            }
            let resting = last.is_some_and(|(l, _)| t - l > LONGEST_GAP);
            let refused = match last {
                Some(_) if !resting => self.admission.garbage(&pose),
                _ => self.admission.first(&pose),
            };
            if let Some(reason) = refused {
                let line = line.unwrap_or(self.input_sent as usize + 1);
                self.bar.suspend(|| console::err(&format!("line {line}: {reason}")));
                errors.push(InputError { line, reason });
                continue;
            }
            let pose = match last {
                None => self.start_and_lead_in(pose)?,
                Some((l, _)) if resting => {
                    self.rest(t - l, fast)?;
                    self.start_and_lead_in(pose)?
                }
                Some((l, from)) => {
                    let to = self.limit(pose);
                    self.between(&from, &to, (t - l).max(0.0))?;
                    to
                }
            };
            last = Some((t, pose));
            self.send(pose, Kind::Input(line), aux)?;
            self.bar.inc(1);
        }
        if last.is_some() {
            self.settle()?;
        }
        self.collect(0)
    }

    /// Streams a live source's samples as they arrive: the platform waits where it is for the first one, leads in
    /// and starts; while the source pauses, the stream stays alive (telemetry washes out to neutral, a pose source's
    /// last pose is held, counted in `held_s` and `held_gaps`); `idle` without a readable sample ends the session.
    pub(super) fn live(
        &mut self,
        source: &mut LiveSource,
        report: &mut DatagramReport,
        errors: &mut Vec<InputError>,
    ) -> Result<(), StreamError> {
        source.receiver.start().map_err(ClientError::Io)?;
        // The largest UDP payload: no datagram is ever cut.
        let mut buf = vec![0u8; 65_536];
        // A game started first: what it sent while the platform powered up and homed is no motion to follow now
        // (replayed in a burst, seconds of it would be played in milliseconds).
        report.before_ready += drop_queued(source, &mut buf);
        let listening = source.receiver.describe();
        self.bar.suspend(|| console::err(&format!("streaming: {listening}")));
        let mut wall = Instant::now();
        let mut last_pose = Instant::now();
        let mut last_idle = Instant::now();
        let mut streaming = false;
        let mut pausing = false;
        loop {
            if (self.interrupted)() {
                return Err(StreamError::Stop(Stop::Interrupted));
            }
            let got = source.receiver.receive(&mut buf).map_err(ClientError::Io)?;
            let now = Instant::now();
            if let Some(news) = source.receiver.news() {
                self.bar.suspend(|| console::err(&format!("telemetry: {news}")));
            }
            capture(source, &buf, got.as_ref());
            // A changed cueing file takes over here, between two samples.
            source.decoder.poll_config(now);
            self.caught_up(now - wall)?;
            wall = now;
            // Only a readable sample of the source counts as the source being there: a stranger's datagrams and
            // unreadable ones (a flood of them included) leave the pause logic below running.
            let readable = got.and_then(|got| read(source, &buf, got, now, report, errors, &self.bar));
            let admitted =
                readable.and_then(|(n, pose)| self.admit(n, pose, streaming, report, errors).map(|p| (n, p)));
            let Some((number, pose)) = admitted else {
                let quiet = now - last_pose;
                // A pause: from half the stream timeout on, a setpoint every 10 ms keeps the stream alive.
                if streaming && quiet > self.stream_timeout / 2 && now - last_idle >= KEEP_ALIVE {
                    let dt = (now - last_idle).min(2 * KEEP_ALIVE);
                    last_idle = now;
                    if !pausing {
                        pausing = true;
                        self.held_gaps += 1;
                    }
                    self.bridge(source, dt, now)?;
                }
                if quiet >= source.idle {
                    return self.collect(0);
                }
                continue;
            };
            last_pose = now;
            last_idle = now;
            pausing = false;
            let pose = if streaming {
                self.limit(pose)
            } else {
                streaming = true;
                let pose = self.start_and_lead_in(pose)?;
                // The lead-in ran on the device's clock; the samples come on the wall clock.
                self.client.transport().keep_pace();
                // The lead-in let its own time pass: the device's clock is already there. Only here: after any
                // other sample the time its work took is the next interval's, or the intervals sent would add up
                // to less than the wall's.
                wall = Instant::now();
                pose
            };
            self.send(pose, Kind::Input(Some(number)), NO_AUX)?;
            self.bar.inc(1);
        }
    }
}

/// Drops the datagrams queued in the socket (captured all the same) and returns how many; shared memory holds no
/// queue, only the game's newest sample.
fn drop_queued(source: &mut LiveSource, buf: &mut [u8]) -> u32 {
    let mut dropped = 0;
    if !matches!(source.receiver, super::live::Receiver::Udp(_)) {
        return dropped;
    }
    // Bounded: a flood does not keep the stream from starting (the socket's reads wait a millisecond).
    for _ in 0..100_000 {
        match source.receiver.receive(buf) {
            Ok(Some(arrival)) => {
                capture(source, buf, Some(&arrival));
                dropped += 1;
            }
            Ok(None) | Err(_) => break,
        }
    }
    dropped
}

/// `--capture`: a datagram as it came (from any sender, readable or not), a shared-memory sample as a line of the
/// `text` telemetry format (its refusals are not samples: not captured).
fn capture(source: &mut LiveSource, buf: &[u8], got: Option<&Arrival>) {
    let Some((writer, _)) = source.capture.as_mut() else {
        return;
    };
    match got {
        Some(Arrival::Datagram { len, from }) => writer.write(&buf[..*len], *from, std::time::SystemTime::now()),
        Some(Arrival::Sample(Ok(sample))) => {
            let line = crate::games::shm::text_line(sample);
            writer.write(line.as_bytes(), super::live::SHM_CAPTURE, std::time::SystemTime::now());
        }
        Some(Arrival::Sample(Err(_))) | None => {}
    }
}

impl<T: Transport> Streamer<'_, T> {
    /// A readable datagram's pose if it may be sent: garbage, or a pose to lead in to that is too far outside, is
    /// refused with its number and counted as unreadable.
    fn admit(
        &mut self,
        number: usize,
        pose: Pose<f64>,
        streaming: bool,
        report: &mut DatagramReport,
        errors: &mut Vec<InputError>,
    ) -> Option<Pose<f64>> {
        let refused = if streaming {
            self.admission.garbage(&pose)
        } else {
            self.admission.first(&pose)
        };
        let Some(reason) = refused else {
            return Some(pose);
        };
        report.unreadable += 1;
        self.bar
            .suspend(|| console::err(&format!("datagram {number}: {reason}")));
        errors.push(InputError { line: number, reason });
        None
    }

    /// One setpoint `dt` into a pause of a live source, keeping the stream alive: the vehicle at rest through the
    /// washout (the platform glides back to neutral), or a pose source's last pose held.
    fn bridge(&mut self, source: &mut LiveSource, dt: Duration, now: Instant) -> Result<(), StreamError> {
        self.held_s += dt.as_secs_f64();
        match source.decoder.idle(dt.as_secs_f64(), now) {
            Some(pose) => {
                let pose = self.limit(pose);
                self.send(pose, Kind::Washout, NO_AUX)?;
                self.washout += 1;
            }
            None => {
                let last = self.last_sent;
                self.send(last, Kind::Held, NO_AUX)?;
                self.held += 1;
            }
        }
        Ok(())
    }
}

/// One arrival of the live source (a datagram, a shared-memory sample): counted, and decoded into its number and
/// pose, or reported as unreadable (or ignored as a stranger's) with `None`.
fn read(
    source: &mut LiveSource,
    buf: &[u8],
    got: Arrival,
    now: Instant,
    report: &mut DatagramReport,
    errors: &mut Vec<InputError>,
    bar: &ProgressBar,
) -> Option<(usize, ringpod_core::kinematics::Pose<f64>)> {
    if let Arrival::Datagram { from, .. } = got {
        if source.from.is_some_and(|ip| ip != from.ip()) {
            report.other_senders += 1;
            return None;
        }
    }
    report.received += 1;
    let number = report.received as usize;
    let decoded = match got {
        Arrival::Datagram { len, .. } => source.decoder.decode(&buf[..len], now),
        Arrival::Sample(sample) => source.decoder.cue(sample, now).map(Some),
    };
    match decoded {
        Ok(Some(pose)) => Some((number, pose)),
        // Another of the game's packets: counted apart; no motion, so the source pauses as far as cueing goes.
        Ok(None) => {
            report.skipped += 1;
            None
        }
        Err(reason) => {
            report.unreadable += 1;
            // The first few of each kind, cut to a line: a source can send anything, for as long as it likes.
            if let Some(kept) = crate::input::unreadable::tally(&mut report.unreadable_by_kind, number, &reason) {
                bar.suspend(|| console::err(&format!("datagram {number}: {}", kept.reason)));
                errors.push(kept);
            }
            None
        }
    }
}

/// Sends the source's poses: timed ones (a motion, a file) on their clock, a live source as it arrives; a live
/// source's datagram counts and capture come back with the outcome.
pub(super) fn feed<T: Transport>(
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
                console::err(&sine.describe(limits));
            }
            let n = (seconds * rate_hz).round() as u64;
            let mut poses = (0..=n).map(|k| {
                let t = k as f64 / rate_hz;
                (None, t, motion_pose(motion, sine.as_ref(), t, home, limits), NO_AUX)
            });
            (s.timed(&mut poses, fast, input_errors), None, None)
        }
        Source::Poses(p) => {
            let mut poses = p.iter().map(|(line, t, pose, aux)| (Some(*line), *t, *pose, *aux));
            (s.timed(&mut poses, fast, input_errors), None, None)
        }
        Source::Live(udp) => {
            let mut d = DatagramReport::default();
            let r = s.live(udp, &mut d, input_errors);
            d.shared_memory = udp.receiver.shm_report();
            d.telemetry_gaps = udp.decoder.gaps();
            d.optimal = udp.decoder.optimal_counts().map(Into::into);
            d.lap_preview = udp.decoder.lap_counts();
            if let Some(c) = d.lap_preview.filter(|c| c.laps > 0 || c.bad_distance > 0) {
                console::err(c.describe().trim_end());
            }
            d.telemetry_format_locks = udp.decoder.locks();
            // Some were counted and not printed: the counts, once.
            if d.unreadable_by_kind
                .values()
                .any(|n| *n > crate::input::unreadable::KEPT_PER_KIND)
            {
                console::err(&format!(
                    "unreadable datagrams: {} in all, by kind: {:?}",
                    d.unreadable, d.unreadable_by_kind
                ));
            }
            (d.cue_reloads, d.cue_refused, d.cue_ignored) = udp.decoder.reloads();
            let capture = udp.capture.take().map(|(writer, path)| {
                let (packets, error) = writer.finish();
                CaptureReport { path, packets, error }
            });
            (r, Some(d), capture)
        }
    }
}
