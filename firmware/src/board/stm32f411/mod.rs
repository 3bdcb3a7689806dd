//! Board: STM32F411CE "Black Pill" (25 MHz crystal, USB-C, 512 KiB flash, 128 KiB RAM).
//!
//! Everything specific to this chip is in this folder: clocks, the pin map, interrupt bindings, USB CDC-ACM and the
//! USART1 link, the TIM1 + DMA2 step generator, EXTI switch inputs, the independent watchdog and the settings flash.
//! Another STM32 (F446, G474, H743) is another folder like this one plus its `memory.x`; `app` stays as it is.
//!
//! | signal | pin | | signal | pin |
//! |---|---|---|---|---|
//! | STEP 1-6 | PB0-PB5 | | E-STOP (NC chain) | PA0 |
//! | DIR 1-6 | PB6-PB10, PB12 | | HOME 1-6 | PA1-PA6 |
//! | ENABLE (active low) | PB13 | | LIMIT 5, 6 (far ends) | PA7, PA8 |
//! | LOGIC_EN relay | PB14 | | LOGIC_OK, POWER_OK | PA9, PC14 |
//! | POWER_EN relay | PB15 | | USB D-/D+ | PA11/PA12 |
//! | AUX1, AUX2 outputs | PC15, PC13 | | USART1 TX, RX (AF7) | PA15, PA10 |
//!
//! With a spare axis fitted in the restored settings, PA9, PA10, PA15 and PC14 are STEP 7, DIR 7, STEP 8 and DIR 8
//! instead (no supply senses, no USART1 link): `steps` explains their DMA rings.
//!
//! All STEP and DIR pins of the platform are on port B so that one 32-bit write to `GPIOB.BSRR` sets and clears all of them at
//! once: the step generator is TIM1 updating every 2.5 us and DMA2 stream 5 (channel 6, TIM1_UP) copying one word
//! per update from a ring of rendered periods into `BSRR`. The CPU renders a period per millisecond; it never
//! touches a pin per step. Inputs are on PA0-PA9 and PC14, each on its own EXTI line (0-9, 14).
//!
//! The host link is served on USB CDC-ACM (the default) and, at the same time, on USART1 at [`USART_BAUD`] for an
//! isolated USB-serial adapter. USART1 is the only USART with a TX pin free on this package (PA15); its RX pins are
//! PA10, PB3 and PB7, so POWER_OK moved from PA10 to PC14 (a plain input; the Black Pill's 32.768 kHz crystal there
//! is unused by this firmware and passes no DC, so it only slows the edges of a debounced supply signal).
//!
//! The auxiliary outputs take the last two free pins, PC15 and PC13 (PB11 is not bonded out, PH0/PH1 carry the
//! 25 MHz crystal, PA13/PA14 are SWD). They are in the backup domain: low speed only and no current sourced
//! (RM0383/datasheet: at most 3 mA through the power switch), so each drives a relay driver's MOSFET gate; the
//! Black Pill's blue LED on PC13 (to 3.3 V) lights while AUX2 is off.
//!
//! One file a job: `resources` (the pin map as code: which peripherals each step takes, the interrupt bindings),
//! `clocks`, `outputs` (relays, enable, auxiliary outputs, STEP/DIR at their idle levels), `switches` (EXTI
//! inputs), `steps` (TIM1 + DMA2 and its interrupt executor), `usb` and `uart` (the two host links), `settings`
//! (flash), `watchdog` (IWDG), `bootloader` (the ROM bootloader entered from the firmware); this file brings them up in
//! order and spawns the tasks.

#[macro_use]
mod resources;
mod bootloader;
mod clocks;
mod outputs;
mod settings;
mod steps;
mod switches;
mod uart;
mod usb;
mod watchdog;

use embassy_executor::Spawner;
use ringpod_core::controller::Controller;
use ringpod_core::motion::pulse::PulseRenderer;
use ringpod_core::protocol::{Firmware, Image, RigSource};
use ringpod_firmware::app::inputs::InputPins;
use ringpod_firmware::app::Shared;
use static_cell::StaticCell;
use {defmt_rtt as _, panic_probe as _};

use resources::{
    AssignedResources, OutputPins, SensePins, SettingsParts, SpareDmaParts, StepDirPins, StepGeneratorParts,
    SwitchPins, UartParts, UsbParts,
};

static SHARED: StaticCell<Shared> = StaticCell::new();

