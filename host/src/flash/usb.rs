//! The machine's USB, through nusb: the ROM bootloader found by its id (0483:df11), its DFU interface claimed (on
//! Windows through WinUSB: the bootloader has no driver of its own there, the book says how to give it one), the
//! internal flash's alternate setting chosen by its layout string, and the class requests of DfuSe.

use std::time::Duration;

use nusb::transfer::{ControlIn, ControlOut, ControlType, Recipient, TransferError};
use nusb::MaybeFuture;

use super::dfuse::{Control, DfuSe, UsbError};
use super::{Bootloader, Bus, BOOTLOADER_USB_ID};

/// How long one control transfer may take: an erase is answered at once (the device then asks to be polled
/// later), so a transfer that takes longer means the device is gone.
const TRANSFER_TIMEOUT: Duration = Duration::from_secs(5);
/// US English, the language the bootloader's strings are in.
const LANGUAGE: u16 = 0x0409;
/// DFU 1.1 4.1.3: the DFU functional descriptor's type.
const DFU_FUNCTIONAL: u8 = 0x21;

/// The machine's USB.
pub struct UsbBus;

/// Whether a ROM bootloader (0483:df11) is on the machine's USB (`ringpod ports`); a bus that cannot be listed has
/// none to show.
pub fn bootloader_listed() -> bool {
    nusb::list_devices()
        .wait()
        .is_ok_and(|mut all| all.any(|d| (d.vendor_id(), d.product_id()) == BOOTLOADER_USB_ID))
}

/// The bootloader's DFU interface.
pub struct UsbPipe {
    interface: nusb::Interface,
    number: u8,
}

fn usb_error(e: TransferError) -> UsbError {
    match e {
        TransferError::Stall => UsbError::Stall,
        TransferError::Disconnected => UsbError::Gone,
        other => UsbError::Other(other.to_string()),
    }
}

impl Control for UsbPipe {
    fn control_in(&mut self, request: u8, value: u16, length: u16) -> Result<Vec<u8>, UsbError> {
        let control = ControlIn {
            control_type: ControlType::Class,
            recipient: Recipient::Interface,
            request,
            value,
            index: u16::from(self.number),
            length,
        };
        self.interface
            .control_in(control, TRANSFER_TIMEOUT)
            .wait()
            .map_err(usb_error)
    }

    fn control_out(&mut self, request: u8, value: u16, data: &[u8]) -> Result<(), UsbError> {
        let control = ControlOut {
            control_type: ControlType::Class,
            recipient: Recipient::Interface,
            request,
            value,
            index: u16::from(self.number),
            data,
        };
        self.interface
            .control_out(control, TRANSFER_TIMEOUT)
            .wait()
            .map_err(usb_error)
    }

    fn sleep(&mut self, wait: Duration) {
        std::thread::sleep(wait);
    }
}

impl Bus for UsbBus {
    type Pipe = UsbPipe;

    fn bootloader(&mut self) -> Result<Option<Bootloader<UsbPipe>>, UsbError> {
        let other = |e: &dyn std::fmt::Display| UsbError::Other(e.to_string());
        let Some(info) = nusb::list_devices()
            .wait()
            .map_err(|e| other(&e))?
            .find(|d| (d.vendor_id(), d.product_id()) == BOOTLOADER_USB_ID)
        else {
            return Ok(None);
        };
        let device = info.open().wait().map_err(|e| other(&e))?;
        let config = device.active_configuration().map_err(|e| other(&e))?;
        // DFU 1.1 4.2.4: one functional descriptor for the interface, after its alternate settings.
        let transfer = config
            .descriptors()
            .find(|d| d.descriptor_type() == DFU_FUNCTIONAL && d.len() >= 7)
            .map(|d| u16::from_le_bytes([d[5], d[6]]));
        // The alternate setting whose string is the internal flash's layout (AN3156: "@Internal Flash ...").
        let mut chosen = None;
        for alt in config.interface_alt_settings() {
            let Some(index) = alt.string_index() else {
                continue;
            };
            let Ok(text) = device.get_string_descriptor(index, LANGUAGE, TRANSFER_TIMEOUT).wait() else {
                continue;
            };
            if text.starts_with("@Internal Flash") {
                chosen = Some((alt.interface_number(), alt.alternate_setting(), text));
                break;
            }
        }
        let Some((number, alt, layout)) = chosen else {
            return Err(UsbError::Other(
                "the DFU device has no \"@Internal Flash\" alternate setting".into(),
            ));
        };
        let interface = device
            .detach_and_claim_interface(number)
            .wait()
            .map_err(|e| other(&e))?;
        interface.set_alt_setting(alt).wait().map_err(|e| other(&e))?;
        Ok(Some(Bootloader {
            dfu: DfuSe {
                control: UsbPipe { interface, number },
                // AN3156: the STM32 bootloaders' transfer size, when the descriptor does not say.
                transfer_size: transfer.unwrap_or(2048),
            },
            layout,
        }))
    }

    fn sleep(&mut self, wait: Duration) {
        std::thread::sleep(wait);
    }
}
