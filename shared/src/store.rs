//! Settings in flash: every [`ConfigKey`] changed over the protocol is stored under its code with
//! `sequential-storage` (a log of key/value items over two or more erase pages), and replayed over the compiled-in
//! defaults at boot through the same checks as `SetConfig`.
//!
//! Power loss: a save cut at any byte of its writes or erases leaves the previous value readable (the crate's
//! guarantee, tested here by cutting a save at every byte on the crate's mock flash). Restoring is generic over the
//! flash so that the firmware's settings task and the host tests run this same code.

use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::cache::NoCache;
use sequential_storage::map::{fetch_item, store_item};

use crate::controller::ControllerConfig;
use crate::protocol::ConfigKey;

/// What boot found in flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Restored {
    /// Stored values applied.
    pub applied: u8,
    /// Stored values refused by the checks (left at their defaults).
    pub refused: u8,
    /// The stored values together did not make a runnable configuration: the defaults run.
    pub fell_back: bool,
    /// Flash could not be read.
    pub unreadable: bool,
}

/// Room for one stored item (key, value and the crate's header).
const ITEM_BUFFER: usize = 32;

/// `defaults` with every stored setting replayed over them, and what was found.
pub async fn restore<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    defaults: ControllerConfig,
) -> (ControllerConfig, Restored) {
    let mut config = defaults;
    let mut report = Restored::default();
    let mut buf = [0u8; ITEM_BUFFER];
    for key in ConfigKey::all() {
        match fetch_item::<u8, f32, _>(flash, range.clone(), &mut NoCache::new(), &mut buf, &key.code()).await {
            Ok(Some(value)) => match config.set(key, value) {
                Ok(()) => report.applied += 1,
                Err(_) => report.refused += 1,
            },
            Ok(None) => {}
            Err(_) => report.unreadable = true,
        }
    }
    if config.validate().is_err() {
        report.fell_back = true;
        config = defaults;
    }
    (config, report)
}

/// Stores one setting. On an error (flash fault, power loss) the previously stored value stays the one a restore
/// finds.
pub async fn store<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    key: ConfigKey,
    value: f32,
) -> Result<(), sequential_storage::Error<F::Error>> {
    let mut buf = [0u8; ITEM_BUFFER];
    store_item(flash, range, &mut NoCache::new(), &mut buf, &key.code(), &value).await
}
