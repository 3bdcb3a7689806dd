//! USART1, the second host link (for an isolated USB-serial adapter), served at the same time as USB.
//!
//! Both directions go through DMA. A byte that arrives while no code can run is kept: erasing a flash sector for the
//! settings stalls every read of flash for up to 2 s (RM0383 3.5; the code and the vector table are there), but not
//! DMA2's writes into SRAM, so a request sent meanwhile waits in the receive ring instead of overrunning the data
//! register (one byte time, 10.8 us) and being lost.

use embassy_stm32::gpio::Pull;
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::DMA2_CH2;
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use embassy_stm32::Peri;
use ringpod_firmware::app::link::{Disconnected, Link};
use ringpod_firmware::app::{self, Shared};
use static_cell::StaticCell;

use super::resources::{Irqs, UartParts};

/// The USART link's baud rate (8N1): a 1 kHz stream of setpoints is about 45 kB/s, beyond 115200 baud. APB2 at
/// 96 MHz gives 923,077 baud (+0.16 %), within any adapter's tolerance.
pub const USART_BAUD: u32 = 921_600;

/// Bytes of the receive ring: a whole request several times over, as the host may send one (and the retries of a
/// handshake) while a sector erase holds the CPU.
const RX_RING: usize = 1024;

/// USART1 through embassy's DMA drivers: the receiver fills a circular ring in the background (woken by an idle
/// line or the ring's half and end), the transmitter sends each answer as one transfer. A UART has no connection to
/// wait for; a line error (noise, framing, an overrun of the ring) is logged and the receiver restarts: the frame
/// it damaged is answered as malformed.
pub struct UartLink {
    tx: UartTx<'static, Async>,
    rx: RingBufferedUartRx<'static>,
}

impl Link for UartLink {
    async fn connected(&mut self) {}

    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected> {
        loop {
            match self.rx.read(buf).await {
                Ok(n @ 1..) => return Ok(n),
                Ok(0) => {}
                Err(e) => defmt::warn!("USART1: {}", e),
            }
        }
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected> {
        self.tx.write(bytes).await.map_err(|_| Disconnected)
    }
}

/// USART1 on TX PA15, RX PA10 (pulled up, so an unplugged adapter reads as an idle line, not noise): the second
/// host link, receiving through DMA2 stream 2 (`rx_dma`, free when no spare axis is fitted).
pub fn new(r: UartParts, rx_dma: Peri<'static, DMA2_CH2>) -> UartLink {
    static RX_BUF: StaticCell<[u8; RX_RING]> = StaticCell::new();
    let mut uart_config = usart::Config::default();
    uart_config.baudrate = USART_BAUD;
    uart_config.rx_pull = Pull::Up;
    match Uart::new(r.usart, r.rx, r.tx, r.tx_dma, rx_dma, Irqs, uart_config) {
        Ok(uart) => {
            let (tx, rx) = uart.split();
            let mut rx = rx.into_ring_buffered(RX_BUF.init([0; RX_RING]));
            // Listening from now on, not from the first read: the host may speak before the link task runs.
            rx.start_uart();
            UartLink { tx, rx }
        }
        Err(e) => defmt::panic!("USART1: {}", e),
    }
}

#[embassy_executor::task]
pub async fn uart_link_task(mut link: UartLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 1, shared).await
}
