//! The host link: the CMSDK APB UART0 of mps2-an386 (QEMU `-serial pty` makes it a pseudo-terminal the host's
//! `ringpod --port` opens), bytes in by its RX interrupt, out by polling.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use ringpod_firmware::app::link::{Disconnected, Link};

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

/// Bytes from the RX interrupt to the link task.
static RX: Pipe<CriticalSectionRawMutex, 4096> = Pipe::new();
/// Bytes the RX interrupt had no room for (each breaks a frame, which the CRC then rejects and the device counts).
static RX_DROPPED: AtomicU32 = AtomicU32::new(0);

/// Enables transmit, receive and the receive interrupt (115,200 Bd of 25 MHz; QEMU does not pace by it).
pub fn init() {
    // SAFETY: UART0's registers on this machine; nothing else drives them.
    unsafe {
        BAUDDIV.write_volatile(217);
        CTRL.write_volatile(0b1011);
    }
}

/// The received byte, if one is waiting; acknowledges the receive interrupt.
fn read() -> Option<u8> {
    // SAFETY: as above.
    unsafe {
        INTCLEAR.write_volatile(RX_FULL);
        (STATE.read_volatile() & RX_FULL != 0).then(|| DATA.read_volatile() as u8)
    }
}

/// Sends `bytes` (QEMU's transmitter never stays full for long).
fn write(bytes: &[u8]) {
    for &b in bytes {
        // SAFETY: as above.
        unsafe {
            while STATE.read_volatile() & TX_FULL != 0 {}
            DATA.write_volatile(u32::from(b));
        }
    }
}

/// The RX interrupt's work: every waiting byte into the pipe.
pub fn on_rx_interrupt() {
    while let Some(b) = read() {
        if RX.try_write(&[b]).is_err() {
            RX_DROPPED.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// Bytes as if they had just arrived on the line (the latency measurement's host, [`crate::latency`]): into the
/// same pipe the RX interrupt fills.
pub fn inject(bytes: &[u8]) {
    for b in bytes {
        if RX.try_write(core::slice::from_ref(b)).is_err() {
            RX_DROPPED.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// The UART as the host link: always connected.
pub struct UartLink;

impl Link for UartLink {
    async fn connected(&mut self) {}

    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Disconnected> {
        Ok(RX.read(buf).await)
    }

    async fn write(&mut self, bytes: &[u8]) -> Result<(), Disconnected> {
        write(bytes);
        Ok(())
    }
}
