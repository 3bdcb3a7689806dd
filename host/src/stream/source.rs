//! Where a stream's poses come from: a built-in motion, a pose file, or a live source (UDP datagrams from simulator
//! software, a game's shared memory: [`super::live`]).

use super::session::Columns;
use ringpod_core::kinematics::presets::TRAINER_MODEL_RANGES;
use ringpod_core::kinematics::Pose;
use ringpod_core::protocol::MotionSettings;

use super::InputError;

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
    /// A sine on one axis (--axis, --frequency, --velocity-amplitude or --amplitude), chapter 5.2's experiments:
    /// its amplitude limited to the device's pose velocity and acceleration limits, saying by how much.
    Sine,
}

/// The pose axis of a sine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Axis {
    X,
    Y,
    Z,
    Roll,
    Pitch,
    Yaw,
}

impl Axis {
    /// The index in `x, y, z, alpha, beta, gamma`.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// What a sine's amplitude is given as.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Amplitude {
    /// Of the velocity (m/s, or rad/s for roll, pitch and yaw).
    Velocity(f64),
    /// Of the position (m, or rad).
    Position(f64),
}

/// A fixed-frequency sine on one axis around home, easing in over its first [`Sine::EASE_PERIODS`] periods (and at
/// least a second) and out over its last, so that it starts and ends at rest without a jump in velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sine {
    pub axis: Axis,
    /// Hz.
    pub frequency: f64,
    pub amplitude: Amplitude,
    /// The motion's length (s): it eases out before.
    pub seconds: f64,
}

/// A sine's amplitudes after the device's limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinePlan {
    /// Position amplitude (m or rad).
    pub position: f64,
    /// Velocity amplitude: `position * 2 pi f`.
    pub velocity: f64,
    /// Acceleration amplitude: `position * (2 pi f)^2`.
    pub acceleration: f64,
    /// The share of the asked amplitude kept (1 when inside the limits), and the limit that bounds it.
    pub kept: f64,
    pub bound: Option<&'static str>,
}

impl Sine {
    /// The ease-in: the amplitude grows over this many periods (and at least a second).
    pub const EASE_PERIODS: f64 = 3.0;

    /// The amplitudes, scaled down to the device's pose velocity and acceleration limits on the axis.
    pub fn plan(&self, limits: &MotionSettings) -> SinePlan {
        let w = std::f64::consts::TAU * self.frequency;
        let asked = match self.amplitude {
            Amplitude::Velocity(v) => v / w,
            Amplitude::Position(a) => a,
        };
        let k = self.axis.index();
        let (vmax, amax) = (
            f64::from(limits.pose_velocity[k]),
            f64::from(limits.pose_acceleration[k]),
        );
        let (by_v, by_a) = (vmax / (asked * w), amax / (asked * w * w));
        let (kept, bound) = if by_v < 1.0 && by_v <= by_a {
            (by_v, Some("velocity"))
        } else if by_a < 1.0 {
            (by_a, Some("acceleration"))
        } else {
            (1.0, None)
        };
        let position = asked * kept;
        SinePlan {
            position,
            velocity: position * w,
            acceleration: position * w * w,
            kept,
            bound,
        }
    }

    /// The plan in one line: what is run, and by how much and by which limit it was cut.
    pub fn describe(&self, limits: &MotionSettings) -> String {
        let p = self.plan(limits);
        let k = self.axis.index();
        let (len, vel, acc) = if k < 3 {
            ("m", "m/s", "m/s^2")
        } else {
            ("rad", "rad/s", "rad/s^2")
        };
        let mut line = format!(
            "sine on {} at {} Hz: amplitude {:.4e} {len}, velocity {:.6} {vel}, acceleration {:.6} {acc}",
            ["x", "y", "z", "roll", "pitch", "yaw"][k],
            crate::input::numbers::readable(self.frequency),
            p.position,
            p.velocity,
            p.acceleration
        );
        match p.bound {
            None => line += " (as asked, inside the limits)",
            Some(bound) => {
                let limit = if bound == "velocity" {
                    format!("{} {vel}", limits.pose_velocity[k])
                } else {
                    format!("{} {acc}", limits.pose_acceleration[k])
                };
                line += &format!(
                    " (limited to {:.1} % of the amplitude asked, {:.4e} {len}, by the {bound} limit of {limit})",
                    p.kept * 100.0,
                    p.position / p.kept
                );
            }
        }
        line
    }

