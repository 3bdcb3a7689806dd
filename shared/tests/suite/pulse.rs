//! The step generator's slot buffers: random trajectories through the real step scheduler, rendered period by
//! period, then the port replayed slot by slot as the DMA would write it. Every scheduled step is exactly one STEP
//! pulse with the right DIR level, and the pulse width, low time and DIR setup and hold hold on the slot grid (the
//! drivers' model, `sim::drivers`, which the QEMU controller's plant also moves by, is checked here against words
//! that break each rule).

// Index loops over parallel per-axis arrays read more plainly than zips here.
#![allow(clippy::needless_range_loop)]

use proptest::prelude::*;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::motion::pulse::{PortMap, PulseRenderer, PulseTiming, PulseTimingError};
use ringpod_core::motion::pulse::{MAX_STEP_SLOTS, STEP_SLOT_NS};
use ringpod_core::motion::{AxisMove, Direction, SchedulerConfig, StepScheduler};
use ringpod_core::sim::drivers::{DriverInputs, TimingRule, TimingViolation};
use ringpod_core::sim::Plant;

/// The Black Pill's map: STEP on PB0-PB5, DIR on PB6-PB10 and PB12; axis 2 wired the other way round.
pub(crate) const MAP: PortMap = PortMap {
    step: [0, 1, 2, 3, 4, 5],
    dir: [6, 7, 8, 9, 10, 12],
    dir_forward_low: 0b000100,
};

/// Plans `targets` period by period, renders and replays them, then two idle periods; returns the port's step
/// counts, which must equal the scheduler's positions.
fn replay(sched: SchedulerConfig, targets: &[[i64; 6]]) -> Result<([i64; 6], [i64; 6]), String> {
    let timing = PulseTiming::new(&sched, STEP_SLOT_NS, MAX_STEP_SLOTS).map_err(|e| format!("{e:?}"))?;
    let mut renderer = PulseRenderer::new(MAP, timing).map_err(|e| format!("{e:?}"))?;
    let mut scheduler = StepScheduler::new(sched, [0; 6]);
    let mut drivers = DriverInputs::new(MAP, timing.slot_ns, sched);
    let mut buf = vec![0u32; timing.slots];
    let last = *targets.last().unwrap_or(&[0; 6]);
    for t in targets.iter().chain([last, last].iter()) {
        let moves = scheduler.plan(t);
        let report = renderer.render(&moves, &mut buf).ok_or("buffer too short")?;
        if report.collisions != 0 {
            return Err(format!("{} collisions", report.collisions));
        }
        for a in 0..6 {
            if report.steps[a] != moves[a].count {
                return Err(format!(
                    "axis {a}: rendered {} of {} steps",
                    report.steps[a], moves[a].count
                ));
            }
        }
        if let Some(v) = drivers.play_all(&buf) {
            return Err(v.to_string());
        }
    }
    if drivers.step_high() {
        return Err("a STEP pin stayed high".into());
    }
    Ok((drivers.position(), scheduler.position()))
}

