//! Time: an `embassy-time` driver on SysTick (25 MHz core clock, an interrupt every 100 us).

use core::cell::{Cell, RefCell};
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use critical_section::Mutex as CsMutex;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

/// SysTick period: 100 us of the 25 MHz core clock.
const TICK_US: u64 = 100;
const SYSTICK_RELOAD: u32 = 25 * TICK_US as u32 - 1;
/// One count of the 25 MHz clock.
const NS_PER_COUNT: u64 = 40;

/// Time in SysTick periods, and the timer queue, both touched from the SysTick exception and thread mode.
struct SysTickDriver {
    ticks: CsMutex<Cell<u64>>,
    queue: CsMutex<RefCell<Queue>>,
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.ticks.borrow(cs).get() * TICK_US)
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            // The SysTick exception looks at the queue every 100 us: no alarm to program.
            self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker);
        });
    }
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    ticks: CsMutex::new(Cell::new(0)),
    queue: CsMutex::new(RefCell::new(Queue::new())),
});

#[exception]
fn SysTick() {
    critical_section::with(|cs| {
        let ticks = DRIVER.ticks.borrow(cs);
        ticks.set(ticks.get() + 1);
        DRIVER
            .queue
            .borrow(cs)
            .borrow_mut()
            .next_expiration(ticks.get() * TICK_US);
    });
}

/// Starts SysTick.
pub fn start(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(SYSTICK_RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Microseconds since start.
pub fn now_us() -> u64 {
    DRIVER.now()
}

/// Nanoseconds since start, to one SysTick count (40 ns of the 25 MHz clock) rather than one 100 us period: the
/// periods counted plus the count within the current one. A wrap the exception has not counted yet (it is pending
/// while this runs with interrupts off) is counted here.
pub fn now_ns() -> u64 {
    critical_section::with(|cs| {
        let before = SCB::is_pendst_pending();
        let mut current = SYST::get_current();
        let wrapped = SCB::is_pendst_pending();
        if wrapped != before {
            // It wrapped between the two looks: the count read may be from before the wrap.
            current = SYST::get_current();
        }
        let periods = DRIVER.ticks.borrow(cs).get() + u64::from(wrapped);
        periods * TICK_US * 1_000 + u64::from(SYSTICK_RELOAD - current.min(SYSTICK_RELOAD)) * NS_PER_COUNT
    })
}
