//! The emulated machine behind the board's pins: the simulated plant of `ringpod_core::sim` (axes, switches at
//! their positions, supply sense following the relays) driven the way a board drives the real one:
//!
//! - the relays and the driver enable are set pin by pin by the control task;
//! - the switch and supply-sense pins are electrical levels, wired as `InputConfig::default()` expects, read and
//!   debounced by the inputs task; a change of the plant wakes it as an EXTI edge would;
//! - the steps task's rendered port words are played, one buffer per control period, into the drivers' model
//!   (`sim::drivers`), and the axes move by the STEP edges it counts; a word that breaks the drivers' timing, or a
//!   step while the drivers are disabled, is reported over semihosting (the QEMU runner fails on it).

use core::cell::RefCell;

use cortex_m_semihosting::hprintln;
use embassy_sync::blocking_mutex::raw::{CriticalSectionRawMutex, ThreadModeRawMutex};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Instant, Timer};
use ringpod_core::motion::pulse::{MAX_STEP_SLOTS, STEP_SLOT_NS};
use ringpod_core::safety::debounce::InputConfig;
use ringpod_core::safety::pins::OutputPin;
use ringpod_core::safety::{Outputs, State};
use ringpod_core::sim::drivers::DriverInputs;
use ringpod_core::sim::Plant;
use ringpod_firmware::app::control::Machine;
use ringpod_firmware::app::inputs::InputPins;
use ringpod_firmware::app::steps::{Overrun, PortOutput};
use ringpod_firmware::app::Shared;

use crate::{time, watchdog};

/// The plant and everything wired to it.
pub struct World {
    plant: Plant,
    outputs: Outputs,
    drivers: DriverInputs,
    /// Each problem is reported once: the first occurrence is the one to look at.
    timing_reported: bool,
    disabled_reported: bool,
    /// The test's wiring (`estop-on-aux2` on the command line): AUX2's relay contact is in the e-stop chain, so
    /// switching AUX2 on opens it, as pressing the button would. The runner checks that the fault drops both
    /// outputs (the chain closes again as AUX2 goes off).
    pub estop_on_aux2: bool,
}

/// The world as the tasks share it (all of them run in thread mode here).
pub type WorldCell = Mutex<ThreadModeRawMutex, RefCell<World>>;

/// The plant changed (a relay, a step): the inputs task's "EXTI edge".
static CHANGED: Signal<CriticalSectionRawMutex, ()> = Signal::new();

impl World {
    /// `plant` with its relays open and its drivers' inputs at the port's idle levels.
    pub fn new(plant: Plant, drivers: DriverInputs) -> Self {
        Self {
            plant,
            outputs: Outputs::OFF,
            drivers,
            timing_reported: false,
            disabled_reported: false,
            estop_on_aux2: false,
        }
    }

    /// Electrical levels of the input pins, in the `safety::debounce::InputBit` layout.
    fn levels(&self) -> u16 {
        let mut inputs = self.plant.inputs(self.outputs.logic_relay, self.outputs.power_relay);
        inputs.estop_open |= self.estop_on_aux2 && self.outputs.aux & 2 != 0;
        inputs.word() ^ InputConfig::default().active_low
    }
}

/// The control loop's side: relays, driver enable, the step queue, the watchdog.
pub struct Controls {
    pub world: &'static WorldCell,
    /// What the tasks share: the stall test looks at the supervisor's state.
    pub shared: &'static Shared,
    /// The stall test (`stall-when-homed` on the command line): the control loop hangs in the first tick that
    /// finds the platform homed and at rest, and the watchdog has to bring the board back.
    pub stall_when_homed: bool,
}

impl Machine for Controls {
    fn write(&mut self, pin: OutputPin, on: bool) {
        self.world.lock(|w| {
            let mut w = w.borrow_mut();
            match pin {
                OutputPin::DriverEnable => w.outputs.driver_enable = on,
                OutputPin::LogicRelay => w.outputs.logic_relay = on,
                OutputPin::PowerRelay => w.outputs.power_relay = on,
                OutputPin::Aux1 | OutputPin::Aux2 => {
                    let bit = if pin == OutputPin::Aux1 { 1 } else { 2 };
                    let was = w.outputs.aux;
                    w.outputs.aux = if on { was | bit } else { was & !bit };
                    if w.outputs.aux != was {
                        // The runner follows the pins themselves, not only what the controller reports.
                        hprintln!("AUX {}", w.outputs.aux);
                    }
                }
            }
        });
        CHANGED.signal(());
    }

