//! The settings in flash: restored at boot into the controller and its step timing, and stored by their task
//! (with the watchdog widened over a sector erase).

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_stm32::flash::{Blocking, Flash};
use ringpod_core::controller::{Controller, ControllerConfig, Restart};
use ringpod_core::motion::pulse::PulseRenderer;
use ringpod_core::protocol::RigSource;
use ringpod_core::store;
use ringpod_firmware::app::{self, Shared};

use super::resources::{SettingsParts, PORT_MAP};
use super::watchdog;

/// The settings live in flash sectors 6 and 7 (0x0804_0000-0x0807_FFFF, two 128 KiB erase pages); `memory.x`
/// gives the program the first 256 KiB. Offsets are from the start of flash.
const SETTINGS: core::ops::Range<u32> = 0x0004_0000..0x0008_0000;

/// The settings flash, as the store's async interface over embassy's blocking driver.
pub type SettingsFlash = BlockingAsync<Flash<'static, Blocking>>;

/// The flash controller as [`SettingsFlash`].
pub fn flash(r: SettingsParts) -> SettingsFlash {
    BlockingAsync::new(Flash::new_blocking(r.flash))
}

/// What the settings give the rest of the bring-up.
pub struct Restored {
    /// The controller on the restored configuration.
    pub controller: Controller,
    /// The step timing of that configuration on this board's port.
    pub renderer: PulseRenderer,
    /// Where its rig came from.
    pub rig: RigSource,
    /// The control tick's period (us).
    pub tick_us: u32,
}

/// The compiled-in defaults with what flash holds replayed over them.
pub async fn read(flash: &mut SettingsFlash) -> (ControllerConfig, store::Restored) {
    app::settings::restore(flash, SETTINGS).await
}

/// The controller and step timing of what [`read`] gave; a stored rig that cannot run is logged and the
/// compiled-in one runs.
pub fn restore((config, restored): (ControllerConfig, store::Restored)) -> Restored {
    defmt::info!("settings: {}", restored);
    if matches!(restored.rig, RigSource::Refused(_) | RigSource::Unreadable) {
        defmt::error!("the stored rig cannot run ({}): the compiled-in rig runs", restored.rig);
    }
    let controller = match Controller::new(config) {
        Ok(c) => c,
        Err(e) => defmt::panic!("the compiled-in configuration cannot run: {}", e),
    };
    let renderer = match config.pulse_timing().and_then(|t| PulseRenderer::new(PORT_MAP, t)) {
        Ok(r) => r,
        Err(e) => defmt::panic!("step timing: {}", e),
    };
    Restored {
        controller,
        renderer,
        rig: restored.rig,
        tick_us: config.pipeline.tick_us,
    }
}

/// The watchdog and the resets, for the settings task.
struct SettingsBoard;

impl app::settings::Board for SettingsBoard {
    fn widen_watchdog(&mut self, wide: bool) {
        watchdog::set_timeout(if wide {
            watchdog::FLASH_WRITE_US
        } else {
            watchdog::NORMAL_US
        })
    }

    fn restart(&mut self, into: Restart) -> ! {
        match into {
            Restart::Controller => cortex_m::peripheral::SCB::sys_reset(),
            Restart::Bootloader => super::bootloader::restart_into(),
        }
    }

    /// CYCCNT counts core clock cycles, stalled ones included (ARMv7-M ARM C1.8.8), at SYSCLK (`clocks`).
    fn stall_clock(&self) -> Option<(u32, u32)> {
        Some((
            cortex_m::peripheral::DWT::cycle_count(),
            super::clocks::SYSCLK_HZ / 1_000_000,
        ))
    }
}

#[embassy_executor::task]
pub async fn settings_task(mut flash: SettingsFlash, shared: &'static Shared) -> ! {
    app::settings::run(&mut flash, SETTINGS, shared, &mut SettingsBoard).await
}
