//! Host benchmark of paper 002's matrix method on the rotopod (6 chains, 18 pairs, 36 variables, 5 loops): one point
//! of a motion, the loops closed from the previous point 1 mm / 0.5 degree away and the drive torques by the Lagrange
//! equation; and the closure alone.
//!
//! `cargo bench -p ringpod-core --bench matrix`.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Matrix3;
use ringpod_core::kinematics::{presets::ROTOPOD_CH4, Mechanism, Pose, RingPlatform};
use ringpod_core::screws::matrix::ring::ring_model;
use std::hint::black_box;

fn matrix(c: &mut Criterion) {
    let home = Pose::new(0.0, 0.0, 0.7, 0.0, 0.0, 0.0);
    let Ok(rm) = ring_model(&ROTOPOD_CH4, &home, 3.5, &Matrix3::from_diagonal_element(0.4)) else {
        return;
    };
    let ring = RingPlatform::<f64>::new(&ROTOPOD_CH4);
    let Ok(q) = ring.inverse(&Pose::new(0.001, 0.0, 0.7, 0.0087, 0.0, 0.0)) else {
        return;
    };
    let rates = [0.1, -0.2, 0.05, 0.3, -0.1, 0.2];
    let accelerations = [1.0, 0.5, -0.7, 0.2, 0.9, -0.4];
    let mut group = c.benchmark_group("matrix/rotopod");
    group.bench_function("close", |b| {
        b.iter(|| black_box(rm.model.closed(black_box(&rm.q), &q.0)))
    });
    group.bench_function("close and inverse dynamics", |b| {
        b.iter(|| black_box(rm.model.solve_point(black_box(&rm.q), &q.0, &rates, &accelerations)))
    });
    group.finish();
}

criterion_group!(benches, matrix);
criterion_main!(benches);
