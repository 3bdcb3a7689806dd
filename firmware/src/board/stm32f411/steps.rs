//! The step generator: TIM1 updating every slot (2.5 us) paces DMA2 stream 5 (channel 6, TIM1_UP), which copies one
//! word per update from a ring of two rendered periods into `GPIOB.BSRR`; its feeder task runs in an interrupt
//! executor above everything but the DMA interrupt that wakes it and USART1's.
//!
//! The spare axes 7 and 8 (PA9, PA10, PA15 and PC14) are on ports A and C, which `GPIOB.BSRR` cannot reach. Their
//! words go through two more rings of the same length, paced by the same timer: TIM1's compare 1 and 2 requests
//! (DMA2 streams 1 and 2, channel 6: RM0383 9.3.3, table 28) into `GPIOA.BSRR` and `GPIOC.BSRR`. Both compares are
//! set to the last count of the slot (`CCRx = ARR`), one timer clock (10.4 ns) before the update, so the three rings
//! play word k of a period in the same slot: the spare axes have the platform's slot grid, pulse widths and DIR
//! set-up and hold. A timer interrupt writing the pins per slot (400,000 a second) would cost most of the CPU; a
//! second timer would drift from TIM1's grid.

use core::future::poll_fn;
use core::task::Poll;

use embassy_executor::InterruptExecutor;
use embassy_stm32::dma::{self, Request, TransferOptions, WritableRingBuffer};
use embassy_stm32::interrupt::{self, InterruptExt};
use embassy_stm32::pac;
use embassy_stm32::peripherals::TIM1;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use embassy_stm32::timer::{Ch1, Ch2, Channel, Dma, UpDma};
use embassy_stm32::Peri;
use embassy_time::Instant;
use ringpod_core::motion::pulse::{PulseRenderer, MAX_STEP_SLOTS};
use ringpod_firmware::app::steps::{Overrun, PortOutput};
use ringpod_firmware::app::{self, Shared};
use static_cell::ConstStaticCell;

use super::resources::{Irqs, SpareDmaParts, StepGeneratorParts, SPARE_PORT_A, SPARE_PORT_C, STEP_EXECUTOR_PRIORITY};

/// The step generator's DMA ring: room for two periods of the longest buffer. It runs over two periods of the
/// configured one, so that its half-transfer and transfer-complete interrupts fall on the period boundaries: the
/// renderer is one period ahead of the pins, no more (a longer ring would hold setpoints back by its length).
const RING: usize = 2 * MAX_STEP_SLOTS;

/// Words masked at a time on their way into a spare ring.
const CHUNK: usize = 80;

/// The DMA ring into GPIOB.BSRR, and with spare axes fitted, the rings into GPIOA.BSRR and GPIOC.BSRR.
pub struct DmaPort {
    ring: WritableRingBuffer<'static, u32>,
    spare: Option<[WritableRingBuffer<'static, u32>; 2]>,
}

impl PortOutput for DmaPort {
    async fn room(&mut self, words: usize) -> Result<Instant, Overrun> {
        // The ring is two periods: its half-transfer and transfer-complete interrupts are the period boundaries,
        // and wake this (at the step executor's priority, so the instant is the boundary's to a few cycles). The
        // spare rings play in step with it, a timer clock ahead: when it has room, so have they.
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
                // Lapped: start the rings afresh together (the step generator's fault is latched by the caller).
                self.ring.clear();
                for ring in self.spare.iter_mut().flatten() {
                    ring.clear();
                }
                Err(Overrun)
            }
        }
    }

    fn write(&mut self, words: &[u32]) -> Result<(), Overrun> {
        write_all(&mut self.ring, words)
    }

    fn write_spare(&mut self, words: &[u32]) -> Result<(), Overrun> {
        let Some([port_a, port_c]) = self.spare.as_mut() else {
            return Err(Overrun);
        };
        let mut a = [0u32; CHUNK];
        let mut c = [0u32; CHUNK];
        for chunk in words.chunks(CHUNK) {
            for (i, &w) in chunk.iter().enumerate() {
                a[i] = w & SPARE_PORT_A;
                c[i] = w & SPARE_PORT_C;
            }
            write_all(port_a, &a[..chunk.len()])?;
            write_all(port_c, &c[..chunk.len()])?;
        }
        Ok(())
    }
}

