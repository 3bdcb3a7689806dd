//! What both QEMU programs share: reporting a failure over semihosting and ending the run (and so QEMU).

#![no_std]

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
