//! What survives a reset: RAM that the startup code neither loads nor zeroes (`.uninit`), holding the reset cause
//! (the STM32 keeps it in RCC_CSR; QEMU's mps2 has no such register) and the settings "flash". QEMU keeps RAM across
//! a system reset and reloads only the program's loaded sections, so this is what a board's flash and reset flags
//! are to the firmware; at power-up it holds whatever QEMU's RAM held (zeros), recognised by the missing marker.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use embedded_storage_async::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};

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

/// The settings flash in retained RAM, with NOR semantics: erase sets a page to 0xFF, a write can only clear bits
/// (so that the store's sequential-storage log meets what it meets on a board's flash).
pub struct RetainedFlash(());

impl RetainedFlash {
    /// The one flash; [`take_watchdog_reset`] must have run.
    pub fn take() -> Self {
        Self(())
    }

    fn bytes(&mut self) -> &mut [u8; FLASH_SIZE] {
        // SAFETY: one `RetainedFlash` exists (the settings task owns it), and the NMI handler never touches `flash`.
        unsafe { &mut *addr_of_mut!((*retained()).flash) }
    }
}

fn range(offset: u32, len: usize) -> Result<core::ops::Range<usize>, NorFlashErrorKind> {
    let start = offset as usize;
    let end = start.checked_add(len).ok_or(NorFlashErrorKind::OutOfBounds)?;
    if end > FLASH_SIZE {
        return Err(NorFlashErrorKind::OutOfBounds);
    }
    Ok(start..end)
}

impl ErrorType for RetainedFlash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for RetainedFlash {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let r = range(offset, bytes.len())?;
        bytes.copy_from_slice(&self.bytes()[r]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        FLASH_SIZE
    }
}

impl NorFlash for RetainedFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        if !(from as usize).is_multiple_of(PAGE) || !(to as usize).is_multiple_of(PAGE) || to < from {
            return Err(NorFlashErrorKind::NotAligned);
        }
        let r = range(from, (to - from) as usize)?;
        self.bytes()[r].fill(0xff);
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if !(offset as usize).is_multiple_of(Self::WRITE_SIZE) || !bytes.len().is_multiple_of(Self::WRITE_SIZE) {
            return Err(NorFlashErrorKind::NotAligned);
        }
        let r = range(offset, bytes.len())?;
        for (cell, b) in self.bytes()[r].iter_mut().zip(bytes) {
            *cell &= *b;
        }
        Ok(())
    }
}
