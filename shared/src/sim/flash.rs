//! Flash in RAM, for the simulated controllers (the host simulator, the QEMU board): they store and restore their
//! configuration through [`crate::store`] exactly as a board does.

use core::ops::Range;

use embedded_storage_async::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};

/// Flash in RAM with NOR semantics: erase sets a page of `PAGE` bytes to 0xFF, a write can only clear bits. The QEMU
/// controller keeps its settings in one (in RAM that survives a reset) and the host simulator in another, so that
/// both store and restore through this module exactly as a board does.
#[derive(Debug)]
pub struct RamFlash<'a, const PAGE: usize> {
    bytes: &'a mut [u8],
}

impl<'a, const PAGE: usize> RamFlash<'a, PAGE> {
    /// Flash over `bytes` as they are (a whole number of pages; erase them first for an empty flash).
    pub fn new(bytes: &'a mut [u8]) -> Self {
        Self { bytes }
    }

    /// Its whole range.
    pub fn range(&self) -> Range<u32> {
        0..self.bytes.len() as u32
    }

    fn span(&self, offset: u32, len: usize) -> Result<Range<usize>, NorFlashErrorKind> {
        let start = offset as usize;
        match start.checked_add(len) {
            Some(end) if end <= self.bytes.len() => Ok(start..end),
            _ => Err(NorFlashErrorKind::OutOfBounds),
        }
    }
}

impl<const PAGE: usize> ErrorType for RamFlash<'_, PAGE> {
    type Error = NorFlashErrorKind;
}

impl<const PAGE: usize> ReadNorFlash for RamFlash<'_, PAGE> {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let r = self.span(offset, bytes.len())?;
        bytes.copy_from_slice(&self.bytes[r]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.bytes.len()
    }
}

impl<const PAGE: usize> NorFlash for RamFlash<'_, PAGE> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        if !(from as usize).is_multiple_of(PAGE) || !(to as usize).is_multiple_of(PAGE) || to < from {
            return Err(NorFlashErrorKind::NotAligned);
        }
        let r = self.span(from, (to - from) as usize)?;
        self.bytes[r].fill(0xff);
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if !(offset as usize).is_multiple_of(Self::WRITE_SIZE) || !bytes.len().is_multiple_of(Self::WRITE_SIZE) {
            return Err(NorFlashErrorKind::NotAligned);
        }
        let r = self.span(offset, bytes.len())?;
        for (cell, b) in self.bytes[r].iter_mut().zip(bytes) {
            *cell &= *b;
        }
        Ok(())
    }
}