    /// The pose at `t` around `home`.
    pub fn pose(&self, t: f64, home: [f64; 6], limits: &MotionSettings) -> Pose<f64> {
        let p = self.plan(limits);
        let ease_time = (Self::EASE_PERIODS / self.frequency).max(1.0);
        // A raised cosine from 0 to 1 over the ease-in, and back over the ease-out.
        let raised = |s: f64| {
            if s >= ease_time {
                1.0
            } else {
                0.5 - 0.5 * (std::f64::consts::PI * s.max(0.0) / ease_time).cos()
            }
        };
        let ease = raised(t).min(raised(self.seconds - t));
        let mut pose = home;
        pose[self.axis.index()] += ease * p.position * (std::f64::consts::TAU * self.frequency * t).sin();
        Pose::from_array(pose)
    }
}

/// A pose of an input file: its line number, its time (s), the pose, and the auxiliary outputs it switches and the
/// spare axes' targets.
pub type TimedPose = (usize, f64, Pose<f64>, Columns);

/// Where poses come from.
pub enum Source {
    /// A motion, sampled at `rate_hz` for `seconds` (generated as it is sent).
    Motion {
        /// Which.
        motion: Motion,
        /// The sine's parameters, for [`Motion::Sine`].
        sine: Option<Sine>,
        /// How long (s).
        seconds: f64,
        /// Setpoints per second.
        rate_hz: f64,
    },
    /// Timed poses from a CSV file.
    Poses(Vec<TimedPose>),
    /// Poses from a live source (UDP datagrams, a game's shared memory), sent as they arrive.
    Live(super::live::LiveSource),
}

/// The columns of a pose file.
pub const POSE_COLUMNS: [&str; 7] = ["t", "x", "y", "z", "alpha", "beta", "gamma"];

/// The optional columns of a pose file: the auxiliary outputs, 0 (off) or 1 (on) in each row, and the spare axes'
/// targets in each axis's unit.
pub const AUX_COLUMNS: [&str; 4] = ["aux1", "aux2", "axis7", "axis8"];

/// Reads a pose file: `t,x,y,z,alpha,beta,gamma` named in its header in any order (seconds, metres, radians or
/// degrees; [`crate::input::table::read`]), and optionally `aux1`, `aux2` (0 or 1: the auxiliary outputs, switched
/// when the row's setpoint is taken; a file without the column leaves that output as it is) and `axis7`, `axis8`
/// (the spare axes' targets in their own units, interpolated by the device like the pose; a file without the column
/// leaves that axis where it is). NaN and infinity in a pose or an axis column are passed on: the device refuses
/// them with a reason, which is the point; an aux value other than 0 or 1 makes the row an error.
pub fn read_csv(text: &str, degrees: bool) -> Result<(Vec<TimedPose>, Vec<InputError>), String> {
    let (rows, mut errors, present) = crate::input::table::read_with_optional(text, &POSE_COLUMNS, &AUX_COLUMNS)?;
    let a = |x: f64| if degrees { x.to_radians() } else { x };
    let mut poses = Vec::with_capacity(rows.len());
    for (line, v) in rows {
        let level = |k: usize, x: f64| match x {
            _ if !present[k] => Ok(None),
            0.0 => Ok(Some(false)),
            1.0 => Ok(Some(true)),
            _ => Err(x),
        };
        let spare = |k: usize| present[k].then_some(v[7 + k] as f32);
        match (level(0, v[7]), level(1, v[8])) {
            (Ok(a1), Ok(a2)) => poses.push((
                line,
                v[0],
                Pose::new(v[1], v[2], v[3], a(v[4]), a(v[5]), a(v[6])),
                Columns {
                    aux: [a1, a2],
                    spare: [spare(2), spare(3)],
                },
            )),
            (Err(x), _) | (_, Err(x)) => errors.push(InputError {
                line,
                reason: format!("an aux column must be 0 or 1, not {x}"),
            }),
        }
    }
    errors.sort_by_key(|e| e.line);
    Ok((poses, errors))
}

