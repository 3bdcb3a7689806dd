//! `ringpod stream`: poses from a file or a built-in motion to the controller, at a fixed rate.

use std::collections::BTreeMap;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL_RANGES};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::{MotionLimits, RejectReason, Setpoint};
use ringpod_core::safety::{FaultReason, State};
use serde::Serialize;

use crate::client::{Client, ClientError, Transport};

/// Built-in motions (trainer-model ranges and the test motions of the physical model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Motion {
    /// All six axes at once within half their ranges, yaw turning at 0.5 rad/s.
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
    /// A motion, sampled at the stream rate for `seconds`.
    Motion { motion: Motion, seconds: f64 },
    /// Timed poses from a CSV file: `(line, t, pose)`.
    Poses(Vec<TimedPose>),
    /// Poses from UDP datagrams, sent as they arrive until `idle` passes without one.
    Udp {
        /// The bound socket.
        socket: std::net::UdpSocket,
        /// Angles in degrees.
        degrees: bool,
        /// End after this long without a datagram.
        idle: Duration,
    },
}

/// Parses one datagram: six numbers separated by spaces, commas or semicolons.
pub fn parse_datagram(bytes: &[u8], degrees: bool) -> Result<Pose<f64>, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not text".to_string())?;
    let v: Vec<f64> = text
        .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f64>().map_err(|e| format!("`{s}`: {e}")))
        .collect::<Result<_, _>>()?;
    if v.len() != 6 {
        return Err(format!("expected 6 numbers, got {}", v.len()));
    }
    let a = |x: f64| if degrees { x.to_radians() } else { x };
    Ok(Pose::new(v[0], v[1], v[2], a(v[3]), a(v[4]), a(v[5])))
}

/// A CSV line that could not be used.
#[derive(Debug, Clone, Serialize)]
pub struct InputError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// Reads `t,x,y,z,alpha,beta,gamma` (seconds, metres, radians or degrees). Bad lines are returned, not fatal.
pub fn read_csv(text: &str, degrees: bool) -> (Vec<TimedPose>, Vec<InputError>) {
    let mut poses = Vec::new();
    let mut errors = Vec::new();
    let mut last_t = f64::NEG_INFINITY;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let raw = raw.trim();
        if raw.is_empty() || raw.starts_with('#') || (line == 1 && raw.starts_with('t')) {
            continue;
        }
        let fields: Result<Vec<f64>, _> = raw.split(',').map(|f| f.trim().parse::<f64>()).collect();
        let v = match fields {
            Ok(v) if v.len() == 7 => v,
            Ok(v) => {
                errors.push(InputError {
                    line,
                    reason: format!("expected 7 fields, got {}", v.len()),
                });
                continue;
            }
            Err(e) => {
                errors.push(InputError {
                    line,
                    reason: format!("not a number: {e}"),
                });
                continue;
            }
        };
        if !v[0].is_finite() || v[0] <= last_t {
            errors.push(InputError {
                line,
                reason: "time is not increasing".into(),
            });
            continue;
        }
        last_t = v[0];
        let a = |x: f64| if degrees { x.to_radians() } else { x };
        // NaN and infinity in a pose are passed on: the device rejects them with a reason, which is the point.
        poses.push((line, v[0], Pose::new(v[1], v[2], v[3], a(v[4]), a(v[5]), a(v[6]))));
    }
    (poses, errors)
}

