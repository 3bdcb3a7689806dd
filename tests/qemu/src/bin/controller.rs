//! The ringpod controller on QEMU's mps2-an386: the firmware's own tasks (`ringpod_firmware::app`: the link and
//! the control tick over `ringpod_core::controller::Controller`) around a board module for the emulated machine:
//!
//! - time: an `embassy-time` driver on SysTick (25 MHz core clock, an interrupt every 100 us);
//! - link: the CMSDK UART0 (QEMU `-serial pty` makes it a pseudo-terminal the host's `ringpod --port` opens), bytes
//!   in by its RX interrupt, out by polling;
//! - machine: the simulated plant of `ringpod_core::sim` (axes that count the step moves of every tick, switches at
//!   their positions, supply sense following the relays), parked where the host simulator parks it.
//!
//! It prints `READY` over semihosting once its tasks run. What differs from the STM32 build is only this file.

#![no_std]
#![no_main]

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicU32, Ordering};
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::NVIC;
use cortex_m_rt::exception;
use cortex_m_semihosting::hprintln;
use critical_section::Mutex as CsMutex;
use embassy_executor::Spawner;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;
use ringpod_core::controller::{Controller, ControllerConfig, Inputs, TickOutput};
use ringpod_core::motion::AxisMove;
use ringpod_core::safety::pins::OutputPin;
use ringpod_core::safety::Outputs;
use ringpod_core::sim::{Plant, TRAINER_MODEL_PARKED};
use ringpod_firmware::app::control::Machine;
use ringpod_firmware::app::link::{Disconnected, Link};
use ringpod_firmware::app::{self, Shared};
use ringpod_qemu::fail;
use static_cell::StaticCell;

/// SysTick period: 100 us of the 25 MHz core clock.
const TICK_US: u64 = 100;
const SYSTICK_RELOAD: u32 = 25 * TICK_US as u32 - 1;

/// Time in SysTick periods, and the timer queue, both touched from the SysTick exception and thread mode.
struct SysTickDriver {
    ticks: CsMutex<Cell<u64>>,
    queue: CsMutex<RefCell<Queue>>,
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.ticks.borrow(cs).get() * TICK_US)
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            // The SysTick exception looks at the queue every 100 us: no alarm to program.
            self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker);
        });
    }
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    ticks: CsMutex::new(Cell::new(0)),
    queue: CsMutex::new(RefCell::new(Queue::new())),
});

#[exception]
fn SysTick() {
    critical_section::with(|cs| {
        let ticks = DRIVER.ticks.borrow(cs);
        ticks.set(ticks.get() + 1);
        DRIVER
            .queue
            .borrow(cs)
            .borrow_mut()
            .next_expiration(ticks.get() * TICK_US);
    });
}

/// The CMSDK APB UART0 of mps2-an386.
mod uart {
    const BASE: usize = 0x4000_4000;
    const DATA: *mut u32 = BASE as *mut u32;
    const STATE: *mut u32 = (BASE + 0x04) as *mut u32;
    const CTRL: *mut u32 = (BASE + 0x08) as *mut u32;
    const INTCLEAR: *mut u32 = (BASE + 0x0c) as *mut u32;
    const BAUDDIV: *mut u32 = (BASE + 0x10) as *mut u32;
    const TX_FULL: u32 = 1;
    const RX_FULL: u32 = 2;
    /// Interrupt number of UART0 RX on the AN385/AN386 images.
    pub const RX_IRQ: u16 = 0;

    /// Enables transmit, receive and the receive interrupt (115,200 Bd of 25 MHz; QEMU does not pace by it).
    pub fn init() {
        // SAFETY: UART0's registers on this machine; nothing else drives them.
        unsafe {
            BAUDDIV.write_volatile(217);
            CTRL.write_volatile(0b1011);
        }
    }

