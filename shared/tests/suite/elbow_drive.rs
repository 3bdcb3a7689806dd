//! The controller drives the elbow trainer: its shoulders (angle axes in steps per turn, index flags at their home
//! angles) and carriages home in the simulated machine. (Streaming it end to end: the host's `stream --sim
//! --mechanism trainer-elbow` test.)

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::kinematics::presets::{Preset, TRAINER_ELBOW};
use ringpod_core::kinematics::{AxisKind, Mechanism, RingPlatform};
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request, PROTOCOL_VERSION};
use ringpod_core::protocol::{Settings, SettingsKind};
use ringpod_core::safety::{Command, FaultReason, State};
use ringpod_core::sim::{Plant, Rig};

fn rig() -> Rig {
    let config = ControllerConfig::for_rig(&TRAINER_ELBOW, Preset::TrainerElbow.home()).unwrap();
    let plant = Plant::for_config(&config);
    let mut controller = Controller::new(config).unwrap();
    let hello = controller.handle(&Request {
        id: 1,
        body: HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    });
    assert!(matches!(hello.body, DeviceMessage::Hello { .. }));
    Rig {
        controller,
        plant,
        ticks: 0,
    }
}

/// Enables and homes; at most 60 s of ticks.
fn home(rig: &mut Rig) -> State {
    for body in [
        HostMessage::Command(Command::Enable),
        HostMessage::Command(Command::Home),
    ] {
        for _ in 0..5_000 {
            if matches!(
                rig.controller.supervisor().state(),
                State::PowerOn { settled: true } | State::Ready
            ) {
                break;
            }
            rig.tick();
        }
        assert_eq!(rig.controller.handle(&Request { id: 9, body }).body, DeviceMessage::Ack);
    }
    for _ in 0..60_000 {
        match rig.controller.supervisor().state() {
            s @ (State::Ready | State::Fault(..)) => return s,
            _ => {
                rig.tick();
            }
        }
    }
    rig.controller.supervisor().state()
}

/// Shoulders first (angle axes, index flags at their home angles, parked a few degrees before them), then the
/// carriages; the platform ends at home with every axis at its flag.
#[test]
fn the_elbow_trainer_homes() {
    let mut rig = rig();
    let axes = RingPlatform::<f64>::new(&TRAINER_ELBOW).axes();
    assert_eq!(&axes[4..], &[AxisKind::Angle, AxisKind::Angle]);
    assert!(
        rig.plant.position[4..].iter().all(|p| *p < 0),
        "{:?}",
        rig.plant.position
    );
    assert_eq!(home(&mut rig), State::Ready);
    assert_eq!(rig.plant.position, [0; 6]);
    assert_eq!(rig.controller.steps(), [0; 6]);
    // The shoulders' scale: steps per turn as the axes section gives it, steps per radian inside.
    let Settings::Axes(a) = rig.controller.config().settings(SettingsKind::Axes) else {
        panic!("no axes section")
    };
    assert_eq!(a[4].steps_per_unit, 64_000.0);
    assert_eq!(a[0].steps_per_unit, 25_600.0);
}

/// A shoulder wired the other way round searches away from its flag and homing fails, as a carriage's does.
#[test]
fn a_reversed_shoulder_fails_homing() {
    let mut rig = rig();
    rig.plant.reversed = 1 << 5;
    assert!(matches!(home(&mut rig), State::Fault(FaultReason::HomingFailed, _)));
}
