//! The spare axes 7 and 8 through the controller and the simulated plant: a stream's `axis7`/`axis8` targets
//! become steps at the plant within each axis's limits, a setpoint without them keeps them, STOP brakes them to
//! rest with the platform, an e-stop stops them at once; their section's ranges and the pins they take.

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::motion::{Setpoint, SpareAxisSettings, SpareTargets};
use ringpod_core::protocol::{ConfigRefusal, DeviceMessage, Field, FieldName, HostMessage, Request, Settings};
use ringpod_core::protocol::{NackReason, SettingsKind};
use ringpod_core::safety::{Command, State};
use ringpod_core::selfcheck::{running_rig_with, Digest};
use ringpod_core::sim::Rig;

const AXIS7: SpareAxisSettings = SpareAxisSettings {
    enabled: true,
    steps_per_unit: 200.0,
    velocity: 40.0,
    acceleration: 400.0,
    travel: [-50.0, 300.0],
};
const AXIS8: SpareAxisSettings = SpareAxisSettings {
    enabled: true,
    steps_per_unit: 1_000.0,
    velocity: 5.0,
    acceleration: 100.0,
    travel: [-20.0, 20.0],
};

/// The trainer model with both spare axes fitted, and so its supply senses off (their pins are STEP/DIR 7-8).
fn fitted() -> ControllerConfig {
    let mut c = ControllerConfig::trainer_model();
    c.supervisor.logic_sense = false;
    c.supervisor.power_sense = false;
    c.apply(&Settings::Spare([AXIS7, AXIS8])).unwrap();
    c
}

fn running() -> Rig {
    running_rig_with(&mut Digest::default(), fitted()).expect("the trainer model homes and starts")
}

/// A setpoint at the pose the controller holds, 10 ms after the previous one.
fn send(rig: &mut Rig, seq: u32, spare: SpareTargets) -> DeviceMessage {
    let body = HostMessage::Setpoint(Setpoint {
        seq,
        time_us: u64::from(seq) * 10_000,
        pose: rig.controller.pipeline().pose(),
        aux: [None; 2],
        spare,
    });
    rig.controller.handle(&Request { id: seq, body }).body
}

/// Ticks `n` periods; returns the largest step count a period gave each spare axis, and checks the speed change
/// between periods against each axis's acceleration (steps/period, with a step of rounding). `speed` is the step
/// count of the period before.
fn ticks(rig: &mut Rig, n: usize, speed: &mut [i64; 2]) -> [i64; 2] {
    let mut most = [0i64; 2];
    let mut last = rig.plant.spare;
    for _ in 0..n {
        rig.tick();
        for (i, axis) in [AXIS7, AXIS8].iter().enumerate() {
            let moved = rig.plant.spare[i] - last[i];
            let change = (moved - speed[i]).abs() as f32;
            let allowed = axis.acceleration * axis.steps_per_unit * 1e-6 + 2.0;
            assert!(
                change <= allowed,
                "axis {}: {change} steps/period more, at most {allowed}",
                i + 7
            );
            speed[i] = moved;
            most[i] = most[i].max(moved.abs());
        }
        last = rig.plant.spare;
    }
    most
}

