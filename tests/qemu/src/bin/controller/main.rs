//! The ringpod controller on QEMU's mps2-an386: all five of the firmware's tasks (`ringpod_firmware::app`: host
//! link, control tick, input debouncing, step generator feed, settings storage, over
//! `ringpod_core::controller::Controller`) around a board module for the emulated machine:
//!
//! - [`time`]: an `embassy-time` driver on SysTick;
//! - [`uart`]: the host link on the CMSDK UART0 (QEMU `-serial pty` gives the host a pseudo-terminal);
//! - [`machine`]: the simulated plant behind the pins: relays, switch levels, and a step port whose rendered words
//!   are played into the drivers' model, which moves the axes by the STEP edges it counts;
//! - [`retained`]: the settings flash and the reset cause, in RAM that survives a reset;
//! - [`watchdog`]: the CMSDK watchdog, fed by the control tick.
//!
//! It prints `READY` over semihosting once its tasks run (`RESET watchdog` before it when the watchdog caused the
//! reset). Its semihosting command line can hold `stall-when-homed` (see [`machine::Controls`]), `estop-on-aux2`
//! (see [`machine::World::estop_on_aux2`]), or `latency` (and `direct` for that follow mode): the latency
//! measurement of [`latency`], whose host runs inside the program. What differs from the STM32 build is only this
//! board module.

#![no_std]
#![no_main]

mod latency;
mod machine;
mod retained;
mod time;
mod uart;
mod watchdog;

use core::cell::RefCell;

use cortex_m::peripheral::NVIC;
use cortex_m_rt::exception;
use cortex_m_semihosting::hprintln;
use embassy_executor::Spawner;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time::{Duration, Instant};
use ringpod_core::controller::Controller;
use ringpod_core::motion::pulse::{PortMap, PulseRenderer};
use ringpod_core::motion::pulse::{MAX_STEP_SLOTS, STEP_SLOT_NS};
use ringpod_core::motion::FollowMode;
use ringpod_core::protocol::RigSource;
use ringpod_core::sim::drivers::DriverInputs;
use ringpod_core::sim::{Plant, TRAINER_MODEL_PARKED};
use ringpod_firmware::app::{self, Shared};
use ringpod_qemu::fail;
use static_cell::StaticCell;

use machine::{Controls, Pins, Port, World, WorldCell};
use retained::RetainedFlash;
use uart::UartLink;

/// The STM32 board's pin map (STEP on bits 0-5, DIR on 6-10 and 12), so that the same words are rendered.
const PORT_MAP: PortMap = PortMap {
    step: [0, 1, 2, 3, 4, 5],
    dir: [6, 7, 8, 9, 10, 12],
    dir_forward_low: 0,
};

/// The whole settings flash.
const SETTINGS: core::ops::Range<u32> = 0..retained::FLASH_SIZE as u32;

/// The watchdog resets the board this long after the control tick last fed it. Longer than the STM32's 50 ms: the
/// emulator runs on the host's clock and a busy CI machine can hold it up for tens of milliseconds.
const WATCHDOG_US: u32 = 1_000_000;

#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: the numbers are interrupt numbers of this machine.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == uart::RX_IRQ as i16 {
        uart::on_rx_interrupt();
    }
}

#[embassy_executor::task]
async fn link_task(mut link: UartLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 0, shared).await
}

#[embassy_executor::task]
async fn control_task(mut machine: Controls, shared: &'static Shared) -> ! {
    app::control::run(&mut machine, shared).await
}

#[embassy_executor::task]
async fn inputs_task(mut pins: Pins, shared: &'static Shared) -> ! {
    app::inputs::run(&mut pins, shared).await
}

#[embassy_executor::task]
async fn steps_task(mut port: Port, renderer: PulseRenderer, shared: &'static Shared) -> ! {
    app::steps::run(&mut port, renderer, None, shared).await
}

#[embassy_executor::task]
async fn settings_task(mut flash: RetainedFlash, shared: &'static Shared) -> ! {
    app::settings::run(&mut flash, SETTINGS, shared, &mut SettingsBoard).await
}

/// The reset, for the settings task.
struct SettingsBoard;

impl app::settings::Board for SettingsBoard {
    fn widen_watchdog(&mut self, _wide: bool) {
        // No flash erase stalls the emulated CPU: the watchdog needs no widening.
    }

    fn restart(&mut self, _into: ringpod_core::controller::Restart) -> ! {
        // SYSRESETREQ: QEMU resets the machine; the retained RAM (settings flash) stays. The emulated board has no
        // ROM bootloader: a request for it restarts the controller.
        cortex_m::peripheral::SCB::sys_reset()
    }
}

static SHARED: StaticCell<Shared> = StaticCell::new();
static WORLD: StaticCell<WorldCell> = StaticCell::new();

