//! Where the instructions of a control tick go: a controller brought to `Running`, then a 1 kHz stream, with every
//! measured tick between calls of `marker_start` and `marker_end`. `tests/qemu/profile` runs it under QEMU with an
//! instruction trace and counts the instructions between the markers per function and per source line.

#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{self, HostMessage, Request};
use ringpod_core::selfcheck::{self, Digest};
use ringpod_core::Real;
use ringpod_qemu::{fail, halt, marker_end, marker_start};

/// Ticks streamed before the measured ones (the stream settles into its steady state).
const LEAD: u32 = 200;
/// Ticks measured.
const MEASURED: u32 = 100;

#[entry]
fn main() -> ! {
    let mut d = Digest::default();
    let mut rig = selfcheck::running_rig(&mut d).unwrap_or_else(|| fail("controller did not reach Running"));
    let home = rig.controller.pipeline().pose();
    let mut out = [0u8; protocol::MAX_FRAME];
    let mut frame = [0u8; protocol::MAX_FRAME];
    for k in 1..=LEAD + MEASURED {
        let t = k as f32 / 1000.0;
        let pose = Pose::new(0.01 * (2.0 * t).sin_(), 0.0, home.z, 0.0, 0.0, 0.2 * t);
        let request = Request {
            id: k,
            body: HostMessage::Setpoint(Setpoint {
                seq: k,
                time_us: u64::from(k) * 1_000,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            }),
        };
        let len = protocol::encode(&request, &mut frame).unwrap_or(1);
        black_box(rig.controller.handle_frame(&frame[..len - 1], &mut out));
        let o = rig.controller.supervisor().outputs();
        rig.controller
            .set_inputs(rig.plant.inputs(o.logic_relay, o.power_relay));
        let measured = k > LEAD;
        if measured {
            marker_start();
        }
        let tick = rig.controller.tick();
        if measured {
            marker_end();
        }
        rig.plant.apply(&tick);
    }
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}
