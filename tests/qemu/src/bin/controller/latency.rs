//! `latency` on the semihosting command line: the time from a setpoint frame's arrival to the first STEP pulse it
//! causes, in device time, measured on the firmware's own tasks. A measurement that prints its figures (read by
//! `cargo run --release -p ringpod-tests --bin latency`), not a check.
//!
//! A host task inside the program ([`host`]) plays the host: it puts frames into the UART's receive pipe as the RX
//! interrupt does (the frame's last byte arriving is the "arrival"), brings the controller up (hello, enable, home,
//! start), streams the home pose at 100 Hz, and then, at ten phases of the 1 ms control period, one setpoint away
//! from home, followed by that setpoint again at 100 Hz until the port plays a STEP edge. Three hooks of the board
//! module time what happens: the start of each control tick ([`tick_started`]), and each period of port words as it
//! plays ([`played`]): the first STEP edge is the buffer's start plus its slot.
//!
//! QEMU runs it under `-icount shift=N,sleep=off`: virtual time advances `2^N` ns per instruction and jumps over
//! idle time to the next timer, so the figures are device time, the same on every run and any host.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m_semihosting::{debug, hprintln};
use critical_section::Mutex as CsMutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{with_timeout, Duration, Instant, Timer};
use ringpod_core::cueing::{CueConfig, Telemetry, Washout, G};
use ringpod_core::kinematics::Pose;
use ringpod_core::motion::Setpoint;
use ringpod_core::protocol::{self, HostMessage, Request, MAX_FRAME, PROTOCOL_VERSION};
use ringpod_core::safety::{Command, State};
use ringpod_firmware::app::Shared;

use crate::{time, uart};

/// The STEP pins' bits of a port word (the low half sets pins; `PORT_MAP.step` is bits 0-5).
const STEP_BITS: u32 = 0x3f;

/// The setpoint being measured: its arrival (ns), and the start of the first control tick after it.
struct Armed {
    arrival_ns: u64,
    tick_ns: Option<u64>,
}

/// What one setpoint took: arrival, the tick that could take it, the first STEP edge (ns), and the periods of
/// moves waiting in the step queue when that edge played.
#[derive(Clone, Copy)]
struct Measured {
    arrival_ns: u64,
    tick_ns: u64,
    pulse_ns: u64,
    depth: usize,
}

static ARMED: CsMutex<Cell<Option<Armed>>> = CsMutex::new(Cell::new(None));
static LAST_TICK_NS: CsMutex<Cell<u64>> = CsMutex::new(Cell::new(0));
static LAST_STEP_NS: CsMutex<Cell<u64>> = CsMutex::new(Cell::new(0));
static RESULT: Signal<CriticalSectionRawMutex, Measured> = Signal::new();
/// Whether a control tick is under way: `Machine::cycles` is read at its start and its end, and the watchdog is
/// fed after it, so the first read after a feed is a tick's start.
static IN_TICK: AtomicBool = AtomicBool::new(false);
/// Whether the measurement runs (the hooks cost nothing otherwise).
static ON: AtomicBool = AtomicBool::new(false);

/// Times the step port fell more than four periods behind and started afresh (`machine::Port` counts them, the
/// `QUEUE` lines print them).
pub static PORT_RESTARTS: AtomicU32 = AtomicU32::new(0);

/// `Machine::cycles` was read: the start of a tick when none is under way.
pub fn cycles_read() {
    if !ON.load(Ordering::Relaxed) || IN_TICK.swap(true, Ordering::Relaxed) {
        return;
    }
    let now = time::now_ns();
    critical_section::with(|cs| {
        LAST_TICK_NS.borrow(cs).set(now);
        let armed = ARMED.borrow(cs);
        if let Some(mut a) = armed.take() {
            if a.tick_ns.is_none() && now >= a.arrival_ns {
                a.tick_ns = Some(now);
            }
            armed.set(Some(a));
        }
    });
}

/// The watchdog was fed: the tick is over.
pub fn tick_ended() {
    IN_TICK.store(false, Ordering::Relaxed);
}

/// A period of port words plays from `start` (us, the end of the buffer before it) in slots of `slot_ns`, with
/// `depth` periods of moves queued behind it.
pub fn played(start_us: u64, words: &[u32], slot_ns: u32, depth: usize) {
    if !ON.load(Ordering::Relaxed) {
        return;
    }
    let Some(slot) = words.iter().position(|w| w & STEP_BITS != 0) else {
        return;
    };
    let pulse_ns = start_us * 1_000 + slot as u64 * u64::from(slot_ns);
    critical_section::with(|cs| {
        LAST_STEP_NS.borrow(cs).set(pulse_ns);
        if let Some(a) = ARMED.borrow(cs).take() {
            RESULT.signal(Measured {
                arrival_ns: a.arrival_ns,
                tick_ns: a.tick_ns.unwrap_or(0),
                pulse_ns,
                depth,
            });
        }
    });
}

/// The host's side of the link: requests framed and put on the line.
struct Host {
    id: u32,
    seq: u32,
}

impl Host {
    /// Frames `body` and puts it into the receive pipe; returns when its last byte arrived (ns).
    fn send(&mut self, body: HostMessage) -> u64 {
        self.id += 1;
        let mut frame = [0u8; MAX_FRAME];
        let len = protocol::encode(&Request { id: self.id, body }, &mut frame).unwrap_or(0);
        uart::inject(&frame[..len]);
        time::now_ns()
    }

    /// The next setpoint of a 100 Hz stream.
    fn setpoint(&mut self, pose: Pose<f32>) -> u64 {
        self.seq += 1;
        let body = HostMessage::Setpoint(Setpoint {
            seq: self.seq,
            time_us: u64::from(self.seq) * 10_000,
            pose,
            aux: [None; 2],
            spare: [None; 2],
        });
        self.send(body)
    }

