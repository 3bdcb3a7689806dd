//! Settings in flash, with `sequential-storage` (a log of key/value items over two or more erase pages). The rig
//! (geometry, home pose and the sections that describe the machine) is one versioned record
//! ([`RIG_RECORD_VERSION`], postcard) under [`RIG_KEY`], restored first through the same checks as `SetRig`; every
//! other section (stream, control) is a versioned item of its own ([`SETTINGS_VERSION`]) under
//! [`SETTINGS_KEY`] plus its code, applied over the rig through the same checks as `SetSettings`.
//!
//! Power loss: a save cut at any byte of its writes or erases leaves the previous value readable (the crate's
//! guarantee, tested here by cutting a save at every byte on the crate's mock flash). Restoring is generic over the
//! flash so that the firmware's settings task and the host tests run this same code.

use core::ops::Range;

use embedded_storage_async::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use sequential_storage::cache::NoCache;
use sequential_storage::map::{fetch_item, store_item};

use crate::controller::ControllerConfig;
use crate::protocol::{RigRecord, RigSource, Settings, SettingsKind};

/// The rig record's key in flash.
pub const RIG_KEY: u8 = 0xf0;
/// Layout of the stored rig record; a record of another version is not read (the compiled-in rig runs and the
/// host sees [`RigSource::Unreadable`]). Version 2 carries the homing section and the motors as settings sections.
pub const RIG_RECORD_VERSION: u16 = 2;
/// Key of the first section stored on its own; a section's key adds its [`SettingsKind::code`]. (Keys 1-53 held
/// the single `f32` settings of protocol versions up to 5: they are never read.)
pub const SETTINGS_KEY: u8 = 0x80;
/// Layout of a stored section; one of another version is not read (its defaults run, counted as refused).
pub const SETTINGS_VERSION: u16 = 1;
/// Room for the stored rig record: its postcard bytes (about 560) and the crate's header.
const RIG_BUFFER: usize = 768;

/// A section as flash holds it.
#[derive(serde::Serialize, serde::Deserialize)]
struct StoredSettings {
    version: u16,
    settings: Settings,
}

/// The stored rig record as flash holds it.
#[derive(serde::Serialize, serde::Deserialize)]
struct StoredRig {
    version: u16,
    rig: RigRecord,
}

/// What boot found in flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Restored {
    /// Stored sections applied.
    pub applied: u8,
    /// Stored sections refused by the checks, or of another layout (left at their defaults).
    pub refused: u8,
    /// The stored values together did not make a runnable configuration: the defaults run.
    pub fell_back: bool,
    /// Flash could not be read.
    pub unreadable: bool,
    /// Where the rig came from.
    pub rig: RigSource,
}

/// Room for any stored item with the crate's header: reading or moving items passes every item through this buffer,
/// the rig record included.
const ITEM_BUFFER: usize = RIG_BUFFER;

/// `defaults` with every stored setting replayed over them, and what was found.
pub async fn restore<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    defaults: ControllerConfig,
) -> (ControllerConfig, Restored) {
    let mut report = Restored::default();
    let (base, rig) = restore_rig(flash, range.clone(), defaults).await;
    report.rig = rig;
    let mut config = base;
    let mut buf = [0u8; ITEM_BUFFER];
    for kind in SettingsKind::ALL.into_iter().filter(|k| !k.in_rig()) {
        let key = SETTINGS_KEY + kind.code();
        match fetch_item::<u8, &[u8], _>(flash, range.clone(), &mut NoCache::new(), &mut buf, &key).await {
            Ok(Some(bytes)) => match postcard::from_bytes::<StoredSettings>(bytes) {
                Ok(s)
                    if s.version == SETTINGS_VERSION
                        && s.settings.kind() == kind
                        && config.apply(&s.settings).is_ok() =>
                {
                    report.applied += 1
                }
                _ => report.refused += 1,
            },
            Ok(None) => {}
            Err(_) => report.unreadable = true,
        }
    }
    if config.validate().is_err() {
        report.fell_back = true;
        config = base;
    }
    (config, report)
}

/// The stored rig with the compiled-in drives and timings, or `defaults` when there is none or it cannot run.
async fn restore_rig<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    defaults: ControllerConfig,
) -> (ControllerConfig, RigSource) {
    let mut buf = [0u8; RIG_BUFFER];
    match fetch_item::<u8, &[u8], _>(flash, range, &mut NoCache::new(), &mut buf, &RIG_KEY).await {
        Ok(None) => (defaults, RigSource::Compiled),
        Ok(Some(bytes)) => match postcard::from_bytes::<StoredRig>(bytes) {
            Ok(stored) if stored.version == RIG_RECORD_VERSION => match ControllerConfig::from_record(&stored.rig) {
                Ok(config) => (config, RigSource::Stored),
                Err(e) => (defaults, RigSource::Refused(e.refusal())),
            },
            _ => (defaults, RigSource::Unreadable),
        },
        Err(_) => (defaults, RigSource::Unreadable),
    }
}

/// Stores a rig for the next start. On an error the previously stored rig (or none) stays the one a restore finds.
pub async fn store_rig<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    rig: &RigRecord,
) -> Result<(), sequential_storage::Error<F::Error>> {
    let mut bytes = [0u8; RIG_BUFFER];
    let record = StoredRig {
        version: RIG_RECORD_VERSION,
        rig: *rig,
    };
    let Ok(encoded) = postcard::to_slice(&record, &mut bytes) else {
        return Err(sequential_storage::Error::ItemTooBig);
    };
    let encoded: &[u8] = encoded;
    let mut buf = [0u8; RIG_BUFFER];
    store_item(flash, range, &mut NoCache::new(), &mut buf, &RIG_KEY, &encoded).await
}

/// Stores one section (one a rig does not carry; the others are stored as part of the rig). On an error (flash
/// fault, power loss) the previously stored section stays the one a restore finds.
pub async fn store<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    settings: &Settings,
) -> Result<(), sequential_storage::Error<F::Error>> {
    let mut bytes = [0u8; RIG_BUFFER];
    let item = StoredSettings {
        version: SETTINGS_VERSION,
        settings: *settings,
    };
    let Ok(encoded) = postcard::to_slice(&item, &mut bytes) else {
        return Err(sequential_storage::Error::ItemTooBig);
    };
    let encoded: &[u8] = encoded;
    let mut buf = [0u8; ITEM_BUFFER];
    let key = SETTINGS_KEY + settings.kind().code();
    store_item(flash, range, &mut NoCache::new(), &mut buf, &key, &encoded).await
}

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
