use proptest::prelude::*;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::{Mechanism, MultiTurn, Pose};
use ringpod_core::motion::StepConverter;
use ringpod_core::protocol::Telemetry;
use ringpod_core::safety::State;

use super::Followed;

/// The trainer model as its compiled-in configuration drives it.
fn trainer() -> (ControllerConfig, Followed) {
    let config = ControllerConfig::trainer_model();
    let followed = Followed::of(&config.rig()).expect("the trainer's record gives a solver");
    (config, followed)
}

/// The steps a homed device counts at `pose`: step 0 of every axis at the home pose.
fn steps_at(config: &ControllerConfig, pose: &Pose<f32>) -> [i64; 6] {
    let mechanism = ringpod_core::kinematics::RingPlatform::<f32>::new(&config.geometry);
    let home = mechanism
        .inverse(&Pose::from_array(config.home.map(|v| v as f32)))
        .unwrap();
    let mut converter = StepConverter::new(config.scales, mechanism.axes());
    for a in 0..6 {
        converter.set_home(a, &MultiTurn::new(home), 0);
    }
    converter.to_steps(&MultiTurn::new(mechanism.inverse(pose).unwrap()))
}

/// A sample in `state` that commands `commanded` and has counted `steps`.
fn sample(state: State, commanded: Pose<f32>, steps: [i64; 6]) -> Telemetry {
    Telemetry {
        time_us: 0,
        state,
        pose: commanded,
        target: commanded,
        steps,
        flags: 0,
        applied: 0,
        limited: 0,
        refused: 0,
        tick_cost: 0,
        inputs: 0,
        outputs: 0,
    }
}

/// Pose near the trainer's home: offsets in mm and degrees.
fn near_home(config: &ControllerConfig, mm: [f32; 3], deg: [f32; 3]) -> Pose<f32> {
    let h = config.home.map(|v| v as f32);
    Pose::from_array([
        h[0] + mm[0] / 1000.0,
        h[1] + mm[1] / 1000.0,
        h[2] + mm[2] / 1000.0,
        h[3] + deg[0].to_radians(),
        h[4] + deg[1].to_radians(),
        h[5] + deg[2].to_radians(),
    ])
}

fn distance(a: &Pose<f32>, b: &Pose<f32>) -> (f32, f32) {
    let (a, b) = (a.to_array(), b.to_array());
    let lin = (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max);
    let ang = (3..6).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max);
    (lin, ang)
}

#[test]
fn a_lagging_yaw_is_shown_where_the_steps_are() {
    let (config, mut followed) = trainer();
    // The carriages are 5 degrees of yaw behind what was commanded (the step scheduler carrying steps over).
    let played = near_home(&config, [0.0, 0.0, 0.0], [0.0, 0.0, 20.0]);
    let commanded = near_home(&config, [0.0, 0.0, 0.0], [0.0, 0.0, 25.0]);
    let mut s = sample(State::Running, commanded, steps_at(&config, &played));
    followed.apply(&mut s);
    let (lin, ang) = distance(&s.pose, &played);
    assert!(lin < 1e-4 && ang < 1e-3, "followed {:?}, played {:?}", s.pose, played);
    assert_eq!(followed.unsolved, 0);
}

#[test]
fn before_homing_the_pose_is_where_the_device_takes_it() {
    let (config, mut followed) = trainer();
    let placeholder = near_home(&config, [0.0; 3], [20.0, 0.0, 0.0]);
    let target = near_home(&config, [0.0; 3], [0.0; 3]);
    for state in [
        State::Off,
        State::LogicOn,
        State::PowerOn { settled: true },
        State::Homing,
        State::Jogging,
    ] {
        let mut s = sample(state, placeholder, [1_000, -2_000, 3_000, 0, 0, 0]);
        s.target = target;
        followed.apply(&mut s);
        assert_eq!(s.pose, target, "{state:?}");
    }
    assert_eq!(followed.unsolved, 0);
}

/// After a STOP the device ramps to rest and shuts down: the seat is where the steps are, not where the last
/// setpoint asked, through the shutdown and the power-down; homing again (or a jog) voids the steps' coordinates.
#[test]
fn after_a_stop_the_pose_is_still_the_counted_one() {
    let (config, mut followed) = trainer();
    let played = near_home(&config, [0.0; 3], [0.0, 0.0, 12.0]);
    let commanded = near_home(&config, [0.0; 3], [0.0, 0.0, 16.0]);
    let steps = steps_at(&config, &played);
    let mut running = sample(State::Running, commanded, steps);
    followed.apply(&mut running);
    use ringpod_core::safety::{FaultReason, Supplies};
    for state in [
        State::ShuttingDown(ringpod_core::safety::supervisor::Shutdown::Drivers),
        State::Off,
        State::Fault(FaultReason::EStop, Supplies::Both),
    ] {
        let mut s = sample(state, commanded, steps);
        followed.apply(&mut s);
        let (lin, ang) = distance(&s.pose, &played);
        assert!(
            lin < 1e-4 && ang < 1e-3,
            "{state:?}: followed {:?}, played {:?}",
            s.pose,
            played
        );
    }
    let mut homing = sample(State::Homing, commanded, steps);
    homing.target = played;
    followed.apply(&mut homing);
    let mut off = sample(State::Off, commanded, steps);
    off.target = commanded;
    followed.apply(&mut off);
    assert_eq!(off.pose, commanded, "homing voided the counted coordinates");
}

#[test]
fn steps_that_give_no_pose_keep_the_device_pose_and_are_counted() {
    let (config, mut followed) = trainer();
    let commanded = near_home(&config, [0.0; 3], [0.0; 3]);
    // Far beyond any carriage's travel: no pose within reach of the guess.
    let mut s = sample(State::Ready, commanded, [i64::MAX / 4, 0, 0, i64::MIN / 4, 0, 0]);
    followed.apply(&mut s);
    assert_eq!(s.pose, commanded);
    assert_eq!(followed.unsolved, 1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Anywhere near home, a commanded pose a few millimetres and degrees from the played one: the followed pose is
    /// the played one, to within what a step resolves.
    #[test]
    fn the_counted_pose_round_trips(
        mm in prop::array::uniform3(-15.0f32..15.0),
        deg in prop::array::uniform3(-8.0f32..8.0),
        lag_mm in prop::array::uniform3(-3.0f32..3.0),
        lag_deg in prop::array::uniform3(-3.0f32..3.0),
    ) {
        let (config, mut followed) = trainer();
        let played = near_home(&config, mm, deg);
        let commanded = near_home(
            &config,
            [mm[0] + lag_mm[0], mm[1] + lag_mm[1], mm[2] + lag_mm[2]],
            [deg[0] + lag_deg[0], deg[1] + lag_deg[1], deg[2] + lag_deg[2]],
        );
        let steps = steps_at(&config, &played);
        let mut s = sample(State::Running, commanded, steps);
        followed.apply(&mut s);
        prop_assert_eq!(followed.unsolved, 0);
        // Its steps are the counted ones, to within a step of rounding.
        let again = steps_at(&config, &s.pose);
        for a in 0..6 {
            prop_assert!((again[a] - steps[a]).abs() <= 1, "axis {}: {} vs {}", a, again[a], steps[a]);
        }
    }
}
