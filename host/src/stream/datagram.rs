//! What a UDP datagram from simulator software means: a pose, or vehicle telemetry that the core's washout turns
//! into a pose (text, or Live for Speed's OutSim packet, which BeamNG.drive also sends).

use std::time::Instant;

use ringpod_core::cueing::{self, SampleError, Telemetry, Washout, G};
use ringpod_core::kinematics::Pose;

/// The telemetry formats `stream --telemetry-udp` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TelemetryFormat {
    /// One text line `t ax ay az wx wy wz` (or without `t`: the arrival time), separated by spaces, commas or
    /// semicolons; the units and axes of `ringpod cue`.
    Text,
    /// Live for Speed's OutSim packet (64 bytes, or 68 with an ID; layout in the README).
    Outsim,
}

/// Turns datagrams into poses.
pub enum Decoder {
    /// Six numbers `x y z alpha beta gamma` (m; rad, or degrees).
    Poses {
        /// Angles in degrees.
        degrees: bool,
    },
    /// Vehicle telemetry through the washout.
    Telemetry {
        /// The format.
        format: TelemetryFormat,
        /// The washout.
        washout: Box<Washout<f64>>,
        /// The platform's neutral pose: the home pose of the rig the device runs, set by the stream once it knows it
        /// ([`Decoder::centre_on`]), before the first datagram is read.
        neutral: Option<Pose<f64>>,
        /// Time of the last sample: its own (s) or its arrival.
        last: Option<(Option<f64>, Instant)>,
        /// Gaps of more than a second after which the washout started again at neutral.
        gaps: u32,
    },
}

/// Six or seven numbers separated by spaces, commas or semicolons.
fn numbers(bytes: &[u8]) -> Result<Vec<f64>, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not text".to_string())?;
    text.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f64>().map_err(|e| format!("`{s}`: {e}")))
        .collect()
}

/// Parses one pose datagram: six numbers.
pub fn parse_pose(bytes: &[u8], degrees: bool) -> Result<Pose<f64>, String> {
    let v = numbers(bytes)?;
    if v.len() != 6 {
        return Err(format!("expected 6 numbers, got {}", v.len()));
    }
    let a = |x: f64| if degrees { x.to_radians() } else { x };
    let pose = [v[0], v[1], v[2], a(v[3]), a(v[4]), a(v[5])];
    // Garbage is not sent: a live source's datagram that no device could follow is unreadable, like a wrong one,
    // and the session goes on (a file's bad row is the device's to refuse, with its reason).
    if let Some(i) = pose.iter().position(|x| !(*x as f32).is_finite()) {
        return Err(format!("value {} is not a finite number (in single precision)", i + 1));
    }
    if pose[5].abs() > crate::input::numbers::MAX_TURNING {
        return Err(format!(
            "a yaw of {} rad is beyond {} rad either way",
            crate::input::numbers::readable(pose[5]),
            crate::input::numbers::readable(crate::input::numbers::MAX_TURNING)
        ));
    }
    Ok(Pose::from_array(pose))
}

/// Parses a text telemetry datagram: `[t] ax ay az wx wy wz`.
pub fn parse_telemetry(bytes: &[u8]) -> Result<(Option<f64>, Telemetry<f64>), String> {
    let v = numbers(bytes)?;
    let (t, v) = match v.len() {
        7 => (Some(v[0]), &v[1..]),
        6 => (None, &v[..]),
        n => return Err(format!("expected 6 or 7 numbers, got {n}")),
    };
    // A time that is not a time would become the reference of every later sample's interval, and a value that is
    // not finite would reach the filters on a first sample: both are unreadable.
    if t.is_some_and(|t| !t.is_finite() || t.abs() > crate::input::table::MAX_TIME_S) {
        return Err(format!(
            "its time is not a time (a finite number of seconds, at most {} either way)",
            crate::input::numbers::readable(crate::input::table::MAX_TIME_S)
        ));
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err("a value is not finite".into());
    }
    Ok((
        t,
        Telemetry {
            force: [v[0], v[1], v[2]],
            rate: [v[3], v[4], v[5]],
        },
    ))
}

