//! The settings task: the controller's changed settings stored in flash through the core's power-loss-safe store
//! (`ringpod_core::store`, tested there with a power cut at every byte of a save), and restored at boot.
//!
//! Flash is only written while the supplies are off: erasing a page stalls the CPU's flash reads (on the F411 a
//! 128 KiB sector takes 1-2 s), which must never happen while steps are being generated.

use core::ops::Range;

use embassy_time::{Duration, Timer};
use embedded_storage_async::nor_flash::NorFlash;
use ringpod_core::controller::ControllerConfig;
pub use ringpod_core::store::Restored;
use ringpod_core::store::{self, store};

use super::Shared;

/// The compiled-in defaults with every stored setting replayed over them.
pub async fn restore<F: NorFlash>(flash: &mut F, range: Range<u32>) -> (ControllerConfig, Restored) {
    store::restore(flash, range, ControllerConfig::trainer_model()).await
}

/// Stores the controller's unsaved settings, one at a time, as it hands them out (only with the supplies off). `widen` is called
/// around each write with `true` and then `false`, for the board to lengthen its watchdog over a possible erase.
pub async fn run<F: NorFlash>(flash: &mut F, range: Range<u32>, shared: &Shared, mut widen: impl FnMut(bool)) -> ! {
    loop {
        Timer::after(Duration::from_millis(100)).await;
        // The controller hands settings out only while the supplies are off.
        let next = shared.with(|c| c.take_unsaved());
        let Some((key, value)) = next else { continue };
        widen(true);
        let result = store(flash, range.clone(), key, value).await;
        widen(false);
        match result {
            Ok(()) => defmt::info!("stored {} = {}", key, value),
            // The running value stays; the next boot uses the last stored one. Said, not hidden.
            Err(_) => defmt::error!("could not store {} = {}", key, value),
        }
    }
}
