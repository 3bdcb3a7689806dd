//! What both QEMU programs share: reporting a failure over semihosting and ending the run (and so QEMU).

#![no_std]

use core::hint::black_box;

use cortex_m_semihosting::{debug, hprintln};

/// Reports `ERROR what` and ends the run with a failure.
pub fn fail(what: &str) -> ! {
    hprintln!("ERROR {}", what);
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

/// Semihosting's exit ends QEMU; should it not, wait for interrupts forever.
pub fn halt() -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("ERROR panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

/// Where a profiled stretch begins: `tests/qemu/profile` counts the instructions between a call of this and one of
/// [`marker_end`] (it finds them by name in QEMU's trace, so neither is ever inlined).
#[inline(never)]
pub fn marker_start() {
    black_box(1);
}

/// Where a profiled stretch ends (see [`marker_start`]).
#[inline(never)]
pub fn marker_end() {
    black_box(2);
}
