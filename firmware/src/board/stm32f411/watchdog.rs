//! The independent watchdog, on its registers: embassy's driver cannot change the timeout once running, and a
//! settings write must widen it over a sector erase.

use embassy_stm32::pac;
use embassy_stm32::pac::iwdg::vals::{Key, Pr};

/// Normal watchdog timeout: 50 control periods.
pub const NORMAL_US: u32 = 50_000;
/// While a settings write may erase a 128 KiB sector (up to 2 s at 3.3 V with x32 parallelism): supplies are off.
pub const FLASH_WRITE_US: u32 = 4_000_000;

/// LSI (32 kHz nominal) / 256 = 125 Hz: 8 ms per count, up to 32.7 s.
fn set(timeout_us: u32) {
    let iwdg = pac::IWDG;
    wait_updated();
    iwdg.kr().write(|w| w.set_key(Key::ENABLE));
    iwdg.pr().write(|w| w.set_pr(Pr::DIVIDE_BY256));
    let counts = (timeout_us / 8_000).clamp(1, 0x0fff);
    iwdg.rlr().write(|w| w.set_rl(counts as u16));
    // The counter lives in the VDD domain: PR and RLR reach it up to 5 LSI periods (at most 0.3 ms) after the
    // write, while IWDG_SR's PVU/RVU read 1 (RM0383 15.4.4). A reload before then loads the old value, so a
    // widening for a sector erase would leave 48 ms, and the erase stalls the CPU for up to 2 s.
    wait_updated();
    pet();
}

fn wait_updated() {
    let iwdg = pac::IWDG;
    while iwdg.sr().read().pvu() || iwdg.sr().read().rvu() {}
}

/// Starts the watchdog with `timeout_us` (it cannot be stopped again).
pub fn start(timeout_us: u32) {
    pac::IWDG.kr().write(|w| w.set_key(Key::START));
    set(timeout_us);
}

/// Changes the timeout.
pub fn set_timeout(timeout_us: u32) {
    set(timeout_us);
}

/// Reloads the counter.
pub fn pet() {
    pac::IWDG.kr().write(|w| w.set_key(Key::RESET));
}

/// Whether the last reset came from the watchdog; clears the reset flags.
pub fn caused_last_reset() -> bool {
    let rcc = pac::RCC;
    let was = rcc.csr().read().wdgrstf();
    rcc.csr().modify(|w| w.set_rmvf(true));
    was
}
