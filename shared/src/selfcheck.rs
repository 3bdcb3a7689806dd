//! The self-check: a fixed workload of the control path in `f32` (IK, all six checks, FK, the step scheduler, the
//! framing, the supervisor, and the whole controller homing and following a recorded stream against the simulated
//! plant), with pass/fail checks and a digest of every output bit.
//!
//! The same code runs on the host and on a Cortex-M4F (QEMU mps2-an386, `tests/qemu`): the digests are equal exactly
//! when the two compute bit-identical results, which is what the core's explicit `libm` calls are for.

use crate::controller::{Controller, ControllerConfig};
use crate::kinematics::presets::{self, ROTOPOD_CH4, TRAINER_MODEL};
use crate::kinematics::{Mechanism, NewtonOptions, Pose, RingPlatform};
use crate::motion::{SchedulerConfig, Setpoint, StepScheduler};
use crate::protocol::{self, DeviceMessage, HostMessage, Request, Response, PROTOCOL_VERSION};
use crate::safety::{Command, State};
use crate::sim::{Plant, Rig, TRAINER_MODEL_PARKED};

/// FNV-1a over the bits of everything the workload computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Digest(pub u64);

impl Default for Digest {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    /// Adds the bytes of a value.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    /// Adds the bits of an `f32`.
    pub fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    /// Adds an integer.
    pub fn i64(&mut self, v: i64) {
        self.bytes(&v.to_le_bytes());
    }
}

/// The names of the checks, in the order of [`Outcome::passed`].
pub const CHECKS: [&str; 7] = [
    "rotopod-ch4 reference IK (f32)",
    "trainer-model IK -> FK round trip, 64 poses",
    "every spec axis at its extremes passes all six checks",
    "step scheduler reaches every target exactly",
    "frames round trip, a corrupted frame is rejected",
    "e-stop while streaming latches a fault, drivers off",
    "controller homes and follows a 60 Hz stream to its last pose",
];

/// What the workload found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    /// Digest of every output.
    pub digest: u64,
    /// Each check of [`CHECKS`].
    pub passed: [bool; 7],
}

/// A small linear congruential generator: the same numbers everywhere.
struct Lcg(u32);

impl Lcg {
    /// Uniform in [-1, 1).
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (self.0 >> 8) as f32 / 8_388_608.0 - 1.0
    }
}

fn home() -> Pose<f32> {
    Pose::new(0.0, 0.0, presets::TRAINER_MODEL_HOME_Z as f32, 0.0, 0.0, 0.0)
}

/// Poses combining all six axes at up to half the model's ranges, any yaw.
pub fn poses(n: usize) -> impl Iterator<Item = Pose<f32>> {
    let mut rng = Lcg(20_261_122);
    let r = presets::TRAINER_MODEL_RANGES;
    (0..n).map(move |_| {
        let h = home();
        Pose::new(
            rng.next() * r[0] as f32 * 0.5,
            rng.next() * r[1] as f32 * 0.5,
            h.z + rng.next() * r[2] as f32 * 0.5,
            rng.next() * r[3] as f32 * 0.5,
            rng.next() * r[4] as f32 * 0.5,
            rng.next() * core::f32::consts::PI,
        )
    })
}

/// Runs the workload.
pub fn run() -> Outcome {
    let mut d = Digest::default();
    let passed = [
        reference_ik(&mut d),
        round_trip(&mut d),
        spec_axes(&mut d),
        scheduler(&mut d),
        frames(&mut d),
        estop(&mut d),
        stream(&mut d),
    ];
    Outcome { digest: d.0, passed }
}

fn reference_ik(d: &mut Digest) -> bool {
    let rotopod = RingPlatform::<f32>::new(&ROTOPOD_CH4);
    let cases: [([f32; 6], [f32; 6]); 2] = [
        (
            [0.0, 0.0, 0.7, 0.0, 0.0, 0.0],
            [
                -0.775_067_4,
                0.775_067_4,
                1.319_288_5,
                2.869_467_5,
                -2.869_467_5,
                -1.319_288_5,
            ],
        ),
        (
            [0.02, 0.0, 0.7, 0.0, 0.0, 0.0],
            [
                -0.769_907_2,
                0.769_907_2,
                1.297_106_8,
                2.851_999_4,
                -2.851_999_4,
                -1.297_106_8,
            ],
        ),
    ];
    cases
        .iter()
        .all(|(pose, expected)| match rotopod.inverse(&Pose::from_array(*pose)) {
            Ok(q) => q.0.iter().zip(expected).all(|(a, e)| {
                d.f32(*a);
                libm::fabsf(a - e) < 2e-5
            }),
            Err(_) => false,
        })
}

