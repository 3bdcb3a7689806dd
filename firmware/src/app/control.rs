//! The control tick: inputs to the controller, one `tick()` per period, relays and driver enable from the
//! supervisor's outputs, the period's step moves to the step generator, and the watchdog fed only when all of
//! that happened.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Instant, Timer};
use ringpod_core::controller::Inputs;
use ringpod_core::motion::phase::TickPhase;
use ringpod_core::safety::pins::{writes, OutputPin};

use super::Shared;

/// The board's side of the control loop: the hardware only. The loop itself reads the debounced inputs and owns
/// the step queue, so every board shares that code.
pub trait Machine {
    /// Sets one output pin (`true`: relay closed, drivers enabled).
    fn write(&mut self, pin: OutputPin, on: bool);
    /// A free-running cycle counter (DWT CYCCNT on a board).
    fn cycles(&self) -> u32;
    /// Reloads the independent watchdog.
    fn feed_watchdog(&mut self);
}

/// Periods a late control loop still ticks to catch up (a tenth of the stream's default timeout at 1 kHz); the
/// rest of a longer hold-up is passed.
const CATCH_UP: u32 = 10;

/// Waits for the next period, unless a stall owes periods: device time the time driver lost (an erase,
/// `settings`), periods gone already, each passed at once before the timer's next (`true`). Counted apart from the
/// timer's deadline, which a stall longer than the time since the start (a save soon after a reset) would take
/// below zero, where the excess would be lost.
async fn next_period(owed_us: &mut u64, tick_us: u32, due: Instant, shared: &Shared) -> bool {
    *owed_us += u64::from(shared.clock_lost_us.swap(0, Ordering::Relaxed));
    let owed = *owed_us >= u64::from(tick_us);
    if owed {
        *owed_us -= u64::from(tick_us);
    } else {
        Timer::at(due).await;
    }
    owed
}

/// Runs the control loop at the controller's rate, forever, each tick held [`TickPhase`]'s lead before the step
/// generator's next period boundary so that its moves are taken at that boundary.
pub async fn run(machine: &mut impl Machine, shared: &Shared) -> ! {
    let tick_us = shared.with(|c| c.pipeline().config().tick_us);
    let period = Duration::from_micros(u64::from(tick_us));
    // A period too short to hold a lead in (no configuration the controller takes) runs free.
    let phase = TickPhase::for_period(tick_us).ok();
    let mut due = Instant::now() + period;
    let mut worst = 0u32;
    let mut n = 0u32;
    let mut owed_us = 0u64;
    loop {
        let owed = next_period(&mut owed_us, tick_us, due, shared).await;
        // After a hold-up the periods it cost are caught up at once (mostly as passes), so that the controller's
        // clocks lose none of them; the phase is only judged on a tick that ran on time, and by when it was due:
        // a tick that starts late behind a link frame is jitter the lead covers, not a phase to correct.
        let scheduled = due;
        let now = Instant::now();
        let on_time = !owed && now < due + period;
        if !owed {
            due += period;
        }
        if !on_time {
            // Catching up: let the link task read what arrived during the hold-up first (a late `Timer::at` is
            // ready at once and would not yield), so that the stream's timeout is judged on the setpoints sent
            // meanwhile, not on device time alone.
            embassy_futures::yield_now().await;
        }
        // A period still queued (only after a hold-up, or the one period a phase correction gives two ticks) is
        // passed rather than ticked; see `Controller::pass`. So is a period the loop is more than [`CATCH_UP`]
        // periods late for: the motors did not move in it, and ticked in a burst such periods would run the stream's
        // timeout out before the host's next setpoints can arrive. Inputs and faults reach the supervisor either way.
        let ahead = owed || shared.steps.len() >= super::AHEAD || now >= scheduled + period * CATCH_UP;
        let inputs = Inputs::from_word(shared.inputs.load(Ordering::Relaxed));
        let step_fault = shared.step_fault.swap(false, Ordering::Relaxed);
        let start = machine.cycles();
        let (outputs, moves, message) = shared.with(|c| {
            if step_fault {
                c.step_generator_fault();
            }
            c.set_inputs(inputs);
            let (outputs, moves) = if ahead {
                (c.pass(), None)
            } else {
                let out = c.tick();
                let period = super::StepPeriod {
                    moves: out.moves,
                    spare: c.spare_moves(),
                };
                (out.outputs, Some(period))
            };
            (outputs, moves, c.unsolicited())
        });
        let cost = machine.cycles().wrapping_sub(start);
        // Outputs first: a fault's disable reaches the drivers before anything else happens; the order of the
        // writes keeps the interlocks between them (`safety::pins`).
        for (pin, on) in writes(&outputs) {
            machine.write(pin, on);
        }
        if let Some(m) = message {
            shared.post(m);
        }
        let Some(moves) = moves else {
            shared.passes.fetch_add(1, Ordering::Relaxed);
            machine.feed_watchdog();
            continue;
        };
        // Waits while the step generator's queue is full: the queue paces the loop as much as the timer does.
        shared.steps.send(moves).await;
        let depth = shared.steps.len() as u16;
        shared.with(|c| {
            c.set_platform_stats(cost, depth);
            c.set_step_counters(
                shared.step_underruns.load(Ordering::Relaxed),
                shared.passes.load(Ordering::Relaxed),
            );
        });
        let boundary = shared.boundary_us.load(Ordering::Relaxed);
        if let Some(delay) = phase
            .filter(|_| on_time)
            .and_then(|p| p.correction(micros(scheduled), boundary))
        {
            due = scheduled + Duration::from_micros(u64::from(delay));
            shared.rephased.fetch_add(1, Ordering::Relaxed);
        }
        worst = worst.max(cost);
        n = n.wrapping_add(1);
        if n.is_multiple_of(5_000) {
            defmt::info!(
                "tick: {} cycles (worst {}), step queue {}, {} periods passed, {} played empty, {} re-phased",
                cost,
                worst,
                depth,
                shared.passes.load(Ordering::Relaxed),
                shared.step_underruns.load(Ordering::Relaxed),
                shared.rephased.load(Ordering::Relaxed)
            );
        }
        machine.feed_watchdog();
    }
}

/// Device time in microseconds, wrapping (the step generator records its boundaries so).
pub fn micros(t: Instant) -> u32 {
    t.as_micros() as u32
}
