//! Host benchmarks of the kinematics core: IK, IK with all six workspace checks, and FK, in f32 and f64.
//!
//! `cargo bench -p ringpod-core --bench kinematics`. Each iteration works on one of 256 poses that combine all axes
//! at up to half the trainer model's spec ranges (with yaw), so the branch mix is realistic; FK starts 1 mm / 0.5 degree away from
//! the answer, as it does at 1 kHz.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ringpod_core::kinematics::{presets, Actuators, Mechanism, NewtonOptions, Pose, RingPlatform};
use ringpod_core::Real;
use std::hint::black_box;

fn poses<T: Real>() -> Vec<Pose<T>> {
    // Half of every range at once: all axes move together, and every pose is inside the workspace.
    let [t, _, h, r, _] = presets::TRAINER_MODEL_RANGES.map(|v| v * 0.5);
    (0..256)
        .map(|k| {
            let s = |f: f64| (k as f64 * f).sin();
            Pose::new(
                t * s(0.37),
                t * s(0.53),
                presets::TRAINER_MODEL_HOME_Z + h * s(0.71),
                r * s(0.29),
                r * s(0.43),
                (k as f64 * 0.1).rem_euclid(std::f64::consts::TAU),
            )
            .cast()
        })
        .collect()
}

fn bench_scalar<T: Real>(c: &mut Criterion, name: &str) {
    let m = RingPlatform::<T>::new(&presets::TRAINER_MODEL);
    let poses = poses::<T>();
    let solved: Vec<(Pose<T>, Actuators<T>)> = poses
        .iter()
        .filter_map(|p| m.inverse(p).ok().map(|q| (*p, q)))
        .collect();
    assert_eq!(solved.len(), poses.len(), "every benchmark pose is reachable");
    let mut group = c.benchmark_group(format!("trainer-model {name}"));
    group.throughput(Throughput::Elements(1));
    let mut i = 0;
    group.bench_function(BenchmarkId::new("ik", name), |b| {
        b.iter(|| {
            i = (i + 1) & 255;
            black_box(m.inverse(black_box(&poses[i])))
        })
    });
    group.bench_function(BenchmarkId::new("ik+checks", name), |b| {
        b.iter(|| {
            i = (i + 1) & 255;
            black_box(m.inverse_checked(black_box(&poses[i])))
        })
    });
    let options = NewtonOptions::default();
    group.bench_function(BenchmarkId::new("fk", name), |b| {
        b.iter(|| {
            i = (i + 1) & 255;
            let (pose, q) = &solved[i];
            let guess = Pose {
                x: pose.x + T::of(1e-3),
                alpha: pose.alpha + T::of(0.0087),
                ..*pose
            };
            black_box(m.forward(black_box(q), &guess, &options))
        })
    });
    group.finish();
}

fn kinematics(c: &mut Criterion) {
    bench_scalar::<f32>(c, "f32");
    bench_scalar::<f64>(c, "f64");
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
