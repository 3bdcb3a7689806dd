//! The step generator's feeder: one period's moves from the queue, rendered into port words
//! (`ringpod_core::motion::pulse`), handed to the board's timer-driven output. Runs at interrupt priority so that
//! neither USB nor the control tick can delay it.

use core::sync::atomic::Ordering;

use embassy_time::Instant;
use ringpod_core::motion::pulse::PulseRenderer;
use ringpod_core::motion::pulse::MAX_STEP_SLOTS;
use ringpod_core::motion::{AxisMove, Direction};

use super::Shared;

/// The overrun: the hardware played words that had not been written yet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct Overrun;

/// Where rendered words go: a DMA ring into the port's set/reset register on a board.
pub trait PortOutput {
    /// Queues one period of words; waits until the hardware has room.
    async fn write(&mut self, words: &[u32]) -> Result<(), Overrun>;

    /// When the hardware last made room for a period (a period boundary), if the port knows it better than the
    /// moment `write` returned; a port whose `write` wakes at interrupt priority and does nothing after the wait
    /// leaves it to that moment.
    fn boundary(&self) -> Option<Instant> {
        None
    }
}

/// Feeds the port forever. An empty queue becomes a period without steps (counted, never a lost step: the
/// controller's positions only advance with moves, and the moves are played later).
pub async fn run(port: &mut impl PortOutput, mut renderer: PulseRenderer, shared: &Shared) -> ! {
    let slots = renderer.timing().slots;
    let period_ns = renderer.timing().slot_ns * slots as u32;
    let idle = [AxisMove {
        direction: Direction::Forward,
        dir_change_ns: None,
        start_ns: 0,
        count: 0,
        period_ns,
    }; 6];
    let mut words = [0u32; MAX_STEP_SLOTS];
    loop {
        // The previous write returned when the hardware had room: a period boundary.
        let boundary = port.boundary().unwrap_or_else(Instant::now);
        shared
            .boundary_us
            .store(super::control::micros(boundary), Ordering::Relaxed);
        let moves = match shared.steps.try_receive() {
            Ok(m) => m,
            Err(_) => {
                shared.step_underruns.fetch_add(1, Ordering::Relaxed);
                idle
            }
        };
        if renderer.render(&moves, &mut words).is_none() || port.write(&words[..slots]).await.is_err() {
            shared.step_fault.store(true, Ordering::Relaxed);
        }
    }
}
