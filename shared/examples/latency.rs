//! Pose-to-motion latency of the two follow modes, in control ticks (1 kHz): `cargo run --release -p
//! ringpod-core --example latency`. The control core chapter's latency table comes from here; `tests/pipeline.rs` holds the
//! same measurement to its figures.

use ringpod_core::kinematics::{presets, Mechanism, Pose, RingPlatform};
use ringpod_core::motion::{AxisScale, FollowMode, Pipeline, PipelineConfig, Setpoint, StepConverter};

/// Latency of one follow mode at one input rate.
#[derive(Debug, Clone, Copy)]
pub struct Latency {
    /// Ticks from a setpoint's arrival (from rest, 1 mm of surge away) to the first step toward it.
    pub first_step: u32,
    /// Ticks from its arrival to the platform at rest on it.
    pub arrival: u32,
    /// Lag behind a steady 20 mm/s surge ramp (ms): how long ago the source was where the platform is.
    pub ramp_lag_ms: f32,
}

fn pipeline(follow: FollowMode) -> Pipeline<RingPlatform<f32>> {
    let m = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let (c, l) = (AxisScale::MODEL_CARRIAGE, AxisScale::MODEL_LINEAR);
    let config = PipelineConfig {
        follow,
        ..PipelineConfig::default()
    };
    let home = Pose::from_array(presets::Preset::TrainerModel.home()).cast();
    let mut p = Pipeline::new(m, config, StepConverter::new([c, c, c, c, l, l], m.axes()), home).unwrap();
    p.start();
    p
}

/// Measures one mode at `rate_hz` setpoints per second.
pub fn measure(follow: FollowMode, rate_hz: u32) -> Latency {
    let interval_us = 1_000_000 / rate_hz;
    let home = Pose::from_array(presets::Preset::TrainerModel.home()).cast::<f32>();
    // Step: a setpoint at rest, then the same setpoint again every interval (a source that stopped there).
    let mut p = pipeline(follow);
    let goal = Pose { x: 0.001, ..home };
    let (mut first_step, mut arrival) = (None, None);
    for tick in 1..=2_000u32 {
        let t_us = u64::from(tick) * 1000;
        if (tick - 1) % (interval_us / 1000) == 0 {
            let seq = (tick - 1) / (interval_us / 1000) + 1;
            p.submit(&Setpoint {
                seq,
                time_us: t_us,
                pose: goal,
                aux: [None; 2],
                spare: [None; 2],
            })
            .unwrap();
        }
        p.tick();
        if first_step.is_none() && p.pose().x > 0.0 {
            first_step = Some(tick);
        }
        if arrival.is_none() && (p.pose().x - goal.x).abs() < 1e-6 && p.at_rest() {
            arrival = Some(tick);
        }
    }
    // Ramp: 20 mm/s of surge, sampled at the input rate; after 1 s the lag is steady.
    let mut p = pipeline(follow);
    let speed = 0.02f32;
    let mut lag = 0.0;
    for tick in 1..=1_500u32 {
        if (tick - 1) % (interval_us / 1000) == 0 {
            let seq = (tick - 1) / (interval_us / 1000) + 1;
            let t = (tick - 1) as f32 * 1e-3;
            let pose = Pose { x: speed * t, ..home };
            p.submit(&Setpoint {
                seq,
                time_us: u64::from(tick) * 1000,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            })
            .unwrap();
        }
        p.tick();
        if tick == 1_500 {
            // The source is at speed * (tick - 1) ms now.
            lag = ((tick - 1) as f32 * 1e-3 - p.pose().x / speed) * 1e3;
        }
    }
    Latency {
        first_step: first_step.unwrap_or(0),
        arrival: arrival.unwrap_or(0),
        ramp_lag_ms: lag,
    }
}

fn main() {
    println!("| follow mode | input | first step | at rest on a 1 mm step | lag behind a 20 mm/s ramp |");
    println!("|---|---|---|---|---|");
    for follow in [FollowMode::Interpolate, FollowMode::Direct] {
        for rate in [60, 250, 1000] {
            let l = measure(follow, rate);
            println!(
                "| {follow:?} | {rate} Hz | {} ticks | {} ticks | {:.1} ms |",
                l.first_step, l.arrival, l.ramp_lag_ms
            );
        }
    }
}