fn trajectory() -> impl Strategy<Value = Vec<[i64; 6]>> {
    // Per period and axis a change of up to +-260 steps (beyond the 200 that fit: carried over), often reversing.
    prop::collection::vec(prop::array::uniform6(-260i64..=260), 1..60).prop_map(|deltas| {
        let mut p = [0i64; 6];
        deltas
            .iter()
            .map(|d| {
                for a in 0..6 {
                    p[a] += d[a];
                }
                p
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1_500))]

    #[test]
    fn rendered_pulses_are_the_scheduled_steps(targets in trajectory()) {
        let (port, scheduled) = replay(SchedulerConfig::default(), &targets).map_err(TestCaseError::fail)?;
        prop_assert_eq!(port, scheduled);
    }

    #[test]
    fn other_rates_render_faithfully(targets in trajectory(), hz in prop::sample::select(vec![500u32, 2_000])) {
        let mut config = ControllerConfig::trainer_model();
        config
            .apply(&ringpod_core::protocol::Settings::Control(ringpod_core::protocol::ControlSettings { tick_hz: hz as u16 }))
            .unwrap();
        let (port, scheduled) = replay(config.scheduler, &targets).map_err(TestCaseError::fail)?;
        prop_assert_eq!(port, scheduled);
    }
}

#[test]
fn six_axes_at_full_rate_with_reversals() {
    // 200 steps per period on every axis (200 k steps/s), reversing every third period.
    let mut p = [0i64; 6];
    let targets: Vec<[i64; 6]> = (0..30)
        .map(|k| {
            let d = if (k / 3) % 2 == 0 { 200 } else { -200 };
            for a in 0..6 {
                p[a] += d;
            }
            p
        })
        .collect();
    let (port, scheduled) = replay(SchedulerConfig::default(), &targets).unwrap();
    assert_eq!(port, scheduled);
    assert!(port.iter().all(|&s| s != 0 || scheduled.iter().all(|&x| x == 0)));
}

#[test]
fn a_pulse_at_the_end_of_a_period_ends_in_the_next_buffer() {
    let timing = ControllerConfig::trainer_model().pulse_timing().unwrap();
    let mut renderer = PulseRenderer::new(MAP, timing).unwrap();
    let period = timing.slots as u32 * timing.slot_ns;
    // One step, late in the window: at start + span/2 = period - slot/2, in the last slot.
    let late = AxisMove {
        direction: Direction::Forward,
        dir_change_ns: None,
        start_ns: period - timing.slot_ns,
        count: 1,
        period_ns: period,
    };
    let idle = AxisMove {
        count: 0,
        start_ns: 0,
        ..late
    };
    let mut buf = vec![0u32; timing.slots];
    renderer
        .render(&[late, idle, idle, idle, idle, idle], &mut buf)
        .unwrap();
    assert_eq!(buf[timing.slots - 1] & 1, 1, "STEP rises in the last slot");
    assert!(
        buf.iter().all(|w| w & (1 << 16) == 0),
        "and does not fall in this buffer"
    );
    renderer.render(&[idle; 6], &mut buf).unwrap();
    assert_eq!(
        buf[0] & (1 << 16),
        1 << 16,
        "it falls in the first slot of the next one"
    );
}

#[test]
fn timings_the_grid_cannot_render_are_refused() {
    let ok = SchedulerConfig::default();
    assert!(PulseTiming::new(&ok, 2_500, 800).is_ok());
    // The slot must divide the period, and the period must fit the buffer.
    assert_eq!(PulseTiming::new(&ok, 3_000, 800), Err(PulseTimingError::Slots));
    assert_eq!(PulseTiming::new(&ok, 2_500, 399), Err(PulseTimingError::Slots));
    assert_eq!(PulseTiming::new(&ok, 0, 800), Err(PulseTimingError::Slots));
    // 5 us spacing on a 5 us grid leaves no low time after a 2.5 us pulse rounded up to a slot.
    assert_eq!(PulseTiming::new(&ok, 5_000, 800), Err(PulseTimingError::Spacing));
    // A 6 us DIR setup quantised to 2.5 us slots could shrink to 5 us.
    let setup = SchedulerConfig {
        dir_setup_ns: 6_000,
        ..ok
    };
    assert_eq!(PulseTiming::new(&setup, 2_500, 800), Err(PulseTimingError::Direction));
    let hold = SchedulerConfig {
        dir_hold_ns: 2_000,
        ..ok
    };
    assert_eq!(PulseTiming::new(&hold, 2_500, 800), Err(PulseTimingError::Direction));
    // A pin map that uses a pin twice.
    let timing = PulseTiming::new(&ok, 2_500, 800).unwrap();
    let twice = PortMap {
        dir: [6, 7, 8, 9, 10, 0],
        ..MAP
    };
    assert_eq!(PulseRenderer::new(twice, timing), Err(PulseTimingError::Pins));
    let off_port = PortMap {
        dir: [6, 7, 8, 9, 10, 16],
        ..MAP
    };
    assert_eq!(PulseRenderer::new(off_port, timing), Err(PulseTimingError::Pins));
}

#[test]
fn a_short_buffer_renders_nothing() {
    let timing = ControllerConfig::trainer_model().pulse_timing().unwrap();
    let mut renderer = PulseRenderer::new(MAP, timing).unwrap();
    let mut short = vec![0u32; timing.slots - 1];
    let idle = AxisMove {
        direction: Direction::Forward,
        dir_change_ns: None,
        start_ns: 0,
        count: 0,
        period_ns: 1_000_000,
    };
    assert_eq!(renderer.render(&[idle; 6], &mut short), None);
}

/// A grid finer than the renderer's, so that hand-written words can break every rule.
const FINE_SLOT_NS: u32 = 500;

/// Plays hand-written words, one every 500 ns, into drivers held to the default timing.
fn first_violation(words: &[u32]) -> Option<TimingViolation> {
    let mut drivers = DriverInputs::new(MAP, FINE_SLOT_NS, SchedulerConfig::default());
    drivers.play_all(words)
}

#[test]
fn the_driver_model_catches_every_broken_rule() {
    let slots = |ns: u32| ns.div_ceil(FINE_SLOT_NS) as usize;
    let (step, dir) = (1u32, 1u32 << 6);
    let idle = |n: usize| vec![0u32; n];
    // A correct pulse: DIR set, setup time, STEP high for the pulse width, low again.
    let mut good = vec![dir << 16];
    good.extend(idle(slots(5_000)));
    good.push(step);
    good.extend(idle(slots(2_500) - 1));
    good.push(step << 16);
    assert_eq!(first_violation(&good), None);

    let mut pulse = vec![dir << 16];
    pulse.extend(idle(slots(5_000)));
    pulse.extend([step, step << 16]);
    assert_eq!(first_violation(&pulse).map(|v| v.rule), Some(TimingRule::PulseWidth));

    let setup = vec![dir << 16, step];
    assert_eq!(first_violation(&setup).map(|v| v.rule), Some(TimingRule::DirSetup));

    let together = vec![dir << 16 | step];
    assert_eq!(
        first_violation(&together).map(|v| v.rule),
        Some(TimingRule::DirWhileStepHigh)
    );

    let mut hold = good.clone();
    hold.push(dir);
    assert_eq!(first_violation(&hold).map(|v| v.rule), Some(TimingRule::DirHold));

    let mut low = good.clone();
    low.push(step);
    let v = first_violation(&low).unwrap();
    assert_eq!((v.rule, v.axis, v.slot), (TimingRule::LowTime, 0, good.len() as u64));
}

/// `play_all` lets idle words (no pin set or reset) pass as time only: the same state and the same first violation
/// as playing every word.
#[test]
fn idle_words_only_let_time_pass() {
    let (step, dir) = (1u32, 1u32 << 6);
    // A correct pulse among idle words, rules broken between them, and idle words only.
    let mut spaced = vec![0u32; 22];
    (spaced[2], spaced[13], spaced[19]) = (dir << 16, step, step << 16);
    let buffers = [spaced, vec![dir << 16, step, 0, 0, step << 16, 0, step, 0], vec![0; 40]];
    for words in &buffers {
        let mut each = DriverInputs::new(MAP, FINE_SLOT_NS, SchedulerConfig::default());
        let first = words.iter().fold(None, |f, &w| {
            let v = each.play(w);
            f.or(v)
        });
        let mut all = DriverInputs::new(MAP, FINE_SLOT_NS, SchedulerConfig::default());
        assert_eq!(all.play_all(words), first, "{words:?}");
        assert_eq!(all, each, "{words:?}");
        // Later words are judged against the same times.
        assert_eq!(all.play(step), each.play(step));
    }
}

#[test]
fn the_plant_moves_by_the_edges_the_drivers_count() {
    let sched = SchedulerConfig::default();
    let timing = PulseTiming::new(&sched, STEP_SLOT_NS, MAX_STEP_SLOTS).unwrap();
    let mut renderer = PulseRenderer::new(MAP, timing).unwrap();
    let mut scheduler = StepScheduler::new(sched, [0; 6]);
    let mut drivers = DriverInputs::new(MAP, timing.slot_ns, sched);
    let mut plant = Plant::trainer_model([0; 6]);
    let mut buf = vec![0u32; timing.slots];
    let targets = [
        [120, -80, 0, 7, 200, -200],
        [60, -80, 3, 0, 400, -350],
        [60, -80, 3, 0, 400, -350],
    ];
    for (k, t) in targets.iter().enumerate() {
        let moves = scheduler.plan(t);
        renderer.render(&moves, &mut buf).unwrap();
        // Drivers disabled in the second period: the plant still moves (as a driver would not, which is why the
        // controller never steps then) and counts what it was sent.
        assert_eq!(plant.play(&mut drivers, &buf, k != 1), None);
    }
    assert_eq!(plant.position, scheduler.position());
    assert_eq!(plant.steps_received, [180, 80, 3, 14, 400, 350]);
    assert_eq!(plant.steps_while_disabled, 60 + 3 + 7 + 200 + 150);
}

/// The renderer's words, written the plain way: every step's closed-form time ([`AxisMove::step_ns`]) divided
/// by the slot, each step looked up in its slot. `carry` holds the resets past the buffer's end, as the renderer's.
fn plain_render(timing: &PulseTiming, carry: &mut [u32; 4], moves: &[AxisMove; 6], out: &mut [u32]) -> ([u32; 6], u32) {
    let slots = timing.slots;
    out.fill(0);
    for (w, c) in out.iter_mut().zip(carry.iter_mut()) {
        *w |= std::mem::take(c);
    }
    let (mut steps, mut collisions) = ([0u32; 6], 0u32);
    let slot_ns = timing.slot_ns.max(1);
    for (a, m) in moves.iter().enumerate() {
        let high = (m.direction == Direction::Forward) != (MAP.dir_forward_low & (1 << a) != 0);
        let dir = (1u32 << MAP.dir[a]) << if high { 0 } else { 16 };
        match m.dir_change_ns {
            Some(t) => out[((t / slot_ns) as usize).min(slots - 1)] |= dir,
            None if m.count > 0 => out[0] |= dir,
            None => {}
        }
        let bit = 1u32 << MAP.step[a];
        for k in 0..m.count {
            let s = (m.step_ns(k) / slot_ns) as usize;
            if s >= slots {
                collisions += 1;
                continue;
            }
            collisions += u32::from(out[s] & bit != 0);
            out[s] |= bit;
            steps[a] += 1;
            let end = s + timing.pulse_slots;
            match out.get_mut(end) {
                Some(w) => *w |= bit << 16,
                None => carry[end - slots] |= bit << 16,
            }
        }
    }
    (steps, collisions)
}

/// Any move, valid or not: windows inside, at the end of or past the period, counts from none to more than the
/// one-division slots hold, DIR changes anywhere.
fn any_move() -> impl Strategy<Value = AxisMove> {
    let period = prop_oneof![Just(1_000_000u32), 1u32..=2_000_000, Just(u32::MAX)];
    let count = prop_oneof![0u32..=3, 0u32..=250, 2_000u32..=2_500];
    (
        period,
        0.0..1.2f64,
        count,
        any::<bool>(),
        prop::option::of(any::<u32>()),
    )
        .prop_map(|(period, start, count, forward, dir_change_ns)| AxisMove {
            direction: if forward {
                Direction::Forward
            } else {
                Direction::Backward
            },
            dir_change_ns,
            start_ns: (f64::from(period) * start).min(f64::from(u32::MAX)) as u32,
            count,
            period_ns: period,
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3_000))]

    /// The renderer's buffers, carries and reports are the plain rendering's, for any grid and any moves (its
    /// slots computed by one division a step, its collision checks skipped where steps are a slot apart).
    #[test]
    fn the_renderer_equals_the_plain_rendering(
        slot_ns in prop_oneof![Just(2_500u32), 1u32..=20_000],
        slots in 2usize..=400,
        pulse_slots in 1usize..=4,
        periods in prop::collection::vec(prop::array::uniform6(any_move()), 1..4),
    ) {
        prop_assume!(pulse_slots < slots);
        let timing = PulseTiming { slot_ns, slots, pulse_slots };
        let mut renderer = PulseRenderer::new(MAP, timing).unwrap();
        let mut carry = [0u32; 4];
        let (mut got, mut want) = (vec![0u32; slots], vec![0u32; slots]);
        let idle = AxisMove { direction: Direction::Forward, dir_change_ns: None, start_ns: 0, count: 0, period_ns: 1 };
        for moves in periods.iter().chain([[idle; 6]].iter()) {
            let report = renderer.render(moves, &mut got).unwrap();
            let (steps, collisions) = plain_render(&timing, &mut carry, moves, &mut want);
            prop_assert_eq!(&got, &want);
            prop_assert_eq!(report.steps, steps);
            prop_assert_eq!(report.collisions, collisions);
        }
    }
}
