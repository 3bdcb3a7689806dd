//! The auxiliary outputs through the controller: switched by the command and by the setpoints' aux
//! levels, reported in the status and the telemetry, driven into the simulated plant, dropped by an e-stop; and
//! the messages that carry them round trip through frames.

use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{
    self, setpoint_request, DeviceMessage, HostMessage, NackReason, Request, Response, MAX_FRAME,
};
use ringpod_core::safety::{Aux, AuxLevels, Command, FaultReason, Refusal, State};
use ringpod_core::selfcheck::{running_rig, Digest};
use ringpod_core::sim::Rig;

fn ask(rig: &mut Rig, body: HostMessage) -> DeviceMessage {
    rig.controller.handle(&Request { id: 7, body }).body
}

fn aux(output: Aux, on: bool) -> HostMessage {
    HostMessage::Command(Command::Aux { output, on })
}

/// A setpoint at the pose the controller holds, through the frame path a board takes (`handle_frame`).
fn setpoint_frame(rig: &mut Rig, seq: u32, levels: AuxLevels) -> DeviceMessage {
    let request = Request {
        id: 100 + seq,
        body: HostMessage::Setpoint(Setpoint {
            seq,
            time_us: u64::from(seq) * 10_000,
            pose: rig.controller.pipeline().pose(),
            aux: levels,
            spare: [None; 2],
        }),
    };
    let mut frame = [0u8; MAX_FRAME];
    let n = protocol::encode(&request, &mut frame).unwrap();
    let mut out = [0u8; MAX_FRAME];
    let m = rig.controller.handle_frame(&frame[..n - 1], &mut out);
    protocol::decode::<Response>(&out[..m - 1]).unwrap().body
}

fn ticks(rig: &mut Rig, n: usize) {
    for _ in 0..n {
        rig.tick();
    }
}

#[test]
fn commands_and_setpoints_switch_them_and_an_estop_drops_them() {
    let mut rig = running_rig(&mut Digest::default()).expect("the trainer model homes and starts");
    assert_eq!(rig.controller.supervisor().state(), State::Running);
    assert_eq!(ask(&mut rig, aux(Aux::Aux1, true)), DeviceMessage::Ack);
    ticks(&mut rig, 1);
    assert_eq!(rig.plant.aux, 1, "the plant's AUX1 follows the command");
    let DeviceMessage::Status(status) = ask(&mut rig, HostMessage::GetStatus) else {
        panic!("a status")
    };
    assert_eq!(status.aux, 1);
    assert_eq!(
        rig.controller.telemetry_sample().outputs >> 3,
        1,
        "telemetry bit 3 is AUX1"
    );

    // The setpoint stream: AUX2 on and AUX1 off in one frame, then a frame without levels keeps them.
    assert_eq!(
        setpoint_frame(&mut rig, 1, [Some(false), Some(true)]),
        DeviceMessage::Ack
    );
    ticks(&mut rig, 10);
    assert_eq!((rig.controller.supervisor().aux(), rig.plant.aux), (2, 2));
    assert_eq!(setpoint_frame(&mut rig, 2, [None, None]), DeviceMessage::Ack);
    ticks(&mut rig, 10);
    assert_eq!(rig.plant.aux, 2, "a setpoint without levels leaves them");
    assert_eq!(
        rig.controller.telemetry_sample().outputs >> 3,
        2,
        "telemetry bit 4 is AUX2"
    );
    // A refused setpoint (stale) switches nothing.
    assert!(matches!(
        setpoint_frame(&mut rig, 2, [Some(true), Some(false)]),
        DeviceMessage::Nack(NackReason::Rejected(_))
    ));
    assert_eq!(rig.controller.supervisor().aux(), 2);

    // E-stop: the fault latches and the outputs are off in the same tick.
    rig.plant.estop_open = true;
    let out = rig.tick();
    assert!(matches!(
        rig.controller.supervisor().state(),
        State::Fault(FaultReason::EStop, _)
    ));
    assert_eq!((out.outputs.aux, rig.plant.aux), (0, 0));
    assert_eq!(
        ask(&mut rig, aux(Aux::Aux2, true)),
        DeviceMessage::Nack(NackReason::Refused(Refusal::Faulted))
    );
    assert_eq!(
        ask(&mut rig, aux(Aux::Aux2, false)),
        DeviceMessage::Ack,
        "off is always taken"
    );
}

#[test]
fn a_stop_keeps_them_a_disable_switches_them_off() {
    let mut rig = running_rig(&mut Digest::default()).expect("the trainer model homes and starts");
    assert_eq!(ask(&mut rig, aux(Aux::Aux2, true)), DeviceMessage::Ack);
    assert_eq!(ask(&mut rig, HostMessage::Command(Command::Stop)), DeviceMessage::Ack);
    ticks(&mut rig, 2000);
    assert_eq!(rig.controller.supervisor().state(), State::Ready);
    assert_eq!(rig.plant.aux, 2, "at rest, AUX2 still on");
    assert_eq!(
        ask(&mut rig, HostMessage::Command(Command::Disable)),
        DeviceMessage::Ack
    );
    ticks(&mut rig, 1);
    assert_eq!(rig.plant.aux, 0, "off with the drivers, before power drops");
    assert_eq!(
        ask(&mut rig, aux(Aux::Aux1, true)),
        DeviceMessage::Nack(NackReason::Refused(Refusal::WrongState))
    );
}

#[test]
fn the_messages_round_trip() {
    for command in Command::ALL {
        let request = Request {
            id: 3,
            body: HostMessage::Command(command),
        };
        let mut frame = [0u8; MAX_FRAME];
        let n = protocol::encode(&request, &mut frame).unwrap();
        assert_eq!(protocol::decode::<Request>(&frame[..n - 1]).unwrap(), request);
    }
    for levels in [
        [None, None],
        [Some(true), None],
        [None, Some(false)],
        [Some(false), Some(true)],
    ] {
        let setpoint = Setpoint {
            seq: 9,
            time_us: 90_000,
            pose: ringpod_core::kinematics::Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.1),
            aux: levels,
            spare: [None; 2],
        };
        let request = Request {
            id: 4,
            body: HostMessage::Setpoint(setpoint),
        };
        let mut payload = [0u8; MAX_FRAME];
        let bytes = postcard::to_slice(&request, &mut payload).unwrap();
        // The stream's hot path reads the aux levels too.
        assert_eq!(setpoint_request(bytes), Some((4, setpoint)));
        // Two bytes without levels, one more per level given; two more for the spare axes' absent targets.
        let given = levels.iter().filter(|l| l.is_some()).count() + 2;
        let bare = postcard::to_slice(&(4u32, 2u32, 9u32, 90_000u64, setpoint.pose), &mut [0u8; 64])
            .unwrap()
            .len();
        assert_eq!(bytes.len(), bare + 2 + given);
    }
}
