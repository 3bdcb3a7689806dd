//! The stored record of version 2 (protocol 7), read once to carry a builder's stored rig across the firmware update
//! that added the actuator limits to the motion section: version 2 had the pose limits alone. Its layout is kept
//! here exactly as it was written (postcard is not self-describing: a record is read only with the types it was
//! written with); the actuator limits a version-2 rig gets are its axes' kinds' on the trainer model's drives,
//! which is what a version-2 device drove them with.

use crate::kinematics::{Chain, RingLimits};
use crate::model;
use crate::protocol::{AxisSettings, HomingSettings, MachineSettings, MotionSettings, RigRecord, RIG_NAME_LEN};
use crate::safety::debounce::InputConfig;
use crate::safety::SupervisorConfig;

/// The rig as version 2 stored it (after the version; the stream and control sections follow it).
#[derive(serde::Deserialize)]
pub(super) struct Rig {
    name: [u8; RIG_NAME_LEN],
    ring_radius: f64,
    rod_length: f64,
    chains: [Chain; 6],
    chain_count: u8,
    limits: RingLimits,
    home: [f64; 6],
    machine: Machine,
}

#[derive(serde::Deserialize)]
struct Machine {
    axes: [AxisSettings; 6],
    motion: Motion,
    inputs: InputConfig,
    supervisor: SupervisorConfig,
    homing: HomingSettings,
}

#[derive(serde::Deserialize)]
struct Motion {
    pose_velocity: [f32; 6],
    pose_acceleration: [f32; 6],
}

impl Rig {
    /// This rig as today's record, its actuators given their kinds' limits. A geometry that is not
    /// valid leaves them at zero: the restore refuses such a rig by its geometry, as it refuses any stored rig
    /// that cannot run.
    pub fn rig(&self) -> RigRecord {
        let r = self;
        let m = &r.machine;
        let mut record = RigRecord {
            name: r.name,
            ring_radius: r.ring_radius,
            rod_length: r.rod_length,
            chains: r.chains,
            chain_count: r.chain_count,
            limits: r.limits,
            home: r.home,
            machine: MachineSettings {
                axes: m.axes,
                motion: MotionSettings {
                    pose_velocity: m.motion.pose_velocity,
                    pose_acceleration: m.motion.pose_acceleration,
                    actuator_velocity: [0.0; 6],
                    actuator_acceleration: [0.0; 6],
                },
                inputs: m.inputs,
                supervisor: m.supervisor,
                homing: m.homing,
            },
        };
        if let Ok(geometry) = record.geometry() {
            let motion = &mut record.machine.motion;
            for (a, kind) in geometry.axes().iter().enumerate() {
                (motion.actuator_velocity[a], motion.actuator_acceleration[a]) = model::actuator_limits(*kind);
            }
        }
        record
    }
}
