//! ringpod-core on an emulated Cortex-M4F (QEMU `mps2-an386`): the self-check workload with its checks and
//! digest, then the cost of the control path in instructions. Output over semihosting, one result a line, read by
//! `cargo run -p ringpod-tests --bin qemu`.
//!
//! Instruction counts: QEMU's `-icount shift=0` advances virtual time by 1 ns per instruction, and SysTick counts the
//! 25 MHz core clock of the AN386 image, so one SysTick count is a fixed number of instructions (40). The number is
//! not assumed: a calibration loop of a known instruction count measures it first.

#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::presets::{TRAINER_MODEL, TRAINER_MODEL_HOME_Z};
use ringpod_core::kinematics::{Mechanism, NewtonOptions, Pose, RingPlatform};
use ringpod_core::motion::pulse::{PortMap, PulseRenderer, PulseTiming, MAX_STEP_SLOTS, STEP_SLOT_NS};
use ringpod_core::motion::{envelope, PipelineConfig, SchedulerConfig, Setpoint, StepScheduler};
use ringpod_core::protocol::{self, ControlSettings, HostMessage, Request, Settings};
use ringpod_core::selfcheck::{self, Digest, CHECKS};
use ringpod_qemu::{fail, halt};

/// SysTick counts elapsed between two reads (it counts down, 24 bits).
fn elapsed(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & 0x00ff_ffff
}

/// Counts of `f` (which must stay under 2^24 counts, about 670 M instructions).
fn counts(mut f: impl FnMut()) -> u32 {
    let start = SYST::get_current();
    f();
    elapsed(start, SYST::get_current())
}

/// A loop of exactly `2 n` instructions (`subs` and `bne`).
fn known_loop(n: u32) {
    // SAFETY: only a register is used and changed.
    unsafe {
        core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) n => _, options(nomem, nostack));
    }
}

#[entry]
fn main() -> ! {
    let mut core = match cortex_m::Peripherals::take() {
        Some(p) => p,
        None => fail("core peripherals"),
    };

    let outcome = selfcheck::run();
    for (name, ok) in CHECKS.iter().zip(outcome.passed) {
        hprintln!("CHECK {} {}", if ok { "PASS" } else { "FAIL" }, name);
    }
    hprintln!("DIGEST {:016x}", outcome.digest);

    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(0x00ff_ffff);
    core.SYST.clear_current();
    core.SYST.enable_counter();

    // Calibration: instructions per SysTick count, from 2 M instructions (in hundredths).
    let calibration = counts(|| known_loop(1_000_000)).max(1);
    let per_count_x100 = 200_000_000 / calibration;
    hprintln!("CALIBRATION {} instructions per count (x100)", per_count_x100);
    let report = |name: &str, total: u32, calls: u32| {
        let instructions = u64::from(total) * u64::from(per_count_x100) / 100 / u64::from(calls.max(1));
        hprintln!("COST {} {}", instructions, name);
    };

    kinematics_costs(&report);
    controller_costs(&report);
    render_costs(&report);
    hprintln!("DONE");
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}

/// IK, IK with its checks, FK and a limited setpoint on the trainer model, over the self-check's 64 poses.
fn kinematics_costs(report: &dyn Fn(&str, u32, u32)) {
    let trainer = RingPlatform::<f32>::new(&TRAINER_MODEL);
    let poses: [Pose<f32>; 64] = {
        let mut all = [Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0); 64];
        for (slot, p) in all.iter_mut().zip(selfcheck::poses(64)) {
            *slot = p;
        }
        all
    };
    let mut q = [trainer.inverse(&poses[0]).unwrap_or_else(|_| fail("ik")); 64];
    for (qi, p) in q.iter_mut().zip(&poses) {
        *qi = trainer.inverse(p).unwrap_or_else(|_| fail("ik"));
    }

    let ik = counts(|| {
        for p in &poses {
            let _ = black_box(trainer.inverse(black_box(p)));
        }
    });
    report("trainer IK (f32)", ik, 64);

    let checks = counts(|| {
        for p in &poses {
            let _ = black_box(trainer.inverse_checked(black_box(p)));
        }
    });
    report("trainer IK + all six checks (f32)", checks, 64);

    // As the self-check: the combined half ranges reach outside the checks, and FK is measured doing its math and
    // every acceptance test but the workspace's.
    let options = NewtonOptions {
        inside: false,
        ..NewtonOptions::default()
    };
    let mut iterations = 0u32;
    let fk = counts(|| {
        for (p, qi) in poses.iter().zip(&q) {
            let guess = Pose::new(p.x + 1e-3, p.y - 1e-3, p.z, p.alpha, p.beta + 0.01, p.gamma);
            if let Ok(s) = trainer.forward(black_box(qi), &guess, &options) {
                iterations += u32::from(s.iterations);
            }
        }
    });
    report("trainer FK, Newton from 1 mm / 0.6 deg off (f32)", fk, 64);
    hprintln!("FK_ITERATIONS {} per solve (x100)", iterations * 100 / 64);

    // One setpoint limited into the envelope: the same 64 poses with their excursions from home tripled (all
    // outside), limited on the ray from home with the pipeline's budget of evaluations.
    let centre = Pose::new(0.0, 0.0, TRAINER_MODEL_HOME_Z as f32, 0.0, 0.0, 0.0);
    let config = PipelineConfig::default();
    let mut outside = poses;
    for p in &mut outside {
        let (a, c) = (p.to_array(), centre.to_array());
        *p = Pose::from_array(core::array::from_fn(|i| {
            if i == 5 {
                a[5]
            } else {
                c[i] + 3.0 * (a[i] - c[i])
            }
        }));
    }
    let mut limited = 0u32;
    // The guard of a control loop, whose configuration being checked the search works in (as the pipeline's).
    let mut guard = Default::default();
    let limit = counts(|| {
        for p in &outside {
            let l = envelope::limit_in(
                &trainer,
                &mut guard,
                &centre,
                black_box(p),
                &config.margins,
                config.limit_evaluations,
            );
            limited += u32::from(l.is_limited());
        }
    });
    report(
        "one setpoint limited into the envelope (8 IK + check evaluations)",
        limit,
        64,
    );
    hprintln!("LIMITED {} of 64", limited);
}

