//! Board: STM32F411CE "Black Pill" (25 MHz crystal, USB-C, 512 KiB flash, 128 KiB RAM).
//!
//! Everything specific to this chip is here: clocks, the pin map, interrupt bindings, USB CDC-ACM and the USART1
//! link, the TIM1 + DMA2 step generator, EXTI switch inputs, the independent watchdog and the settings flash. Another STM32
//! (F446, G474, H743) is another module like this one plus its `memory.x`; `app` stays as it is.
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
//! All STEP and DIR pins are on port B so that one 32-bit write to `GPIOB.BSRR` sets and clears all of them at
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

use core::future::poll_fn;
use core::task::Poll;

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::dma::{self, TransferOptions, WritableRingBuffer};
use embassy_stm32::exti::{self, ExtiInput};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::gpio::{Level, Output, Pull, Speed};
use embassy_stm32::interrupt::{self, InterruptExt, Priority};
use embassy_stm32::mode::Async;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use embassy_stm32::timer::UpDma;
use embassy_stm32::usart::{self, BufferedUart};
use embassy_stm32::usb::{self, Driver};
use embassy_stm32::{bind_interrupts, pac, peripherals, rcc, Config, Peri};
use embassy_time::Instant;
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use embassy_usb::{Builder, UsbDevice};
use ringpod_core::controller::Controller;
use ringpod_core::motion::pulse::MAX_STEP_SLOTS;
use ringpod_core::motion::pulse::{PortMap, PulseRenderer};
use ringpod_core::protocol::RigSource;
use ringpod_core::safety::debounce::InputBit;
use ringpod_core::safety::pins::OutputPin;
use static_cell::StaticCell;
use {defmt_rtt as _, panic_probe as _};

use ringpod_firmware::app::link::{Disconnected, Link};
use ringpod_firmware::app::steps::{Overrun, PortOutput};
use ringpod_firmware::app::{self, control::Machine, inputs::InputPins, Shared};

bind_interrupts!(struct Irqs {
    OTG_FS => usb::InterruptHandler<peripherals::USB_OTG_FS>;
    USART1 => usart::BufferedInterruptHandler<peripherals::USART1>;
    DMA2_STREAM5 => dma::InterruptHandler<peripherals::DMA2_CH5>;
    EXTI0 => exti::InterruptHandler<interrupt::typelevel::EXTI0>;
    EXTI1 => exti::InterruptHandler<interrupt::typelevel::EXTI1>;
    EXTI2 => exti::InterruptHandler<interrupt::typelevel::EXTI2>;
    EXTI3 => exti::InterruptHandler<interrupt::typelevel::EXTI3>;
    EXTI4 => exti::InterruptHandler<interrupt::typelevel::EXTI4>;
    EXTI9_5 => exti::InterruptHandler<interrupt::typelevel::EXTI9_5>;
    EXTI15_10 => exti::InterruptHandler<interrupt::typelevel::EXTI15_10>;
});

/// STEP on PB0-PB5, DIR on PB6-PB10 and PB12 (PB11 is not bonded out on the F411CE's package).
pub const PORT_MAP: PortMap = PortMap {
    step: [0, 1, 2, 3, 4, 5],
    dir: [6, 7, 8, 9, 10, 12],
    dir_forward_low: 0,
};

/// The settings live in flash sectors 6 and 7 (0x0804_0000-0x0807_FFFF, two 128 KiB erase pages); `memory.x`
/// gives the program the first 256 KiB. Offsets are from the start of flash.
const SETTINGS: core::ops::Range<u32> = 0x0004_0000..0x0008_0000;

/// The USART link's baud rate (8N1): a 1 kHz stream of setpoints is about 45 kB/s, beyond 115200 baud. APB2 at
/// 96 MHz gives 923,077 baud (+0.16 %), within any adapter's tolerance.
pub const USART_BAUD: u32 = 921_600;