/// Whether the semihosting command line holds `word`.
fn command_line_has(word: &[u8]) -> bool {
    let mut buf = [0u8; 128];
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: SYS_GET_CMDLINE writes at most `buf.len()` bytes into `buf` and the length into `block`; both are
    // passed as pointers that may be written through (the debugger writes them while the CPU waits).
    let failed =
        unsafe { cortex_m_semihosting::syscall1(cortex_m_semihosting::nr::GET_CMDLINE, block.as_mut_ptr() as usize) };
    let len = block[1].min(buf.len());
    failed == 0 && buf[..len].split(|b| *b == b' ' || *b == 0).any(|w| w == word)
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let watchdog_reset = retained::take_watchdog_reset();
    let mut core = match cortex_m::Peripherals::take() {
        Some(p) => p,
        None => fail("core peripherals"),
    };
    time::start(&mut core.SYST);
    uart::init();
    // SAFETY: the handler above is ready for the RX interrupt.
    unsafe { NVIC::unmask(Irq(uart::RX_IRQ)) };

    // Settings as the STM32 board restores them: the compiled-in defaults with what flash holds replayed over them.
    let mut flash = retained::flash();
    let (mut config, restored) = app::settings::restore(&mut flash, SETTINGS).await;
    let measure_latency = command_line_has(b"latency");
    if measure_latency && command_line_has(b"direct") {
        config.pipeline.follow = FollowMode::Direct;
    }
    let controller = Controller::new(config).unwrap_or_else(|_| fail("configuration"));
    let timing = config.pulse_timing().unwrap_or_else(|_| fail("step timing"));
    let renderer = PulseRenderer::new(PORT_MAP, timing).unwrap_or_else(|_| fail("pin map"));

    let drivers = DriverInputs::new(PORT_MAP, STEP_SLOT_NS, config.scheduler);
    // The machine of the rig that runs (the trainer model unless another was stored), parked where the host
    // simulator parks it, so that the same input ends at the same steps.
    let plant = match restored.rig {
        RigSource::Stored => Plant::for_config(&config),
        _ => Plant::trainer_model(TRAINER_MODEL_PARKED),
    };
    let mut world = World::new(plant, drivers);
    world.estop_on_aux2 = command_line_has(b"estop-on-aux2");
    let world: &'static WorldCell = WORLD.init(Mutex::new(RefCell::new(world)));
    let mut pins = Pins { world, last: 0 };
    let first = ringpod_firmware::app::inputs::InputPins::read(&mut pins);
    let shared: &'static Shared = SHARED.init(Shared::new(controller, first));
    shared.with(|c| c.set_rig_source(restored.rig));
    if restored.rig != RigSource::Compiled {
        hprintln!("RIG {} ({:?})", config.rig().name(), restored.rig);
    }
    if watchdog_reset {
        hprintln!("RESET watchdog");
        shared.with(|c| c.watchdog_reset());
    }
    if restored.applied > 0 || restored.refused > 0 || restored.unreadable {
        hprintln!(
            "SETTINGS {} restored, {} refused{}",
            restored.applied,
            restored.refused,
            if restored.unreadable { ", flash unreadable" } else { "" }
        );
    }

    let period = Duration::from_micros(u64::from(config.pipeline.tick_us));
    let port = Port {
        world,
        shared,
        period,
        busy_until: Instant::now(),
        pending: [0; MAX_STEP_SLOTS],
        pending_len: 0,
    };
    let controls = Controls {
        world,
        shared,
        stall_when_homed: command_line_has(b"stall-when-homed") && !watchdog_reset,
    };
    watchdog::start(WATCHDOG_US);
    spawner.spawn(steps_task(port, renderer, shared).unwrap_or_else(|_| fail("spawn")));
    spawner.spawn(control_task(controls, shared).unwrap_or_else(|_| fail("spawn")));
    spawner.spawn(inputs_task(pins, shared).unwrap_or_else(|_| fail("spawn")));
    spawner.spawn(link_task(UartLink, shared).unwrap_or_else(|_| fail("spawn")));
    spawner.spawn(settings_task(flash, shared).unwrap_or_else(|_| fail("spawn")));
    if measure_latency {
        spawner.spawn(latency::host(shared).unwrap_or_else(|_| fail("spawn")));
    }
    hprintln!("READY");
}

/// defmt's output goes nowhere here: the program reports over semihosting and the host reads the device's state
/// over the protocol.
#[defmt::global_logger]
struct NoLog;

// SAFETY: a logger that does nothing is trivially sound.
unsafe impl defmt::Logger for NoLog {
    fn acquire() {}
    unsafe fn flush() {}
    unsafe fn release() {}
    unsafe fn write(_bytes: &[u8]) {}
}
