//! The step generator: TIM1 updating every slot (2.5 us) paces DMA2 stream 5 (channel 6, TIM1_UP), which copies one
//! word per update from a ring of two rendered periods into `GPIOB.BSRR`; its feeder task runs in an interrupt
//! executor above everything but the DMA interrupt that wakes it and USART1's.

use core::future::poll_fn;
use core::task::Poll;

use embassy_executor::InterruptExecutor;
use embassy_stm32::dma::{self, TransferOptions, WritableRingBuffer};
use embassy_stm32::interrupt::{self, InterruptExt};
use embassy_stm32::pac;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use embassy_stm32::timer::UpDma;
use embassy_time::Instant;
use ringpod_core::motion::pulse::{PulseRenderer, MAX_STEP_SLOTS};
use ringpod_firmware::app::steps::{Overrun, PortOutput};
use ringpod_firmware::app::{self, Shared};
use static_cell::StaticCell;

use super::resources::{Irqs, StepGeneratorParts, STEP_EXECUTOR_PRIORITY};

/// The step generator's DMA ring: room for two periods of the longest buffer. It runs over two periods of the
/// configured one, so that its half-transfer and transfer-complete interrupts fall on the period boundaries: the
/// renderer is one period ahead of the pins, no more (a longer ring would hold setpoints back by its length).
const RING: usize = 2 * MAX_STEP_SLOTS;

/// The DMA ring into GPIOB.BSRR.
pub struct DmaPort {
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

static STEP_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

/// The step generator's executor runs in the USART6 interrupt (unused on this board), above everything but the
/// DMA interrupt that wakes it and USART1's receive interrupt (`resources::set_priorities`).
#[embassy_stm32::interrupt]
#[allow(non_snake_case)]
unsafe fn USART6() {
    // SAFETY: the executor is started on this interrupt below and this is its only handler.
    unsafe { STEP_EXECUTOR.on_interrupt() }
}

#[embassy_executor::task]
async fn steps_task(mut port: DmaPort, renderer: PulseRenderer, shared: &'static Shared) -> ! {
    app::steps::run(&mut port, renderer, shared).await
}

/// Starts the step generator and its feeder task in the USART6 interrupt's executor.
pub fn start(r: StepGeneratorParts, renderer: PulseRenderer, shared: &'static Shared) {
    let ring = step_generator(r, 2 * renderer.timing().slots);

    interrupt::USART6.set_priority(STEP_EXECUTOR_PRIORITY);
    let high = STEP_EXECUTOR.start(interrupt::USART6);
    high.spawn(defmt::unwrap!(steps_task(DmaPort { ring }, renderer, shared)));
}

/// The DMA ring of `words` words first (it starts playing zeros: no pin changes), then TIM1, whose update every slot paces it into
/// GPIOB's BSRR.
fn step_generator(r: StepGeneratorParts, words: usize) -> WritableRingBuffer<'static, u32> {
    static RING_BUF: StaticCell<[u32; RING]> = StaticCell::new();
    let ring_buf = &mut RING_BUF.init([0; RING])[..words.min(RING)];
    let channel = r.dma;
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
    let timer = Timer::new(r.timer);
    timer.set_frequency(
        Hertz(1_000_000_000 / ringpod_core::motion::pulse::STEP_SLOT_NS),
        RoundTo::Faster,
    );
    timer.enable_update_dma(true);
    timer.start();
    core::mem::forget(timer);
    ring
}
