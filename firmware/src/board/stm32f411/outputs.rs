//! The outputs, each set to its safe level as it becomes an output: the relays, the driver enable and the auxiliary
//! outputs the control task switches (through [`Machine`]), and the STEP/DIR pins the step generator's DMA writes.

use embassy_stm32::gpio::{Level, Output, Speed};
use ringpod_core::safety::pins::OutputPin;
use ringpod_firmware::app::{self, control::Machine, Shared};

use super::resources::{OutputPins, SensePins, StepDirPins, UartParts, PORT_MAP, SPARE_MAP};
use super::watchdog;

/// Relays, driver enable, cycle counter, watchdog: the control loop's hardware.
pub struct BlackPill {
    logic_relay: Output<'static>,
    power_relay: Output<'static>,
    driver_enable_n: Output<'static>,
    aux: [Output<'static>; 2],
}

impl Machine for BlackPill {
    fn write(&mut self, pin: OutputPin, on: bool) {
        match pin {
            // ENABLE is active low on the drivers.
            OutputPin::DriverEnable => self.driver_enable_n.set_level(Level::from(!on)),
            OutputPin::LogicRelay => self.logic_relay.set_level(Level::from(on)),
            OutputPin::PowerRelay => self.power_relay.set_level(Level::from(on)),
            OutputPin::Aux1 => self.aux[0].set_level(Level::from(on)),
            OutputPin::Aux2 => self.aux[1].set_level(Level::from(on)),
        }
    }

    fn cycles(&self) -> u32 {
        cortex_m::peripheral::DWT::cycle_count()
    }

    fn feed_watchdog(&mut self) {
        watchdog::pet();
    }
}

/// Drivers disabled, relays and auxiliary outputs off: the first pins the board drives.
pub fn safe_state(r: OutputPins) -> BlackPill {
    let driver_enable_n = Output::new(r.driver_enable_n, Level::High, Speed::Low);
    let logic_relay = Output::new(r.logic_relay, Level::Low, Speed::Low);
    let power_relay = Output::new(r.power_relay, Level::Low, Speed::Low);
    let aux = [
        Output::new(r.aux1, Level::Low, Speed::Low),
        Output::new(r.aux2, Level::Low, Speed::Low),
    ];
    BlackPill {
        logic_relay,
        power_relay,
        driver_enable_n,
        aux,
    }
}

/// STEP low and DIR at its idle level, as outputs for the life of the program: the DMA writes their levels through
/// BSRR from then on.
pub fn hold_step_dir(r: StepDirPins) {
    let idle = PORT_MAP.idle_word();
    let level = |pin: u8| Level::from(idle & (1 << pin) != 0);
    let step_dir = [
        Output::new(r.step1, level(0), Speed::VeryHigh),
        Output::new(r.step2, level(1), Speed::VeryHigh),
        Output::new(r.step3, level(2), Speed::VeryHigh),
        Output::new(r.step4, level(3), Speed::VeryHigh),
        Output::new(r.step5, level(4), Speed::VeryHigh),
        Output::new(r.step6, level(5), Speed::VeryHigh),
        Output::new(r.dir1, level(6), Speed::VeryHigh),
        Output::new(r.dir2, level(7), Speed::VeryHigh),
        Output::new(r.dir3, level(8), Speed::VeryHigh),
        Output::new(r.dir4, level(9), Speed::VeryHigh),
        Output::new(r.dir5, level(10), Speed::VeryHigh),
        Output::new(r.dir6, level(12), Speed::VeryHigh),
    ];
    // Dropping an `Output` would make the pin an input again.
    core::mem::forget(step_dir);
}

/// STEP7 (PA9) and STEP8 (PA15) low, DIR7 (PA10) and DIR8 (PC14) at their idle level, as outputs for the life of the
/// program, from the pins of the supply senses and the USART1 link. PC14 is in the backup domain: low speed only
/// (the F411 datasheet's pin table: at most 2 MHz through the power switch), enough for a DIR level, which is set
/// up microseconds before its step.
pub fn hold_spare(senses: SensePins, uart: UartParts) {
    let idle = SPARE_MAP.idle_word();
    let level = |pin: u8| Level::from(idle & (1 << pin) != 0);
    let spare = (
        Output::new(senses.logic_ok, level(9), Speed::VeryHigh),
        Output::new(uart.rx, level(10), Speed::VeryHigh),
        Output::new(uart.tx, level(15), Speed::VeryHigh),
        Output::new(senses.power_ok, level(14), Speed::Low),
    );
    core::mem::forget(spare);
}

#[embassy_executor::task]
pub async fn control_task(mut machine: BlackPill, shared: &'static Shared) -> ! {
    app::control::run(&mut machine, shared).await
}