/// Normal watchdog timeout: 50 control periods.
const WATCHDOG_US: u32 = 50_000;
/// While a settings write may erase a 128 KiB sector (up to 2 s at 3.3 V with x32 parallelism): supplies are off.
const WATCHDOG_FLASH_US: u32 = 4_000_000;

/// The step generator's DMA ring: room for two periods of the longest buffer. It runs over two periods of the
/// configured one, so that its half-transfer and transfer-complete interrupts fall on the period boundaries: the
/// renderer is one period ahead of the pins, no more (a longer ring would hold setpoints back by its length).
const RING: usize = 2 * MAX_STEP_SLOTS;

/// Clock tree from the 25 MHz HSE crystal. USB needs exactly 48 MHz from the same PLL as the core, and no VCO
/// frequency gives both 100 MHz (PLLP) and 48 MHz (PLLQ), so the core runs at 96 MHz:
/// VCO  = 25 MHz / 25 (PLLM) * 384 (PLLN) = 384 MHz
/// SYSCLK = 384 MHz / 4 (PLLP) = 96 MHz;  USB = 384 MHz / 8 (PLLQ) = 48 MHz
/// APB1 = 96 / 2 = 48 MHz (max 50), APB2 = 96 MHz (max 100); TIM1 on APB2 counts at 96 MHz: 2.5 us = 240 counts.
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

/// The independent watchdog, on its registers: embassy's driver cannot change the timeout once running, and a
/// settings write must widen it over a sector erase.
mod watchdog {
    use embassy_stm32::pac;
    use embassy_stm32::pac::iwdg::vals::{Key, Pr};

    /// LSI (32 kHz nominal) / 256 = 125 Hz: 8 ms per count, up to 32.7 s.
    fn set(timeout_us: u32) {
        let iwdg = pac::IWDG;
        wait_updated();
        iwdg.kr().write(|w| w.set_key(Key::ENABLE));
        iwdg.pr().write(|w| w.set_pr(Pr::DIVIDE_BY256));
        let counts = (timeout_us / 8_000).clamp(1, 0x0fff);
        iwdg.rlr().write(|w| w.set_rl(counts as u16));
        // The counter lives in the VDD domain: PR and RLR reach it up to 5 LSI periods (at most 0.3 ms) after the
        // write, while IWDG_SR's PVU/RVU read 1 (RM0383 15.4.4). A reload before then loads the old value, so a
        // widening for a sector erase would leave 48 ms, and the erase stalls the CPU for up to 2 s.
        wait_updated();
        pet();
    }

    fn wait_updated() {
        let iwdg = pac::IWDG;
        while iwdg.sr().read().pvu() || iwdg.sr().read().rvu() {}
    }

    /// Starts the watchdog with `timeout_us` (it cannot be stopped again).
    pub fn start(timeout_us: u32) {
        pac::IWDG.kr().write(|w| w.set_key(Key::START));
        set(timeout_us);
    }

    /// Changes the timeout.
    pub fn set_timeout(timeout_us: u32) {
        set(timeout_us);
    }

    /// Reloads the counter.
    pub fn pet() {
        pac::IWDG.kr().write(|w| w.set_key(Key::RESET));
    }

    /// Whether the last reset came from the watchdog; clears the reset flags.
    pub fn caused_last_reset() -> bool {
        let rcc = pac::RCC;
        let was = rcc.csr().read().wdgrstf();
        rcc.csr().modify(|w| w.set_rmvf(true));
        was
    }
}

