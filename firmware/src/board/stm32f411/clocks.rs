//! The clock tree.

use embassy_stm32::time::Hertz;
use embassy_stm32::{rcc, Config};

/// The core clock the tree below gives (the cycle counter's rate).
pub const SYSCLK_HZ: u32 = 96_000_000;

/// Clock tree from the 25 MHz HSE crystal. USB needs exactly 48 MHz from the same PLL as the core, and no VCO
/// frequency gives both 100 MHz (PLLP) and 48 MHz (PLLQ), so the core runs at 96 MHz:
/// VCO  = 25 MHz / 25 (PLLM) * 384 (PLLN) = 384 MHz
/// SYSCLK = 384 MHz / 4 (PLLP) = 96 MHz;  USB = 384 MHz / 8 (PLLQ) = 48 MHz
/// APB1 = 96 / 2 = 48 MHz (max 50), APB2 = 96 MHz (max 100); TIM1 on APB2 counts at 96 MHz: 2.5 us = 240 counts.
pub fn config() -> Config {
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
