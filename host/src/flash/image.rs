//! The firmware image `ringpod flash` writes: an ELF (its load segments, as a programmer lays them into flash) or a
//! raw `.bin` (from the start of flash), checked before anything is erased: it starts at the start of flash, fits
//! the program's area (sectors 0-5, `memory.x`: the settings in sectors 6-7 are never written), and begins with a
//! Cortex-M vector table whose stack pointer is in RAM and whose reset vector is Thumb code inside the image.

use ringpod_core::protocol::Image;

/// Where flash starts (RM0383 3.3: the main memory at 0x0800_0000).
pub const FLASH: u32 = 0x0800_0000;
/// The program's area: sectors 0-5, 256 KiB (`memory.x`); sectors 6-7 hold the settings.
pub const PROGRAM_AREA: u32 = 256 * 1024;
/// The F411's SRAM (RM0383 2.3: 128 KiB at 0x2000_0000): where the initial stack pointer must point.
const RAM: std::ops::RangeInclusive<u32> = 0x2000_0000..=0x2002_0000;

/// An image, laid out from `address`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FirmwareImage {
    /// Where it is written.
    pub address: u32,
    /// Its bytes, gaps between segments 0xFF (erased flash).
    pub bytes: Vec<u8>,
}

/// Why an image is refused (before anything is erased).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ImageError {
    /// Not an ELF of a 32-bit little-endian ARM program.
    #[error("not a firmware ELF: {0}")]
    Elf(String),
    /// A part of it lies outside the program's area of flash.
    #[error("{what} at {at:#010x}..{end:#010x} is outside the program's area of flash (0x08000000..0x08040000: sectors 0-5; 6-7 keep the settings)")]
    Outside {
        /// What.
        what: String,
        /// Its start.
        at: u32,
        /// Its end.
        end: u64,
    },
    /// It does not start with a vector table this MCU can start.
    #[error("no Cortex-M vector table at its start: {0}")]
    VectorTable(String),
    /// It holds nothing.
    #[error("the image is empty")]
    Empty,
}

impl FirmwareImage {
    /// A raw image from the start of flash (a `.bin`), or an ELF's load segments: an ELF is told by its magic.
    pub fn from_file_bytes(bytes: &[u8]) -> Result<FirmwareImage, ImageError> {
        let image = if bytes.starts_with(b"\x7fELF") {
            Self::from_elf(bytes)?
        } else {
            FirmwareImage {
                address: FLASH,
                bytes: bytes.to_vec(),
            }
        };
        image.check()?;
        Ok(image)
    }