/// Pose of a built-in motion at time `t` (s) around `home`; the vibration sweep scales its amplitude to `limits` (the
/// device's pose limits). On the trainer model every motion stays inside the envelope at any time and yaw (tested for
/// 120 s each), so host limiting leaves it unchanged.
pub fn motion_pose(motion: Motion, sine: Option<&Sine>, t: f64, home: [f64; 6], limits: &MotionSettings) -> Pose<f64> {
    if let (Motion::Sine, Some(sine)) = (motion, sine) {
        return sine.pose(t, home, limits);
    }
    let mut p = home;
    let tau = std::f64::consts::TAU;
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
        // Without its parameters (the command line requires them): home.
        Motion::Sine => {}
    }
    Pose::from_array(p)
}

#[cfg(test)]
mod tests {
    use super::super::session::NO_AUX;
    use super::*;

    #[test]
    fn aux_columns_are_optional_and_0_or_1() {
        let (poses, errors) = read_csv("t,x,y,z,alpha,beta,gamma\n0,0,0,0.2,0,0,0\n", false).unwrap();
        assert!(errors.is_empty());
        assert_eq!(
            poses[0].3, NO_AUX,
            "without the columns the outputs and the spare axes are left as they are"
        );
        let text = "aux2,t,x,y,z,alpha,beta,gamma\n1,0,0,0,0.2,0,0,0\n0,1,0,0,0.2,0,0,0\n0.5,2,0,0,0.2,0,0,0\n";
        let (poses, errors) = read_csv(text, false).unwrap();
        assert_eq!(
            poses.iter().map(|p| p.3.aux).collect::<Vec<_>>(),
            [[None, Some(true)], [None, Some(false)]]
        );
        assert_eq!(poses[1].2.z, 0.2, "the pose columns read in the header's order");
        assert_eq!(errors.len(), 1);
        assert_eq!(errors[0].line, 4);
        assert!(
            errors[0].reason.contains("must be 0 or 1, not 0.5"),
            "{}",
            errors[0].reason
        );
        let short = read_csv("t,x,y,z,alpha,beta,gamma,aux1,aux2\n0,0,0,0.2,0,0,0,1\n", false).unwrap();
        assert!(short.0.is_empty() && short.1[0].reason.contains("expected 9 fields, got 8"));
        let unknown = read_csv("t,x,y,z,alpha,beta,gamma,aux3\n", false).unwrap_err();
        assert!(unknown.contains("may name aux1,aux2,axis7,axis8"), "{unknown}");
    }

    #[test]
    fn spare_axis_columns_are_optional_targets() {
        let text = "t,x,y,z,alpha,beta,gamma,axis8\n0,0,0,0.2,0,0,0,12.5\n1,0,0,0.2,0,0,0,-3\n2,0,0,0.2,0,0,0,nan\n";
        let (poses, errors) = read_csv(text, false).unwrap();
        assert!(errors.is_empty(), "{errors:?}");
        let spare: Vec<_> = poses.iter().map(|p| p.3.spare).collect();
        assert_eq!(spare[..2], [[None, Some(12.5)], [None, Some(-3.0)]]);
        assert!(
            spare[2][1].is_some_and(f32::is_nan),
            "passed on for the device to refuse"
        );
        assert_eq!(poses[0].3.aux, [None, None]);
    }
}
