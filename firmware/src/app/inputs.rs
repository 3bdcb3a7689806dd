//! Switch inputs: an edge wakes the task (EXTI on a board), then the pins are sampled every millisecond until the
//! debouncer has settled; a sweep every 10 ms catches an edge that came between two waits.

use core::sync::atomic::Ordering;

use embassy_futures::select::select;
use embassy_time::{Duration, Timer};
use ringpod_core::safety::debounce::Debouncer;

use super::Shared;

/// The board's input pins.
pub trait InputPins {
    /// Electrical levels of all inputs now, in the `safety::debounce::InputBit` layout (1 = high).
    fn read(&mut self) -> u16;
    /// Waits for an edge on any input.
    async fn edge(&mut self);
}

/// Debounces the inputs into `shared.inputs`, forever, and gives the controller every raw sample (for `device
/// inputs`). Polarity and debounce length follow the controller's
/// (live) settings.
pub async fn run(pins: &mut impl InputPins, shared: &Shared) -> ! {
    let mut config = shared.with(|c| c.config().inputs);
    let first = pins.read();
    let mut debouncer = Debouncer::new(config, first);
    shared.inputs.store(debouncer.stable(), Ordering::Relaxed);
    shared.with(|c| c.set_raw_inputs(first));
    loop {
        select(pins.edge(), Timer::after(Duration::from_millis(10))).await;
        loop {
            let now = shared.with(|c| c.config().inputs);
            if now != config {
                config = now;
                debouncer = Debouncer::new(config, pins.read());
            }
            let raw = pins.read();
            shared.with(|c| c.set_raw_inputs(raw));
            shared.inputs.store(debouncer.sample(raw), Ordering::Relaxed);
            if !debouncer.settling() {
                break;
            }
            Timer::after(Duration::from_millis(1)).await;
        }
    }
}