    fn cycles(&self) -> u32 {
        crate::latency::cycles_read();
        // No DWT cycle counter in QEMU: microseconds of SysTick time, in 25 MHz cycles.
        (time::now_us() * 25) as u32
    }

    fn feed_watchdog(&mut self) {
        if self.stall_when_homed && self.shared.with(|c| c.supervisor().state() == State::Ready) {
            hprintln!("STALL");
            // A control loop caught in an endless computation before the end of its tick: interrupts still run,
            // the loop never comes back to feed the watchdog.
            loop {
                cortex_m::asm::nop();
            }
        }
        crate::latency::tick_ended();
        watchdog::feed();
    }
}

/// The input pins, wired to the plant.
pub struct Pins {
    pub world: &'static WorldCell,
    /// What the inputs task last read: an "edge" is a difference from it.
    pub last: u16,
}

impl InputPins for Pins {
    fn read(&mut self) -> u16 {
        self.last = self.world.lock(|w| w.borrow().levels());
        self.last
    }

    async fn edge(&mut self) {
        loop {
            CHANGED.wait().await;
            if self.world.lock(|w| w.borrow().levels()) != self.last {
                return;
            }
        }
    }
}

/// The step port, as a board's two-period DMA ring: the period written at a boundary plays from the next one,
/// after the period that has just started (the plant takes each period's words when it starts).
pub struct Port {
    pub world: &'static WorldCell,
    /// The step queue, whose depth the latency measurement reports.
    pub shared: &'static Shared,
    pub period: Duration,
    /// When the period playing now ends: the next boundary.
    pub busy_until: Instant,
    /// The period written at the last boundary, waiting for the next.
    pub pending: [u32; MAX_STEP_SLOTS],
    pub pending_len: usize,
}

impl PortOutput for Port {
    async fn room(&mut self, _words: usize) -> Result<Instant, Overrun> {
        // The boundary: the period written at the last one starts. Should the emulator have been held up for
        // longer than the queue covers, start afresh rather than play a burst (a board would have underrun).
        Timer::at(self.busy_until).await;
        let now = Instant::now();
        let start = if now > self.busy_until + self.period * 4 {
            crate::latency::PORT_RESTARTS.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
            now
        } else {
            self.busy_until
        };
        self.busy_until = start + self.period;
        let len = core::mem::take(&mut self.pending_len);
        if len > 0 {
            self.play(start, len);
        }
        Ok(start)
    }

    fn write(&mut self, words: &[u32]) -> Result<(), Overrun> {
        let to = self.pending.get_mut(..words.len()).ok_or(Overrun)?;
        to.copy_from_slice(words);
        self.pending_len = words.len();
        Ok(())
    }

    /// Never called: this program's step generator is given no spare renderer (its plant has no spare axes), so
    /// a call would be a fault, not steps dropped unseen.
    fn write_spare(&mut self, _words: &[u32]) -> Result<(), Overrun> {
        Err(Overrun)
    }
}

impl Port {
    /// The plant takes a period's words as it starts to play.
    fn play(&mut self, start: Instant, len: usize) {
        let words = &self.pending[..len];
        let depth = self.shared.steps.len();
        crate::latency::played(start.as_micros(), words, STEP_SLOT_NS, depth);
        self.world.lock(|w| {
            let w = &mut *w.borrow_mut();
            let enabled = w.outputs.driver_enable;
            let before = w.plant.steps_while_disabled;
            if let Some(v) = w.plant.play(&mut w.drivers, words, enabled) {
                if !w.timing_reported {
                    w.timing_reported = true;
                    hprintln!("TIMING {}", v);
                }
            }
            if w.plant.steps_while_disabled > before && !w.disabled_reported {
                w.disabled_reported = true;
                hprintln!(
                    "DISABLED {} steps with the drivers disabled",
                    w.plant.steps_while_disabled - before
                );
            }
        });
        CHANGED.signal(());
    }
}
