//! The 1:20 trainer model of FIRMWARE.md, every number of it in this one file: its motors, pose and actuator limits,
//! homing, and where the simulator parks it. Its geometry and home pose
//! are a preset among the source's mechanisms (`kinematics::presets::TRAINER_MODEL`, `Preset::TrainerModel`) and
//! its spec ranges are there too; its motors' torque curves are host data (`ringpod presets --export`). Another rig
//! takes its own numbers from its rig file and starts from these where the file says nothing
//! ([`crate::controller::ControllerConfig::default_record`]); the configuration the firmware compiles in is
//! [`crate::controller::ControllerConfig::trainer_model`], built from these.

use crate::kinematics::AxisKind;
use crate::motion::{AxisScale, MotionLimits};
use crate::protocol::{HomingSettings, SwitchSettings, Toward};

impl MotionLimits {
    /// The 1:20 trainer model: 0.05 m/s (spec table), 1.9 rad/s of yaw (its test motion) and 1 rad/s of tilt;
    /// accelerations of 1 m/s^2 and 20 rad/s^2 let the 50 Hz vibration tests run at small amplitude. Actuators:
    /// 2.4 rad/s on the carriages (9.8 k steps/s) and 0.06 m/s on the linear actuators (96 k steps/s), inside the
    /// 100 k steps/s the step generator sustains. Actuator accelerations (100 rad/s^2, 5 m/s^2) are above what the
    /// pose limits ask through the Jacobian over the workspace, so they bind only near singularities, where the
    /// motion is slowed to keep the steppers from losing steps.
    pub const TRAINER_MODEL: MotionLimits = MotionLimits {
        pose_velocity: [0.05, 0.05, 0.05, 1.0, 1.0, 1.9],
        pose_acceleration: [1.0, 1.0, 1.0, 20.0, 20.0, 20.0],
        actuator_velocity: [2.4, 2.4, 2.4, 2.4, 0.06, 0.06],
        actuator_acceleration: [100.0, 100.0, 100.0, 100.0, 5.0, 5.0],
    };
}

impl AxisScale {
    /// FL20 (200 full steps) at 1/16 microstepping on an 8:1 ring gear: 25,600 steps per carriage turn. The source
    /// gives the FL20 and no gearing: the 8:1 ratio is the specification's assumption (FIRMWARE.md, "Step rates").
    pub const MODEL_CARRIAGE: AxisScale = AxisScale {
        steps_per_turn: 25_600,
        steps_per_unit: 25_600.0 / core::f32::consts::TAU,
        invert: false,
    };
    /// FL20 at 1/16 on a 2 mm lead screw: 1.6 M steps per metre (the lead, too, is the specification's assumption).
    pub const MODEL_LINEAR: AxisScale = AxisScale {
        steps_per_turn: 0,
        steps_per_unit: 1.6e6,
        invert: false,
    };
    /// An elbow chain's shoulder (`trainer-elbow`): FL20 at 1/16 on a 20:1 gear, 64,000 steps per shoulder turn
    /// (10.2 k steps/rad). The source builds no such arm: the gear is an assumption, chosen so that the FL20 holds
    /// the arm's static torque with margin and the shoulder's top speed stays within the step generator's rate.
    pub const MODEL_SHOULDER: AxisScale = AxisScale {
        steps_per_turn: 64_000,
        steps_per_unit: 64_000.0 / core::f32::consts::TAU,
        invert: false,
    };
}

/// Actuator limits of an elbow chain's shoulder on the trainer model's FL20 drives: 3 rad/s (30.6 k steps/s at
/// [`AxisScale::MODEL_SHOULDER`]) and 60 rad/s^2, above what the pose limits ask through the Jacobian over the
/// spec box (the arm's 105 mm upper arm turns about 0.5 rad/s at 0.05 m/s of heave).
pub const SHOULDER_VELOCITY: f32 = 3.0;
/// See [`SHOULDER_VELOCITY`] (rad/s^2).
pub const SHOULDER_ACCELERATION: f32 = 60.0;

