//! The controller's tasks, the same code on every board: the host link, the control tick, input debouncing, the
//! step queue and settings storage. Each is an `async fn` over a small trait that a board module implements
//! (`board/*.rs`: pins, timers, USB or UART); the board module's `#[embassy_executor::task]`s call them, because
//! embassy tasks cannot be generic.
//!
//! Every decision is `ringpod_core::controller::Controller`'s; these functions only move bytes, levels and step
//! buffers between it and the hardware.

pub mod control;
pub mod inputs;
pub mod link;
pub mod settings;
pub mod steps;

use core::cell::RefCell;
use core::sync::atomic::{AtomicU16, AtomicU32, AtomicU8, Ordering};

use embassy_sync::blocking_mutex::raw::{CriticalSectionRawMutex, ThreadModeRawMutex};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::channel::Channel;
use ringpod_core::controller::Controller;
use ringpod_core::motion::{AxisMove, SPARE_AXES};
use ringpod_core::protocol::Response;
use ringpod_core::safety::debounce::Debouncer;

/// Host links a board may serve at once (the F411: USB CDC-ACM and USART1), numbered from 0.
pub const LINKS: usize = 2;

/// Periods of step moves the control tick may run ahead of the step generator.
pub const STEP_QUEUE: usize = 4;

/// Periods queued at a control tick from which the period is passed (`Controller::pass`, in `control::run`), so
/// that the step generator drains the queue back. A tick held before the generator's boundary (`motion::phase`) finds the queue
/// empty: the previous tick's moves were taken at the boundary between them. Only a catch-up after a hold-up, or
/// the one period a phase correction gives two ticks, finds a period queued.
pub const AHEAD: usize = 1;

/// One control period's step moves, from the control tick to the step generator.
#[derive(Debug, Clone, Copy)]
pub struct StepPeriod {
    /// The platform's six axes.
    pub moves: [AxisMove; 6],
    /// The spare axes 7 and 8 (`None` when neither is fitted).
    pub spare: Option<[AxisMove; SPARE_AXES]>,
}

/// What the tasks share. The controller is only touched from thread mode (link, control, inputs, settings),
/// briefly and never across an `.await`; the step queue crosses to the step generator's interrupt priority.
pub struct Shared {
    /// The control core.
    pub controller: Mutex<ThreadModeRawMutex, RefCell<Controller>>,
    /// Unsolicited messages (faults, telemetry) for each link to send; [`Shared::post`] picks the link.
    pub outboxes: [Channel<ThreadModeRawMutex, Response, 4>; LINKS],
    /// The link whose hello the controller accepted last: its connection is the controller's, so the unsolicited
    /// messages go there. Every link's requests are answered on that link.
    pub host_link: AtomicU8,
    /// One period's step moves per entry, from the control tick to the step generator.
    pub steps: Channel<CriticalSectionRawMutex, StepPeriod, STEP_QUEUE>,
    /// Debounced logical input levels (`safety::debounce` layout), written by the inputs task.
    pub inputs: AtomicU16,
    /// Periods the step generator had to fill with no steps because the queue was empty.
    pub step_underruns: AtomicU32,
    /// Control periods passed because the queue was [`AHEAD`] periods ahead of the step generator.
    pub passes: AtomicU32,
    /// When the step generator last took a period from the queue (device microseconds, wrapping): its period
    /// boundary, which the control tick keeps its phase to.
    pub boundary_us: AtomicU32,
    /// Control ticks moved to their phase (`motion::phase`): once at start, and after a hold-up.
    pub rephased: AtomicU32,
    /// Device time a stall of the CPU cost the time driver (a flash erase: `settings::run` measures it), in
    /// microseconds, for the control loop to catch up.
    pub clock_lost_us: AtomicU32,
    /// The step generator found its buffer overrun (the DMA lapped it): a fault for the control tick to latch.
    pub step_fault: core::sync::atomic::AtomicBool,
}

impl Shared {
    /// Shares `controller`, with the electrical levels of the inputs as the board read them at reset (the
    /// debouncer applies the polarity, here as in the inputs task).
    pub fn new(controller: Controller, levels: u16) -> Self {
        let inputs = Debouncer::new(controller.config().inputs, levels).stable();
        Self {
            controller: Mutex::new(RefCell::new(controller)),
            outboxes: [Channel::new(), Channel::new()],
            host_link: AtomicU8::new(0),
            steps: Channel::new(),
            inputs: AtomicU16::new(inputs),
            step_underruns: AtomicU32::new(0),
            passes: AtomicU32::new(0),
            boundary_us: AtomicU32::new(0),
            rephased: AtomicU32::new(0),
            clock_lost_us: AtomicU32::new(0),
            step_fault: core::sync::atomic::AtomicBool::new(false),
        }
    }

    /// Queues an unsolicited message for the link that said hello last; dropped when its queue is full (a fault
    /// stays latched in the state, and the host sees it in the status).
    pub fn post(&self, message: Response) {
        let link = usize::from(self.host_link.load(Ordering::Relaxed)).min(LINKS - 1);
        let _ = self.outboxes[link].try_send(message);
    }

    /// Runs `f` on the controller.
    pub fn with<R>(&self, f: impl FnOnce(&mut Controller) -> R) -> R {
        self.controller.lock(|c| f(&mut c.borrow_mut()))
    }
}
