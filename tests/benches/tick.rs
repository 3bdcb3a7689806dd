//! One control tick of the whole core (pipeline with IK and checks, step scheduler, supervisor) while streaming,
//! and the decode + dispatch of one setpoint frame. `cargo bench -p ringpod-tests --bench tick`.

use criterion::{criterion_group, criterion_main, Criterion};
use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{self, HostMessage, Request, PROTOCOL_VERSION};
use ringpod_core::safety::State;
use ringpod_tests::plant::{Plant, Rig};
use std::hint::black_box;

fn running_rig() -> Rig {
    let controller = Controller::new(ControllerConfig::trainer_model()).unwrap();
    let mut rig = Rig {
        controller,
        plant: Plant::trainer_model([-500, -400, -300, -200, 8_000, 9_000]),
        ticks: 0,
    };
    for body in [
        HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
        HostMessage::Enable,
    ] {
        rig.controller.handle(&Request { id: 1, body });
    }
    for _ in 0..400 {
        rig.tick();
    }
    rig.controller.handle(&Request {
        id: 2,
        body: HostMessage::Home,
    });
    while rig.controller.supervisor().state() != State::Ready {
        rig.tick();
        assert!(rig.ticks < 60_000, "homing finished");
    }
    rig.controller.handle(&Request {
        id: 3,
        body: HostMessage::Start,
    });
    rig
}

/// The demo-like motion: every axis moving, within the limits at 1 kHz.
fn pose_at(k: u64) -> Pose<f32> {
    let t = k as f32 * 1e-3;
    Pose::new(
        0.01 * (0.5 * t).sin(),
        0.01 * (0.3 * t).sin(),
        0.227 + 0.01 * (0.4 * t).sin(),
        0.05 * (0.6 * t).sin(),
        0.05 * (0.7 * t).sin(),
        (0.5 * t) % core::f32::consts::TAU,
    )
}

/// Setpoint `k` of the 1 kHz stream.
fn setpoint(k: u64) -> HostMessage {
    HostMessage::Setpoint(Setpoint {
        seq: k as u32,
        time_us: k * 1000,
        pose: pose_at(k),
    })
}

fn tick(c: &mut Criterion) {
    let mut rig = running_rig();
    let mut k = 0u64;
    c.bench_function("control tick (setpoint + pipeline + scheduler + supervisor)", |b| {
        b.iter(|| {
            k += 1;
            black_box(rig.controller.handle(&Request {
                id: k as u32,
                body: setpoint(k),
            }));
            black_box(rig.controller.tick())
        })
    });
    assert_eq!(
        rig.controller.status().rejected.total(),
        0,
        "the benchmark stream is valid"
    );
    let mut frame = [0u8; protocol::MAX_FRAME];
    let mut out = [0u8; protocol::MAX_FRAME];
    c.bench_function("decode + dispatch of one setpoint frame", |b| {
        b.iter(|| {
            k += 1;
            let n = protocol::encode(
                &Request {
                    id: 7,
                    body: setpoint(k),
                },
                &mut frame,
            )
            .unwrap();
            black_box(rig.controller.handle_frame(black_box(&frame[..n - 1]), &mut out))
        })
    });
}

criterion_group!(benches, tick);
criterion_main!(benches);