/// Pose of a built-in motion at time `t` (s) around `home`.
pub fn motion_pose(motion: Motion, t: f64, home: [f64; 6]) -> Pose<f64> {
    let mut p = home;
    let tau = std::f64::consts::TAU;
    let limits = MotionLimits::TRAINER_MODEL;
    match motion {
        Motion::Demo => {
            // Half of each range, frequencies low enough for the 0.05 m/s and 1 rad/s limits; the motion starts at
            // home and eases in over the first two seconds.
            let ease = (t / 2.0).min(1.0);
            for (i, f) in [0.2, 0.15, 0.25, 0.3, 0.22].iter().enumerate() {
                p[i] += ease * 0.5 * TRAINER_MODEL_RANGES[i] * (tau * f * t).sin();
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

/// The end-of-run report (`--report-json`).
#[derive(Debug, Serialize)]
pub struct Report {
    /// Final device state.
    pub state: String,
    /// Setpoints sent.
    pub setpoints_sent: u32,
    /// Setpoints the device accepted.
    pub setpoints_applied: u32,
    /// Setpoints the device rejected, by reason.
    pub rejected: BTreeMap<String, u32>,
    /// Step position of each axis at the end.
    pub final_steps: [i64; 6],
    /// Faults the device reported.
    pub faults: Vec<String>,
    /// Input lines that could not be used (never sent).
    pub input_errors: Vec<InputError>,
    /// The last pose the device accepted.
    pub last_applied_pose: Option<[f64; 6]>,
    /// The device's own counters agree with what the host counted.
    pub counts_agree: bool,
}

/// Stream settings.
pub struct Options {
    /// Setpoints per second (motions; files keep their own times).
    pub rate_hz: f64,
    /// Home even if the device is homed already.
    pub home: bool,
    /// No progress bar.
    pub quiet: bool,
}

fn reason_name(r: RejectReason) -> String {
    match r {
        RejectReason::Workspace(c) => format!("workspace:{}", c.name()),
        other => format!("{other:?}")
            .to_lowercase()
            .replace("nonfinite", "non_finite")
            .replace("toofast", "too_fast")
            .replace("notstreaming", "not_streaming"),
    }
}

/// What the host counted while streaming.
#[derive(Default)]
struct Counts {
    seq: u32,
    sent: u32,
    applied: u32,
    rejected: BTreeMap<String, u32>,
    last_applied: Option<Pose<f64>>,
}

impl Counts {
    /// Sends one setpoint and counts the device's answer; a rejected line of a file is reported with its number.
    fn send<T: Transport>(
        &mut self,
        client: &mut Client<T>,
        pose: Pose<f64>,
        t_us: u64,
        line: Option<usize>,
        bar: &ProgressBar,
    ) -> Result<(), ClientError> {
        self.seq += 1;
        self.sent += 1;
        match client.setpoint(Setpoint {
            seq: self.seq,
            time_us: t_us,
            pose: pose.cast(),
        })? {
            Ok(()) => {
                self.applied += 1;
                self.last_applied = Some(pose);
            }
            Err(reason) => {
                *self.rejected.entry(reason_name(reason)).or_default() += 1;
                if let Some(line) = line {
                    bar.suspend(|| eprintln!("line {line}: rejected by the device: {}", reason_name(reason)));
                }
            }
        }
        Ok(())
    }
}

/// Brings the device to `Running`: hello, power up, home if needed, start.
fn prepare<T: Transport>(client: &mut Client<T>, home: bool) -> Result<(), ClientError> {
    let preset = client.hello()?;
    if preset != Preset::TrainerModel {
        eprintln!("note: the device drives {}", preset.name());
    }
    let mut status = client.status()?;
    if matches!(status.state, State::Fault(..)) {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}: clear the fault first",
            status.state
        )));
    }
    if status.state == State::Off {
        client.enable()?;
        status = client.wait_for(Duration::from_secs(5), |s| {
            matches!(s.state, State::PowerOn { settled: true } | State::Fault(..))
        })?;
    }
    if !status.homed || home {
        client.home()?;
        status = client.wait_for(Duration::from_secs(120), |s| {
            matches!(s.state, State::Ready | State::Fault(..))
        })?;
    }
    if status.state != State::Ready {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}, not ready",
            status.state
        )));
    }
    client.start()
}

