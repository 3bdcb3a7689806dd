//! The control tick: inputs to the controller, one `tick()` per period, relays and driver enable from the
//! supervisor's outputs, the period's step moves to the step generator, and the watchdog fed only when all of
//! that happened.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Ticker};
use ringpod_core::controller::Inputs;
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

/// Runs the control loop at the controller's rate, forever.
pub async fn run(machine: &mut impl Machine, shared: &Shared) -> ! {
    let tick_us = shared.with(|c| c.pipeline().config().tick_us);
    let mut ticker = Ticker::every(Duration::from_micros(u64::from(tick_us)));
    let mut worst = 0u32;
    let mut n = 0u32;
    loop {
        ticker.next().await;
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
        // Waits while the step generator's queue is full: the queue paces the loop as much as the ticker does.
        shared.steps.send(out.moves).await;
        let depth = shared.steps.len() as u16;
        shared.with(|c| c.set_platform_stats(cost, depth));
        if let Some(m) = message {
            shared.post(m);
        }
        worst = worst.max(cost);
        n = n.wrapping_add(1);
        if n.is_multiple_of(5_000) {
            defmt::info!("tick: {} cycles (worst {}), step queue {}", cost, worst, depth);
        }
        machine.feed_watchdog();
    }
}