/// The velocity and acceleration limits of an actuator of `kind` on the trainer model's drives: what a rig's
/// `[motion]` takes for an actuator it gives no limits for, and what a stored record of version 2 (which had none)
/// is given.
pub fn actuator_limits(kind: AxisKind) -> (f32, f32) {
    let model = MotionLimits::TRAINER_MODEL;
    match kind {
        AxisKind::Ring => (model.actuator_velocity[0], model.actuator_acceleration[0]),
        AxisKind::Linear => (model.actuator_velocity[4], model.actuator_acceleration[4]),
        AxisKind::Angle => (SHOULDER_VELOCITY, SHOULDER_ACCELERATION),
    }
}

/// An elbow chain's shoulder homing: an index flag at the shoulder's home-pose angle, as a carriage's, searched
/// up to 20 degrees at 8,000 steps/s of its 64,000 per turn, backed off 2 degrees, approached at 1,000 steps/s.
///
/// Not an end switch at the end of the travel, as a linear actuator's: with one shoulder at the end of its travel
/// and the other axes at home the platform is far outside its workspace (`trainer-elbow`: both shoulders at the
/// lower end roll it by 56 degrees), where forward kinematics after homing cannot find it. The flag is passed in
/// normal motion, so it is no limit; the reach check keeps the shoulder inside its travel.
pub const SHOULDER_HOMING: SwitchSettings = SwitchSettings {
    toward: Toward::Plus,
    switch: 0.0,
    search: 20.0 * core::f32::consts::PI / 180.0,
    backoff: 2.0 * core::f32::consts::PI / 180.0,
    fast: 8_000.0 * core::f32::consts::TAU / 64_000.0,
    slow: 1_000.0 * core::f32::consts::TAU / 64_000.0,
};

/// The trainer model's motors in actuator order: four carriages on the ring, two linear actuators.
pub const SCALES: [AxisScale; 6] = [
    AxisScale::MODEL_CARRIAGE,
    AxisScale::MODEL_CARRIAGE,
    AxisScale::MODEL_CARRIAGE,
    AxisScale::MODEL_CARRIAGE,
    AxisScale::MODEL_LINEAR,
    AxisScale::MODEL_LINEAR,
];

/// Its homing: the two linear actuators first, then the carriages in the order 1, 3, 2, 4, searching up to 20
/// degrees of ring (linear actuators up to 40 mm); then the platform moves to the home pose under the normal limits.
pub const HOMING: HomingSettings = HomingSettings {
    axes: [
        CARRIAGE_HOMING,
        CARRIAGE_HOMING,
        CARRIAGE_HOMING,
        CARRIAGE_HOMING,
        LINEAR_HOMING,
        LINEAR_HOMING,
    ],
    order: [4, 5, 0, 2, 1, 3],
};

/// Telemetry samples a second while a host is connected and asks for them.
pub const TELEMETRY_HZ: u16 = 100;

/// The trainer model's carriage homing: the index flags sit at the carriages' home-pose angles; searched up to 20
/// degrees of ring at 4,000 steps/s of its 25,600 per turn, backed off 2 degrees, approached at 500 steps/s.
pub const CARRIAGE_HOMING: SwitchSettings = SwitchSettings {
    toward: Toward::Plus,
    switch: 0.0,
    search: 20.0 * core::f32::consts::PI / 180.0,
    backoff: 2.0 * core::f32::consts::PI / 180.0,
    fast: 4_000.0 * core::f32::consts::TAU / 25_600.0,
    slow: 500.0 * core::f32::consts::TAU / 25_600.0,
};

/// The trainer model's linear-actuator homing: the lower end switch at 165 mm, below the 173 mm the spec ranges use
/// and above the 160 mm stroke minimum, 66.31 mm below the home-pose length of 231.31 mm (the platform parks low);
/// searched up to 40 mm (the platform parks within 40 mm of the switches) at 20 mm/s, backed off 2 mm, approached
/// at 2.5 mm/s.
pub const LINEAR_HOMING: SwitchSettings = SwitchSettings {
    toward: Toward::Minus,
    switch: -0.066_31,
    search: 0.040,
    backoff: 0.002,
    fast: 0.020,
    slow: 0.0025,
};

/// Where the simulator parks the trainer model (steps from each axis's switch): carriages a few degrees before
/// their index flags, linear actuators 5-6 mm above their home ends. The host simulator, the QEMU controller and the
/// tests start here, so that the same input ends at the same step positions on each of them.
pub const TRAINER_MODEL_PARKED: [i64; 6] = [-500, -400, -300, -200, 8_000, 9_000];
