//! Writing an image into the ROM bootloader's flash over DfuSe: the sectors the image covers erased (only those:
//! the settings' sectors stay), the image written block by block, read back and compared, and DFU left so that the
//! new program starts.
//!
//! The first block, which holds the vector table, is written last: a write cut half way (the cable pulled, the
//! power gone) leaves the first word of flash erased, so that a half-written program never runs (the core's reset
//! finds no stack pointer or reset vector and locks up, driving no pin). The F411 picks its boot memory by the
//! BOOT0 pin alone (AN2606: no empty-flash check on this family), so the board is then taken into the ROM
//! bootloader with BOOT0 held at reset, and a second `flash` finishes the job.

use super::dfuse::{Control, DfuError, DfuSe, Layout};
use super::image::FirmwareImage;

/// What is being done, for the progress bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Erasing the sectors the image covers (counted in bytes of sector).
    Erase,
    /// Writing the image (bytes).
    Write,
    /// Reading it back (bytes).
    Verify,
}

/// Why writing an image failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ProgramError {
    /// The bootloader's memory cannot take this image.
    #[error("the bootloader's memory cannot take the image: {0}")]
    Layout(String),
    /// A DfuSe step failed.
    #[error("{phase:?} at {at:#010x}: {error}")]
    Dfu {
        /// Which step.
        phase: Phase,
        /// Where.
        at: u32,
        /// What.
        error: DfuError,
    },
    /// The image read back differs from the one written.
    #[error("read back, the image differs from {at:#010x} on: the flash did not take it")]
    Verify {
        /// The first address that differs.
        at: u32,
    },
}

/// The sectors of `layout` the image covers, or why it cannot be written there: checked before anything is erased.
pub fn sectors(layout: &Layout, image: &FirmwareImage) -> Result<Vec<(u32, u32)>, ProgramError> {
    let len = u32::try_from(image.bytes.len()).map_err(|_| ProgramError::Layout("larger than 4 GiB".into()))?;
    layout.pages_for(image.address, len).map_err(ProgramError::Layout)
}