    /// The load segments of an ELF32 little-endian ARM executable with bytes in the file, each at its physical
    /// (load) address: `.data`'s initial values where the startup code copies them from (ELF, System V ABI:
    /// program headers).
    pub fn from_elf(elf: &[u8]) -> Result<FirmwareImage, ImageError> {
        let bad = |why: &str| ImageError::Elf(why.to_owned());
        let u16_at = |at: usize| elf.get(at..at + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
        let u32_at = |at: usize| {
            elf.get(at..at + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        if elf.get(4..6) != Some(&[1, 1]) {
            return Err(bad("not 32-bit little-endian"));
        }
        if u16_at(18) != Some(40) {
            return Err(bad("not an ARM program (e_machine)"));
        }
        let (Some(phoff), Some(phentsize), Some(phnum)) = (u32_at(28), u16_at(42), u16_at(44)) else {
            return Err(bad("truncated header"));
        };
        let mut segments = Vec::new();
        for i in 0..usize::from(phnum) {
            let at = phoff as usize + i * usize::from(phentsize);
            let field = |n: usize| u32_at(at + 4 * n).ok_or_else(|| bad("truncated program header"));
            let (kind, offset, paddr, filesz) = (field(0)?, field(1)?, field(3)?, field(4)?);
            if kind != 1 || filesz == 0 {
                continue; // not PT_LOAD, or nothing to write (.bss)
            }
            let data = elf
                .get(offset as usize..offset as usize + filesz as usize)
                .ok_or_else(|| bad("a segment runs past the end of the file"))?;
            segments.push((paddr, data));
        }
        let start = segments.iter().map(|s| s.0).min().ok_or(ImageError::Empty)?;
        let end = segments
            .iter()
            .map(|s| u64::from(s.0) + s.1.len() as u64)
            .max()
            .unwrap_or(0);
        if start < FLASH || end > u64::from(FLASH + PROGRAM_AREA) {
            let (at, data) = segments
                .iter()
                .find(|s| s.0 < FLASH || u64::from(s.0) + s.1.len() as u64 > u64::from(FLASH + PROGRAM_AREA))
                .copied()
                .unwrap_or((start, &[][..]));
            return Err(ImageError::Outside {
                what: "a load segment".into(),
                at,
                end: u64::from(at) + data.len() as u64,
            });
        }
        let mut bytes = vec![0xFF; (end - u64::from(start)) as usize];
        for (at, data) in segments {
            let from = (at - start) as usize;
            bytes[from..from + data.len()].copy_from_slice(data);
        }
        Ok(FirmwareImage { address: start, bytes })
    }

    /// Refuses an image this board cannot start, or one that would reach the settings.
    pub fn check(&self) -> Result<(), ImageError> {
        let end = u64::from(self.address) + self.bytes.len() as u64;
        if self.bytes.is_empty() {
            return Err(ImageError::Empty);
        }
        if self.address != FLASH || end > u64::from(FLASH + PROGRAM_AREA) {
            return Err(ImageError::Outside {
                what: format!("the image ({} B)", self.bytes.len()),
                at: self.address,
                end,
            });
        }
        let word = |n: usize| {
            self.bytes
                .get(4 * n..4 * n + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        let (Some(sp), Some(reset)) = (word(0), word(1)) else {
            return Err(ImageError::VectorTable("shorter than two words".into()));
        };
        if !RAM.contains(&sp) || sp % 8 != 0 {
            return Err(ImageError::VectorTable(format!(
                "the initial stack pointer {sp:#010x} is not an 8-byte aligned address in RAM (0x20000000..=0x20020000)"
            )));
        }
        let code = u64::from(reset & !1);
        if reset & 1 == 0 || code < u64::from(self.address) + 8 || code >= end {
            return Err(ImageError::VectorTable(format!(
                "the reset vector {reset:#010x} is not Thumb code inside the image"
            )));
        }
        Ok(())
    }

    /// Its length and CRC-32C, as the firmware reports the image it runs.
    pub fn id(&self) -> Image {
        Image::of(&self.bytes)
    }
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A minimal ELF32 ARM executable with the given load segments `(paddr, bytes)` (and one `.bss`-like segment
    /// without file bytes).
    pub fn elf(segments: &[(u32, Vec<u8>)]) -> Vec<u8> {
        let phnum = segments.len() + 1;
        let mut out = vec![0u8; 52 + 32 * phnum];
        out[..4].copy_from_slice(b"\x7fELF");
        out[4] = 1;
        out[5] = 1;
        out[6] = 1;
        out[16..18].copy_from_slice(&2u16.to_le_bytes());
        out[18..20].copy_from_slice(&40u16.to_le_bytes());
        out[28..32].copy_from_slice(&52u32.to_le_bytes());
        out[42..44].copy_from_slice(&32u16.to_le_bytes());
        out[44..46].copy_from_slice(&(phnum as u16).to_le_bytes());
        let mut offset = out.len() as u32;
        let mut data = Vec::new();
        let bss = (0x2000_0400u32, Vec::new());
        for (i, (paddr, bytes)) in segments.iter().chain(std::iter::once(&bss)).enumerate() {
            let h = 52 + 32 * i;
            let words = [
                1,
                offset,
                *paddr,
                *paddr,
                bytes.len() as u32,
                bytes.len() as u32 + 64,
                5,
                4,
            ];
            for (n, w) in words.iter().enumerate() {
                out[h + 4 * n..h + 4 * n + 4].copy_from_slice(&w.to_le_bytes());
            }
            offset += bytes.len() as u32;
            data.extend_from_slice(bytes);
        }
        out.extend(data);
        out
    }

    /// A vector table (stack pointer at the top of RAM, reset vector at 0x0800_0009: Thumb code right after it)
    /// and `len` bytes of program in all.
    pub fn program(len: usize) -> Vec<u8> {
        let mut bytes: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
        bytes[..8].copy_from_slice(&[0x00, 0x00, 0x02, 0x20, 0x09, 0x00, 0x00, 0x08]);
        bytes
    }

    #[test]
    fn an_elf_is_laid_out_by_its_load_addresses() {
        // Code, then `.data`'s initial values after a gap (loaded at 0x0800_1000, run in RAM).
        let code = program(0x400);
        let data = vec![0xAB; 16];
        let image =
            FirmwareImage::from_file_bytes(&elf(&[(FLASH, code.clone()), (FLASH + 0x1000, data.clone())])).unwrap();
        assert_eq!(image.address, FLASH);
        assert_eq!(image.bytes.len(), 0x1010);
        assert_eq!(&image.bytes[..0x400], &code[..]);
        assert!(
            image.bytes[0x400..0x1000].iter().all(|&b| b == 0xFF),
            "the gap is erased flash"
        );
        assert_eq!(&image.bytes[0x1000..], &data[..]);
        // A .bin is the same bytes from the start of flash.
        assert_eq!(FirmwareImage::from_file_bytes(&image.bytes).unwrap(), image);
    }

    #[test]
    fn every_kind_of_bad_image_is_refused() {
        let refused = |bytes: &[u8]| FirmwareImage::from_file_bytes(bytes).unwrap_err();
        // Not an ARM ELF, or a broken one.
        let mut other = elf(&[(FLASH, program(64))]);
        other[18] = 62; // x86-64
        assert!(matches!(refused(&other), ImageError::Elf(_)));
        let truncated = elf(&[(FLASH, program(64))]);
        assert!(matches!(
            refused(&truncated[..truncated.len() - 10]),
            ImageError::Elf(_)
        ));
        assert!(matches!(refused(&truncated[..40]), ImageError::Elf(_)));
        // Into the settings' sectors, or past the program's area, or not at the start of flash.
        let big = elf(&[(FLASH, program(64)), (FLASH + PROGRAM_AREA - 4, vec![0; 8])]);
        assert!(matches!(refused(&big), ImageError::Outside { .. }));
        assert!(matches!(
            refused(&program(PROGRAM_AREA as usize + 1)),
            ImageError::Outside { .. }
        ));
        let moved = elf(&[(FLASH + 0x4000, program(64))]);
        assert!(matches!(refused(&moved), ImageError::Outside { .. }));
        // No vector table: a stack pointer outside RAM, a reset vector in ARM state or outside the image.
        let mut sp = program(64);
        sp[3] = 0x30;
        assert!(matches!(refused(&sp), ImageError::VectorTable(_)));
        let mut arm = program(64);
        arm[4] = 0x08;
        assert!(matches!(refused(&arm), ImageError::VectorTable(_)));
        let mut far = program(64);
        far[5] = 0x80;
        assert!(matches!(refused(&far), ImageError::VectorTable(_)));
        assert_eq!(refused(&[]), ImageError::Empty);
        assert!(matches!(refused(&[0x00, 0x00]), ImageError::VectorTable(_)));
        assert_eq!(refused(&elf(&[])), ImageError::Empty);
    }
}