/// Brings the board up and spawns the tasks.
pub async fn start(spawner: Spawner) {
    bootloader::enter_if_marked();
    let watchdog_reset = watchdog::caused_last_reset();
    let p = embassy_stm32::init(clocks::config());
    let r = split_resources!(p);

    // Safe state first: drivers disabled, relays off, STEP low and DIR at its idle level, before anything else.
    // (During reset and clock start-up the pins float: the wiring's pull resistors hold the same levels.)
    let machine = outputs::safe_state(r.outputs);
    outputs::hold_step_dir(r.step_dir);
    enable_cycle_counter();

    // Settings: the compiled-in defaults with what flash holds replayed over them.
    let mut flash = settings::flash(r.settings);
    let restored = settings::restore(settings::read(&mut flash).await);
    // A spare axis fitted in the restored settings takes the supply senses' and USART1's pins for STEP/DIR 7-8
    // (a settings choice, applied at this start: the configuration refuses sensed supplies beside it).
    let spare = spare_renderer(&restored);
    // DMA2 stream 2 is the spare port C ring's or USART1's receive ring (resources: why one stream for both).
    let (senses, uart, spare_dma) = match spare {
        Some(_) => {
            outputs::hold_spare(r.senses, r.uart);
            (None, None, Some(r.spare_dma))
        }
        None => (Some(r.senses), Some((r.uart, r.spare_dma.port_c)), None),
    };
    let mut switches = switches::new(r.switches, senses);
    let shared = share(restored.controller, &mut switches, restored.rig, watchdog_reset);
    let firmware = firmware();
    shared.with(|c| c.set_firmware(firmware));

    steps::start(
        r.step_generator,
        restored.renderer,
        spare.zip(spare_dma).map(|(s, d)| (d, s)),
        shared,
    );
    let (device, usb_link) = usb::new(r.usb);
    let uart_link = uart.map(|(parts, rx_dma)| uart::new(parts, rx_dma));

    resources::set_priorities();
    watchdog::start(watchdog::NORMAL_US);
    spawner.spawn(defmt::unwrap!(outputs::control_task(machine, shared)));
    spawner.spawn(defmt::unwrap!(switches::inputs_task(switches, shared)));
    spawner.spawn(defmt::unwrap!(usb::usb_task(device)));
    spawner.spawn(defmt::unwrap!(usb::link_task(usb_link, shared)));
    if let Some(link) = uart_link {
        spawner.spawn(defmt::unwrap!(uart::uart_link_task(link, shared)));
    }
    spawner.spawn(defmt::unwrap!(settings::settings_task(flash, shared)));
    defmt::info!("ringpod firmware up: {} Hz control tick", 1_000_000 / restored.tick_us);
}

/// The spare axes' renderer (their pin map on the platform's slot grid) when the restored settings fit either.
fn spare_renderer(restored: &settings::Restored) -> Option<PulseRenderer> {
    if !restored.controller.config().pipeline.spare.iter().any(|a| a.enabled) {
        return None;
    }
    // The map is a valid constant and the grid the platform's renderer accepted: this cannot fail.
    match PulseRenderer::new(resources::SPARE_MAP, *restored.renderer.timing()) {
        Ok(renderer) => Some(renderer),
        Err(e) => defmt::panic!("the spare pin map: {}", e),
    }
}

/// The firmware this is, with the image as flash holds it: from the start of flash to the end of `.data`'s initial
/// values (cortex-m-rt's link.x: they start at `__sidata` and are `__edata - __sdata` long), checksummed at boot
/// (`ringpod_core::protocol::firmware`: why at boot; about 2 M cycles, 20 ms, before the watchdog starts).
fn firmware() -> Firmware {
    extern "C" {
        static __sidata: u8;
        static __sdata: u8;
        static __edata: u8;
    }
    const FLASH: usize = 0x0800_0000;
    let (load, start, end) = (
        core::ptr::addr_of!(__sidata) as usize,
        core::ptr::addr_of!(__sdata) as usize,
        core::ptr::addr_of!(__edata) as usize,
    );
    let size = load + (end - start) - FLASH;
    // SAFETY: flash from its start to the end of the image is mapped and never written while the firmware runs
    // (the settings sectors lie beyond the program's, memory.x).
    let image = unsafe { core::slice::from_raw_parts(FLASH as *const u8, size) };
    Firmware {
        image: Some(Image::of(image)),
        ..Firmware::BUILT
    }
}

/// The cycle counter the control task measures its tick with.
fn enable_cycle_counter() {
    let mut core = match cortex_m::Peripherals::take() {
        Some(p) => p,
        None => defmt::panic!("core peripherals taken twice"),
    };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
}

/// The state the tasks share: the controller with the switches' levels at reset, where its rig came from, and
/// whether the watchdog caused this start.
fn share(
    controller: Controller,
    switches: &mut impl InputPins,
    rig: RigSource,
    watchdog_reset: bool,
) -> &'static Shared {
    let shared: &'static Shared = SHARED.init(Shared::new(controller, switches.read()));
    shared.with(|c| c.set_rig_source(rig));
    if watchdog_reset {
        defmt::error!("the last reset was the watchdog's");
        shared.with(|c| c.watchdog_reset());
    }
    shared
}