fn write_all(ring: &mut WritableRingBuffer<'static, u32>, words: &[u32]) -> Result<(), Overrun> {
    match ring.write(words) {
        Ok((written, _)) if written == words.len() => Ok(()),
        _ => Err(Overrun),
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
async fn steps_task(
    mut port: DmaPort,
    renderer: PulseRenderer,
    spare: Option<PulseRenderer>,
    shared: &'static Shared,
) -> ! {
    app::steps::run(&mut port, renderer, spare, shared).await
}

/// Starts the step generator and its feeder task in the USART6 interrupt's executor; with `spare` (the spare axes'
/// rings and their renderer), the spare axes' rings beside the platform's.
pub fn start(
    r: StepGeneratorParts,
    renderer: PulseRenderer,
    spare: Option<(SpareDmaParts, PulseRenderer)>,
    shared: &'static Shared,
) {
    let words = 2 * renderer.timing().slots;
    // Every ring is started (playing zeros: no pin changes) before the timer, so that all count their words from
    // the same first slot. The rings are zeroed statics taken in place: built as values they would pass through the
    // stack (6.4 KB each, measured 13 KB deeper at boot).
    let ring = {
        static RING_BUF: ConstStaticCell<[u32; RING]> = ConstStaticCell::new([0; RING]);
        let request = r.dma.request();
        start_ring(
            r.dma,
            request,
            pac::GPIOB.bsrr().as_ptr() as *mut u32,
            RING_BUF.take(),
            words,
        )
    };
    let (spare_rings, spare_renderer) = match spare {
        Some((d, spare_renderer)) => {
            static RING_BUF_A: ConstStaticCell<[u32; RING]> = ConstStaticCell::new([0; RING]);
            static RING_BUF_C: ConstStaticCell<[u32; RING]> = ConstStaticCell::new([0; RING]);
            let req_a = Dma::<TIM1, Ch1>::request(&*d.port_a);
            let req_c = Dma::<TIM1, Ch2>::request(&*d.port_c);
            let a = start_ring(
                d.port_a,
                req_a,
                pac::GPIOA.bsrr().as_ptr() as *mut u32,
                RING_BUF_A.take(),
                words,
            );
            let c = start_ring(
                d.port_c,
                req_c,
                pac::GPIOC.bsrr().as_ptr() as *mut u32,
                RING_BUF_C.take(),
                words,
            );
            (Some([a, c]), Some(spare_renderer))
        }
        None => (None, None),
    };
    start_timer(r.timer, spare_rings.is_some());

    interrupt::USART6.set_priority(STEP_EXECUTOR_PRIORITY);
    let high = STEP_EXECUTOR.start(interrupt::USART6);
    let port = DmaPort {
        ring,
        spare: spare_rings,
    };
    high.spawn(defmt::unwrap!(steps_task(port, renderer, spare_renderer, shared)));
}

/// A started DMA ring of `words` words of `buf` into the set/reset register at `bsrr`, paced by `request`.
fn start_ring<C: dma::ChannelInstance>(
    channel: Peri<'static, C>,
    request: Request,
    bsrr: *mut u32,
    buf: &'static mut [u32; RING],
    words: usize,
) -> WritableRingBuffer<'static, u32>
where
    Irqs: embassy_stm32::interrupt::typelevel::Binding<C::Interrupt, dma::InterruptHandler<C>>,
{
    // SAFETY: the ring buffer owns the channel and its memory for the life of the program; the peripheral address
    // is a GPIO port's set/reset register, which accepts any 32-bit word.
    let mut ring = unsafe {
        WritableRingBuffer::new(
            dma::Channel::new(channel, Irqs),
            request,
            bsrr,
            &mut buf[..words.min(RING)],
            TransferOptions::default(),
        )
    };
    ring.start();
    ring
}

/// TIM1 with its update every slot (the platform's ring), and with `spare`, compares 1 and 2 at the slot's last count
/// (the spare rings).
fn start_timer(tim: Peri<'static, TIM1>, spare: bool) {
    let timer = Timer::new(tim);
    timer.set_frequency(
        Hertz(1_000_000_000 / ringpod_core::motion::pulse::STEP_SLOT_NS),
        RoundTo::Faster,
    );
    timer.enable_update_dma(true);
    if spare {
        // Compare mode "frozen" (the reset value): the channels only time the requests, they drive no pin
        // (PA8 and PA9 are not in TIM1's alternate function; RM0383 12.3.8, 12.4.7 CCxDE).
        let last = timer.get_max_compare_value();
        for ch in [Channel::Ch1, Channel::Ch2] {
            timer.set_compare_value(ch, last);
            timer.set_cc_dma_enable_state(ch, true);
        }
    }
    timer.start();
    core::mem::forget(timer);
}
