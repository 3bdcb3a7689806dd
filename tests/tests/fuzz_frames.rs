//! Ten million random and mutated frames through the decoder and the dispatcher of the controller: no panic,
//! no corrupted frame ever executed, and the interlocks hold throughout. `RINGPOD_FUZZ_FRAMES` changes the count.

use ringpod_core::controller::{Controller, ControllerConfig};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::FollowMode;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{
    self, DeviceMessage, HostMessage, NackReason, Request, Response, Settings, SettingsKind, StreamSettings,
    PROTOCOL_VERSION,
};
use ringpod_core::safety::Command;
use ringpod_tests::plant::{Plant, Rig, TRAINER_MODEL_PARKED};

/// xorshift64*: fast and repeatable.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
    fn f32(&mut self) -> f32 {
        match self.below(8) {
            0 => f32::from_bits(self.next() as u32),
            1 => [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0, f32::MAX][self.below(6) as usize],
            _ => (self.below(2_000_001) as f32 - 1_000_000.0) * 1e-6,
        }
    }
}

fn random_request(rng: &mut Rng, seq: &mut u32) -> Request {
    let body = match rng.below(14) {
        0 => HostMessage::Hello {
            version: if rng.below(4) == 0 {
                rng.next() as u16
            } else {
                PROTOCOL_VERSION
            },
        },
        1 => HostMessage::Command(Command::Enable),
        2 => HostMessage::Command(Command::Disable),
        3 => HostMessage::Command(Command::Home),
        4 => HostMessage::Command(Command::Start),
        5 => HostMessage::Command(Command::Stop),
        6 => HostMessage::Command(Command::ClearFault),
        7 => HostMessage::GetStatus,
        8 => HostMessage::GetSettings(SettingsKind::ALL[rng.below(7) as usize]),
        9 => HostMessage::SetSettings(Settings::Stream(StreamSettings {
            timeout_ms: rng.below(20_000) as u16,
            gross_jump_ms: rng.below(20_000) as u16,
            follow: FollowMode::Interpolate,
            margins: [rng.f32(); 6],
            telemetry_hz: rng.below(4_000) as u16,
            host_gone_ms: rng.below(70_000) as u16,
        })),
        _ => {
            *seq = seq.wrapping_add(if rng.below(10) == 0 { rng.next() as u32 } else { 1 });
            let home = [0.0, 0.0, 0.227, 0.0, 0.0, 0.0];
            let pose = Pose::from_array(core::array::from_fn(|i| {
                if rng.below(3) == 0 {
                    rng.f32()
                } else {
                    home[i] + rng.f32() * 1e-3
                }
            }));
            HostMessage::Setpoint(Setpoint {
                seq: *seq,
                time_us: u64::from(*seq) * 1000,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            })
        }
    };
    Request {
        id: rng.next() as u32,
        body,
    }
}

fn mutate(rng: &mut Rng, frame: &mut Vec<u8>) {
    for _ in 0..=rng.below(3) {
        let len = frame.len().max(1);
        match rng.below(5) {
            0 => {
                let i = rng.below(len as u64) as usize;
                if let Some(b) = frame.get_mut(i) {
                    *b ^= 1 << rng.below(8);
                }
            }
            1 => {
                let i = rng.below(len as u64) as usize;
                if let Some(b) = frame.get_mut(i) {
                    *b = rng.next() as u8;
                }
            }
            2 => frame.truncate(rng.below(len as u64) as usize),
            3 => frame.insert(rng.below(len as u64 + 1) as usize % (frame.len() + 1), rng.next() as u8),
            _ => {
                if !frame.is_empty() {
                    frame.remove(rng.below(frame.len() as u64) as usize);
                }
            }
        }
    }
}

#[test]
fn ten_million_frames() {
    let total: u64 = std::env::var("RINGPOD_FUZZ_FRAMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000_000);
    let controller = Controller::new(ControllerConfig::trainer_model()).unwrap();
    let mut rig = Rig {
        controller,
        plant: Plant::trainer_model(TRAINER_MODEL_PARKED),
        ticks: 0,
    };
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    let mut seq = 0u32;
    let mut out = [0u8; protocol::MAX_FRAME];
    let mut buf = [0u8; protocol::MAX_FRAME];
    let (mut random, mut mutated, mut valid, mut executed_corrupt, mut rejected_corrupt) =
        (0u64, 0u64, 0u64, 0u64, 0u64);
    for n in 0..total {
        let request = random_request(&mut rng, &mut seq);
        let len = protocol::encode(&request, &mut buf).unwrap();
        let original = &buf[..len - 1];
        let (frame, corrupt) = match rng.below(10) {
            0..=3 => {
                random += 1;
                let len = rng.below(80) as usize;
                let f: Vec<u8> = (0..len).map(|_| (rng.next() as u8).max(1)).collect();
                let corrupt = f != original;
                (f, corrupt)
            }
            4..=8 => {
                mutated += 1;
                let mut f = original.to_vec();
                mutate(&mut rng, &mut f);
                f.retain(|b| *b != 0); // the link splits at 0x00: a frame never contains one
                let corrupt = f != original;
                (f, corrupt)
            }
            _ => {
                valid += 1;
                (original.to_vec(), false)
            }
        };
        let m = rig.controller.handle_frame(&frame, &mut out);
        assert!(m > 1, "every frame gets a response");
        let response: Response = protocol::decode(&out[..m - 1]).expect("the device's response decodes");
        let malformed = response.id == 0 && response.body == DeviceMessage::Nack(NackReason::Malformed);
        if corrupt {
            if malformed {
                rejected_corrupt += 1;
            } else {
                executed_corrupt += 1;
            }
        } else {
            assert!(!malformed, "a valid frame was refused as malformed");
            assert_eq!(response.id, request.id);
        }
        if n % 100 == 0 {
            let o = rig.tick().outputs;
            assert!(!o.power_relay || o.logic_relay, "power without logic");
            assert!(!o.driver_enable || o.power_relay, "drivers without power");
        }
    }
    println!(
        "{total} frames: {random} random, {mutated} mutated, {valid} valid; {rejected_corrupt} corrupted frames rejected, {executed_corrupt} executed; {} ticks",
        rig.ticks
    );
    assert_eq!(executed_corrupt, 0, "a corrupted frame was executed");
    assert_eq!(rig.controller.status().bad_frames as u64, rejected_corrupt);
    assert!(valid + mutated + random == total);
}
