//! `ringpod flash` on the machine's USB: the image, the board, the bootloader, the write, the new firmware.

use std::path::Path;
use std::time::{Duration, Instant};

use ringpod_core::protocol::Firmware;

use super::image::FirmwareImage;
use super::{await_bootloader, end_line, enter_bootloader, load, progress_bar, write, Bus, FlashError};
use crate::link::client::Client;
use crate::link::BOARD_USB_ID;
use crate::link::{self, Target};
use crate::out::console;

/// `ringpod flash [--image FILE] [--port PORT] [--dfu tcp://HOST:PORT]`: 0 when flashed, verified and answering;
/// else the class's code.
pub fn run(image: Option<&Path>, port: Option<&str>, dfu: Option<&str>) -> u8 {
    let outcome = load(image).and_then(|image| match dfu {
        Some(address) => {
            let address = address.strip_prefix("tcp://").unwrap_or(address);
            let mut bus = super::tcp::TcpBus::connect(address)
                .map_err(|e| FlashError::Board(format!("the DFU bridge at {address}: {e}")))?;
            flash(&mut bus, &image, port)
        }
        None => flash(&mut super::usb::UsbBus, &image, port),
    });
    match outcome {
        Ok(line) => {
            console::out(&format!("{line}\n"));
            0
        }
        Err(e) => {
            console::err(&format!("ringpod: flash: {e}"));
            if let Some(advice) = e.advice() {
                console::err(&format!("ringpod: {advice}"));
            }
            e.code()
        }
    }
}

/// Finds or asks for the bootloader on `bus`, writes `image`, and waits for the new firmware.
fn flash<B: Bus>(bus: &mut B, image: &FirmwareImage, port: Option<&str>) -> Result<String, FlashError> {
    let mut found = match bus.bootloader() {
        Ok(Some(found)) => {
            console::err("the board waits in its ROM bootloader (USB 0483:df11)");
            found
        }
        _ => {
            let port = board_port(port)?;
            let transport = link::connect(&Target::Port(port.clone()), false)
                .map_err(|e| FlashError::Board(format!("the board's port: {e}")))?;
            let mut client = Client::new(transport);
            let was = enter_bootloader(&mut client)?;
            drop(client);
            console::err(&format!(
                "{port}: the board ({}) restarts into its ROM bootloader",
                was.as_deref().unwrap_or("firmware unknown")
            ));
            await_bootloader(bus, link::patience(Duration::from_secs(10)))?
        }
    };
    write(&mut found, image, &mut progress_bar())?;
    drop(found);
    let runs = await_firmware(port, link::patience(Duration::from_secs(15)))?;
    end_line(image, &runs)
}

/// The board's serial port: the one given, or the only one with the board's USB id.
fn board_port(given: Option<&str>) -> Result<String, FlashError> {
    if let Some(port) = given {
        return Ok(port.to_owned());
    }
    let boards = board_ports();
    match boards.as_slice() {
        [one] => Ok(one.clone()),
        [] => Err(FlashError::Board(
            "no board found: neither a ringpod board (USB 1209:0001) nor the ROM bootloader (USB 0483:df11) is \
             plugged in; on a board that does not start, hold BOOT0 while plugging it in"
                .into(),
        )),
        more => Err(FlashError::Board(format!(
            "{} ringpod boards are plugged in ({}): say which with --port",
            more.len(),
            more.join(", ")
        ))),
    }
}

fn board_ports() -> Vec<String> {
    serialport::available_ports()
        .unwrap_or_default()
        .into_iter()
        .filter(|p| matches!(&p.port_type, serialport::SerialPortType::UsbPort(u) if (u.vid, u.pid) == BOARD_USB_ID))
        .map(|p| p.port_name)
        .collect()
}

/// Waits for the new firmware to enumerate and answer the handshake; what it says it runs.
fn await_firmware(port: Option<&str>, limit: Duration) -> Result<Firmware, FlashError> {
    let since = Instant::now();
    let mut last = String::from("no board port appeared");
    while since.elapsed() < limit {
        std::thread::sleep(Duration::from_millis(200));
        let candidates = port.map_or_else(board_ports, |p| vec![p.to_owned()]);
        for name in candidates {
            let Ok(transport) = link::connect(&Target::Port(name.clone()), false) else {
                continue;
            };
            let mut client = Client::new(transport);
            match client.hello() {
                Ok(device) => return Ok(device.firmware),
                Err(e) => last = format!("{name}: {e}"),
            }
        }
    }
    Err(FlashError::Restart(format!(
        "written and verified, but the new firmware did not answer within {limit:?} ({last})"
    )))
}
