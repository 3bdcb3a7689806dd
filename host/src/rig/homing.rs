//! Whether a rig homes, as `rig check`'s "drivable" needs: the core's controller (the firmware's and the
//! simulator's) with the simulated machine of the rig's own drives and switches (`ringpod_core::sim`), parked as a
//! board is before its first homing, enabled and homed. A configuration the core accepts can still never home: a
//! home yaw of a million radians is a move the controller refuses after the switches (`Fault(HomingFailed)`), a
//! pose velocity of 1e-30 a move home that never ends. Both are seen here, in simulated time, before a device is.

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::protocol::{DeviceMessage, HostMessage, Request, RigRecord, PROTOCOL_VERSION};
use ringpod_core::safety::{Command, State};
use ringpod_core::sim::{Plant, Rig};

/// The longest homing a rig may take (simulated s): a search of every axis at its rates and the move home.
pub const HOMING_LIMIT_S: f64 = 300.0;
/// Simulated seconds without a step of any axis after which homing is taken as never ending (the move home of a
/// pose velocity so small that no step is due).
pub const STALL_S: f64 = 20.0;

/// The simulated seconds a rig takes from enabled to homed, or why it does not home.
pub fn homing_time(record: &RigRecord) -> Result<f64, String> {
    let config = ControllerConfig::from_record(record).map_err(|e| e.to_string())?;
    let tick_s = f64::from(config.pipeline.tick_us) * 1e-6;
    let plant = Plant::for_config(&config);
    let controller = Controller::new(config).map_err(|e| e.to_string())?;
    let mut rig = Rig {
        controller,
        plant,
        ticks: 0,
    };
    let ask = |rig: &mut Rig, body| rig.controller.handle(&Request { id: 1, body }).body;
    ask(
        &mut rig,
        HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    );
    ask(&mut rig, HostMessage::Command(Command::Enable));
    // The supplies come up and settle first (a second or two of the supervisor's delays).
    let settle = (10.0 / tick_s) as u64;
    while !matches!(
        rig.controller.supervisor().state(),
        State::PowerOn { settled: true } | State::Ready
    ) {
        if rig.ticks > settle {
            return Err(format!(
                "the supplies did not settle within 10 s ({:?})",
                rig.controller.supervisor().state()
            ));
        }
        rig.tick();
    }
    if let DeviceMessage::Nack(e) = ask(&mut rig, HostMessage::Command(Command::Home)) {
        return Err(format!("homing was refused: {e:?}"));
    }
    let start = rig.ticks;
    let (mut last_steps, mut still) = (rig.plant.position, 0u64);
    let limit = (HOMING_LIMIT_S / tick_s) as u64;
    let stall = (STALL_S / tick_s) as u64;
    loop {
        match rig.controller.supervisor().state() {
            State::Ready => return Ok((rig.ticks - start) as f64 * tick_s),
            State::Homing => {}
            other => return Err(format!("homing ends in {other:?}")),
        }
        if rig.ticks - start > limit {
            return Err(format!("homing takes longer than {HOMING_LIMIT_S} s"));
        }
        rig.tick();
        if rig.plant.position == last_steps {
            still += 1;
            if still > stall {
                return Err(format!(
                    "homing stalls: no axis steps for {STALL_S} s (a move home too slow to end: check [motion] \
                     pose_velocity and the home pose)"
                ));
            }
        } else {
            (last_steps, still) = (rig.plant.position, 0);
        }
    }
}