/// Relays, driver enable, cycle counter, watchdog: the control loop's hardware.
struct BlackPill {
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

/// The switch inputs on PA0-PA9 and PC14 (order of `InputBit`).
struct Switches {
    pins: [ExtiInput<'static, Async>; 11],
}

/// Which logical bit each of `Switches::pins` is.
const SWITCH_BITS: [InputBit; 11] = [
    InputBit::EStop,
    InputBit::Home(0),
    InputBit::Home(1),
    InputBit::Home(2),
    InputBit::Home(3),
    InputBit::Home(4),
    InputBit::Home(5),
    InputBit::Limit(4),
    InputBit::Limit(5),
    InputBit::LogicOk,
    InputBit::PowerOk,
];

/// The inputs this board has no pin for (far ends of carriages 1-4) read high, as an open switch to ground on a
/// pull-up does: inactive with the default wiring, instead of four limit switches always tripped.
const UNWIRED_HIGH: u16 =
    InputBit::Limit(0).mask() | InputBit::Limit(1).mask() | InputBit::Limit(2).mask() | InputBit::Limit(3).mask();

impl InputPins for Switches {
    fn read(&mut self) -> u16 {
        self.pins
            .iter()
            .zip(SWITCH_BITS)
            .fold(UNWIRED_HIGH, |w, (p, b)| if p.is_high() { w | b.mask() } else { w })
    }

    async fn edge(&mut self) {
        let waits = self.pins.each_mut().map(|p| p.wait_for_any_edge());
        embassy_futures::select::select_array(waits).await;
    }
}

/// USB CDC-ACM: 64-byte packets; a write that ends on a full packet is closed by a zero-length packet.
struct UsbLink {
    class: CdcAcmClass<'static, Driver<'static, peripherals::USB_OTG_FS>>,
}

impl Link for UsbLink {
    async fn connected(&mut self) {
        self.class.wait_connection().await;
    }

    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected> {
        self.class.read_packet(buf).await.map_err(|_| Disconnected)
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected> {
        for chunk in bytes.chunks(64) {
            self.class.write_packet(chunk).await.map_err(|_| Disconnected)?;
        }
        if bytes.len().is_multiple_of(64) {
            self.class.write_packet(&[]).await.map_err(|_| Disconnected)?;
        }
        Ok(())
    }
}

/// USART1 through embassy's interrupt-driven buffered driver. A UART has no connection to wait for; line errors
/// (noise, framing, overrun) are logged by the driver and the frame they damaged is answered as malformed.
struct UartLink {
    uart: BufferedUart<'static>,
}

impl Link for UartLink {
    async fn connected(&mut self) {}

    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected> {
        loop {
            if let Ok(n @ 1..) = embedded_io_async::Read::read(&mut self.uart, buf).await {
                return Ok(n);
            }
        }
    }

    /// In pieces of at most half the transmit buffer, each sent before the next: embassy's buffered write refuses
    /// a slice longer than its buffer, and waits for room without a waker when the slice does not fit.
    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected> {
        for chunk in bytes.chunks(UART_BUF / 2) {
            embedded_io_async::Write::write_all(&mut self.uart, chunk)
                .await
                .map_err(|_| Disconnected)?;
            embedded_io_async::Write::flush(&mut self.uart)
                .await
                .map_err(|_| Disconnected)?;
        }
        Ok(())
    }
}

/// Bytes of each of USART1's software buffers.
const UART_BUF: usize = 256;

/// The DMA ring into GPIOB.BSRR.
struct DmaPort {
    ring: WritableRingBuffer<'static, u32>,
}

impl PortOutput for DmaPort {
    async fn room(&mut self, words: usize) -> Result<Instant, Overrun> {
        // The ring is two periods: its half-transfer and transfer-complete interrupts are the period boundaries,
        // and wake this (at the step executor's priority, so the instant is the boundary's to a few cycles).
        let free = poll_fn(|cx| {
            self.ring.set_waker(cx.waker());
            match self.ring.len() {
                Ok(free) if free < words => Poll::Pending,
                other => Poll::Ready(other),
            }
        })
        .await;
        match free {
            Ok(_) => Ok(Instant::now()),
            Err(_) => {
                // Lapped: start the ring afresh (the step generator's fault is latched by the caller).
                self.ring.clear();
                Err(Overrun)
            }
        }
    }

