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
    loop {
        Timer::at(due).await;
        // After a hold-up the periods it cost are caught up at once (mostly as passes), so that the controller's
        // clocks lose none of them; the phase is only judged on a tick that ran on time, and by when it was due:
        // a tick that starts late behind a link frame is jitter the lead covers, not a phase to correct.
        let scheduled = due;
        let on_time = Instant::now() < due + period;
        due += period;
        if shared.steps.len() >= super::AHEAD {
            pass(machine, shared);
            continue;
        }
        let inputs = Inputs::from_word(shared.inputs.load(Ordering::Relaxed));
        let step_fault = shared.step_fault.swap(false, Ordering::Relaxed);
        let start = machine.cycles();
        let (out, message) = shared.with(|c| {
            if step_fault {
                c.step_generator_fault();
            }
            c.set_inputs(inputs);
            let out = c.tick();
            (out, c.unsolicited())
        });
        let cost = machine.cycles().wrapping_sub(start);
        // Outputs first: a fault's disable reaches the drivers before anything else happens; the order of the
        // writes keeps the interlocks between them (`safety::pins`).
        for (pin, on) in writes(&out.outputs) {
            machine.write(pin, on);
        }
        // Waits while the step generator's queue is full: the queue paces the loop as much as the timer does.
        shared.steps.send(out.moves).await;
        let depth = shared.steps.len() as u16;
        shared.with(|c| {
            c.set_platform_stats(cost, depth);
            c.set_step_counters(
                shared.step_underruns.load(Ordering::Relaxed),
                shared.passes.load(Ordering::Relaxed),
            );
        });
        if let Some(m) = message {
            shared.post(m);
        }
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

/// A period the step generator does not need (see [`super::AHEAD`]): after a hold-up longer than a period (a flash
/// erase, a burst of link traffic) the ticker catches up the periods it missed at once, while the step generator
/// played them empty. Ticking them would queue their moves behind each other, and every later period's behind
/// those, for the rest of the session (measured on the QEMU controller: 4 periods queued, 6-7 ms from a setpoint
/// to its first step). The controller's clocks still advance (`Controller::pass`), so the supply
/// sequence and a power-down end when they are due; the outputs a timer changed are written as in a tick.
fn pass(machine: &mut impl Machine, shared: &Shared) {
    let (outputs, message) = shared.with(|c| (c.pass(), c.unsolicited()));
    for (pin, on) in writes(&outputs) {
        machine.write(pin, on);
    }
    if let Some(m) = message {
        shared.post(m);
    }
    shared.passes.fetch_add(1, Ordering::Relaxed);
    machine.feed_watchdog();
}
