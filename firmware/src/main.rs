//! ringpod controller firmware (STM32F411CE "Black Pill").
//!
//! This first version brings the board up in a safe state and proves the kinematics core runs on the
//! MCU: it computes the trainer-model inverse kinematics at the home pose every second and logs it.
//! The real controller (USB link, control tick, step generation, supervisor) lands with its own issue.

#![no_std]
#![no_main]

mod board;

use defmt::info;
use embassy_executor::Spawner;
use embassy_time::{Duration, Ticker};
use ringpod_core::kinematics::{presets, Mechanism, Pose, RingPlatform};
use {defmt_rtt as _, panic_probe as _};

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(board::clocks());
    // Safe state first: relays off, drivers disabled, before anything else runs.
    let _outputs = board::SafeOutputs::new(p.PB12, p.PB13, p.PB14);
    info!("ringpod firmware up (kinematics self-check only)");

    let trainer = RingPlatform::<f32>::new(&presets::TRAINER_MODEL);
    let home = Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z as f32, 0.0, 0.0, 0.0);
    let mut ticker = Ticker::every(Duration::from_secs(1));
    loop {
        let start = embassy_time::Instant::now();
        match trainer.inverse(&home) {
            Ok(q) => info!("IK at home: {} ({} us)", q.as_array(), start.elapsed().as_micros()),
            Err(e) => defmt::error!("IK failed at home: {}", e),
        }
        ticker.next().await;
    }
}