fn round_trip(d: &mut Digest) -> bool {
    let trainer = RingPlatform::<f32>::new(&TRAINER_MODEL);
    // The poses combine all axes at half their ranges, and not all of that box is inside the checks: FK is asked
    // for the math here (every acceptance test but the workspace runs).
    let options = NewtonOptions {
        inside: false,
        ..NewtonOptions::default()
    };
    let mut ok = true;
    for pose in poses(64) {
        let Ok(q) = trainer.inverse(&pose) else {
            return false;
        };
        let report = trainer.workspace(&pose, &q);
        for m in q.0 {
            d.f32(m);
        }
        d.f32(report.singularity_index);
        let guess = Pose::new(
            pose.x + 1e-3,
            pose.y - 1e-3,
            pose.z,
            pose.alpha,
            pose.beta + 0.01,
            pose.gamma,
        );
        match trainer.forward(&q, &guess, &options) {
            Ok(fk) => {
                d.i64(i64::from(fk.iterations));
                let p = fk.pose.to_array();
                for (a, b) in p.iter().zip(pose.to_array()) {
                    d.f32(*a);
                    ok &= libm::fabsf(a - b) < 2e-4;
                }
            }
            Err(_) => return false,
        }
    }
    ok
}

fn spec_axes(d: &mut Digest) -> bool {
    let trainer = RingPlatform::<f32>::new(&TRAINER_MODEL);
    let r = presets::TRAINER_MODEL_RANGES;
    let mut ok = true;
    for axis in 0..5 {
        for sign in [-1.0f32, 1.0] {
            let mut p = home().to_array();
            p[axis] += sign * r[axis] as f32;
            let pose = Pose::from_array(p);
            match trainer.inverse(&pose) {
                Ok(q) => {
                    let report = trainer.workspace(&pose, &q);
                    d.f32(report.singularity_index);
                    ok &= report.all_pass();
                }
                Err(_) => ok = false,
            }
        }
    }
    ok
}

fn scheduler(d: &mut Digest) -> bool {
    let mut s = StepScheduler::new(SchedulerConfig::default(), [0; 6]);
    let mut rng = Lcg(7);
    let mut target = [0i64; 6];
    for _ in 0..200 {
        for t in target.iter_mut() {
            *t += (rng.next() * 150.0) as i64;
        }
        for m in s.plan(&target) {
            d.i64(m.signed());
            d.i64(i64::from(m.start_ns));
        }
    }
    // Idle periods let carried steps catch up.
    for _ in 0..10 {
        s.plan(&target);
    }
    s.position() == target
}

fn frames(d: &mut Digest) -> bool {
    let request = Request {
        id: 42,
        body: HostMessage::Setpoint(Setpoint {
            seq: 7,
            time_us: 123_456,
            pose: home(),
            aux: [None; 2],
            spare: [None; 2],
        }),
    };
    let mut buf = [0u8; protocol::MAX_FRAME];
    let Ok(n) = protocol::encode(&request, &mut buf) else {
        return false;
    };
    d.bytes(&buf[..n]);
    let frame = &buf[..n - 1];
    let back = protocol::decode::<Request>(frame);
    let mut corrupted = [0u8; protocol::MAX_FRAME];
    corrupted[..n - 1].copy_from_slice(frame);
    corrupted[3] ^= 0x10;
    back == Ok(request) && protocol::decode::<Request>(&corrupted[..n - 1]).is_err()
}

/// A controller and the simulated plant, powered up (Enable), homed and started: `Running`, at the home pose.
pub fn running_rig(d: &mut Digest) -> Option<Rig> {
    running_rig_with(d, ControllerConfig::trainer_model())
}