    fn write(&mut self, words: &[u32]) -> Result<(), Overrun> {
        match self.ring.write(words) {
            Ok((written, _)) if written == words.len() => Ok(()),
            _ => Err(Overrun),
        }
    }
}

static SHARED: StaticCell<Shared> = StaticCell::new();
static STEP_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

/// The step generator's executor runs in the USART6 interrupt (unused on this board), above everything else.
#[embassy_stm32::interrupt]
#[allow(non_snake_case)]
unsafe fn USART6() {
    // SAFETY: the executor is started on this interrupt below and this is its only handler.
    unsafe { STEP_EXECUTOR.on_interrupt() }
}

#[embassy_executor::task]
async fn usb_task(mut device: UsbDevice<'static, Driver<'static, peripherals::USB_OTG_FS>>) -> ! {
    device.run().await
}

#[embassy_executor::task]
async fn link_task(mut link: UsbLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 0, shared).await
}

#[embassy_executor::task]
async fn uart_link_task(mut link: UartLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 1, shared).await
}

#[embassy_executor::task]
async fn control_task(mut machine: BlackPill, shared: &'static Shared) -> ! {
    app::control::run(&mut machine, shared).await
}

#[embassy_executor::task]
async fn inputs_task(mut switches: Switches, shared: &'static Shared) -> ! {
    app::inputs::run(&mut switches, shared).await
}

#[embassy_executor::task]
async fn steps_task(mut port: DmaPort, renderer: PulseRenderer, shared: &'static Shared) -> ! {
    app::steps::run(&mut port, renderer, shared).await
}

#[embassy_executor::task]
async fn settings_task(mut flash: BlockingAsync<Flash<'static, Blocking>>, shared: &'static Shared) -> ! {
    app::settings::run(&mut flash, SETTINGS, shared, &mut SettingsBoard).await
}

/// The watchdog and the reset, for the settings task.
struct SettingsBoard;

impl app::settings::Board for SettingsBoard {
    fn widen_watchdog(&mut self, wide: bool) {
        watchdog::set_timeout(if wide { WATCHDOG_FLASH_US } else { WATCHDOG_US })
    }

