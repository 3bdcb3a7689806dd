//! The configuration in flash: one versioned record ([`RECORD_VERSION`], postcard) under [`CONFIG_KEY`] with
//! `sequential-storage` (a log of key/value items over two or more erase pages): the rig (geometry, home pose and the
//! settings sections that describe the machine) and the sections stored with it (stream, control). At boot the rig
//! is restored through the same checks as `SetRig`, then the sections through the same checks as `SetSettings`; a
//! record that cannot run leaves the compiled-in defaults running, and says why.
//!
//! One record, so that a save is all or nothing: a save cut at any byte of its writes or erases leaves the previous
//! record readable (the crate's guarantee, tested here by cutting saves at every byte on the crate's mock flash),
//! never a rig of one save with sections of another. Restoring is generic over the flash so that the firmware's
//! settings task, the simulator and the host tests run this same code.

use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::cache::NoCache;
use sequential_storage::map::{fetch_item, store_item};

use crate::controller::ControllerConfig;
use crate::motion::{SpareAxisSettings, SPARE_AXES};
use crate::protocol::{wire, ControlSettings, RigRecord, RigSource, Settings, StreamSettings};

mod v2;
mod v3;

/// The record's key in flash. (Keys 1-53 held the single `f32` settings of protocol versions up to 5: never read.)
pub const CONFIG_KEY: u8 = 0xf0;
/// Layout of the stored record. Version 1 held the rig alone; 2 adds the machine's settings sections (homing among
/// them) and the stream and control sections; 3 adds the actuator limits to the motion section; 4 the time for a
/// host gone (`host_gone_ms`) to the stream section; 5 the spare axes' section after the control section. Records of versions 2 and 3 are read and migrated (version 2's
/// actuators get their kinds' limits, what a version-2 device drove them with; both get the default time for a host
/// gone); one of another version is not read (the compiled-in defaults run and the host sees
/// [`RigSource::Unreadable`]). A record of version 4 is version 5 without the spare axes: it is read as none fitted.
pub const RECORD_VERSION: u16 = 5;
/// Room for the record's postcard bytes (about 690 with elbow chains, and 52 for the spare axes) and the crate's
/// header; every item read or moved passes through a buffer of this size.
const RECORD_BUFFER: usize = 832;

/// The record as flash holds it (read back field by field: `read`).
#[derive(serde::Serialize)]
struct Record {
    version: u16,
    rig: RigRecord,
    stream: StreamSettings,
    control: ControlSettings,
    spare: [SpareAxisSettings; SPARE_AXES],
}

/// What boot found in flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Restored {
    /// Stored sections besides the rig applied (stream, control, spare).
    pub applied: u8,
    /// Stored sections refused by the checks (left at their defaults).
    pub refused: u8,
    /// The stored rig and sections together did not make a runnable configuration: the stored rig runs alone.
    pub fell_back: bool,
    /// Flash could not be read.
    pub unreadable: bool,
    /// Where the rig came from.
    pub rig: RigSource,
}

/// `defaults`, or the stored configuration, and what was found.
pub async fn restore<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    defaults: ControllerConfig,
) -> (ControllerConfig, Restored) {
    let mut report = Restored::default();
    let mut buf = [0u8; RECORD_BUFFER];
    let record = match fetch_item::<u8, &[u8], _>(flash, range, &mut NoCache::new(), &mut buf, &CONFIG_KEY).await {
        Ok(None) => return (defaults, report),
        Ok(Some(bytes)) => match read(bytes) {
            Some(record) => record,
            None => {
                report.rig = RigSource::Unreadable;
                return (defaults, report);
            }
        },
        Err(_) => {
            report.unreadable = true;
            report.rig = RigSource::Unreadable;
            return (defaults, report);
        }
    };
    let base = match ControllerConfig::from_record(&record.rig) {
        Ok(config) => config,
        Err(e) => {
            report.rig = RigSource::Refused(e.refusal());
            return (defaults, report);
        }
    };
    report.rig = RigSource::Stored;
    let mut config = base;
    for section in [
        Settings::Stream(record.stream),
        Settings::Control(record.control),
        Settings::Spare(record.spare),
    ] {
        match config.apply(&section) {
            Ok(()) => report.applied += 1,
            Err(_) => report.refused += 1,
        }
    }
    if config.validate().is_err() {
        report.fell_back = true;
        config = base;
    }
    (config, report)
}

/// The record in `bytes`, of this version or migrated from version 2 or 3, read field by field: the version first,
/// which decides the layout of the rig (version 2's has no actuator limits) and of the stream section (versions 2
/// and 3 have no `host_gone_ms`); one reading of each type serves every version (the firmware has room for one).
fn read(bytes: &[u8]) -> Option<Record> {
    let (version, rest) = wire::take_from_bytes::<u16>(bytes).ok()?;
    let (rig, rest) = match version {
        2 => {
            let (old, rest) = wire::take_from_bytes::<v2::Rig>(rest).ok()?;
            (old.rig(), rest)
        }
        3 | 4 | RECORD_VERSION => wire::take_from_bytes::<RigRecord>(rest).ok()?,
        _ => return None,
    };
    let (stream, rest) = if version >= 4 {
        wire::take_from_bytes::<StreamSettings>(rest).ok()?
    } else {
        v3::stream(rest)?
    };
    let (control, rest) = wire::take_from_bytes::<ControlSettings>(rest).ok()?;
    let spare = if version == RECORD_VERSION {
        wire::take_from_bytes::<[SpareAxisSettings; SPARE_AXES]>(rest).ok()?.0
    } else {
        [SpareAxisSettings::NONE; SPARE_AXES]
    };
    Some(Record {
        version: RECORD_VERSION,
        rig,
        stream,
        control,
        spare,
    })
}

/// Stores `config` (what the next start is to run) as the record. On an error the previously stored record (or
/// none) stays the one a restore finds.
pub async fn store<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    config: &ControllerConfig,
) -> Result<(), sequential_storage::Error<F::Error>> {
    let record = Record {
        version: RECORD_VERSION,
        rig: config.rig(),
        stream: config.stream(),
        control: config.control(),
        spare: config.pipeline.spare,
    };
    let mut bytes = [0u8; RECORD_BUFFER];
    let Ok(len) = wire::to_slice(&record, &mut bytes) else {
        return Err(sequential_storage::Error::ItemTooBig);
    };
    let encoded: &[u8] = &bytes[..len];
    let mut buf = [0u8; RECORD_BUFFER];
    store_item(flash, range, &mut NoCache::new(), &mut buf, &CONFIG_KEY, &encoded).await
}