/// Erases the sectors the image covers, writes it, reads it back and compares, then leaves DFU to start it.
/// `progress(phase, done, total)` is told after each step.
pub fn program<C: Control>(
    dfu: &mut DfuSe<C>,
    layout: &Layout,
    image: &FirmwareImage,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<(), ProgramError> {
    let sectors = sectors(layout, image)?;
    let fail = |phase, at| move |error| ProgramError::Dfu { phase, at, error };
    dfu.idle().map_err(fail(Phase::Erase, image.address))?;
    let total: u64 = sectors.iter().map(|s| u64::from(s.1)).sum();
    let mut done = 0;
    progress(Phase::Erase, 0, total);
    for &(at, size) in &sectors {
        dfu.erase(at).map_err(fail(Phase::Erase, at))?;
        done += u64::from(size);
        progress(Phase::Erase, done, total);
    }

    let size = usize::from(dfu.transfer_size.max(1));
    let total = image.bytes.len() as u64;
    let chunks: Vec<&[u8]> = image.bytes.chunks(size).collect();
    dfu.set_address(image.address)
        .map_err(fail(Phase::Write, image.address))?;
    // The vector table's block last (see above).
    let order = (1..chunks.len()).chain(std::iter::once(0));
    for (n, i) in order.enumerate() {
        let at = image.address + (i * size) as u32;
        let block = u16::try_from(i + 2).map_err(|_| ProgramError::Layout("more than 65,533 blocks".into()))?;
        dfu.write_block(block, chunks[i]).map_err(fail(Phase::Write, at))?;
        progress(Phase::Write, ((n + 1) * size).min(image.bytes.len()) as u64, total);
    }

    // UM0424 6.2: the pointer set, then back to dfuIDLE (ABORT), then uploads from block 2.
    dfu.set_address(image.address)
        .map_err(fail(Phase::Verify, image.address))?;
    dfu.idle().map_err(fail(Phase::Verify, image.address))?;
    for (i, chunk) in image.bytes.chunks(size).enumerate() {
        let at = image.address + (i * size) as u32;
        let block = u16::try_from(i + 2).map_err(|_| ProgramError::Layout("more than 65,533 blocks".into()))?;
        let read = dfu
            .read_block(block, chunk.len() as u16)
            .map_err(fail(Phase::Verify, at))?;
        if let Some(k) = read.iter().zip(chunk).position(|(a, b)| a != b) {
            return Err(ProgramError::Verify { at: at + k as u32 });
        }
        progress(Phase::Verify, ((i + 1) * size).min(image.bytes.len()) as u64, total);
    }
    dfu.idle().map_err(fail(Phase::Verify, image.address))?;
    dfu.leave(image.address).map_err(fail(Phase::Verify, image.address))
}

#[cfg(test)]
mod tests {
    use super::super::dfuse::UsbError;
    use super::super::image::tests::program as image_bytes;
    use super::super::model::{RomModel, F411_LAYOUT, TRANSFER_SIZE};
    use super::*;

    fn pipe(model: RomModel) -> DfuSe<RomModel> {
        DfuSe {
            control: model,
            transfer_size: TRANSFER_SIZE,
        }
    }

    fn image(len: usize) -> FirmwareImage {
        FirmwareImage::from_file_bytes(&image_bytes(len)).unwrap()
    }

    fn layout() -> Layout {
        Layout::parse(F411_LAYOUT).unwrap()
    }

    /// What the settings' sectors hold: a stored record, to be kept.
    const SETTINGS: u32 = 0x0804_0000;

    #[test]
    fn an_image_is_written_verified_and_started_and_the_settings_are_kept() {
        let mut model = RomModel::new();
        // An old program everywhere in sectors 0-5, and a settings record in sector 6.
        model.flash[..0x4_0000].fill(0x5A);
        model.flash[0x4_0000..0x4_0100].fill(0x3C);
        let image = image(195_580);
        let mut dfu = pipe(model);
        let mut seen = Vec::new();
        program(&mut dfu, &layout(), &image, &mut |phase, done, total| {
            seen.push((phase, done, total))
        })
        .unwrap();
        let model = dfu.control;
        assert_eq!(model.read(0x0800_0000, image.bytes.len()), &image.bytes[..]);
        // Sectors 0-5 erased, each once; sector 6's record untouched; past the image in sector 5, erased flash.
        assert_eq!(
            model.erased,
            [
                0x0800_0000,
                0x0800_4000,
                0x0800_8000,
                0x0800_C000,
                0x0801_0000,
                0x0802_0000
            ]
        );
        assert!(model.read(SETTINGS, 0x100).iter().all(|&b| b == 0x3C));
        assert!(model.read(0x0800_0000 + 195_580, 0x100).iter().all(|&b| b == 0xFF));
        assert_eq!(model.early_polls, 0, "every poll timeout was waited");
        assert_eq!(model.started, Some(0x0800_0000));
        // The erase times the bootloader asked for: 4 x 0.5 s, 1.1 s, 2 s; and the writes' and reads' time.
        assert!(model.now >= std::time::Duration::from_millis(5_100), "{:?}", model.now);
        // Progress ends at each phase's total.
        for phase in [Phase::Erase, Phase::Write, Phase::Verify] {
            let last = seen.iter().rev().find(|s| s.0 == phase).unwrap();
            assert_eq!(last.1, last.2, "{phase:?}");
        }
        assert_eq!(seen.iter().rev().find(|s| s.0 == Phase::Write).unwrap().2, 195_580);
    }

    #[test]
    fn a_cable_pulled_mid_write_is_finished_by_a_second_flash() {
        let image = image(100_000);
        // The cable pulled 60 requests in: sectors erased, some blocks written.
        let mut model = RomModel::new();
        model.cable = Some(60);
        let mut dfu = pipe(model);
        let cut = program(&mut dfu, &layout(), &image, &mut |_, _, _| {}).unwrap_err();
        assert!(
            matches!(
                cut,
                ProgramError::Dfu {
                    error: DfuError::Usb(UsbError::Gone),
                    ..
                }
            ),
            "{cut:?}"
        );
        let mut model = dfu.control;
        assert_ne!(model.read(0x0800_0000, image.bytes.len()), &image.bytes[..]);
        assert_eq!(model.started, None);
        // Blocks after the first were written; the vector table's was not: a reset finds no program to run.
        assert_eq!(model.read(0x0800_0800, 16), &image.bytes[0x800..0x810]);
        assert!(model.read(0x0800_0000, 8).iter().all(|&b| b == 0xFF));
        // Plugged again (BOOT0, or the bootloader kept running): the second flash completes.
        model.cable = None;
        let mut dfu = pipe(model);
        program(&mut dfu, &layout(), &image, &mut |_, _, _| {}).unwrap();
        assert_eq!(dfu.control.read(0x0800_0000, image.bytes.len()), &image.bytes[..]);
        assert_eq!(dfu.control.started, Some(0x0800_0000));
    }

    #[test]
    fn flash_that_does_not_take_the_image_fails_verification() {
        // Sector 1 is not erased by the bootloader (a worn sector): programming cannot set its zero bits.
        struct Worn(RomModel);
        impl Control for Worn {
            fn control_in(&mut self, r: u8, v: u16, l: u16) -> Result<Vec<u8>, UsbError> {
                self.0.control_in(r, v, l)
            }
            fn control_out(&mut self, r: u8, v: u16, d: &[u8]) -> Result<(), UsbError> {
                let out = self.0.control_out(r, v, d);
                self.0.flash[0x4000..0x4010].fill(0);
                out
            }
            fn sleep(&mut self, w: std::time::Duration) {
                self.0.sleep(w)
            }
        }
        let image = image(40_000);
        let mut dfu = DfuSe {
            control: Worn(RomModel::new()),
            transfer_size: TRANSFER_SIZE,
        };
        let err = program(&mut dfu, &layout(), &image, &mut |_, _, _| {}).unwrap_err();
        let first = (0x4000..0x4010).find(|&i| image.bytes[i] != 0).unwrap() as u32;
        assert_eq!(
            err,
            ProgramError::Verify {
                at: 0x0800_0000 + first
            }
        );
        assert_eq!(
            dfu.control.0.started, None,
            "an image that did not verify is not started"
        );
    }

    #[test]
    fn an_image_the_layout_cannot_take_is_refused_before_any_request() {
        let mut dfu = pipe(RomModel::new());
        let small = Layout::parse("@Internal Flash  /0x08000000/04*016Kg").unwrap();
        let err = program(&mut dfu, &small, &image(100_000), &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(err, ProgramError::Layout(_)), "{err:?}");
        assert!(dfu.control.requests.is_empty());
    }
}
