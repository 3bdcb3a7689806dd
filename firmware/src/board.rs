//! Board support for the STM32F411CE "Black Pill": clocks and the safety-relevant outputs.
//!
//! Another board (F446, G474, H743) is another module like this one plus its `memory.x`.

use embassy_stm32::gpio::{Level, Output, Pin, Speed};
use embassy_stm32::{rcc, time::Hertz, Config, Peri};

/// Clock tree from the 25 MHz HSE crystal. USB needs exactly 48 MHz from the same PLL as the core, and no VCO
/// frequency gives both 100 MHz (PLLP) and 48 MHz (PLLQ), so the core runs at 96 MHz:
/// VCO  = 25 MHz / 25 (PLLM) * 384 (PLLN) = 384 MHz
/// SYSCLK = 384 MHz / 4 (PLLP) = 96 MHz;  USB = 384 MHz / 8 (PLLQ) = 48 MHz
/// APB1 = 96 / 2 = 48 MHz (max 50), APB2 = 96 MHz (max 100).
pub fn clocks() -> Config {
    let mut config = Config::default();
    config.rcc.hse = Some(rcc::Hse {
        freq: Hertz(25_000_000),
        mode: rcc::HseMode::Oscillator,
    });
    config.rcc.pll_src = rcc::PllSource::HSE;
    config.rcc.pll = Some(rcc::Pll {
        prediv: rcc::PllPreDiv::DIV25,
        mul: rcc::PllMul::MUL384,
        divp: Some(rcc::PllPDiv::DIV4),
        divq: Some(rcc::PllQDiv::DIV8),
        divr: None,
    });
    config.rcc.ahb_pre = rcc::AHBPrescaler::DIV1;
    config.rcc.apb1_pre = rcc::APBPrescaler::DIV2;
    config.rcc.apb2_pre = rcc::APBPrescaler::DIV1;
    config.rcc.sys = rcc::Sysclk::PLL1_P;
    config
}

/// The outputs that can energise the machine, driven to their safe level at construction.
///
/// Owning them is the point: dropping an embassy `Output` returns the pin to a floating input, which must never
/// happen to a relay or enable line. The supervisor task of the firmware issue will drive them.
#[allow(dead_code)]
pub struct SafeOutputs<'d> {
    /// Logic supply relay (LOGIC_EN), off.
    pub logic_relay: Output<'d>,
    /// Power supply relay (POWER_EN), off.
    pub power_relay: Output<'d>,
    /// Stepper driver enable (active low on common drivers): high = disabled.
    pub driver_enable_n: Output<'d>,
}

impl<'d> SafeOutputs<'d> {
    /// Claims the relay and enable pins in their safe state.
    pub fn new(logic: Peri<'d, impl Pin>, power: Peri<'d, impl Pin>, enable_n: Peri<'d, impl Pin>) -> Self {
        Self {
            logic_relay: Output::new(logic, Level::Low, Speed::Low),
            power_relay: Output::new(power, Level::Low, Speed::Low),
            driver_enable_n: Output::new(enable_n, Level::High, Speed::Low),
        }
    }
}