    fn restart(&mut self) -> ! {
        cortex_m::peripheral::SCB::sys_reset()
    }
}

/// Brings the board up and spawns the tasks.
pub async fn start(spawner: Spawner) {
    let watchdog_reset = watchdog::caused_last_reset();
    let p = embassy_stm32::init(clocks());

    // Safe state first: drivers disabled, relays off, STEP low and DIR at its idle level, before anything else.
    // (During reset and clock start-up the pins float: the wiring's pull resistors hold the same levels.)
    let driver_enable_n = Output::new(p.PB13, Level::High, Speed::Low);
    let logic_relay = Output::new(p.PB14, Level::Low, Speed::Low);
    let power_relay = Output::new(p.PB15, Level::Low, Speed::Low);
    let aux = [
        Output::new(p.PC15, Level::Low, Speed::Low),
        Output::new(p.PC13, Level::Low, Speed::Low),
    ];
    let idle = PORT_MAP.idle_word();
    let level = |pin: u8| Level::from(idle & (1 << pin) != 0);
    let _step_dir = [
        Output::new(p.PB0, level(0), Speed::VeryHigh),
        Output::new(p.PB1, level(1), Speed::VeryHigh),
        Output::new(p.PB2, level(2), Speed::VeryHigh),
        Output::new(p.PB3, level(3), Speed::VeryHigh),
        Output::new(p.PB4, level(4), Speed::VeryHigh),
        Output::new(p.PB5, level(5), Speed::VeryHigh),
        Output::new(p.PB6, level(6), Speed::VeryHigh),
        Output::new(p.PB7, level(7), Speed::VeryHigh),
        Output::new(p.PB8, level(8), Speed::VeryHigh),
        Output::new(p.PB9, level(9), Speed::VeryHigh),
        Output::new(p.PB10, level(10), Speed::VeryHigh),
        Output::new(p.PB12, level(12), Speed::VeryHigh),
    ];
    // The pins stay outputs for the life of the program; the DMA writes their levels through BSRR.
    core::mem::forget(_step_dir);

    let mut core = unwrap_core();
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();

    // Settings: the compiled-in defaults with what flash holds replayed over them.
    let mut flash = BlockingAsync::new(Flash::new_blocking(p.FLASH));
    let (config, restored) = app::settings::restore(&mut flash, SETTINGS).await;
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

    let switches = Switches {
        pins: [
            ExtiInput::new(p.PA0, p.EXTI0, Pull::None, Irqs),
            ExtiInput::new(p.PA1, p.EXTI1, Pull::Up, Irqs),
            ExtiInput::new(p.PA2, p.EXTI2, Pull::Up, Irqs),
            ExtiInput::new(p.PA3, p.EXTI3, Pull::Up, Irqs),
            ExtiInput::new(p.PA4, p.EXTI4, Pull::Up, Irqs),
            ExtiInput::new(p.PA5, p.EXTI5, Pull::Up, Irqs),
            ExtiInput::new(p.PA6, p.EXTI6, Pull::Up, Irqs),
            ExtiInput::new(p.PA7, p.EXTI7, Pull::Up, Irqs),
            ExtiInput::new(p.PA8, p.EXTI8, Pull::Up, Irqs),
            ExtiInput::new(p.PA9, p.EXTI9, Pull::Down, Irqs),
            ExtiInput::new(p.PC14, p.EXTI14, Pull::Down, Irqs),
        ],
    };
    let mut switches = switches;
    let shared: &'static Shared = SHARED.init(Shared::new(controller, switches.read()));
    shared.with(|c| c.set_rig_source(restored.rig));
    if watchdog_reset {
        defmt::error!("the last reset was the watchdog's");
        shared.with(|c| c.watchdog_reset());
    }

    let ring = step_generator(p.DMA2_CH5, p.TIM1, 2 * renderer.timing().slots);

    interrupt::USART6.set_priority(Priority::P1);
    let high = STEP_EXECUTOR.start(interrupt::USART6);
    high.spawn(defmt::unwrap!(steps_task(DmaPort { ring }, renderer, shared)));

    let (device, class) = usb(p.USB_OTG_FS, p.PA12, p.PA11);

    let uart = usart1(p.USART1, p.PA10, p.PA15);

    watchdog::start(WATCHDOG_US);
    let machine = BlackPill {
        logic_relay,
        power_relay,
        driver_enable_n,
        aux,
    };
    spawner.spawn(defmt::unwrap!(control_task(machine, shared)));
    spawner.spawn(defmt::unwrap!(inputs_task(switches, shared)));
    spawner.spawn(defmt::unwrap!(usb_task(device)));
    spawner.spawn(defmt::unwrap!(link_task(UsbLink { class }, shared)));
    spawner.spawn(defmt::unwrap!(uart_link_task(UartLink { uart }, shared)));
    spawner.spawn(defmt::unwrap!(settings_task(flash, shared)));
    defmt::info!(
        "ringpod firmware up: {} Hz control tick",
        1_000_000 / config.pipeline.tick_us
    );
}

/// The USB CDC-ACM device and its serial class (the default host link).
fn usb(
    otg: Peri<'static, peripherals::USB_OTG_FS>,
    dp: Peri<'static, peripherals::PA12>,
    dm: Peri<'static, peripherals::PA11>,
) -> (
    UsbDevice<'static, Driver<'static, peripherals::USB_OTG_FS>>,
    CdcAcmClass<'static, Driver<'static, peripherals::USB_OTG_FS>>,
) {
    static EP_OUT: StaticCell<[u8; 256]> = StaticCell::new();
    static CONFIG_DESC: StaticCell<[u8; 256]> = StaticCell::new();
    static BOS_DESC: StaticCell<[u8; 256]> = StaticCell::new();
    static CONTROL_BUF: StaticCell<[u8; 64]> = StaticCell::new();
    static CDC_STATE: StaticCell<State> = StaticCell::new();
    let mut usb_config = usb::Config::default();
    // The Black Pill does not wire VBUS to PA9 (PA9 is LOGIC_OK here).
    usb_config.vbus_detection = false;
    let driver = Driver::new_fs(otg, Irqs, dp, dm, EP_OUT.init([0; 256]), usb_config);
    let mut device_config = embassy_usb::Config::new(0x1209, 0x0001);
    device_config.manufacturer = Some("ringpod");
    device_config.product = Some("ringpod motion controller");
    device_config.serial_number = Some("ringpod-f411");
    let mut builder = Builder::new(
        driver,
        device_config,
        CONFIG_DESC.init([0; 256]),
        BOS_DESC.init([0; 256]),
        &mut [],
        CONTROL_BUF.init([0; 64]),
    );
    let class = CdcAcmClass::new(&mut builder, CDC_STATE.init(State::new()), 64);
    let device = builder.build();
    (device, class)
}

/// USART1 on TX PA15, RX PA10 (pulled up, so an unplugged adapter reads as an idle line, not noise): the second
/// host link.
fn usart1(
    usart: Peri<'static, peripherals::USART1>,
    rx: Peri<'static, peripherals::PA10>,
    tx: Peri<'static, peripherals::PA15>,
) -> BufferedUart<'static> {
    static UART_TX: StaticCell<[u8; UART_BUF]> = StaticCell::new();
    static UART_RX: StaticCell<[u8; UART_BUF]> = StaticCell::new();
    let mut uart_config = usart::Config::default();
    uart_config.baudrate = USART_BAUD;
    uart_config.rx_pull = Pull::Up;
    match BufferedUart::new(
        usart,
        rx,
        tx,
        UART_TX.init([0; UART_BUF]),
        UART_RX.init([0; UART_BUF]),
        Irqs,
        uart_config,
    ) {
        Ok(u) => u,
        Err(e) => defmt::panic!("USART1: {}", e),
    }
}

