//! Telemetry: unsolicited samples at the configured rate while a host is connected, with device time and flags
//! that say what happened since the previous sample.

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{
    self, DeviceMessage, HostMessage, Request, Response, Settings, SettingsKind, Telemetry, TelemetryFlags, MAX_FRAME,
    PROTOCOL_VERSION,
};
use ringpod_core::safety::{FaultReason, State, Supplies};

fn hello(c: &mut Controller) {
    let r = c.handle(&Request {
        id: 1,
        body: HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    });
    assert!(matches!(r.body, DeviceMessage::Hello { .. }));
}

fn subscribe(c: &mut Controller, on: bool) {
    let r = c.handle(&Request {
        id: 9,
        body: HostMessage::Telemetry(on),
    });
    assert_eq!(r.body, DeviceMessage::Ack);
}

/// Ticks `n` times, collecting the telemetry the controller has to send after each tick.
fn run(c: &mut Controller, n: usize) -> Vec<Telemetry> {
    let mut out = Vec::new();
    for _ in 0..n {
        c.tick();
        while let Some(r) = c.unsolicited() {
            assert_eq!(r.id, 0);
            if let DeviceMessage::Telemetry(t) = r.body {
                out.push(t);
            }
        }
    }
    out
}

#[test]
fn samples_come_at_the_configured_rate_only_while_connected() {
    let mut c = Controller::new(ControllerConfig::trainer_model()).unwrap();
    assert!(run(&mut c, 500).is_empty(), "no host, no telemetry");
    hello(&mut c);
    assert!(run(&mut c, 500).is_empty(), "a host that did not ask gets none");
    subscribe(&mut c, true);
    let samples = run(&mut c, 1000);
    assert_eq!(samples.len(), 100, "100 Hz at a 1 kHz tick");
    for w in samples.windows(2) {
        assert_eq!(w[1].time_us - w[0].time_us, 10_000);
    }
    assert_eq!(samples[0].state, State::Off);
    let set = |c: &mut Controller, hz: u16| {
        let Settings::Stream(mut s) = c.config().settings(SettingsKind::Stream) else {
            panic!("not the stream section")
        };
        s.telemetry_hz = hz;
        c.handle(&Request {
            id: 2,
            body: HostMessage::SetSettings(Settings::Stream(s)),
        })
        .body
    };
    assert_eq!(set(&mut c, 250), DeviceMessage::Ack);
    assert_eq!(run(&mut c, 1000).len(), 250);
    assert_eq!(set(&mut c, 0), DeviceMessage::Ack);
    assert!(run(&mut c, 1000).is_empty());
    assert!(matches!(set(&mut c, 2500), DeviceMessage::Nack(_)));
    assert_eq!(set(&mut c, 100), DeviceMessage::Ack);
    assert_eq!(run(&mut c, 100).len(), 10);
    subscribe(&mut c, false);
    assert!(run(&mut c, 1000).is_empty(), "unsubscribed");
    subscribe(&mut c, true);
    hello(&mut c);
    assert!(
        run(&mut c, 1000).is_empty(),
        "a new connection starts without telemetry"
    );
}

#[test]
fn a_refusal_is_flagged_in_the_next_sample_only() {
    let mut c = Controller::new(ControllerConfig::trainer_model()).unwrap();
    hello(&mut c);
    subscribe(&mut c, true);
    run(&mut c, 20);
    // Not streaming: refused.
    let r = c.handle(&Request {
        id: 3,
        body: HostMessage::Setpoint(Setpoint {
            seq: 1,
            time_us: 0,
            pose: Pose::new(0.0, 0.0, 0.227, 0.0, 0.0, 0.0),
            aux: [None; 2],
            spare: [None; 2],
        }),
    });
    assert!(matches!(r.body, DeviceMessage::Nack(_)), "{r:?}");
    let samples = run(&mut c, 20);
    assert_eq!(samples.len(), 2);
    assert_eq!(samples[0].flags, TelemetryFlags::REFUSED);
    assert_eq!(samples[0].refused, 1);
    assert_eq!(samples[1].flags, 0);
    assert_eq!(samples[1].refused, 1);
}

#[test]
fn the_largest_sample_fits_a_frame() {
    let big = Pose::new(f32::MAX, f32::MIN, f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    let t = Telemetry {
        time_us: u64::MAX,
        state: State::Fault(FaultReason::Limit(u8::MAX), Supplies::Both),
        pose: big,
        target: big,
        steps: [i64::MIN, i64::MAX, i64::MIN, i64::MAX, i64::MIN, i64::MAX],
        flags: u8::MAX,
        applied: u32::MAX,
        limited: u32::MAX,
        refused: u32::MAX,
        tick_cost: u32::MAX,
        inputs: u16::MAX,
        outputs: u8::MAX,
    };
    let response = Response {
        id: u32::MAX,
        body: DeviceMessage::Telemetry(t),
    };
    let mut buf = [0u8; MAX_FRAME];
    let n = protocol::encode(&response, &mut buf).unwrap();
    assert_eq!(protocol::decode::<Response>(&buf[..n - 1]).unwrap(), response);
}