    /// `n` setpoints of `pose`, 10 ms apart.
    async fn stream(&mut self, pose: Pose<f32>, n: u32) {
        for _ in 0..n {
            self.setpoint(pose);
            Timer::after(Duration::from_millis(10)).await;
        }
    }
}

/// Waits (at most `limit_ms`) until the supervisor's state satisfies `done`.
async fn until(shared: &Shared, limit_ms: u32, done: impl Fn(State) -> bool) -> bool {
    for _ in 0..limit_ms {
        if done(shared.with(|c| c.supervisor().state())) {
            return true;
        }
        Timer::after(Duration::from_millis(1)).await;
    }
    false
}

/// Prints the step queue's depth, the periods the step generator found it empty so far, the control periods
/// passed and re-phased (`app::control`), and the times the port fell behind and started afresh.
fn queue(shared: &Shared, when: &str) {
    hprintln!(
        "QUEUE {} depth {} underruns {} passes {} re-phased {} port restarts {}",
        when,
        shared.steps.len(),
        shared.step_underruns.load(Ordering::Relaxed),
        shared.passes.load(Ordering::Relaxed),
        shared.rephased.load(Ordering::Relaxed),
        PORT_RESTARTS.load(Ordering::Relaxed)
    );
}

/// The washout's pose offset after 10 ms of braking at 6 m/s^2 from rest (the simulator's case).
fn braking_cue() -> [f32; 6] {
    let Ok(mut washout) = Washout::<f32>::new(CueConfig::default()) else {
        return [0.0; 6];
    };
    let rest = Telemetry {
        force: [0.0, 0.0, G as f32],
        rate: [0.0; 3],
    };
    let braking = Telemetry {
        force: [-6.0, 0.0, G as f32],
        rate: [0.0; 3],
    };
    let _ = washout.step(&rest, 0.01);
    washout.step(&braking, 0.01).unwrap_or([0.0; 6])
}

/// Runs the measurement, prints `LATENCY case phase_us arrival_ns tick_ns pulse_ns depth` per setpoint (`LATENCY
/// case phase_us none` when no STEP edge came within a second) and `LATENCY done`, and ends the program.
#[embassy_executor::task]
pub async fn host(shared: &'static Shared) {
    ON.store(true, Ordering::Relaxed);
    let mut host = Host { id: 0, seq: 0 };
    host.send(HostMessage::Hello {
        version: PROTOCOL_VERSION,
    });
    host.send(HostMessage::Command(Command::Enable));
    let up = until(shared, 5_000, |s| matches!(s, State::PowerOn { settled: true })).await;
    queue(shared, "powered");
    host.send(HostMessage::Command(Command::Home));
    let homed = up && until(shared, 60_000, |s| s == State::Ready).await;
    host.send(HostMessage::Command(Command::Start));
    if !homed {
        ringpod_qemu::fail("latency: the controller did not home");
    }
    queue(shared, "homed");
    let home = shared.with(|c| c.status().pose).to_array();
    host.stream(Pose::from_array(home), 50).await;
    let cases: [(&str, [f32; 6]); 3] = [
        ("braking", braking_cue()),
        ("surge-0.1mm", [0.0001, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ("surge-1mm", [0.001, 0.0, 0.0, 0.0, 0.0, 0.0]),
    ];
    for (name, offset) in cases {
        let mut target = home;
        for (t, d) in target.iter_mut().zip(offset) {
            *t += d;
        }
        for phase_us in (0..1_000u64).step_by(100) {
            // Back home and at rest: no STEP edge for 100 ms (within 5 s, or the run ends with an error).
            let mut rounds = 0;
            loop {
                host.stream(Pose::from_array(home), 10).await;
                let quiet = critical_section::with(|cs| time::now_ns().saturating_sub(LAST_STEP_NS.borrow(cs).get()));
                if quiet > 100_000_000 {
                    break;
                }
                rounds += 1;
                if rounds == 50 {
                    queue(shared, "not at rest");
                    ringpod_qemu::fail("latency: the platform did not come to rest at home");
                }
            }
            // `phase_us` after the start of a control tick.
            let tick_us = critical_section::with(|cs| LAST_TICK_NS.borrow(cs).get()) / 1_000;
            Timer::at(Instant::from_micros(tick_us + 1_000 + phase_us)).await;
            RESULT.reset();
            // No await between the frame's arrival and the arming: no tick or port buffer can come between.
            let arrival_ns = host.setpoint(Pose::from_array(target));
            critical_section::with(|cs| {
                ARMED.borrow(cs).set(Some(Armed {
                    arrival_ns,
                    tick_ns: None,
                }))
            });
            let mut measured = None;
            for _ in 0..100 {
                match with_timeout(Duration::from_millis(10), RESULT.wait()).await {
                    Ok(m) => {
                        measured = Some(m);
                        break;
                    }
                    // The stream goes on at 100 Hz, at the new pose.
                    Err(_) => {
                        host.setpoint(Pose::from_array(target));
                    }
                }
            }
            match measured {
                Some(m) => hprintln!(
                    "LATENCY {} {} {} {} {} {}",
                    name,
                    phase_us,
                    m.arrival_ns,
                    m.tick_ns,
                    m.pulse_ns,
                    m.depth
                ),
                None => hprintln!("LATENCY {} {} none", name, phase_us),
            }
        }
    }
    queue(shared, "done");
    hprintln!("LATENCY done");
    debug::exit(debug::EXIT_SUCCESS);
}
