//! The CMSDK APB watchdog of mps2-an386 (QEMU models it at 0x4000_8000, clocked at 25 MHz, its interrupt on NMI):
//! the counter runs down from its load value; the first time it reaches zero it raises the interrupt and reloads,
//! the second time, with the interrupt still pending, it resets the machine. Feeding clears the interrupt and
//! reloads. The NMI leaves "watchdog" as the reset cause for the next boot, as the STM32's reset flags do.

use cortex_m_rt::exception;

use crate::retained;

const BASE: usize = 0x4000_8000;
const LOAD: *mut u32 = BASE as *mut u32;
const CONTROL: *mut u32 = (BASE + 0x08) as *mut u32;
const INTCLR: *mut u32 = (BASE + 0x0c) as *mut u32;
const LOCK: *mut u32 = (BASE + 0xc00) as *mut u32;
const UNLOCK_KEY: u32 = 0x1acc_e551;
/// CONTROL: counter and interrupt enabled, reset enabled.
const INTEN_RESEN: u32 = 0b11;
const CLOCK_HZ: u32 = 25_000_000;

fn unlocked(f: impl FnOnce()) {
    // SAFETY: the watchdog's registers on this machine; only this module touches them, from thread mode.
    unsafe {
        LOCK.write_volatile(UNLOCK_KEY);
        f();
        LOCK.write_volatile(0);
    }
}

/// Starts the watchdog: a reset `timeout_us` after the last feed (half of it to the interrupt, half to the reset).
pub fn start(timeout_us: u32) {
    let half = (u64::from(CLOCK_HZ) * u64::from(timeout_us) / 2_000_000) as u32;
    // SAFETY (inside): as in `unlocked`.
    unlocked(|| unsafe {
        LOAD.write_volatile(half);
        CONTROL.write_volatile(INTEN_RESEN);
    });
}

/// Reloads the counter.
pub fn feed() {
    // SAFETY (inside): as in `unlocked`.
    unlocked(|| unsafe { INTCLR.write_volatile(1) });
}

#[exception]
unsafe fn NonMaskableInt() {
    // The control loop has not fed the watchdog for half its timeout: the reset follows. On the STM32 the reset
    // itself floats the pins (the pull resistors hold relays and drivers off); here the program's state is gone
    // with it. Only the cause is left for the next boot.
    retained::mark_watchdog_reset();
}
