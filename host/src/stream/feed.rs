//! Feeding a run its poses: those known beforehand (a file, a motion) each at its own time, or a UDP source's as
//! they arrive, with the washout while it pauses.

use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use ringpod_core::kinematics::Pose;
use ringpod_core::safety::AuxLevels;

use ringpod_core::protocol::MotionSettings;

use super::report::{CaptureReport, DatagramReport};
use super::session::{Kind, Stop, StreamError, Streamer, NO_AUX};
use super::{motion_pose, InputError, Source, UdpSource};
use crate::link::client::{ClientError, Transport};

impl<T: Transport> Streamer<'_, T> {
    /// Streams timed poses (a file or a motion): each at its own time; a gap longer than the stream timeout
    /// lets the platform come to rest, and the stream is led in and started again at the next pose.
    pub(super) fn timed(
        &mut self,
        poses: &mut dyn Iterator<Item = (Option<usize>, f64, Pose<f64>, AuxLevels)>,
        fast: bool,
    ) -> Result<(), StreamError> {
        let mut last_t: Option<f64> = None;
        for (line, t, pose, aux) in poses {
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
            self.send(pose, Kind::Input(line), aux)?;
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
    pub(super) fn live(
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
        let mut last_pose = Instant::now();
        let mut last_idle = Instant::now();
        let mut streaming = false;
        loop {
            if (self.interrupted)() {
                return Err(StreamError::Stop(Stop::Interrupted));
            }
            let got = source.socket.recv_from(&mut buf);
            let now = Instant::now();
            if let (Ok((n, from)), Some((capture, _))) = (&got, source.capture.as_mut()) {
                capture.write(&buf[..*n], *from, std::time::SystemTime::now());
            }
            // A changed cueing file takes over here, between two samples.
            source.decoder.poll_config(now);
            self.elapse(now - wall)?;
            wall = now;
            let datagram = match got {
                Ok(got) => Some(got),
                // A signal (Ctrl-C) interrupts the wait: nothing arrived, and the loop then sees the flag.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    None
                }
                Err(e) => return Err(ClientError::Io(e).into()),
            };
            // Only a readable datagram of the source counts as the source being there: a stranger's datagrams and
            // unreadable ones (a flood of them included) leave the pause logic below running.
            let Some((number, pose)) =
                datagram.and_then(|(n, from)| read(source, &buf[..n], from, now, report, errors, &self.bar))
            else {
                let quiet = now - last_pose;
                // Telemetry that pauses washes out: the vehicle at rest, through the washout, every 10 ms
                // from half the stream timeout on, so the platform glides back to neutral.
                if streaming && quiet > self.stream_timeout / 2 && now - last_idle >= Duration::from_millis(10) {
                    let dt = (now - last_idle).min(Duration::from_millis(20)).as_secs_f64();
                    last_idle = now;
                    if let Some(pose) = source.decoder.idle(dt, now) {
                        let pose = self.limit(pose);
                        self.send(pose, Kind::Washout, NO_AUX)?;
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
            };
            last_pose = now;
            last_idle = now;
            let pose = if streaming {
                self.limit(pose)
            } else {
                if self.last_applied.is_some() {
                    report.resumed += 1;
                }
                streaming = true;
                self.start_and_lead_in(pose)?
            };
            self.send(pose, Kind::Input(Some(number)), NO_AUX)?;
            self.bar.inc(1);
            // The lead-in let its own time pass: the device's clock is already there.
            wall = Instant::now();
        }
    }
}

/// One datagram of the UDP source: counted, and decoded into its number and pose, or reported as unreadable (or
/// ignored as a stranger's) with `None`.
fn read(
    source: &mut UdpSource,
    bytes: &[u8],
    from: std::net::SocketAddr,
    now: Instant,
    report: &mut DatagramReport,
    errors: &mut Vec<InputError>,
    bar: &ProgressBar,
) -> Option<(usize, ringpod_core::kinematics::Pose<f64>)> {
    if source.from.is_some_and(|ip| ip != from.ip()) {
        report.other_senders += 1;
        return None;
    }
    report.received += 1;
    let number = report.received as usize;
    match source.decoder.decode(bytes, now) {
        Ok(pose) => Some((number, pose)),
        Err(reason) => {
            report.unreadable += 1;
            // The first few of each kind, cut to a line: a source can send anything, for as long as it likes.
            if let Some(kept) = crate::input::unreadable::tally(&mut report.unreadable_by_kind, number, &reason) {
                bar.suspend(|| eprintln!("datagram {number}: {}", kept.reason));
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
            d.telemetry_format_locks = udp.decoder.locks();
            // Some were counted and not printed: the counts, once.
            if d.unreadable_by_kind
                .values()
                .any(|n| *n > crate::input::unreadable::KEPT_PER_KIND)
            {
                eprintln!(
                    "unreadable datagrams: {} in all, by kind: {:?}",
                    d.unreadable, d.unreadable_by_kind
                );
            }
            (d.cue_reloads, d.cue_refused) = udp.decoder.reloads();
            let capture = udp.capture.take().map(|(writer, path)| {
                let (packets, error) = writer.finish();
                CaptureReport { path, packets, error }
            });
            (r, Some(d), capture)
        }
    }
}
