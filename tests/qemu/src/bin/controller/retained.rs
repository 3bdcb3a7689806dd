//! What survives a reset: RAM that the startup code neither loads nor zeroes (`.uninit`), holding the reset cause
//! (the STM32 keeps it in RCC_CSR; QEMU's mps2 has no such register) and the settings "flash". QEMU keeps RAM across
//! a system reset and reloads only the program's loaded sections, so this is what a board's flash and reset flags
//! are to the firmware; at power-up it holds whatever QEMU's RAM held (zeros), recognised by the missing marker.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use ringpod_core::sim::RamFlash;

/// Size of the emulated settings flash: four 2 KiB erase pages.
pub const FLASH_SIZE: usize = 8 * 1024;
const PAGE: usize = 2 * 1024;
/// Marks the retained RAM as initialised by an earlier run of this program.
const MARKER: u32 = 0x7269_6e67; // "ring"
/// The reset cause the watchdog's early-warning interrupt leaves for the next boot.
const CAUSE_WATCHDOG: u32 = 0x5744_4f47; // "WDOG"

#[repr(C)]
struct Retained {
    marker: u32,
    cause: u32,
    flash: [u8; FLASH_SIZE],
}

#[link_section = ".uninit.ringpod"]
static mut RETAINED: MaybeUninit<Retained> = MaybeUninit::uninit();

/// Every access goes through this pointer: from thread mode at boot, from the settings task (thread mode) and from
/// the NMI handler (which writes `cause` only, one word).
fn retained() -> *mut Retained {
    addr_of_mut!(RETAINED).cast()
}

/// At boot: whether the watchdog caused this reset (cleared for the next one). At power-up, initialises the
/// retained RAM: erased flash, no cause.
pub fn take_watchdog_reset() -> bool {
    let r = retained();
    // SAFETY: see `retained`; at boot nothing else runs yet. Any bit pattern is a valid u32 and u8 array.
    unsafe {
        if addr_of_mut!((*r).marker).read_volatile() != MARKER {
            addr_of_mut!((*r).flash).write_bytes(0xff, 1);
            addr_of_mut!((*r).cause).write_volatile(0);
            addr_of_mut!((*r).marker).write_volatile(MARKER);
        }
        let cause = addr_of_mut!((*r).cause).read_volatile();
        addr_of_mut!((*r).cause).write_volatile(0);
        cause == CAUSE_WATCHDOG
    }
}

/// Leaves the watchdog as the cause of the coming reset.
pub fn mark_watchdog_reset() {
    // SAFETY: see `retained`; a single word write.
    unsafe { addr_of_mut!((*retained()).cause).write_volatile(CAUSE_WATCHDOG) };
}

/// The settings flash: the core's NOR model over the retained RAM.
pub type RetainedFlash = RamFlash<'static, PAGE>;

/// The one settings flash; [`take_watchdog_reset`] must have run, and this is called once (the settings task owns
/// it; the NMI handler never touches `flash`).
pub fn flash() -> RetainedFlash {
    // SAFETY: called once, so this is the only reference to `flash`.
    RamFlash::new(unsafe { &mut *addr_of_mut!((*retained()).flash) })
}
