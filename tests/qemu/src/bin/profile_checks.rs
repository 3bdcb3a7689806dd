//! Where the instructions of trainer IK with all six checks go: the self-check's 64 poses, each call between calls
//! of `marker_start` and `marker_end` (`tests/qemu/profile LINES profile_checks` counts them per function and line).

#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
use ringpod_core::kinematics::presets::TRAINER_MODEL;
use ringpod_core::kinematics::{Mechanism, RingPlatform};
use ringpod_core::selfcheck;
use ringpod_qemu::{halt, marker_end, marker_start};

#[entry]
fn main() -> ! {
    let trainer = RingPlatform::<f32>::new(&TRAINER_MODEL);
    for p in selfcheck::poses(64) {
        marker_start();
        let _ = black_box(trainer.inverse_checked(black_box(&p)));
        marker_end();
    }
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}
