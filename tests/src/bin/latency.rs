//! Latency from a telemetry datagram's arrival to the first step pulse it causes, in `interpolate` and `direct`
//! follow modes: `cargo run --release -p ringpod-tests --bin latency`. A measurement that prints a table (the
//! book's Benchmarks chapter), not a test.
//!
//! The path of `stream --sim --telemetry-udp` (and of a board), in three parts:
//! 1. host, wall time on this machine: the datagram over loopback UDP (send to receive), then what the host does
//!    with it: the washout step, the cue's pose, limiting into the envelope (f64, 16 evaluations, as the stream
//!    does) and the setpoint frame's encoding;
//! 2. the wait for the next control tick: the frame is handled between ticks, so 0 to one period (the simulator
//!    handles what arrived at its next tick; a board's UART/USB interrupt queues it for the next tick likewise);
//! 3. device time, counted in control periods by the core itself (the same code the firmware runs, here on the
//!    simulated plant): from the tick that takes the setpoint to the first step pulse, at the time the step
//!    scheduler gives it within its period (`start + (period - start) / (2 count)`).
//!
//! The case: a platform at rest at home, a 100 Hz telemetry stream holding it there, then the sample of a braking
//! car (the washout's pose after 10 ms at -6 m/s^2, and larger steps for comparison). The first pulse comes when
//! the reference has moved one step: a small cue takes longer than a large one, and `interpolate` spreads the move
//! over the setpoint's interval (10 ms at 100 Hz) where `direct` heads for it at once under the limits.
//!
//! Then the same on the QEMU controller (the firmware's tasks on the emulated Cortex-M4F, `tests/qemu`, program
//! argument `latency`): device time under `-icount shift=3,sleep=off` (8 ns an instruction, idle time skipped),
//! from the setpoint frame's last byte in the link's receive pipe to the first STEP edge the port plays, at ten
//! phases of the control period, which takes in the wait for the tick, the tick, the step queue and the slot of
//! the first pulse (parts 2 and 3 as the firmware does them). Skipped with a message when QEMU is missing.

use std::time::Instant;

use ringpod_core::controller::ControllerConfig;
use ringpod_core::cueing::{self, CueConfig, Telemetry, Washout, G};
use ringpod_core::kinematics::presets::{Preset, TRAINER_MODEL};
use ringpod_core::kinematics::{Pose, RingPlatform};
use ringpod_core::motion::{envelope, EnvelopeMargins, FollowMode, Setpoint};
use ringpod_core::protocol::{self, HostMessage, Request};
use ringpod_core::selfcheck;
use ringpod_tests::emulator;

/// Median and 99th percentile.
fn spread(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[(v.len() * 99) / 100])
}