    /// The received byte, if one is waiting; acknowledges the receive interrupt.
    pub fn read() -> Option<u8> {
        // SAFETY: as above.
        unsafe {
            INTCLEAR.write_volatile(RX_FULL);
            (STATE.read_volatile() & RX_FULL != 0).then(|| DATA.read_volatile() as u8)
        }
    }

    /// Sends `bytes` (QEMU's transmitter never stays full for long).
    pub fn write(bytes: &[u8]) {
        for &b in bytes {
            // SAFETY: as above.
            unsafe {
                while STATE.read_volatile() & TX_FULL != 0 {}
                DATA.write_volatile(u32::from(b));
            }
        }
    }
}

/// Bytes from the RX interrupt to the link task.
static RX: Pipe<CriticalSectionRawMutex, 4096> = Pipe::new();
/// Bytes the RX interrupt had no room for (each breaks a frame, which the CRC then rejects and the device counts).
static RX_DROPPED: AtomicU32 = AtomicU32::new(0);

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
        while let Some(b) = uart::read() {
            if RX.try_write(&[b]).is_err() {
                RX_DROPPED.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

/// The UART as the host link: always connected.
struct UartLink;

impl Link for UartLink {
    async fn connected(&mut self) {}

    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected> {
        Ok(RX.read(buf).await)
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected> {
        uart::write(bytes);
        Ok(())
    }
}

/// The simulated machine: the plant counts each tick's moves as they are handed to the step generator.
struct VirtualMachine {
    plant: Plant,
    outputs: Outputs,
}

impl Machine for VirtualMachine {
    fn inputs(&mut self, _shared: &Shared) -> Inputs {
        self.plant.inputs(self.outputs.logic_relay, self.outputs.power_relay)
    }

    fn write(&mut self, pin: OutputPin, on: bool) {
        match pin {
            OutputPin::DriverEnable => self.outputs.driver_enable = on,
            OutputPin::LogicRelay => self.outputs.logic_relay = on,
            OutputPin::PowerRelay => self.outputs.power_relay = on,
        }
    }

    async fn steps(&mut self, moves: &[AxisMove; 6], _shared: &Shared) {
        self.plant.apply(&TickOutput {
            moves: *moves,
            outputs: self.outputs,
        });
    }

    fn queue_depth(&self, _shared: &Shared) -> u16 {
        0
    }

    fn cycles(&self) -> u32 {
        // No DWT cycle counter in QEMU: microseconds of SysTick time, in 25 MHz cycles.
        (DRIVER.now() * 25) as u32
    }

    fn feed_watchdog(&mut self) {}
}

#[embassy_executor::task]
async fn link_task(mut link: UartLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, shared).await
}

#[embassy_executor::task]
async fn control_task(mut machine: VirtualMachine, shared: &'static Shared) -> ! {
    app::control::run(&mut machine, shared).await
}

static SHARED: StaticCell<Shared> = StaticCell::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let mut core = match cortex_m::Peripherals::take() {
        Some(p) => p,
        None => fail("core peripherals"),
    };
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(SYSTICK_RELOAD);
    core.SYST.clear_current();
    core.SYST.enable_interrupt();
    core.SYST.enable_counter();
    uart::init();
    // SAFETY: the handler above is ready for the RX interrupt.
    unsafe { NVIC::unmask(Irq(uart::RX_IRQ)) };

    // The host simulator's machine: the same configuration and the same parking positions.
    let controller = Controller::new(ControllerConfig::trainer_model()).unwrap_or_else(|_| fail("configuration"));
    let plant = Plant::trainer_model(TRAINER_MODEL_PARKED);
    let shared: &'static Shared = SHARED.init(Shared::new(controller, 0));
    let machine = VirtualMachine {
        plant,
        outputs: Outputs::OFF,
    };
    spawner.spawn(link_task(UartLink, shared).unwrap_or_else(|_| fail("spawn")));
    spawner.spawn(control_task(machine, shared).unwrap_or_else(|_| fail("spawn")));
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
