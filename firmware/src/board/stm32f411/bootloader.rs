//! The STM32F411's ROM bootloader entered from the application, to be flashed over the USB cable (AN2606: the
//! F411's bootloader is in system memory at 0x1FFF_0000 and serves USB DFU on PA11/PA12).
//!
//! The usual way on Cortex-M: a marker in RAM that a reset keeps (`.uninit`, which cortex-m-rt neither zeroes nor
//! initialises; SRAM holds its contents through a system reset), a SYSRESETREQ reset, and at the very start of the
//! next boot, before clocks or any peripheral are set up, the system memory's stack pointer and reset vector taken.
//! The reset is what makes the jump safe: every peripheral is at its reset state (the bootloader expects that: it
//! runs on HSI and sets up its own clocks), the independent watchdog is stopped (a software watchdog runs only
//! once written, RM0383 15.3), and USB detaches: the OTG core's reset drops the D+ pull-up, so the host sees the
//! controller leave before the bootloader enumerates as 0483:df11.
//!
//! Two words, the second the first's complement, so that the random contents of RAM at power-on are not taken for
//! a request (one chance in 2^64).

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use embassy_stm32::pac;

/// System memory: the bootloader's vector table (AN2606, STM32F411xx: 0x1FFF_0000).
const SYSTEM_MEMORY: u32 = 0x1FFF_0000;
/// The marker's first word ("DFU!"); the second is its complement.
const ASKED: u32 = 0x2155_4644;

#[link_section = ".uninit.ringpod_bootloader"]
static mut MARKER: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();

/// Marks the next start for the bootloader and resets the MCU.
pub fn restart_into() -> ! {
    // SAFETY: a plain volatile write of the marker; nothing else touches it until the reset.
    unsafe { addr_of_mut!(MARKER).cast::<[u32; 2]>().write_volatile([ASKED, !ASKED]) };
    cortex_m::peripheral::SCB::sys_reset()
}

/// At the very start of `main`, before the clocks and any peripheral are set up: a start [`restart_into`] marked
/// runs the ROM bootloader instead of the firmware (the marker is cleared first, so that the bootloader's own
/// reset, when it leaves, starts the firmware).
pub fn enter_if_marked() {
    let marker = addr_of_mut!(MARKER).cast::<[u32; 2]>();
    // SAFETY: `.uninit` is ordinary RAM: any bit pattern is a valid `[u32; 2]`.
    if unsafe { marker.read_volatile() } != [ASKED, !ASKED] {
        return;
    }
    // SAFETY: as above.
    unsafe { marker.write_volatile([0, 0]) };
    // RM0383 6.3.12 (RCC_APB2ENR.SYSCFGEN) and 7.2.1 (SYSCFG_MEMRMP.MEM_MODE = 01): system memory aliased at 0, where
    // VTOR (0 after reset) finds the bootloader's vector table for its own interrupts.
    pac::RCC.apb2enr().modify(|w| w.set_syscfgen(true));
    pac::SYSCFG.memrm().modify(|w| w.set_mem_mode(1));
    // SAFETY: system memory holds the ROM bootloader's vector table: its stack pointer, then its reset vector.
    unsafe { cortex_m::asm::bootload(SYSTEM_MEMORY as *const u32) }
}
