//! The pin map as code: which peripherals each bring-up step takes (embassy's `Peripherals` split by job with
//! `assign_resources!`), the interrupts the drivers bind, and the STEP/DIR bits of port B.

use assign_resources::assign_resources;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::{bind_interrupts, dma, exti, interrupt, peripherals, usart, usb, Peri};
use ringpod_core::motion::pulse::PortMap;

bind_interrupts!(pub struct Irqs {
    OTG_FS => usb::InterruptHandler<peripherals::USB_OTG_FS>;
    USART1 => usart::InterruptHandler<peripherals::USART1>;
    DMA2_STREAM1 => dma::InterruptHandler<peripherals::DMA2_CH1>;
    DMA2_STREAM2 => dma::InterruptHandler<peripherals::DMA2_CH2>;
    DMA2_STREAM5 => dma::InterruptHandler<peripherals::DMA2_CH5>;
    DMA2_STREAM7 => dma::InterruptHandler<peripherals::DMA2_CH7>;
    EXTI0 => exti::InterruptHandler<interrupt::typelevel::EXTI0>;
    EXTI1 => exti::InterruptHandler<interrupt::typelevel::EXTI1>;
    EXTI2 => exti::InterruptHandler<interrupt::typelevel::EXTI2>;
    EXTI3 => exti::InterruptHandler<interrupt::typelevel::EXTI3>;
    EXTI4 => exti::InterruptHandler<interrupt::typelevel::EXTI4>;
    EXTI9_5 => exti::InterruptHandler<interrupt::typelevel::EXTI9_5>;
    EXTI15_10 => exti::InterruptHandler<interrupt::typelevel::EXTI15_10>;
});

/// The step generator's feeder (the interrupt executor on USART6) renders the next period while the DMA plays the
/// current one: it has a whole period for that, so only short handlers may pre-empt it: the DMA interrupts (their
/// handlers note a transfer's progress and wake; `dma_interrupt_priority`, P0 by default), among them the one that
/// wakes it. USART1 receives and sends through DMA, so no byte waits for a handler. Lower numbers pre-empt higher
/// ones; the F411 implements 4 priority bits (PM0214 4.3.7).
pub const STEP_EXECUTOR_PRIORITY: Priority = Priority::P1;
/// Embassy's time driver (TIM5): below the step executor, above USB and the switches, so that a long USB handler
/// does not delay the clock's half-period interrupt.
const TIME_PRIORITY: Priority = Priority::P2;
/// USB (its core buffers whole packets and NAKs the host while it is busy), USART1 (its handler sees an idle line or
/// a line error; the bytes go through DMA) and the switches' edges (debounced over milliseconds): their handlers only
/// move packets and wake tasks in thread mode.
const IO_PRIORITY: Priority = Priority::P3;

/// Gives every enabled interrupt but the step generator's its priority (embassy's drivers enable theirs at P0).
pub fn set_priorities() {
    interrupt::TIM5.set_priority(TIME_PRIORITY);
    for irq in [
        interrupt::OTG_FS,
        interrupt::USART1,
        interrupt::EXTI0,
        interrupt::EXTI1,
        interrupt::EXTI2,
        interrupt::EXTI3,
        interrupt::EXTI4,
        interrupt::EXTI9_5,
        interrupt::EXTI15_10,
    ] {
        irq.set_priority(IO_PRIORITY);
    }
}

/// STEP on PB0-PB5, DIR on PB6-PB10 and PB12 (PB11 is not bonded out on the F411CE's package).
pub const PORT_MAP: PortMap = PortMap {
    step: [0, 1, 2, 3, 4, 5],
    dir: [6, 7, 8, 9, 10, 12],
    dir_forward_low: 0,
};