/// A control tick and a setpoint frame at 1 kHz, and the tick at 2 kHz.
fn controller_costs(report: &dyn Fn(&str, u32, u32)) {
    // A controller brought to Running through power-up and homing, then fed a setpoint frame every tick.
    let (tick, frame, n) = stream_costs(ControllerConfig::trainer_model(), 1_000);
    report(
        "control tick: pipeline (limits, IK + checks) + scheduler + supervisor",
        tick,
        n,
    );
    report(
        "decode + dispatch of one setpoint frame (COBS, CRC, postcard, validation, envelope check)",
        frame,
        n,
    );
    let mut fast = ControllerConfig::trainer_model();
    if fast
        .apply(&Settings::Control(ControlSettings { tick_hz: 2_000 }))
        .is_err()
    {
        fail("control.tick_hz 2000");
    }
    let (tick, _, n) = stream_costs(fast, 2_000);
    report("control tick at 2 kHz (the same work, half the period)", tick, n);
    let (tick, _, n) = stream_costs_with(spare_fitted(), 1_000, true);
    report(
        "control tick with the spare axes 7 and 8 fitted and streaming (their trackers and step plan)",
        tick,
        n,
    );
}

/// The trainer model with both spare axes fitted (and so no supply senses: their pins are STEP/DIR 7-8).
fn spare_fitted() -> ControllerConfig {
    let mut c = ControllerConfig::trainer_model();
    c.supervisor.logic_sense = false;
    c.supervisor.power_sense = false;
    let axis = ringpod_core::motion::SpareAxisSettings {
        enabled: true,
        steps_per_unit: 400.0,
        velocity: 50.0,
        acceleration: 500.0,
        travel: [-10.0, 10.0],
    };
    if c.apply(&Settings::Spare([axis; 2])).is_err() || c.validate().is_err() {
        fail("the spare axes' section");
    }
    c
}

/// The step generator's CPU work for one period of step buffers, idle, at typical rates, at the trainer model's
/// fastest motion and at the top rate.
fn render_costs(report: &dyn Fn(&str, u32, u32)) {
    let rows: [(&str, [i64; 6]); 4] = [
        ("render one period of step buffers, idle (no steps)", [0; 6]),
        (
            "render one period of step buffers, typical motion (6 axes x 10 k steps/s)",
            [10; 6],
        ),
        (
            "render one period of step buffers, the trainer's fastest motion (4 x 10 k, 2 x 96 k steps/s)",
            [10, 10, 10, 10, 96, 96],
        ),
        (
            "render one period of step buffers (6 axes x 100 k steps/s, 1 kHz)",
            [100; 6],
        ),
    ];
    for (name, per_period) in rows {
        let (total, periods) = render_cost(per_period);
        report(name, total, periods);
    }
    // The spare axes' period beside it, on the F411's spare map (axes 0 and 1 its STEP7/DIR7 and STEP8/DIR8, the
    // other four never stepping): the step generator renders it every period while an axis is fitted.
    let (total, periods) = render_cost_on(SPARE_MAP, [10, 10, 0, 0, 0, 0]);
    report(
        "render the spare axes' period of step buffers (their map, 2 axes x 10 k steps/s)",
        total,
        periods,
    );
}

