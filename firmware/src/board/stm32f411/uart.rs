//! USART1, the second host link (for an isolated USB-serial adapter), served at the same time as USB.

use embassy_stm32::gpio::Pull;
use embassy_stm32::usart::{self, BufferedUart};
use ringpod_firmware::app::link::{Disconnected, Link};
use ringpod_firmware::app::{self, Shared};
use static_cell::StaticCell;

use super::resources::{Irqs, UartParts};

/// The USART link's baud rate (8N1): a 1 kHz stream of setpoints is about 45 kB/s, beyond 115200 baud. APB2 at
/// 96 MHz gives 923,077 baud (+0.16 %), within any adapter's tolerance.
pub const USART_BAUD: u32 = 921_600;

/// Bytes of each of USART1's software buffers.
const UART_BUF: usize = 256;

/// USART1 through embassy's interrupt-driven buffered driver. A UART has no connection to wait for; line errors
/// (noise, framing, overrun) are logged by the driver and the frame they damaged is answered as malformed.
pub struct UartLink {
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

/// USART1 on TX PA15, RX PA10 (pulled up, so an unplugged adapter reads as an idle line, not noise): the second
/// host link.
pub fn new(r: UartParts) -> UartLink {
    static UART_TX: StaticCell<[u8; UART_BUF]> = StaticCell::new();
    static UART_RX: StaticCell<[u8; UART_BUF]> = StaticCell::new();
    let mut uart_config = usart::Config::default();
    uart_config.baudrate = USART_BAUD;
    uart_config.rx_pull = Pull::Up;
    match BufferedUart::new(
        r.usart,
        r.rx,
        r.tx,
        UART_TX.init([0; UART_BUF]),
        UART_RX.init([0; UART_BUF]),
        Irqs,
        uart_config,
    ) {
        Ok(uart) => UartLink { uart },
        Err(e) => defmt::panic!("USART1: {}", e),
    }
}

#[embassy_executor::task]
pub async fn uart_link_task(mut link: UartLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 1, shared).await
}