/// Part 1: loopback UDP send to receive (us).
fn udp_us(n: usize) -> (f64, f64) {
    let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let tx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let to = rx.local_addr().unwrap();
    let mut buf = [0u8; 1500];
    let packet = [0u8; 64];
    let mut v = Vec::with_capacity(n);
    for _ in 0..n {
        let t0 = Instant::now();
        tx.send_to(&packet, to).unwrap();
        rx.recv_from(&mut buf).unwrap();
        v.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    spread(v)
}

/// Part 1: the host's work on one telemetry sample (us).
fn host_us(n: usize) -> (f64, f64) {
    let home = Preset::TrainerModel.home();
    let neutral = Pose::from_array(home);
    let mechanism = RingPlatform::new(&TRAINER_MODEL);
    let margins = EnvelopeMargins::default();
    let mut washout = Washout::<f64>::new(CueConfig::default()).unwrap();
    let mut frame = [0u8; protocol::MAX_FRAME];
    let mut v = Vec::with_capacity(n);
    for k in 0..n {
        let sample = Telemetry {
            force: [-6.0 * (k as f64 * 0.01).sin(), 2.0, G],
            rate: [0.0, 0.0, 0.3],
        };
        let t0 = Instant::now();
        let offset = washout.step(&sample, 0.01).unwrap();
        let wanted = cueing::pose(&neutral, &offset);
        let limited = envelope::limit(&mechanism, &neutral, &wanted, &margins, 16);
        let p = limited.pose;
        let pose = Pose::new(
            p.x as f32,
            p.y as f32,
            p.z as f32,
            p.alpha as f32,
            p.beta as f32,
            p.gamma as f32,
        );
        let request = Request {
            id: k as u32,
            body: HostMessage::Setpoint(Setpoint {
                seq: k as u32,
                time_us: k as u64 * 10_000,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            }),
        };
        let len = protocol::encode(&request, &mut frame).unwrap();
        std::hint::black_box(len);
        v.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    spread(v)
}

/// Part 3: device time (us) from the tick that takes a setpoint `offset` away from home to the first step pulse,
/// the platform at rest at home and a 100 Hz stream before it. `None` when no pulse comes within a second.
fn device_us(follow: FollowMode, offset: [f32; 6]) -> Option<(f64, u32)> {
    let mut config = ControllerConfig::trainer_model();
    config.pipeline.follow = follow;
    let period_us = f64::from(config.pipeline.tick_us);
    let mut rig = selfcheck::running_rig_with(&mut selfcheck::Digest::default(), config)?;
    let home = rig.controller.status().pose;
    let mut id = 0u32;
    let mut send = |rig: &mut ringpod_core::sim::Rig, seq: u32, time_us: u64, pose: Pose<f32>| {
        id += 1;
        rig.controller.handle(&Request {
            id,
            body: HostMessage::Setpoint(Setpoint {
                seq,
                time_us,
                pose,
                aux: [None; 2],
                spare: [None; 2],
            }),
        });
    };
    // Half a second of home at 100 Hz: the stream is established and the platform at rest.
    let per = (10_000.0 / period_us) as u64;
    for k in 0..50u32 {
        send(&mut rig, k, u64::from(k) * 10_000, home);
        for _ in 0..per {
            let out = rig.tick();
            if out.moves.iter().any(|m| m.count > 0) {
                return None;
            }
        }
    }
    let mut p = home.to_array();
    for (a, d) in p.iter_mut().zip(offset) {
        *a += d;
    }
    send(&mut rig, 50, 500_000, Pose::from_array(p));
    for tick in 0..(1_000_000.0 / period_us) as u32 {
        // Keep the stream alive at 100 Hz, at the new pose.
        if tick > 0 && u64::from(tick) % per == 0 {
            let k = 50 + tick / per as u32;
            send(&mut rig, k, u64::from(k) * 10_000, Pose::from_array(p));
        }
        let out = rig.tick();
        let first = out
            .moves
            .iter()
            .filter(|m| m.count > 0)
            .map(|m| f64::from(m.start_ns) + f64::from(m.period_ns - m.start_ns) / (2.0 * f64::from(m.count)))
            .min_by(f64::total_cmp);
        if let Some(ns) = first {
            return Some((f64::from(tick) * period_us + ns / 1000.0, tick));
        }
    }
    None
}

/// One setpoint measured on the QEMU controller (ns of device time), and the step queue's depth then.
struct Emulated {
    case: String,
    arrival: f64,
    tick: f64,
    pulse: f64,
    depth: u32,
}

/// QEMU's `-icount` shift: 2^3 = 8 ns an instruction (125 M instructions/s; the F411 runs at most 96 M/s).
const ICOUNT_SHIFT: u32 = 3;

/// Part 4: the QEMU controller in `follow` mode (`tests/qemu`, built here), or why not.
/// Returns the measurements and the program's `QUEUE` lines (the step queue and its counters at each stage).
fn emulated(direct: bool) -> Result<(Vec<Emulated>, Vec<String>), String> {
    let elf = emulator::build("ringpod-qemu-controller")?;
    let args: &[&str] = if direct { &["latency", "direct"] } else { &["latency"] };
    let out = emulator::qemu(&elf, Some(&format!("shift={ICOUNT_SHIFT},sleep=off")), args)
        .args(["-serial", "null"])
        .stdin(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("qemu-system-arm: {e} (apt-get install qemu-system-arm)"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !text.lines().any(|l| l == "LATENCY done") {
        return Err(format!("the QEMU controller did not finish: {text}"));
    }
    let queue = text
        .lines()
        .filter(|l| l.starts_with("QUEUE "))
        .map(str::to_string)
        .collect();
    let measured = text
        .lines()
        .filter_map(|l| l.strip_prefix("LATENCY "))
        .filter(|l| *l != "done")
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            let n = |i: usize| {
                f.get(i)
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or(format!("no pulse: {l}"))
            };
            Ok(Emulated {
                case: f[0].to_string(),
                arrival: n(2)?,
                tick: n(3)?,
                pulse: n(4)?,
                depth: n(5)? as u32,
            })
        })
        .collect::<Result<_, String>>()?;
    Ok((measured, queue))
}

fn main() {
    let n = 20_000;
    let (udp_med, udp_p99) = udp_us(n);
    let (host_med, host_p99) = host_us(n);
    let period_us = f64::from(ControllerConfig::trainer_model().pipeline.tick_us);
    // The braking sample's cue: the washout's offset after 10 ms at -6 m/s^2 from rest.
    let mut washout = Washout::<f64>::new(CueConfig::default()).unwrap();
    let rest = Telemetry {
        force: [0.0, 0.0, G],
        rate: [0.0; 3],
    };
    washout.step(&rest, 0.01).unwrap();
    let braking = washout
        .step(
            &Telemetry {
                force: [-6.0, 0.0, G],
                rate: [0.0; 3],
            },
            0.01,
        )
        .unwrap();
    let cue: [f32; 6] = std::array::from_fn(|i| braking[i] as f32);
    let cases: [(&str, [f32; 6]); 3] = [
        ("braking sample (washout, 10 ms at -6 m/s^2)", cue),
        ("surge 0.1 mm", [0.0001, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ("surge 1 mm", [0.001, 0.0, 0.0, 0.0, 0.0, 0.0]),
    ];
    println!("ringpod latency: telemetry datagram arrival -> first step pulse (trainer model, {period_us} us tick)");
    println!();
    println!("host, wall time on this machine ({n} samples): median / p99");
    println!("  loopback UDP send -> receive            {udp_med:7.1} / {udp_p99:7.1} us");
    println!("  washout + pose + envelope limit + frame {host_med:7.1} / {host_p99:7.1} us");
    println!("wait for the next control tick: 0 to {period_us} us (uniform)");
    println!();
    println!("| case | follow | device: setpoint -> first pulse | total, median (host + tick wait + device) | worst (p99 host + full tick + device) | goal 2 ms + 1 tick |");
    println!("|---|---|---|---|---|---|");
    let goal = 2000.0 + period_us;
    for (name, offset) in cases {
        for (mode, follow) in [("interpolate", FollowMode::Interpolate), ("direct", FollowMode::Direct)] {
            match device_us(follow, offset) {
                Some((dev, ticks)) => {
                    let typical = udp_med + host_med + period_us / 2.0 + dev;
                    let worst = udp_p99 + host_p99 + period_us + dev;
                    println!(
                        "| {name} | {mode} | {dev:.0} us (tick {ticks}) | {typical:.0} us | {worst:.0} us | {} |",
                        if worst <= goal { "met" } else { "not met" }
                    );
                }
                None => println!("| {name} | {mode} | no pulse within 1 s | | | not met |"),
            }
        }
    }
    emulated_table(udp_p99 + host_p99, goal);
}

/// The QEMU controller's part: device time from arrival to the first pulse at ten phases of the period, in both
/// follow modes, beside the host's worst (`host_p99_us`, us) against the goal (`goal`, us).
fn emulated_table(host_p99_us: f64, goal: f64) {
    println!();
    println!(
        "QEMU controller (firmware tasks on the emulated M4F), device time under -icount shift={ICOUNT_SHIFT} \
         ({} ns an instruction), ten phases of the control period each:",
        1 << ICOUNT_SHIFT
    );
    println!();
    println!("| case | follow | wait for the tick | tick to first pulse | device: arrival to first pulse, min / median / max | step queue | worst + host p99 | goal 2 ms + 1 tick |");
    println!("|---|---|---|---|---|---|---|---|");
    let runs = std::thread::scope(|s| {
        let interpolate = s.spawn(|| emulated(false));
        let direct = s.spawn(|| emulated(true));
        [
            ("interpolate", interpolate.join().unwrap_or(Err("panicked".into()))),
            ("direct", direct.join().unwrap_or(Err("panicked".into()))),
        ]
    });
    let ms = |ns: f64| ns / 1e6;
    for case in ["braking", "surge-0.1mm", "surge-1mm"] {
        for (mode, run) in &runs {
            let run = match run {
                Ok((r, _)) => r,
                Err(e) => {
                    println!("| {case} | {mode} | not measured: {e} | | | | | |");
                    continue;
                }
            };
            let of: Vec<&Emulated> = run.iter().filter(|m| m.case == case).collect();
            let range = |v: Vec<f64>| {
                let (lo, hi) = v
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(*x), hi.max(*x)));
                (lo, spread(v).0, hi)
            };
            let (wait_lo, _, wait_hi) = range(of.iter().map(|m| ms(m.tick - m.arrival)).collect());
            let (run_lo, _, run_hi) = range(of.iter().map(|m| ms(m.pulse - m.tick)).collect());
            let (lo, med, hi) = range(of.iter().map(|m| ms(m.pulse - m.arrival)).collect());
            let depths: Vec<u32> = of.iter().map(|m| m.depth).collect();
            let worst = hi + host_p99_us / 1000.0;
            println!(
                "| {case} | {mode} | {wait_lo:.2}-{wait_hi:.2} ms | {run_lo:.2}-{run_hi:.2} ms | {lo:.2} / {med:.2} / {hi:.2} ms | {}-{} | {worst:.2} ms | {} |",
                depths.iter().min().unwrap_or(&0),
                depths.iter().max().unwrap_or(&0),
                if worst <= goal / 1000.0 { "met" } else { "not met" }
            );
        }
    }
    println!();
    for (mode, run) in &runs {
        if let Ok((_, queue)) = run {
            for line in queue {
                println!("{mode}: {line}");
            }
        }
    }
}
