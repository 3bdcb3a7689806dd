//! The mappings and the drive (Windows only).

use std::f64::consts::TAU;
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[path = "../../src/vr/mapping.rs"]
mod mapping;

const G: f64 = 9.80665;

/// A named mapping this program created, written in little-endian fields at the publisher's offsets.
struct Mapping(mapping::Mapping);

impl Mapping {
    fn create(name: &str, len: usize) -> Result<Self, String> {
        mapping::Mapping::create(name, len)
            .map(Self)
            .map_err(|e| format!("{name}: {e}"))
    }

    /// This program's own offsets: one outside the mapping is its bug.
    fn put(&mut self, at: usize, bytes: &[u8]) {
        assert!(
            self.0.write(at, bytes),
            "{} bytes at {at}: outside the mapping",
            bytes.len()
        );
    }

    fn f32s(&mut self, at: usize, v: &[f64]) {
        let b: Vec<u8> = v.iter().flat_map(|x| (*x as f32).to_le_bytes()).collect();
        self.put(at, &b);
    }

    fn f64s(&mut self, at: usize, v: &[f64]) {
        let b: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.put(at, &b);
    }

    fn i32(&mut self, at: usize, v: i32) {
        self.put(at, &v.to_le_bytes());
    }
}

/// One moment of the drive: acceleration without gravity (m/s^2, x forward, y left, z up), angular rates (rad/s
/// about those axes), attitude (rad: nose up, right side down).
#[derive(Clone, Copy, Default)]
struct Moment {
    accel: [f64; 3],
    rate: [f64; 3],
    pitch: f64,
    roll: f64,
}

impl Moment {
    /// With gravity's reaction: what an accelerometer in the car reads.
    fn specific_force(&self) -> [f64; 3] {
        let (sp, cp) = self.pitch.sin_cos();
        let (sr, cr) = self.roll.sin_cos();
        [
            self.accel[0] + G * sp,
            self.accel[1] + G * cp * sr,
            self.accel[2] + G * cp * cr,
        ]
    }
}

/// The drive at `t` seconds, `None` in its pause.
fn drive(t: f64) -> Option<Moment> {
    let m = Moment::default();
    Some(match (t % 7.5) as u32 {
        0 => m,
        1 => Moment {
            accel: [3.0, 0.0, 0.0],
            ..m
        },
        2 => Moment {
            accel: [-8.0, 0.0, 0.0],
            ..m
        },
        3 => Moment {
            accel: [0.0, 6.0, 0.0],
            rate: [0.0, 0.0, 0.4],
            ..m
        },
        4 => Moment { pitch: 0.15, ..m },
        5 => Moment { roll: 0.12, ..m },
        _ => return None,
    })
}

/// One game's mappings and how a sample is written into them.
trait Game {
    /// The period between samples.
    fn period(&self) -> Duration;
    /// Writes sample number `n` (from 1) at game time `t`.
    fn write(&mut self, n: u32, t: f64, m: &Moment);
}

struct Ac(Mapping);

impl Game for Ac {
    fn period(&self) -> Duration {
        Duration::from_millis(3)
    }
    fn write(&mut self, n: u32, _: f64, m: &Moment) {
        let p = &mut self.0;
        // SPageFilePhysics: accG at 44 (x left, y up, z forward, g), pitch 212, roll 216, localAngularVel 296.
        p.f32s(44, &[m.accel[1] / G, m.accel[2] / G, m.accel[0] / G]);
        p.f32s(212, &[m.pitch, m.roll]);
        p.f32s(296, &[m.rate[1], m.rate[2], m.rate[0]]);
        p.i32(0, n as i32);
    }
}

/// iRacing: 7 variables, 3 buffers of 64 bytes at 2048.
struct Iracing(Mapping);

const IR_VARS: [(&str, i32, usize); 7] = [
    ("SessionTime", 5, 0),
    ("LongAccel", 4, 8),
    ("LatAccel", 4, 12),
    ("VertAccel", 4, 16),
    ("RollRate", 4, 20),
    ("PitchRate", 4, 24),
    ("YawRate", 4, 28),
];

impl Iracing {
    fn new(mut m: Mapping) -> Self {
        for (at, v) in [(0, 2), (4, 1), (8, 60), (24, 7), (28, 112), (32, 3), (36, 64)] {
            m.i32(at, v);
        }
        for (i, (name, ty, offset)) in IR_VARS.iter().enumerate() {
            let h = 112 + 144 * i;
            m.i32(h, *ty);
            m.i32(h + 4, *offset as i32);
            m.i32(h + 8, 1);
            m.put(h + 16, name.as_bytes());
        }
        for b in 0..3 {
            m.i32(48 + 16 * b + 4, (2048 + 64 * b) as i32);
        }
        Self(m)
    }
}

impl Game for Iracing {
    fn period(&self) -> Duration {
        Duration::from_micros(16_667)
    }
    fn write(&mut self, n: u32, t: f64, m: &Moment) {
        let (p, b) = (&mut self.0, n as usize % 3);
        let buf = 2048 + 64 * b;
        let f = m.specific_force();
        p.f64s(buf, &[t]);
        p.f32s(buf + 8, &[f[0], f[1], f[2], m.rate[0], m.rate[1], m.rate[2]]);
        p.i32(48 + 16 * b, n as i32);
    }
}