/// Streams a source and returns the report. Ctrl-C, the end of the input and errors all end with a stop and a
/// wait for rest.
pub fn run<T: Transport>(
    client: &mut Client<T>,
    source: Source,
    input_errors: Vec<InputError>,
    options: &Options,
    interrupted: &dyn Fn() -> bool,
) -> Result<Report, ClientError> {
    prepare(client, options.home)?;
    let home = Preset::TrainerModel.home();
    let schedule: Vec<(Option<usize>, f64, Pose<f64>)> = match &source {
        Source::Motion { motion, seconds } => {
            let n = (seconds * options.rate_hz).round() as usize;
            (0..=n)
                .map(|k| {
                    let t = k as f64 / options.rate_hz;
                    (None, t, motion_pose(*motion, t, home))
                })
                .collect()
        }
        Source::Poses(p) => p.iter().map(|(line, t, pose)| (Some(*line), *t, *pose)).collect(),
        Source::Udp { .. } => Vec::new(),
    };
    // Lead-in: from where the platform is to the first pose, at a quarter of the velocity limits.
    let now = client.status()?.pose.cast::<f64>();
    let first = schedule.first().map_or(now, |s| s.2);
    let limits = MotionLimits::TRAINER_MODEL;
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
    let lead_s = (0..6).fold(0.0f64, |m, i| {
        m.max(way[i].abs() / (0.25 * f64::from(limits.pose_velocity[i])))
    });
    let lead_n = (lead_s * 100.0).ceil() as usize;
    let bar = if options.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new((schedule.len() + lead_n) as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} setpoints {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut counts = Counts::default();
    let mut clock_us = 0u64;
    for k in 1..=lead_n {
        let f = k as f64 / lead_n as f64;
        let pose = Pose::from_array(std::array::from_fn(|i| a[i] + way[i] * f));
        client.transport().elapse(Duration::from_millis(10));
        clock_us += 10_000;
        counts.send(client, pose, clock_us, None, &bar)?;
        bar.inc(1);
    }
    let mut t_prev = schedule.first().map_or(0.0, |s| s.1);
    let mut result = Ok(());
    for (i, (line, t, pose)) in schedule.iter().enumerate() {
        if interrupted() {
            bar.suspend(|| eprintln!("interrupted: stopping"));
            break;
        }
        let dt = (t - t_prev).max(0.0);
        t_prev = *t;
        if i > 0 {
            client.transport().elapse(Duration::from_secs_f64(dt));
        }
        clock_us += ((dt * 1e6).round() as u64).max(1);
        if let Err(e) = counts.send(client, *pose, clock_us, *line, &bar) {
            result = Err(e);
            break;
        }
        bar.inc(1);
        if i % 100 == 0 {
            let total: u32 = counts.rejected.values().sum();
            bar.set_message(format!("rejected {total}"));
        }
    }
    let mut input_errors = input_errors;
    if let Source::Udp { socket, degrees, idle } = &source {
        socket.set_read_timeout(Some(Duration::from_millis(1)))?;
        bar.suspend(|| {
            eprintln!(
                "streaming: send datagrams to {}",
                socket.local_addr().map_or("?".into(), |a| a.to_string())
            )
        });
        let mut buf = [0u8; 512];
        let (mut quiet_for, mut datagrams) = (Duration::ZERO, 0usize);
        let mut wall = std::time::Instant::now();
        while quiet_for < *idle && !interrupted() {
            let got = socket.recv(&mut buf);
            let now = std::time::Instant::now();
            let dt = now - wall;
            wall = now;
            client.transport().elapse(dt);
            clock_us += (dt.as_micros() as u64).max(1);
            match got {
                Ok(n) => {
                    datagrams += 1;
                    quiet_for = Duration::ZERO;
                    match parse_datagram(&buf[..n], *degrees) {
                        Ok(pose) => {
                            counts.send(client, pose, clock_us, None, &bar)?;
                            bar.inc(1);
                        }
                        Err(reason) => {
                            bar.suspend(|| eprintln!("datagram {datagrams}: {reason}"));
                            input_errors.push(InputError {
                                line: datagrams,
                                reason,
                            });
                        }
                    }
                }
                // A signal (Ctrl-C) interrupts the wait: nothing arrived, and the loop then sees the flag.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    quiet_for += dt
                }
                Err(e) => return Err(e.into()),
            }
        }
    }
    // End of input: hold the last pose for a settle time, as simulator software does when it stops, so that the
    // platform arrives there (the device runs one setpoint interval behind); then stop. Ctrl-C or an error: stop now.
    let running = result.is_ok() && client.status().is_ok_and(|s| s.state == State::Running);
    if running && !interrupted() {
        if let Some(last) = counts.last_applied.or(schedule.last().map(|s| s.2)) {
            for _ in 0..25 {
                client.transport().elapse(Duration::from_millis(10));
                clock_us += 10_000;
                counts.send(client, last, clock_us, None, &bar)?;
            }
        }
    }
    bar.finish_and_clear();
    // Stop, and wait for rest.
    let _ = client.stop();
    let status = client.wait_for(Duration::from_secs(10), |s| {
        !matches!(s.state, State::Running | State::Stopping)
    })?;
    result?;
    let Counts {
        sent,
        applied,
        rejected,
        last_applied,
        ..
    } = counts;
    let device_rejected = status.rejected.total();
    let host_rejected: u32 = rejected.values().sum();
    Ok(Report {
        state: format!("{:?}", status.state),
        setpoints_sent: sent,
        setpoints_applied: applied,
        rejected,
        final_steps: status.steps,
        faults: client.faults.iter().map(|f: &FaultReason| f.to_string()).collect(),
        input_errors,
        last_applied_pose: last_applied.map(|p| p.to_array()),
        counts_agree: status.applied == applied && device_rejected == host_rejected && sent == applied + host_rejected,
    })
}
