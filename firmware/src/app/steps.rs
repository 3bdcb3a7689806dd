//! The step generator's feeder: one period's moves from the queue, rendered into port words
//! (`ringpod_core::motion::pulse`), handed to the board's timer-driven output. Runs at interrupt priority so that
//! neither USB nor the control tick can delay it.

use core::sync::atomic::Ordering;

use embassy_time::Instant;
use ringpod_core::motion::pulse::PulseRenderer;
use ringpod_core::motion::pulse::MAX_STEP_SLOTS;
use ringpod_core::motion::{AxisMove, Direction, SPARE_AXES};

use super::Shared;

/// The overrun: the hardware played words that had not been written yet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct Overrun;

/// Where rendered words go: a DMA ring into the port's set/reset register on a board, two periods long, so that
/// the period written at a boundary plays right after the one that has just started.
pub trait PortOutput {
    /// Waits until the hardware has room for a period of `words` words, and returns when it made it: a period
    /// boundary, which the control tick keeps its phase to.
    async fn room(&mut self, words: usize) -> Result<Instant, Overrun>;
    /// Writes one period into the room [`PortOutput::room`] found; does not wait.
    fn write(&mut self, words: &[u32]) -> Result<(), Overrun>;
    /// Writes the spare axes' words of the same period (rendered on the board's spare pin map), to play in the
    /// same slots as [`PortOutput::write`]'s. Only called when [`run`] was given a spare renderer.
    fn write_spare(&mut self, words: &[u32]) -> Result<(), Overrun>;
}

/// Feeds the port forever. An empty queue becomes a period without steps (counted, never a lost step: the
/// controller's positions only advance with moves, and the moves are played later). With `spare` (a renderer on the
/// board's spare pin map: the spare axes as its axes 0 and 1) the spare axes' words are written every period too,
/// idle when the period has none: their ring would otherwise play its old words again.
pub async fn run(
    port: &mut impl PortOutput,
    mut renderer: PulseRenderer,
    mut spare: Option<PulseRenderer>,
    shared: &Shared,
) -> ! {
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
        // The queue is read at the boundary, not before: the moves the control tick queued just before it play in
        // the next period, one period after the tick rather than two.
        let boundary = match port.room(slots).await {
            Ok(at) => at,
            Err(Overrun) => {
                shared.step_fault.store(true, Ordering::Relaxed);
                Instant::now()
            }
        };
        shared
            .boundary_us
            .store(super::control::micros(boundary), Ordering::Relaxed);
        let period = match shared.steps.try_receive() {
            Ok(p) => p,
            Err(_) => {
                shared.step_underruns.fetch_add(1, Ordering::Relaxed);
                super::StepPeriod {
                    moves: idle,
                    spare: None,
                }
            }
        };
        let mut fault = renderer.render(&period.moves, &mut words).is_none() || port.write(&words[..slots]).is_err();
        if let Some(spare) = spare.as_mut() {
            let mut moves = idle;
            if let Some(m) = period.spare {
                moves[..SPARE_AXES].copy_from_slice(&m);
            }
            fault |= spare.render(&moves, &mut words).is_none() || port.write_spare(&words[..slots]).is_err();
        }
        if fault {
            shared.step_fault.store(true, Ordering::Relaxed);
        }
    }
}