#[test]
fn a_stream_steps_the_spare_axes_to_their_columns_within_their_limits_and_holds_them() {
    let mut rig = running();
    let mut speed = [0; 2];
    assert_eq!(rig.plant.spare, [0, 0]);
    // 100 units for axis 7 (beyond what its speed covers in one interval) and 3 for axis 8, in one setpoint; the
    // stream then goes on without the columns: the targets are kept.
    assert_eq!(send(&mut rig, 1, [Some(100.0), Some(3.0)]), DeviceMessage::Ack);
    let mut most = [0i64; 2];
    for seq in 2..400 {
        assert_eq!(send(&mut rig, seq, [None, None]), DeviceMessage::Ack);
        let m = ticks(&mut rig, 10, &mut speed);
        most = [most[0].max(m[0]), most[1].max(m[1])];
    }
    assert_eq!(rig.plant.spare, [20_000, 3_000], "100 x 200 and 3 x 1,000 steps");
    assert_eq!(rig.controller.spare_steps(), rig.plant.spare);
    assert_eq!(
        rig.controller.status().spare_steps,
        rig.plant.spare,
        "the status says them"
    );
    // The speed limits, in steps a period (1 ms): 40 x 200 / 1000 = 8 and 5 x 1000 / 1000 = 5, reached, and
    // exceeded by no more than the rounding of a position to whole steps.
    assert!((8..=9).contains(&most[0]) && (5..=6).contains(&most[1]), "{most:?}");
    // Past its travel: limited to its end.
    assert!(matches!(send(&mut rig, 400, [None, Some(-1e6)]), DeviceMessage::Ack));
    for seq in 401..1_000 {
        send(&mut rig, seq, [None, None]);
        ticks(&mut rig, 10, &mut speed);
    }
    assert_eq!(rig.plant.spare, [20_000, -20_000]);
    assert_eq!(rig.plant.steps_while_disabled, 0);
}

#[test]
fn stop_brakes_the_spare_axes_to_rest_and_an_estop_stops_them_at_once() {
    let mut rig = running();
    let mut speed = [0; 2];
    send(&mut rig, 1, [Some(250.0), Some(-15.0)]);
    for seq in 2..60 {
        send(&mut rig, seq, [None, None]);
        ticks(&mut rig, 10, &mut speed);
    }
    let moving = rig.plant.spare;
    assert!(moving[0] > 1_000 && moving[0] < 50_000, "{moving:?}");
    let stop = HostMessage::Command(Command::Stop);
    assert_eq!(
        rig.controller.handle(&Request { id: 99, body: stop }).body,
        DeviceMessage::Ack
    );
    // Braking from 8 steps a period at 0.08 steps a period per period: 100 periods, 400 steps for axis 7.
    ticks(&mut rig, 120, &mut speed);
    let rest = rig.plant.spare;
    assert!(rest[0] - moving[0] <= 8 * 100 / 2 + 16, "{moving:?} -> {rest:?}");
    assert!(rest[0] < 50_000, "short of the target");
    ticks(&mut rig, 200, &mut speed);
    assert_eq!(rig.plant.spare, rest, "at rest after STOP");
    assert_eq!(rig.controller.supervisor().state(), State::Ready);
    assert_eq!(
        send(&mut rig, 100, [Some(0.0), None]),
        DeviceMessage::Nack(NackReason::Rejected(ringpod_core::motion::RejectReason::NotStreaming,))
    );

    // Streaming again, then the e-stop chain opens: no spare step after the drivers are disabled.
    let start = HostMessage::Command(Command::Start);
    assert_eq!(
        rig.controller.handle(&Request { id: 101, body: start }).body,
        DeviceMessage::Ack
    );
    send(&mut rig, 200, [Some(-40.0), None]);
    for seq in 201..220 {
        send(&mut rig, seq, [None, None]);
        ticks(&mut rig, 10, &mut speed);
    }
    let moving = rig.plant.spare;
    assert!(moving[0] < rest[0] - 500, "moving back: {rest:?} -> {moving:?}");
    rig.plant.estop_open = true;
    ticks(&mut rig, 300, &mut [0; 2]);
    let stopped = rig.plant.spare;
    assert!(
        (stopped[0] - moving[0]).abs() <= 8 * 10,
        "{moving:?} -> {stopped:?}: the debounce's periods at most"
    );
    assert_eq!(rig.plant.steps_while_disabled, 0);
    assert!(matches!(rig.controller.supervisor().state(), State::Fault(..)));
    // The pipeline takes the counted steps as where the axes are: nothing is owed to a later stream.
    assert_eq!(rig.controller.pipeline().spare_steps(), stopped);
}

