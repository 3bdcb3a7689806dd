//! What an input pose must be to be sent at all, one rule for every source (a file's rows, a built-in motion,
//! UDP poses, cued telemetry): a pose of numbers a device can hold, of a sane magnitude, is sent (limited into the
//! envelope where needed); anything else is garbage, refused on the host with its line or datagram named and
//! counted as an input error, never sent. And the pose a stream leads in to must not lie so far outside the
//! envelope that no pose after it could follow without a gross jump.

use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins};

use crate::input::numbers::{readable, MAX_LENGTHS, MAX_TILT, MAX_TURNING};

/// The bounds an input pose is checked against, from the device's rig and settings.
pub(super) struct Admission {
    /// Translations beyond this either way (m): [`MAX_LENGTHS`] ring radii, far outside any workspace.
    reach: f64,
    /// How far any axis moves at its velocity limit within the device's gross-jump window (m, rad): the device
    /// refuses a setpoint further than this from the one before.
    pub(super) window: [f64; 6],
    mechanism: RingPlatform<f64>,
    centre: Pose<f64>,
    margins: EnvelopeMargins,
}

const NAMES: [&str; 6] = ["x", "y", "z", "alpha", "beta", "gamma"];

impl Admission {
    pub(super) fn new(
        geometry: &ringpod_core::kinematics::RingGeometry,
        home: [f64; 6],
        margins: EnvelopeMargins,
        velocity: [f32; 6],
        gross_jump_ms: u16,
    ) -> Self {
        Self {
            reach: MAX_LENGTHS * geometry.ring_radius,
            window: std::array::from_fn(|i| f64::from(velocity[i]) * f64::from(gross_jump_ms) * 1e-3),
            mechanism: RingPlatform::new(geometry),
            centre: Pose::from_array(home),
            margins,
        }
    }

    /// Why `pose` is garbage: a value no device can hold (not finite in single precision: NaN, infinity, 1e308), a
    /// translation beyond [`MAX_LENGTHS`] ring radii, a tilt beyond a turn, a yaw beyond [`MAX_TURNING`] (where an
    /// `f32` angle no longer resolves a step, so the motion it describes is lost); `None` when it may be sent.
    pub(super) fn garbage(&self, pose: &Pose<f64>) -> Option<String> {
        let p = pose.to_array();
        if let Some(i) = p.iter().position(|v| !(*v as f32).is_finite()) {
            return Some(format!(
                "{} = {} is not a finite number (in single precision)",
                NAMES[i],
                readable(p[i])
            ));
        }
        (0..6).find_map(|i| {
            let (limit, unit) = match i {
                0..=2 => (self.reach, "m"),
                3 | 4 => (MAX_TILT, "rad"),
                _ => (MAX_TURNING, "rad"),
            };
            (p[i].abs() > limit).then(|| {
                format!(
                    "{} = {} {unit} is beyond {} {unit} either way: not a pose",
                    NAMES[i],
                    readable(p[i]),
                    readable(limit)
                )
            })
        })
    }

    /// The pose limited into the envelope (whether or not the host limits what it sends: a lead-in goes here).
    pub(super) fn limited(&self, pose: &Pose<f64>) -> Pose<f64> {
        envelope::limit(&self.mechanism, &self.centre, pose, &self.margins, 16).pose
    }

    /// Why `pose` cannot be the first of a stream (the pose it leads in to): garbage, or so far outside the
    /// envelope that limiting it moves an axis by more than that axis travels in the gross-jump window. The
    /// platform would be led to the envelope's edge, and every pose after it, back inside, refused as a gross jump.
    pub(super) fn first(&self, pose: &Pose<f64>) -> Option<String> {
        if let Some(why) = self.garbage(pose) {
            return Some(why);
        }
        let (p, l) = (pose.to_array(), self.limited(pose).to_array());
        (0..6).find_map(|i| {
            let off = (p[i] - l[i]).abs();
            (off > self.window[i]).then(|| {
                let (scale, unit) = if i < 3 { (1e3, "mm") } else { (1f64.to_degrees(), "deg") };
                format!(
                    "the first pose is {:.1} {unit} outside the envelope in {}, more than the {:.1} {unit} the \
                     platform moves in the device's gross-jump window: refused (the stream starts at the next pose)",
                    off * scale,
                    NAMES[i],
                    self.window[i] * scale
                )
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};

    fn admission() -> Admission {
        let velocity = [0.05, 0.05, 0.05, 1.0, 1.0, 1.0];
        Admission::new(
            &TRAINER_MODEL,
            Preset::TrainerModel.home(),
            EnvelopeMargins::default(),
            velocity,
            500,
        )
    }

    #[test]
    fn garbage_of_every_kind_is_named_and_a_pose_is_not() {
        let a = admission();
        let home = Preset::TrainerModel.home();
        assert_eq!(a.garbage(&Pose::from_array(home)), None);
        assert_eq!(a.first(&Pose::from_array(home)), None, "home leads in");
        for (i, v, words) in [
            (0, f64::NAN, "x = NaN is not a finite"),
            (2, f64::INFINITY, "z = inf is not a finite"),
            (1, 1e308, "y = 1e308 is not a finite"),
            (0, 1e39, "not a finite"),
            (0, 1000.0, "x = 1000 m is beyond"),
            (3, -7.0, "alpha = -7 rad is beyond"),
            (5, 1e6, "gamma = 1e6 rad is beyond 10000 rad"),
        ] {
            let mut p = home;
            p[i] = v;
            let why = a.garbage(&Pose::from_array(p)).unwrap_or_default();
            assert!(why.contains(words), "{p:?}: {why}");
            assert!(a.first(&Pose::from_array(p)).is_some(), "{p:?} is no first pose either");
        }
        let mut turning = home;
        turning[5] = -9_999.0;
        assert_eq!(
            a.garbage(&Pose::from_array(turning)),
            None,
            "many turns of yaw are a pose"
        );
    }

    #[test]
    fn a_first_pose_far_outside_is_refused_and_one_near_the_edge_is_not() {
        let a = admission();
        let home = Preset::TrainerModel.home();
        let mut far = home;
        far[0] = 1.0;
        let why = a.first(&Pose::from_array(far)).unwrap();
        assert!(
            why.contains("outside the envelope in x") && why.contains("25.0 mm"),
            "{why}"
        );
        // Just beyond the edge along x: limited by less than the window, so a stream may start there.
        let edge = a.limited(&Pose::from_array(far)).to_array();
        let mut near = home;
        near[0] = edge[0] + 0.01 * (edge[0] - home[0]).signum();
        assert_eq!(a.first(&Pose::from_array(near)), None, "{edge:?}");
    }
}