/// The spare axes 7 and 8 as a renderer's axes 0 and 1 (STEP7 PA9, DIR7 PA10, STEP8 PA15, DIR8 PC14), on one
/// word of bit positions shared by ports A and C: its [`SPARE_PORT_A`] bits go to `GPIOA.BSRR`, its
/// [`SPARE_PORT_C`] bits to `GPIOC.BSRR` (PC14 is bit 14, a bit no port A pin of the map uses). Axes 2-5 are never
/// given steps; their pins are only there to make a valid map and are masked off.
pub const SPARE_MAP: PortMap = PortMap {
    step: [9, 15, 0, 1, 2, 3],
    dir: [10, 14, 4, 5, 6, 7],
    dir_forward_low: 0,
};
/// The set and reset bits of STEP7 (PA9), DIR7 (PA10) and STEP8 (PA15) in [`SPARE_MAP`]'s words.
pub const SPARE_PORT_A: u32 = set_reset(SPARE_MAP.step[0]) | set_reset(SPARE_MAP.dir[0]) | set_reset(SPARE_MAP.step[1]);
/// The set and reset bits of DIR8 (PC14) in [`SPARE_MAP`]'s words.
pub const SPARE_PORT_C: u32 = set_reset(SPARE_MAP.dir[1]);

/// A pin's set (BSy) and reset (BRy) bits in a BSRR word (RM0383 8.4.7).
const fn set_reset(pin: u8) -> u32 {
    (1 << pin) | (1 << (pin + 16))
}

assign_resources! {
    /// Driver enable (active low), the two supply relays and the auxiliary outputs.
    outputs: OutputPins {
        driver_enable_n: PB13,
        logic_relay: PB14,
        power_relay: PB15,
        aux1: PC15,
        aux2: PC13,
    }
    /// STEP 1-6 and DIR 1-6, all on port B ([`PORT_MAP`]).
    step_dir: StepDirPins {
        step1: PB0,
        step2: PB1,
        step3: PB2,
        step4: PB3,
        step5: PB4,
        step6: PB5,
        dir1: PB6,
        dir2: PB7,
        dir3: PB8,
        dir4: PB9,
        dir5: PB10,
        dir6: PB12,
    }
    /// The switches, each with its EXTI line (the order of `switches::SWITCH_BITS`).
    switches: SwitchPins {
        estop: PA0,
        estop_line: EXTI0,
        home1: PA1,
        home1_line: EXTI1,
        home2: PA2,
        home2_line: EXTI2,
        home3: PA3,
        home3_line: EXTI3,
        home4: PA4,
        home4_line: EXTI4,
        home5: PA5,
        home5_line: EXTI5,
        home6: PA6,
        home6_line: EXTI6,
        limit5: PA7,
        limit5_line: EXTI7,
        limit6: PA8,
        limit6_line: EXTI8,
    }
    /// The supply senses LOGIC_OK (PA9) and POWER_OK (PC14) with their EXTI lines; with a spare axis fitted, the
    /// pins are STEP7 and DIR8.
    senses: SensePins {
        logic_ok: PA9,
        logic_ok_line: EXTI9,
        power_ok: PC14,
        power_ok_line: EXTI14,
    }
    /// The step generator: TIM1's update paces DMA2 stream 5 into GPIOB's BSRR.
    step_generator: StepGeneratorParts {
        dma: DMA2_CH5,
        timer: TIM1,
    }
    /// The spare axes' rings: TIM1's compare 1 paces DMA2 stream 1 into GPIOA's BSRR, compare 2 stream 2 into
    /// GPIOC's (channel 6 both, RM0383 9.3.3, table 28). Without spare axes, stream 2 is USART1's receive ring
    /// (channel 4): the only other stream USART1_RX has is the step generator's 5, and TIM1_CH2's other one (stream 6
    /// channel 0) also takes compare 1's and 3's requests.
    spare_dma: SpareDmaParts {
        port_a: DMA2_CH1,
        port_c: DMA2_CH2,
    }
    /// USB OTG FS on PA12 (D+) and PA11 (D-).
    usb: UsbParts {
        otg: USB_OTG_FS,
        dp: PA12,
        dm: PA11,
    }
    /// USART1 on RX PA10 and TX PA15, sending through DMA2 stream 7 (channel 4); with a spare axis fitted, the
    /// pins are DIR7 and STEP8.
    uart: UartParts {
        usart: USART1,
        rx: PA10,
        tx: PA15,
        tx_dma: DMA2_CH7,
    }
    /// The flash controller (settings in sectors 6 and 7).
    settings: SettingsParts {
        flash: FLASH,
    }
}
