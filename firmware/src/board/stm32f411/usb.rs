//! USB CDC-ACM, the default host link: the device, its serial class and the tasks that run them.

use embassy_stm32::peripherals;
use embassy_stm32::usb::{self, Driver};
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use embassy_usb::{Builder, UsbDevice};
use ringpod_firmware::app::link::{Disconnected, Link};
use ringpod_firmware::app::{self, Shared};
use static_cell::StaticCell;

use super::resources::{Irqs, UsbParts};

/// The USB device of this board.
pub type Device = UsbDevice<'static, Driver<'static, peripherals::USB_OTG_FS>>;

/// USB CDC-ACM: 64-byte packets; a write that ends on a full packet is closed by a zero-length packet.
pub struct UsbLink {
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

/// The USB CDC-ACM device and its serial class (the default host link).
pub fn new(r: UsbParts) -> (Device, UsbLink) {
    static EP_OUT: StaticCell<[u8; 256]> = StaticCell::new();
    static CONFIG_DESC: StaticCell<[u8; 256]> = StaticCell::new();
    static BOS_DESC: StaticCell<[u8; 256]> = StaticCell::new();
    static CONTROL_BUF: StaticCell<[u8; 64]> = StaticCell::new();
    static CDC_STATE: StaticCell<State> = StaticCell::new();
    static SERIAL: StaticCell<[u8; 24]> = StaticCell::new();
    let mut usb_config = usb::Config::default();
    // The Black Pill does not wire VBUS to PA9 (PA9 is LOGIC_OK here).
    usb_config.vbus_detection = false;
    let driver = Driver::new_fs(r.otg, Irqs, r.dp, r.dm, EP_OUT.init([0; 256]), usb_config);
    let mut device_config = embassy_usb::Config::new(0x1209, 0x0001);
    device_config.manufacturer = Some("ringpod");
    device_config.product = Some("ringpod motion controller");
    // The chip's 96-bit unique ID (RM0383 39.1, at 0x1FFF7A10) as 24 hexadecimal digits, byte by byte from the
    // lowest address: two boards on one PC have two serial numbers, so the host (and Windows' COM-port assignment)
    // tells them apart.
    device_config.serial_number = Some(serial_number(SERIAL.init([0; 24])));
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
    (device, UsbLink { class })
}

/// The chip's unique ID as 24 upper-case hexadecimal digits in `hex`, byte by byte from the lowest address.
fn serial_number(hex: &'static mut [u8; 24]) -> &'static str {
    const DIGITS: &[u8; 16] = b"0123456789ABCDEF";
    for (pair, byte) in hex.chunks_exact_mut(2).zip(embassy_stm32::uid::uid()) {
        pair[0] = DIGITS[usize::from(byte >> 4)];
        pair[1] = DIGITS[usize::from(byte & 0xF)];
    }
    // SAFETY: every byte is one of DIGITS, ASCII.
    unsafe { core::str::from_utf8_unchecked(hex) }
}

#[embassy_executor::task]
pub async fn usb_task(mut device: Device) -> ! {
    device.run().await
}

#[embassy_executor::task]
pub async fn link_task(mut link: UsbLink, shared: &'static Shared) -> ! {
    app::link::serve(&mut link, 0, shared).await
}
