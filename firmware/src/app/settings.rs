//! The settings task: the controller's changed configuration (settings sections, a loaded rig) stored in flash as
//! one record through the core's power-loss-safe store (`ringpod_core::store`, tested there with a power cut at
//! every byte of a save), restored at boot, and the restart the host asked for once everything is stored.
//!
//! Flash is only written while the supplies are off: erasing a page stalls the CPU's flash reads (on the F411 a
//! 128 KiB sector takes 1-2 s), which must never happen while steps are being generated.

use core::ops::Range;

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Instant, Timer};
use embedded_storage_async::nor_flash::NorFlash;
use ringpod_core::controller::{ControllerConfig, Restart};
pub use ringpod_core::store::Restored;
use ringpod_core::store::{self, store};

use super::Shared;

/// What the settings task needs of the board besides its flash.
pub trait Board {
    /// Lengthens the watchdog over a write that may erase a page (`true`), and back (`false`).
    fn widen_watchdog(&mut self, wide: bool);
    /// Resets the MCU into `into`: the controller (the next start restores what was stored), or the MCU's ROM
    /// bootloader to be flashed.
    fn restart(&mut self, into: Restart) -> !;
    /// A free-running cycle counter that counts on while an erase stalls the CPU (DWT CYCCNT on a board), and its
    /// cycles per microsecond; `None` where an erase does not stall device time.
    fn stall_clock(&self) -> Option<(u32, u32)> {
        None
    }
}

/// The compiled-in defaults, or the stored rig, with every stored setting replayed over them.
pub async fn restore<F: NorFlash>(flash: &mut F, range: Range<u32>) -> (ControllerConfig, Restored) {
    store::restore(flash, range, ControllerConfig::trainer_model()).await
}

/// Stores the controller's changed configuration as it hands it out (only with the supplies off); restarts when the
/// host asked for it and nothing waits to be stored.
pub async fn run<F: NorFlash>(flash: &mut F, range: Range<u32>, shared: &Shared, board: &mut impl Board) -> ! {
    loop {
        Timer::after(Duration::from_millis(100)).await;
        // The controller hands it out only while the supplies are off.
        if let Some(config) = shared.with(|c| c.take_unsaved()) {
            let (since, cycles) = (Instant::now(), board.stall_clock());
            board.widen_watchdog(true);
            let result = store(flash, range.clone(), &config).await;
            board.widen_watchdog(false);
            if let (Some((c0, per_us)), Some((c1, _))) = (cycles, board.stall_clock()) {
                // An erase stalls the CPU, so the time driver's interrupt that counts its timer's wraps cannot run:
                // device time loses most of the erase. The cycle counter does not; the control loop catches the
                // difference up as passed periods, so that the supervisor's and the stream's timers lose nothing.
                let real_us = c1.wrapping_sub(c0) / per_us.max(1);
                let seen_us = u32::try_from(since.elapsed().as_micros()).unwrap_or(u32::MAX);
                let lost = real_us.saturating_sub(seen_us);
                shared.clock_lost_us.fetch_add(lost, Ordering::Relaxed);
                defmt::info!(
                    "the store took {} us, {} us of them lost to device time: caught up",
                    real_us,
                    lost
                );
            }
            let rig = config.rig();
            match result {
                Ok(()) => defmt::info!("stored the configuration (rig {})", rig.name()),
                // The running configuration stays; the next start finds the record stored before. Said, not hidden.
                Err(_) => defmt::error!("could not store the configuration (rig {})", rig.name()),
            }
            continue;
        }
        if let Some(into) = shared.with(|c| c.restart_due()) {
            defmt::info!("restarting into {}, as the host asked", into);
            Timer::after(Duration::from_millis(20)).await; // the Ack on its way out
            board.restart(into);
        }
    }
}