/// rF2's telemetry and scoring buffers, one vehicle (mID 1, the player's).
struct Rf2(Mapping, Mapping);

impl Game for Rf2 {
    fn period(&self) -> Duration {
        Duration::from_millis(20)
    }
    fn write(&mut self, n: u32, t: f64, m: &Moment) {
        let (tel, sc) = (&mut self.0, &mut self.1);
        sc.put(0, &[1, 0, 0, 0, 1, 0, 0, 0]);
        sc.i32(116, 1);
        sc.i32(560, 1);
        sc.put(560 + 196, &[1]);
        // The version block: begin moves before the write, end after it.
        tel.i32(0, n as i32);
        tel.i32(12, 1);
        tel.i32(16, 1);
        // Published axes: x left, y up, z back; +x pitches up, +y yaws right, +z rolls right.
        let (sp, cp) = m.pitch.sin_cos();
        let (sr, cr) = m.roll.sin_cos();
        tel.f64s(16 + 12, &[t]);
        tel.f64s(16 + 208, &[m.accel[1], m.accel[2], -m.accel[0]]);
        tel.f64s(16 + 256, &[cp * sr, cp * cr, -sp]);
        tel.f64s(16 + 304, &[-m.rate[1], -m.rate[2], m.rate[0]]);
        tel.i32(4, n as i32);
    }
}

/// AMS2's `$pcars2$` (the car's axes x left, y up, z back, as Project CARS's recording shows).
struct Ams2(Mapping);

impl Game for Ams2 {
    fn period(&self) -> Duration {
        Duration::from_micros(16_667)
    }
    fn write(&mut self, n: u32, _: f64, m: &Moment) {
        let p = &mut self.0;
        p.i32(0, 14);
        p.i32(7320, 2 * n as i32 - 1);
        p.f32s(6908, &[m.pitch, 0.0, m.roll]);
        p.f32s(6944, &[m.rate[1], m.rate[2], -m.rate[0]]);
        p.f32s(6956, &[m.accel[1], m.accel[2], -m.accel[0]]);
        p.i32(7320, 2 * n as i32);
    }
}

/// The scs-sdk-plugin's map (published axes x right, y up, z back; turns per second; pitch and roll in turns).
struct Ets2(Mapping);

impl Game for Ets2 {
    fn period(&self) -> Duration {
        Duration::from_micros(16_667)
    }
    fn write(&mut self, _: u32, t: f64, m: &Moment) {
        let p = &mut self.0;
        p.put(0, &[1]);
        p.i32(40, 10);
        p.f32s(1880, &[-m.rate[1] / TAU, m.rate[2] / TAU, -m.rate[0] / TAU]);
        p.f32s(1892, &[-m.accel[1], m.accel[2], -m.accel[0]]);
        p.f64s(2232, &[m.pitch / TAU, -m.roll / TAU]);
        p.put(8, &((t * 1e6) as u64).to_le_bytes());
    }
}

fn open(name: &str) -> Result<Box<dyn Game>, String> {
    Ok(match name {
        "ac" | "acc" => Box::new(Ac(Mapping::create(r"Local\acpmf_physics", 4096)?)),
        "iracing" => Box::new(Iracing::new(Mapping::create(r"Local\IRSDKMemMapFileName", 8192)?)),
        "rf2" | "lmu" => Box::new(Rf2(
            Mapping::create("$rFactor2SMMP_Telemetry$", 4096)?,
            Mapping::create("$rFactor2SMMP_Scoring$", 4096)?,
        )),
        "ams2" => Box::new(Ams2(Mapping::create("$pcars2$", 8192)?)),
        "ets2" => Box::new(Ets2(Mapping::create(r"Local\SCSTelemetry", 32 * 1024)?)),
        other => return Err(format!("no game {other}: ac, acc, iracing, rf2, lmu, ams2 or ets2")),
    })
}

pub fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seconds: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(30.0);
    let mut game = match args.first().map(|name| open(name)) {
        Some(Ok(game)) => game,
        Some(Err(e)) => {
            eprintln!("shm_games: {e}");
            return ExitCode::from(2);
        }
        None => {
            eprintln!("usage: shm_games GAME [SECONDS]");
            return ExitCode::from(2);
        }
    };
    // The mappings exist: a runner waiting for this line starts the reader now.
    println!("shm_games: ready");
    let _ = std::io::Write::flush(&mut std::io::stdout());
    let start = Instant::now();
    let (mut n, mut written) = (0u32, 0u64);
    // Each sample at its own deadline, not a period after the last write: a sleep overshoots (by a millisecond or
    // more under Wine), and sleeping a whole period after each would write below the game's rate.
    let mut next = start;
    while start.elapsed().as_secs_f64() < seconds {
        let t = start.elapsed().as_secs_f64();
        if let Some(m) = drive(t) {
            n += 1;
            game.write(n, t, &m);
            written += 1;
        }
        next += game.period();
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    println!("shm_games: {written} samples written in {seconds} s");
    ExitCode::SUCCESS
}