#[test]
fn a_non_finite_column_refuses_the_setpoint_whole() {
    let mut rig = running();
    let answer = send(&mut rig, 1, [None, Some(f32::NAN)]);
    assert_eq!(
        answer,
        DeviceMessage::Nack(NackReason::Rejected(ringpod_core::motion::RejectReason::NonFinite))
    );
    ticks(&mut rig, 50, &mut [0; 2]);
    assert_eq!(rig.plant.spare, [0, 0]);
}

#[test]
fn the_section_names_the_field_out_of_range_and_the_pins_it_takes() {
    let refused = |c: &ControllerConfig, s: Settings| {
        let mut c = *c;
        c.apply(&s).and_then(|()| c.validate()).map_err(|e| e.refusal())
    };
    let at = |i: usize, name| Err(ConfigRefusal::OutOfRange(Field::at(SettingsKind::Spare, i, name)));
    let base = fitted();
    let none = SpareAxisSettings::NONE;
    for (axis, name) in [
        (
            SpareAxisSettings {
                steps_per_unit: 0.0,
                ..AXIS8
            },
            FieldName::StepsPerUnit,
        ),
        (
            SpareAxisSettings {
                velocity: 201.0,
                ..AXIS8
            },
            FieldName::Velocity,
        ),
        (
            SpareAxisSettings {
                velocity: f32::NAN,
                ..AXIS8
            },
            FieldName::Velocity,
        ),
        (
            SpareAxisSettings {
                acceleration: 0.0,
                ..AXIS8
            },
            FieldName::Acceleration,
        ),
        (
            SpareAxisSettings {
                travel: [1.0, 2.0],
                ..AXIS8
            },
            FieldName::Travel,
        ),
    ] {
        assert_eq!(refused(&base, Settings::Spare([AXIS7, axis])), at(1, name), "{axis:?}");
        // Not fitted, its values are never used: not checked.
        let unfitted = SpareAxisSettings { enabled: false, ..axis };
        assert_eq!(refused(&base, Settings::Spare([none, unfitted])), Ok(()));
    }
    // Fitted, an axis takes the supply senses' pins: a configuration that senses a supply is refused.
    let sensing = ControllerConfig::trainer_model();
    assert_eq!(
        refused(&sensing, Settings::Spare([none, AXIS8])),
        at(1, FieldName::Enabled)
    );
    let text = ConfigRefusal::OutOfRange(Field::at(SettingsKind::Spare, 1, FieldName::Enabled)).to_string();
    assert!(
        text.starts_with("spare[1].enabled: must be off while the supervisor senses"),
        "{text}"
    );
    assert!(Controller::new(sensing).is_ok());
    assert!(Controller::new(base).is_ok());
}

/// A board that drives no spare axes refuses a section that fits one, takes one that fits none, and runs a stored
/// one with none fitted.
#[test]
fn a_board_without_spare_outputs_refuses_a_fitted_axis() {
    let connected = || {
        let mut c = Controller::new(fitted()).unwrap();
        let version = ringpod_core::protocol::PROTOCOL_VERSION;
        let hello = c
            .handle(&Request {
                id: 1,
                body: HostMessage::Hello { version },
            })
            .body;
        assert!(matches!(hello, DeviceMessage::Hello { .. }), "{hello:?}");
        c
    };
    let mut c = connected();
    assert!(c.pipeline().spare().any());
    c.no_spare_outputs();
    assert!(!c.pipeline().spare().any(), "the stored axes are not run");
    let set = |c: &mut Controller, axes| {
        c.handle(&Request {
            id: 1,
            body: HostMessage::SetSettings(Settings::Spare(axes)),
        })
        .body
    };
    assert_eq!(
        set(&mut c, [SpareAxisSettings::NONE, AXIS8]),
        DeviceMessage::Nack(NackReason::BadConfig(ConfigRefusal::NoSpareOutputs))
    );
    assert_eq!(set(&mut c, [SpareAxisSettings::NONE; 2]), DeviceMessage::Ack);
    let mut driven = connected();
    assert_eq!(set(&mut driven, [SpareAxisSettings::NONE, AXIS8]), DeviceMessage::Ack);
}