/// The F411's spare pin map (`firmware/src/board/stm32f411/resources.rs`, built only for that board).
const SPARE_MAP: PortMap = PortMap {
    step: [9, 15, 0, 1, 2, 3],
    dir: [10, 14, 4, 5, 6, 7],
    dir_forward_low: 0,
};

/// SysTick counts of rendering 20 periods of `per_period` steps on each axis, DIR reversing every period, and the
/// number of periods.
fn render_cost(per_period: [i64; 6]) -> (u32, u32) {
    let map = PortMap {
        step: [0, 1, 2, 3, 4, 5],
        dir: [6, 7, 8, 9, 10, 11],
        dir_forward_low: 0,
    };
    render_cost_on(map, per_period)
}

/// [`render_cost`] on the pins of `map`.
fn render_cost_on(map: PortMap, per_period: [i64; 6]) -> (u32, u32) {
    let scheduler = SchedulerConfig::default();
    let timing = PulseTiming::new(&scheduler, STEP_SLOT_NS, MAX_STEP_SLOTS).unwrap_or_else(|_| fail("pulse timing"));
    let mut renderer = PulseRenderer::new(map, timing).unwrap_or_else(|_| fail("pulse renderer"));
    let mut plan = StepScheduler::new(scheduler, [0; 6]);
    let mut buffer = [0u32; MAX_STEP_SLOTS];
    let (mut total, mut rendered) = (0u32, 0i64);
    let periods = 20u32;
    for k in 0..periods {
        let target = if k % 2 == 0 { per_period } else { [0; 6] };
        let moves = plan.plan(&target);
        total += counts(|| {
            if let Some(r) = renderer.render(black_box(&moves), &mut buffer) {
                rendered += r.steps.iter().map(|&n| i64::from(n)).sum::<i64>();
            }
        });
    }
    if rendered != i64::from(periods) * per_period.iter().sum::<i64>() {
        fail("rendered steps");
    }
    (total, periods)
}

/// SysTick counts of the control ticks and of the setpoint frames of 500 ticks of a stream moving
/// surge and yaw, for a controller brought to `Running` with `config` ticking at `rate_hz`.
fn stream_costs(config: ControllerConfig, rate_hz: u32) -> (u32, u32, u32) {
    stream_costs_with(config, rate_hz, false)
}

/// [`stream_costs`], the setpoints carrying targets for the spare axes when `spare` (a sine on each, in the units of
/// [`spare_fitted`]).
fn stream_costs_with(config: ControllerConfig, rate_hz: u32, spare: bool) -> (u32, u32, u32) {
    let mut d = Digest::default();
    let mut rig =
        selfcheck::running_rig_with(&mut d, config).unwrap_or_else(|| fail("controller did not reach Running"));
    let home = rig.controller.pipeline().pose();
    let mut out = [0u8; protocol::MAX_FRAME];
    let mut frame = [0u8; protocol::MAX_FRAME];
    let (mut tick_total, mut decode_total) = (0u32, 0u32);
    let n = 500u32;
    let period_us = 1_000_000 / rate_hz;
    for k in 1..=n {
        let t = (k * period_us) as f32 * 1e-6;
        let pose = Pose::new(0.01 * libm_sin(2.0 * t), 0.0, home.z, 0.0, 0.0, 0.2 * t);
        let request = Request {
            id: k,
            body: HostMessage::Setpoint(Setpoint {
                seq: k,
                time_us: u64::from(k * period_us),
                pose,
                aux: [None; 2],
                spare: if spare {
                    [Some(5.0 * libm_sin(3.0 * t)), Some(-2.0 * libm_sin(5.0 * t))]
                } else {
                    [None; 2]
                },
            }),
        };
        let len = protocol::encode(&request, &mut frame).unwrap_or(1);
        decode_total += counts(|| {
            black_box(rig.controller.handle_frame(&frame[..len - 1], &mut out));
        });
        let o = rig.controller.supervisor().outputs();
        rig.controller
            .set_inputs(rig.plant.inputs(o.logic_relay, o.power_relay));
        let mut tick = None;
        tick_total += counts(|| tick = Some(rig.controller.tick()));
        if let Some(t) = tick {
            rig.plant.apply(&t);
        }
    }
    if rig.controller.status().applied != n {
        fail("setpoints were rejected");
    }
    // Totals in counts, and the number of calls (the caller's report scales and divides).
    (tick_total, decode_total, n)
}

/// `sinf` through libm, as the core calls it.
fn libm_sin(x: f32) -> f32 {
    ringpod_core::Real::sin_(x)
}