/// The step generator: the DMA ring first (it starts playing zeros: no pin changes), then TIM1, whose update
/// every slot paces it into GPIOB's BSRR.
fn step_generator(
    channel: Peri<'static, peripherals::DMA2_CH5>,
    tim: Peri<'static, peripherals::TIM1>,
    words: usize,
) -> WritableRingBuffer<'static, u32> {
    static RING_BUF: StaticCell<[u32; RING]> = StaticCell::new();
    let ring_buf = &mut RING_BUF.init([0; RING])[..words.min(RING)];
    let request = channel.request();
    let bsrr = pac::GPIOB.bsrr().as_ptr() as *mut u32;
    // SAFETY: the ring buffer owns the channel and its memory for the life of the program; the peripheral address
    // is GPIOB's set/reset register, which accepts any 32-bit word.
    let mut ring = unsafe {
        WritableRingBuffer::new(
            dma::Channel::new(channel, Irqs),
            request,
            bsrr,
            ring_buf,
            TransferOptions::default(),
        )
    };
    ring.start();
    let timer = Timer::new(tim);
    timer.set_frequency(
        Hertz(1_000_000_000 / ringpod_core::motion::pulse::STEP_SLOT_NS),
        RoundTo::Faster,
    );
    timer.enable_update_dma(true);
    timer.start();
    core::mem::forget(timer);
    ring
}

fn unwrap_core() -> cortex_m::Peripherals {
    match cortex_m::Peripherals::take() {
        Some(p) => p,
        None => defmt::panic!("core peripherals taken twice"),
    }
}
