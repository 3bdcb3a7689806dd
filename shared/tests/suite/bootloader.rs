//! The bootloader request: taken without a handshake, only in `Off` (supplies and drivers off), refused with the
//! reason in any other state; the hello and a version mismatch name the firmware the device runs.

use crate::common::device;

use ringpod_core::controller::{Controller, ControllerConfig, Restart};
use ringpod_core::protocol::{
    DeviceMessage, Firmware, HostMessage, Image, NackReason, Request, Settings, SettingsKind, PROTOCOL_VERSION,
};
use ringpod_core::safety::{Refusal, State};
use ringpod_core::selfcheck::{running_rig, Digest};

fn ask(c: &mut Controller, body: HostMessage) -> DeviceMessage {
    c.handle(&Request { id: 3, body }).body
}

const FLASHED: Firmware = Firmware {
    version: [0, 1, 0],
    image: Some(Image {
        size: 195_580,
        crc: 0x1234_5678,
    }),
};

#[test]
fn running_refuses_the_bootloader_and_nothing_changes() {
    let mut rig = running_rig(&mut Digest::default()).expect("the trainer model homes and starts");
    let outputs = rig.controller.supervisor().outputs();
    let position = rig.plant.position;
    assert_eq!(
        ask(&mut rig.controller, HostMessage::EnterBootloader),
        DeviceMessage::Nack(NackReason::Refused(Refusal::WrongState))
    );
    for _ in 0..100 {
        rig.tick();
    }
    assert_eq!(rig.controller.supervisor().state(), State::Running);
    assert_eq!(rig.controller.supervisor().outputs(), outputs);
    assert_eq!(rig.plant.position, position, "the platform held still");
    assert_eq!(rig.controller.restart_due(), None);
}

#[test]
fn off_takes_it_without_a_handshake_once_everything_is_stored() {
    // No hello at all: any other request is refused as not connected, this one is taken.
    let mut c = Controller::new(ControllerConfig::trainer_model()).unwrap();
    assert_eq!(
        ask(&mut c, HostMessage::GetStatus),
        DeviceMessage::Nack(NackReason::NotConnected)
    );
    assert_eq!(ask(&mut c, HostMessage::EnterBootloader), DeviceMessage::Ack);
    assert_eq!(c.restart_due(), Some(Restart::Bootloader));

    // A setting changed just before waits to be stored first.
    let mut c = device::connected();
    let stream = ControllerConfig::trainer_model().settings(SettingsKind::Stream);
    let Settings::Stream(mut changed) = stream else {
        panic!("a stream section")
    };
    changed.timeout_ms += 10;
    assert_eq!(
        ask(&mut c, HostMessage::SetSettings(Settings::Stream(changed))),
        DeviceMessage::Ack
    );
    assert_eq!(ask(&mut c, HostMessage::EnterBootloader), DeviceMessage::Ack);
    assert_eq!(c.restart_due(), None, "the setting is not stored yet");
    assert!(c.take_unsaved().is_some());
    assert_eq!(c.restart_due(), Some(Restart::Bootloader));
    // A plain restart is the controller's.
    let mut c = device::connected();
    assert_eq!(ask(&mut c, HostMessage::Restart), DeviceMessage::Ack);
    assert_eq!(c.restart_due(), Some(Restart::Controller));
}

#[test]
fn the_hello_and_a_mismatch_name_the_firmware() {
    let mut c = Controller::new(ControllerConfig::trainer_model()).unwrap();
    assert_eq!(c.firmware(), Firmware::BUILT);
    c.set_firmware(FLASHED);
    match ask(
        &mut c,
        HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    ) {
        DeviceMessage::Hello { version, firmware, .. } => assert_eq!((version, firmware), (PROTOCOL_VERSION, FLASHED)),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        ask(
            &mut c,
            HostMessage::Hello {
                version: PROTOCOL_VERSION + 1
            }
        ),
        DeviceMessage::Nack(NackReason::VersionMismatch {
            device: PROTOCOL_VERSION,
            firmware: Some(FLASHED),
        })
    );
    // The mismatch ended the connection: nothing but the handshake and the bootloader request is taken.
    assert_eq!(
        ask(&mut c, HostMessage::GetStatus),
        DeviceMessage::Nack(NackReason::NotConnected)
    );
}
