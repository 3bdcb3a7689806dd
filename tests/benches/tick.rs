//! One control tick of the whole core (pipeline with IK and checks, step scheduler, supervisor) while streaming,
//! and the decode + dispatch of one setpoint frame. `cargo bench -p ringpod-tests --bench tick`.

use criterion::{criterion_group, criterion_main, Criterion};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{self, HostMessage, Request};
use ringpod_core::selfcheck;
use ringpod_core::sim::Rig;
use std::hint::black_box;

/// A controller brought to `Running` through power-up and homing, with its simulated plant (the same procedure the
/// self-check and the QEMU cost table use).
fn running_rig() -> Rig {
    selfcheck::running_rig(&mut selfcheck::Digest::default()).expect("the controller reaches Running")
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
        aux: [None; 2],
        spare: [None; 2],
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
