//! Settings in flash: every [`ConfigKey`] changed over the protocol is stored under its code with
//! `sequential-storage` (a log of key/value items over two or more erase pages: a write interrupted by a power
//! loss leaves the previous value readable, which is the crate's guarantee), and replayed over the compiled-in
//! defaults at boot through the same checks as `SetConfig`.
//!
//! Flash is only written while the supplies are off: erasing a page stalls the CPU's flash reads (on the F411 a
//! 128 KiB sector takes 1-2 s), which must never happen while steps are being generated.

use core::ops::Range;

use embassy_time::{Duration, Timer};
use embedded_storage_async::nor_flash::NorFlash;
use ringpod_core::controller::ControllerConfig;
use ringpod_core::protocol::ConfigKey;
use sequential_storage::cache::NoCache;
use sequential_storage::map::{fetch_item, store_item};

use super::Shared;

/// What boot found in flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, defmt::Format)]
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

/// The defaults with every stored setting replayed over them.
pub async fn restore<F: NorFlash>(flash: &mut F, range: Range<u32>) -> (ControllerConfig, Restored) {
    let defaults = ControllerConfig::trainer_model();
    let mut config = defaults;
    let mut report = Restored::default();
    let mut buf = [0u8; 32];
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

/// Stores the controller's unsaved settings, one at a time, as it hands them out (only with the supplies off). `widen` is called
/// around each write with `true` and then `false`, for the board to lengthen its watchdog over a possible erase.
pub async fn run<F: NorFlash>(flash: &mut F, range: Range<u32>, shared: &Shared, mut widen: impl FnMut(bool)) -> ! {
    let mut buf = [0u8; 32];
    loop {
        Timer::after(Duration::from_millis(100)).await;
        // The controller hands settings out only while the supplies are off.
        let next = shared.with(|c| c.take_unsaved());
        let Some((key, value)) = next else { continue };
        widen(true);
        let result = store_item(flash, range.clone(), &mut NoCache::new(), &mut buf, &key.code(), &value).await;
        widen(false);
        match result {
            Ok(()) => defmt::info!("stored {} = {}", key, value),
            // The running value stays; the next boot uses the last stored one. Said, not hidden.
            Err(_) => defmt::error!("could not store {} = {}", key, value),
        }
    }
}