/// [`running_rig`] with a configuration of the trainer model's (another tick rate, say).
pub fn running_rig_with(d: &mut Digest, config: ControllerConfig) -> Option<Rig> {
    let mut rig = Rig {
        controller: Controller::new(config).ok()?,
        plant: Plant::trainer_model(TRAINER_MODEL_PARKED),
        ticks: 0,
    };
    let mut id = 0;
    let mut ask = |rig: &mut Rig, body: HostMessage| {
        id += 1;
        rig.controller.handle(&Request { id, body }).body
    };
    let ack = |m: DeviceMessage| matches!(m, DeviceMessage::Ack);
    let hello = ask(
        &mut rig,
        HostMessage::Hello {
            version: PROTOCOL_VERSION,
        },
    );
    if !matches!(hello, DeviceMessage::Hello { .. }) || !ack(ask(&mut rig, HostMessage::Command(Command::Enable))) {
        return None;
    }
    until(&mut rig, d, 5_000, |s| matches!(s, State::PowerOn { settled: true }))?;
    if !ack(ask(&mut rig, HostMessage::Command(Command::Home))) {
        return None;
    }
    until(&mut rig, d, 40_000, |s| s == State::Ready)?;
    ack(ask(&mut rig, HostMessage::Command(Command::Start))).then_some(rig)
}

/// Ticks until the state satisfies `done`, at most `limit` ticks.
fn until(rig: &mut Rig, d: &mut Digest, limit: u32, done: impl Fn(State) -> bool) -> Option<()> {
    for _ in 0..limit {
        if done(rig.controller.supervisor().state()) {
            return Some(());
        }
        let out = rig.tick();
        for m in out.moves {
            d.i64(m.signed());
        }
    }
    None
}

fn estop(d: &mut Digest) -> bool {
    let Some(mut rig) = running_rig(d) else {
        return false;
    };
    rig.plant.estop_open = true;
    let out = rig.tick();
    let state = rig.controller.supervisor().state();
    d.i64(rig.controller.steps()[0]);
    matches!(state, State::Fault(..)) && !out.outputs.driver_enable && out.moves.iter().all(|m| m.count == 0)
}

fn stream(d: &mut Digest) -> bool {
    let Some(mut rig) = running_rig(d) else {
        return false;
    };
    // Homing defined the controller's step origins; the plant counts from its switches. The difference is fixed
    // from here on exactly when every pulse reached the plant.
    let offset: [i64; 6] = core::array::from_fn(|a| rig.plant.position[a] - rig.controller.steps()[a]);
    let mut last = home();
    for k in 1..=120u32 {
        // A recorded 2 s motion: surge and heave sweeps with a yaw turn, 60 Hz.
        let t = k as f32 / 60.0;
        let h = home();
        last = Pose::new(
            0.01 * libm::sinf(2.0 * t),
            0.01 * libm::sinf(1.5 * t),
            h.z + 0.008 * libm::sinf(2.5 * t),
            0.0,
            0.05 * libm::sinf(2.0 * t),
            0.3 * t,
        );
        let id = 1_000 + k;
        let sp = Setpoint {
            seq: k,
            time_us: u64::from(k) * 16_667,
            pose: last,
            aux: [None; 2],
            spare: [None; 2],
        };
        let reply = rig
            .controller
            .handle(&Request {
                id,
                body: HostMessage::Setpoint(sp),
            })
            .body;
        if reply != DeviceMessage::Ack {
            return false;
        }
        for _ in 0..17 {
            let out = rig.tick();
            for m in out.moves {
                d.i64(m.signed());
            }
        }
    }
    for _ in 0..250 {
        rig.tick();
    }
    let status = rig.controller.status();
    for s in status.steps {
        d.i64(s);
    }
    let reached = status
        .pose
        .to_array()
        .iter()
        .zip(last.to_array())
        .all(|(a, b)| libm::fabsf(a - b) < 1e-5);
    let steps = rig.controller.steps();
    let counted = (0..6).all(|a| rig.plant.position[a] - steps[a] == offset[a]) && rig.plant.steps_while_disabled == 0;
    let response = Response {
        id: 0,
        body: DeviceMessage::Status(status),
    };
    let mut buf = [0u8; protocol::MAX_FRAME];
    if let Ok(n) = protocol::encode(&response, &mut buf) {
        d.bytes(&buf[..n]);
    }
    reached && counted && status.applied == 120
}