/// Live for Speed's OutSim packet (`OutSimPack`, the layout without the `OutSim Opts` extensions), little-endian:
///
/// | bytes | field | |
/// |---|---|---|
/// | 0-3 | `Time` | u32, ms |
/// | 4-15 | `AngVel` | 3 x f32, rad/s, world axes |
/// | 16-19, 20-23, 24-27 | `Heading`, `Pitch`, `Roll` | f32, rad |
/// | 28-39 | `Accel` | 3 x f32, m/s^2, world axes |
/// | 40-51 | `Vel` | 3 x f32, m/s |
/// | 52-63 | `Pos` | 3 x i32, 1 m = 65536 |
/// | 64-67 | `ID` | i32, only when an OutSim ID is set |
///
/// World axes are x right, y forward, z up at zero heading; heading turns about z, pitch about the car's right
/// (x) axis, roll about its forward (y) axis, each anticlockwise, applied in that order. The car's acceleration
/// plus gravity's reaction is turned into the car's frame and then into ringpod's vehicle axes (x forward, y left,
/// z up), as are the angular rates.
pub mod outsim {
    use super::{Telemetry, G};

    /// Reads one packet: its time (s) and the telemetry in ringpod's vehicle axes.
    pub fn parse(bytes: &[u8]) -> Result<(f64, Telemetry<f64>), String> {
        if bytes.len() != 64 && bytes.len() != 68 {
            return Err(format!("an OutSim packet is 64 or 68 bytes, this one {}", bytes.len()));
        }
        let word = |at: usize| [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]];
        let f = |at: usize| f64::from(f32::from_le_bytes(word(at)));
        let time = f64::from(u32::from_le_bytes(word(0))) / 1000.0;
        let ang_vel = [f(4), f(8), f(12)];
        let (heading, pitch, roll) = (f(16), f(20), f(24));
        let accel = [f(28), f(32), f(36)];
        // Specific force in world axes: acceleration minus gravity (gravity is -g on z).
        let specific = [accel[0], accel[1], accel[2] + G];
        let to_car = |v: [f64; 3]| {
            // The car's axes in world axes: R = Rz(heading) Rx(pitch) Ry(roll); world to car is R^T.
            let v = rotate_z(v, -heading);
            let v = rotate_x(v, -pitch);
            rotate_y(v, -roll)
        };
        let (fc, wc) = (to_car(specific), to_car(ang_vel));
        // Car axes x right, y forward, z up -> ringpod's x forward, y left, z up.
        let ours = |v: [f64; 3]| [v[1], -v[0], v[2]];
        Ok((
            time,
            Telemetry {
                force: ours(fc),
                rate: ours(wc),
            },
        ))
    }

    fn rotate_z(v: [f64; 3], a: f64) -> [f64; 3] {
        let (s, c) = a.sin_cos();
        [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
    }

    fn rotate_x(v: [f64; 3], a: f64) -> [f64; 3] {
        let (s, c) = a.sin_cos();
        [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
    }

    fn rotate_y(v: [f64; 3], a: f64) -> [f64; 3] {
        let (s, c) = a.sin_cos();
        [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
    }
}

impl Decoder {
    /// The pose a datagram asks for, arriving at `now`.
    pub fn decode(&mut self, bytes: &[u8], now: Instant) -> Result<Pose<f64>, String> {
        match self {
            Decoder::Poses { degrees } => parse_pose(bytes, *degrees),
            Decoder::Telemetry {
                format,
                washout,
                neutral,
                last,
                gaps,
            } => {
                let neutral = neutral.ok_or("the platform's neutral pose is not known yet")?;
                let (t, sample) = match format {
                    TelemetryFormat::Text => parse_telemetry(bytes)?,
                    TelemetryFormat::Outsim => outsim::parse(bytes).map(|(t, s)| (Some(t), s))?,
                };
                let dt = match *last {
                    None => None,
                    Some((Some(t0), _)) if t.is_some() => t.map(|t| t - t0),
                    Some((_, arrived)) => Some(now.duration_since(arrived).as_secs_f64()),
                };
                let offset = match dt.map(|dt| washout.step(&sample, dt)) {
                    None => Ok(washout.offset()),
                    Some(Ok(offset)) => Ok(offset),
                    Some(Err(SampleError::NonFinite)) => Err("a value is not finite".to_string()),
                    Some(Err(SampleError::Interval)) if dt.is_some_and(|dt| dt > 0.0) => {
                        // A pause of more than a second: wash out to neutral and start again from here.
                        *gaps += 1;
                        washout.reset();
                        Ok(washout.offset())
                    }
                    Some(Err(SampleError::Interval)) => Err("its time is not after the last one's".to_string()),
                };
                let offset = offset?;
                *last = Some((t, now));
                Ok(cueing::pose(&neutral, &offset))
            }
        }
    }

    /// A telemetry source paused for `dt` more seconds (until `now`): the pose of the vehicle at rest through the
    /// washout (washing out to neutral), or `None` for a pose source (the platform holds).
    pub fn idle(&mut self, dt: f64, now: Instant) -> Option<Pose<f64>> {
        match self {
            Decoder::Poses { .. } => None,
            Decoder::Telemetry {
                washout, neutral, last, ..
            } => {
                // The next sample's interval runs from here, by arrival: the washout has covered the pause.
                *last = Some((None, now));
                let rest = Telemetry {
                    force: [0.0, 0.0, G],
                    rate: [0.0; 3],
                };
                let offset = washout.step(&rest, dt).ok()?;
                Some(cueing::pose(&(*neutral)?, &offset))
            }
        }
    }

    /// Cues around `home` (the home pose of the rig the device runs); a pose source has no neutral.
    pub fn centre_on(&mut self, home: Pose<f64>) {
        if let Decoder::Telemetry { neutral, .. } = self {
            *neutral = Some(home);
        }
    }

    /// Whether a pause of the source washes out (telemetry) rather than letting the platform rest where it is.
    pub fn washes_out(&self) -> bool {
        matches!(self, Decoder::Telemetry { .. })
    }

    /// Gaps after which the washout started again (telemetry only).
    pub fn gaps(&self) -> u32 {
        match self {
            Decoder::Poses { .. } => 0,
            Decoder::Telemetry { gaps, .. } => *gaps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An OutSim packet built as LFS lays it out: time (ms), angular velocity, heading, pitch, roll, acceleration
    /// (world axes), velocity and position zero, and an ID when asked.
    fn packet(time_ms: u32, ang_vel: [f32; 3], hpr: [f32; 3], accel: [f32; 3], id: bool) -> Vec<u8> {
        let mut out = time_ms.to_le_bytes().to_vec();
        for v in ang_vel.iter().chain(&hpr).chain(&accel).chain(&[0.0f32; 3]) {
            out.extend(v.to_le_bytes());
        }
        out.extend([0u8; 12]);
        if id {
            out.extend(7i32.to_le_bytes());
        }
        assert_eq!(out.len(), if id { 68 } else { 64 });
        out
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn outsim_packets_become_telemetry_in_vehicle_axes() {
        let g = G;
        // At rest, level, any heading: gravity's reaction straight up.
        let (t, s) = outsim::parse(&packet(1500, [0.0; 3], [2.0, 0.0, 0.0], [0.0; 3], false)).unwrap();
        assert_eq!(t, 1.5);
        assert!(close(s.force, [0.0, 0.0, g]) && close(s.rate, [0.0; 3]), "{s:?}");
        // Heading a quarter turn anticlockwise (facing world -x) and accelerating that way at 3 m/s^2: 3 forward.
        let quarter = std::f32::consts::FRAC_PI_2;
        let (_, s) = outsim::parse(&packet(0, [0.0; 3], [quarter, 0.0, 0.0], [-3.0, 0.0, 0.0], true)).unwrap();
        assert!(close(s.force, [3.0, 0.0, g]), "{s:?}");
        // Cornering to the left at heading 0 (world -x is the car's left): a force to the left.
        let (_, s) = outsim::parse(&packet(0, [0.0, 0.0, 0.5], [0.0; 3], [-4.0, 0.0, 0.0], false)).unwrap();
        assert!(close(s.force, [0.0, 4.0, g]) && close(s.rate, [0.0, 0.0, 0.5]), "{s:?}");
        // Nose up 10 degrees at rest: gravity pushes the rider back, as accelerating does.
        let p = 10f32.to_radians();
        let (_, s) = outsim::parse(&packet(0, [0.0; 3], [0.0, p, 0.0], [0.0; 3], false)).unwrap();
        let (sp, cp) = f64::from(p).sin_cos();
        assert!(close(s.force, [g * sp, 0.0, g * cp]), "{s:?}");
        // Rolled 10 degrees anticlockwise seen from the front (right side down): gravity pulls the rider to the
        // right, so the seat pushes to the left.
        let r = 10f32.to_radians();
        let (_, s) = outsim::parse(&packet(0, [0.0; 3], [0.0, 0.0, r], [0.0; 3], false)).unwrap();
        let (sr, cr) = f64::from(r).sin_cos();
        assert!(close(s.force, [0.0, g * sr, g * cr]), "{s:?}");
        for len in [0, 63, 65, 72] {
            assert!(outsim::parse(&vec![0u8; len]).is_err(), "{len} bytes");
        }
    }

    #[test]
    fn text_telemetry_with_and_without_time() {
        let (t, s) = parse_telemetry(b"1.5 0.1 -0.2 9.81 0 0 0.3").unwrap();
        assert_eq!(t, Some(1.5));
        assert_eq!(s.force, [0.1, -0.2, 9.81]);
        assert_eq!(s.rate, [0.0, 0.0, 0.3]);
        let (t, _) = parse_telemetry(b"0.1,-0.2;9.81 0 0 0.3").unwrap();
        assert_eq!(t, None);
        assert!(parse_telemetry(b"1 2 3").is_err());
        assert!(parse_telemetry(b"1 2 3 4 5 x").is_err());
        assert!(parse_telemetry(&[0xff, 0xfe]).is_err());
    }

    #[test]
    fn a_telemetry_stream_is_cued_and_a_pause_washes_out() {
        let washout = Washout::new(ringpod_core::cueing::CueConfig::default()).unwrap();
        let neutral = Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.0);
        let mut d = Decoder::Telemetry {
            format: TelemetryFormat::Text,
            washout: Box::new(washout),
            neutral: Some(neutral),
            last: None,
            gaps: 0,
        };
        let now = Instant::now();
        // Braking at 6 m/s^2 for a second at 100 Hz: the platform moves back and pitches nose down.
        let mut pose = neutral;
        for k in 0..100 {
            let text = format!("{} -6 0 {G} 0 0 0", f64::from(k) * 0.01);
            pose = d.decode(text.as_bytes(), now).unwrap();
        }
        assert!(pose.x < 0.0 && pose.beta > 0.0, "{pose:?}");
        // Not finite: refused, nothing changes.
        assert!(d.decode(b"1.0 NaN 0 9.8 0 0 0", now).is_err());
        // Three seconds later: the washout starts again at neutral.
        let text = format!("4.0 0 0 {G} 0 0 0");
        assert_eq!(d.decode(text.as_bytes(), now).unwrap(), neutral);
        assert_eq!(d.gaps(), 1);
    }
}
