//! One sample of the optimal cueing (its three axes' solves and the search of the tilt's room) on the trainer
//! model's envelope, at the default horizon: the time the 2 ms budget of a 100 Hz sample is measured against; and
//! the same with the tilts' loss of vertical force priced (a cost matrix that changes every sample), with the lap
//! preview (its alignment against eight laps kept and its reference), and the preview alone.

use criterion::{criterion_group, criterion_main, Criterion};
use ringpod_core::cueing::{Algorithm, CueConfig, Telemetry, G};
use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};
use ringpod_core::kinematics::{Pose, RingPlatform};

// The optimal cueing's module as the binary builds it (the host is a binary crate: no library to link).
#[allow(dead_code, unused_imports)]
#[path = "../src/cueing/optimal/mod.rs"]
mod optimal;

#[allow(dead_code, unused_imports)]
#[path = "../src/cueing/lap/mod.rs"]
mod lap;

fn sample(t: f64) -> Telemetry<f64> {
    Telemetry {
        force: [-6.0 * (t * 0.7).sin(), 8.0 * (t * 0.3).sin(), G + (t * 9.0).sin()],
        rate: [0.1 * (t * 2.0).sin(), 0.05 * (t * 1.3).cos(), 0.3],
    }
}

/// The optimal cueing at its defaults on the trainer model, with the rig: each sample also searches the tilt's
/// shared room; the tilts' loss of vertical force priced at `loss_weight`.
fn optimiser(loss_weight: f64) -> (CueConfig, optimal::Optimal) {
    let mut config = CueConfig {
        algorithm: Algorithm::Optimal,
        ..CueConfig::default()
    };
    config.optimal.tilt_loss_weight = loss_weight;
    // The trainer model's ranges about home as the workspace scan finds them (m, rad).
    let ranges = [
        (-0.129, 0.129),
        (-0.055, 0.095),
        (-0.067, 0.059),
        (-0.454, 0.384),
        (-0.358, 0.358),
    ];
    let envelope = optimal::Envelope {
        ranges,
        rig: Some((
            RingPlatform::new(&TRAINER_MODEL),
            Pose::from_array(Preset::TrainerModel.home()),
        )),
    };
    let o = optimal::Optimal::new(config, &envelope).expect("the defaults are valid");
    (config, o)
}

fn one_sample(c: &mut Criterion) {
    for (weight, name) in [
        (0.0, "optimal cueing: one sample (three axes)"),
        (50.0, "optimal cueing, the tilts' loss priced: one sample (three axes)"),
    ] {
        let (_, mut o) = optimiser(weight);
        o.begin(&sample(0.0)).expect("finite");
        let mut t = 0.0;
        c.bench_function(name, |b| {
            b.iter(|| {
                t += 0.01;
                o.step(&sample(t), 0.01, &[]).expect("finite")
            })
        });
    }
}

/// The lap's input at distance `s` (m) of a 1800 m lap driven at 30 m/s: its forces repeat every lap.
fn on_lap(s: f64) -> Telemetry<f64> {
    sample(s / 30.0)
}

/// A preview that has kept its eight laps (nine driven), at the start of the tenth.
fn previewing() -> (lap::LapPreview, f64) {
    let mut p = lap::LapPreview::new(lap::Settings::default());
    let mut t = 0.0;
    for k in 0..9 * 6000 {
        let s = (k % 6000) as f64 * 0.3;
        p.observe(t, s, &on_lap(s));
        t += 0.01;
    }
    (p, t)
}

fn one_sample_with_the_lap_preview(c: &mut Criterion) {
    let (config, mut o) = optimiser(0.0);
    o.begin(&on_lap(0.0)).expect("finite");
    let (mut p, mut t) = previewing();
    let (n, h) = (config.optimal.horizon as usize, config.optimal.step_s);
    let mut k = 0usize;
    c.bench_function(
        "optimal cueing with the lap preview: one sample (eight laps kept)",
        |b| {
            b.iter(|| {
                let s = (k % 6000) as f64 * 0.3;
                let x = on_lap(s);
                p.observe(t, s, &x);
                let ahead = p.ahead(&x, n, h);
                t += 0.01;
                k += 1;
                o.step(&x, 0.01, &ahead).expect("finite")
            })
        },
    );
    let (mut p, mut t) = previewing();
    let mut k = 0usize;
    c.bench_function("lap preview alone: one sample (eight laps kept)", |b| {
        b.iter(|| {
            let s = (k % 6000) as f64 * 0.3;
            let x = on_lap(s);
            p.observe(t, s, &x);
            t += 0.01;
            k += 1;
            p.ahead(&x, n, h)
        })
    });
}

criterion_group!(benches, one_sample, one_sample_with_the_lap_preview);
criterion_main!(benches);
