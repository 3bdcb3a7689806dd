//! Talking to one controller: `device ACTION`, `monitor`, `simulate --pty` and `ports`.

pub mod commission;
mod error;
pub mod monitor;
pub mod rig;
pub mod settings;

use std::io::Write;
use std::path::PathBuf;

use ringpod_core::protocol::{Firmware, RigSource, PROTOCOL_VERSION};
use ringpod_core::safety::State;

use crate::link::client::{Client, ClientError};
use crate::link::{self, sim, Target};
use crate::signals::Signals;
pub use error::DeviceError;

/// What `ringpod device` does.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Print the status and the rig the board runs.
    Status,
    Enable,
    Disable,
    /// Home, waiting for the supplies first and for the homing's end.
    Home,
    Start,
    Stop,
    Clear,
    /// The settings: the words after `config` (nothing, `get SECTION[.PATH]`, `set SECTION.PATH VALUE`).
    Config(Vec<String>),
    /// Every input, once or watched until a signal.
    Inputs {
        watch: bool,
    },
    /// `jog AXIS DISTANCE`, the words as given.
    Jog(Vec<String>),
    /// `buzz AXIS`, the words as given.
    Buzz(Vec<String>),
    /// Store a rig file on the device for its next start.
    LoadRig(PathBuf),
    /// The rig the device runs, as a rig file.
    ShowRig,
    /// Restart once everything is stored.
    Restart,
    /// Restart into the ROM bootloader once everything is stored (no handshake first).
    Bootloader,
    /// Switch an auxiliary output.
    Aux {
        output: ringpod_core::safety::Aux,
        on: bool,
    },
}

/// `ringpod device ACTION`: 0 when done; a signal ends `inputs --watch` with 128 + its number.
pub fn run(target: &Target, action: &Action) -> Result<u8, DeviceError> {
    let mut client = Client::new(link::connect(target, false)?);
    // The bootloader is asked without a handshake, so that a board of another protocol version can be updated.
    if *action != Action::Bootloader {
        client.hello()?;
    }
    let text = match action {
        Action::Status => status(&mut client)?,
        Action::Enable => status_after(&mut client, |c| c.enable())?,
        Action::Disable => status_after(&mut client, |c| c.disable())?,
        Action::Start => status_after(&mut client, |c| c.start())?,
        Action::Stop => status_after(&mut client, |c| c.stop())?,
        Action::Clear => status_after(&mut client, |c| c.clear())?,
        Action::Aux { output, on } => status_after(&mut client, |c| c.aux(*output, *on))?,
        Action::Home => status_after(&mut client, home)?,
        Action::Jog(words) => commission::jog(&mut client, words, false)?,
        Action::Buzz(words) => commission::jog(&mut client, words, true)?,
        Action::Inputs { watch: true } => {
            // Watched until a signal, which is its normal end: 128 + the signal, as a shell reports it. A reader
            // that went away ends it too, and `main` exits with the output's failure (141) then.
            let signals = Signals::install()?;
            commission::inputs(&mut client, true, &|| signals.received())?;
            return Ok(signals.exit_code());
        }
        Action::Inputs { watch: false } => {
            commission::inputs(&mut client, false, &|| false)?;
            return Ok(0);
        }
        Action::LoadRig(file) => rig::load(&mut client, file)?,
        Action::ShowRig => rig::show(&mut client)?,
        Action::Restart => rig::restart(&mut client)?,
        Action::Bootloader => {
            client.enter_bootloader()?;
            "the board restarts into its ROM bootloader (USB DFU, 0483:df11) once everything is stored".into()
        }
        Action::Config(words) => serde_json::to_string_pretty(&settings::run(&mut client, words)?)?,
    };
    // A failed write decides the exit code in `main`.
    crate::out::console::out(&format!("{text}\n"));
    Ok(0)
}

/// Homes: right after `device enable` the supplies may still be coming up, so it waits for them (as `stream`
/// does) instead of being refused for the state, then waits for the homing's end.
fn home<T: link::client::Transport>(client: &mut Client<T>) -> Result<(), link::client::ClientError> {
    client.wait_for(std::time::Duration::from_secs(5), |s| {
        !matches!(s.state, State::LogicOn | State::PowerOn { settled: false })
    })?;
    client.home()?;
    client
        .wait_for(std::time::Duration::from_secs(120), |s| {
            !matches!(s.state, State::Homing)
        })
        .map(|_| ())
}

/// Does a command and then gives the status.
fn status_after<T: link::client::Transport>(
    client: &mut Client<T>,
    command: impl FnOnce(&mut Client<T>) -> Result<(), link::client::ClientError>,
) -> Result<String, DeviceError> {
    command(client)?;
    status(client)
}

/// The status as JSON, and the rig the board runs: where it came from and whether another waits for the next
/// start (a refused or unreadable stored rig is warned about on stderr).
fn status<T: link::client::Transport>(client: &mut Client<T>) -> Result<String, DeviceError> {
    let status = client.status()?;
    let (rig, source, pending) = client.rig()?;
    if let RigSource::Refused(_) | RigSource::Unreadable = source {
        eprintln!("warning: {source}");
    }
    let mut json = serde_json::to_value(status)?;
    json["rig"] = serde_json::json!({ "name": rig.name(), "source": source.to_string(), "pending": pending });
    if let Some(device) = client.device {
        json["firmware"] = firmware_json(&device.firmware);
    }
    Ok(serde_json::to_string_pretty(&json)?)
}

/// The firmware a device of this host's protocol runs, in a few words (`ports`, the workbench).
pub fn firmware_text(firmware: &Firmware) -> String {
    format!("{firmware}, protocol {PROTOCOL_VERSION}")
}

/// The firmware a device runs, as `device status` gives it: ringpod's version, the protocol (this host's: the
/// handshake agreed), and the flashed image's length and CRC-32C (`null` for the simulated controller).
pub fn firmware_json(firmware: &Firmware) -> serde_json::Value {
    let [major, minor, patch] = firmware.version;
    serde_json::json!({
        "version": format!("{major}.{minor}.{patch}"),
        "protocol": PROTOCOL_VERSION,
        "image": firmware.image.map(|i| serde_json::json!({ "size": i.size, "crc32c": format!("{:08x}", i.crc) })),
    })
}

/// `ringpod monitor`: until `frames` frames are drawn or a signal (then 128 + its number).
pub fn monitor(target: &Target, frames: Option<u64>) -> Result<u8, DeviceError> {
    let mut client = Client::new(link::connect(target, true)?);
    let source = match target {
        Target::Port(port) => port.clone(),
        Target::Sim => "the simulated controller".to_owned(),
    };
    let signals = Signals::install()?;
    monitor::run(&mut client, &source, frames, &|| signals.received())?;
    Ok(if signals.received() { signals.exit_code() } else { 0 })
}

/// The platform a simulated controller runs instead of the trainer model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Platform {
    /// A rig file's.
    File(PathBuf),
    /// A preset's, by name.
    Preset(String),
}

impl Platform {
    /// The rig to simulate: none for the trainer model (compiled in).
    pub fn rig(platform: Option<&Platform>) -> Result<Option<crate::rig::Rig>, crate::error::CliError> {
        Ok(match platform {
            None => None,
            Some(Platform::File(path)) => Some(crate::rig::load(path)?),
            Some(Platform::Preset(name)) => crate::rig::preset(name)?,
        })
    }
}

/// `ringpod simulate --pty | --tcp ADDRESS [--geometry RIG.toml | --mechanism PRESET]`: serves until a signal, and
/// exits with 128 + its number.
pub fn simulate(platform: Option<&Platform>, tcp: Option<std::net::SocketAddr>) -> Result<u8, DeviceError> {
    let device = match Platform::rig(platform)? {
        Some(rig) => sim::SimDevice::for_rig(true, &rig)?,
        None => sim::SimDevice::new(true),
    };
    let signals = Signals::install()?;
    match tcp {
        Some(addr) => link::tcp::serve(device, addr, &|| signals.received()).map_err(link::LinkError::from)?,
        None => serve_pty(device, &signals)?,
    }
    eprintln!("ringpod: simulator stopped by {}", signals.name());
    Ok(signals.exit_code())
}

#[cfg(unix)]
fn serve_pty(device: sim::SimDevice, signals: &Signals) -> Result<(), DeviceError> {
    Ok(link::pty::serve(device, &|| signals.received())?)
}

/// A pseudo-terminal is a Unix device: refused by name, before anything runs.
#[cfg(not(unix))]
fn serve_pty(_: sim::SimDevice, _: &Signals) -> Result<(), DeviceError> {
    Err(DeviceError::Unsupported(
        "simulate --pty: pseudo-terminals exist only on Unix; serve the simulator over TCP instead (simulate --tcp 127.0.0.1:PORT, then --port tcp://127.0.0.1:PORT)",
    ))
}

/// `ringpod ports`: the serial ports this machine has, and what each is; a board is asked which firmware it runs. A
/// board waiting in its ROM bootloader (USB 0483:df11, no serial port) is named too.
pub fn ports() -> Result<u8, DeviceError> {
    let ports = serialport::available_ports()?;
    let mut text = port_list(&ports, &identify);
    if crate::flash::usb::bootloader_listed() {
        text += "USB 0483:df11 STM32 BOOTLOADER  <- a board in its ROM bootloader: `ringpod flash` writes it\n";
    }
    let _ = std::io::stdout().write_all(text.as_bytes());
    Ok(0)
}

/// What the board on `port` says it runs, in a few words: one handshake, half a second's wait (lengthened by
/// [`link::PATIENCE_VAR`]). A port another program holds cannot be opened (serial ports are opened exclusively) and
/// is left alone.
fn identify(port: &str) -> String {
    let transport = match link::connect(&Target::Port(port.to_owned()), false) {
        Ok(t) => t,
        Err(e) => return format!("not opened: {e}"),
    };
    let mut client = Client::new(transport);
    match client.hello_once(link::patience(std::time::Duration::from_millis(500))) {
        Ok(device) => firmware_text(&device.firmware),
        Err(ClientError::VersionMismatch { device, firmware, .. }) => {
            let runs = firmware.map_or_else(|| "firmware".to_owned(), |f| f.to_string());
            format!("{runs}, protocol {device}: not this ringpod's (protocol {PROTOCOL_VERSION}), run `ringpod flash`")
        }
        Err(e) => format!("no answer: {e}"),
    }
}

pub use crate::link::BOARD_USB_ID;

/// One line a port: its name (`/dev/ttyACM0`, `COM5`), its kind with a USB port's VID:PID, and a board marked as
/// such with what `identify` finds it runs, so that it is found without the system's device manager.
fn port_list(ports: &[serialport::SerialPortInfo], identify: &dyn Fn(&str) -> String) -> String {
    if ports.is_empty() {
        return "no serial ports found\n".into();
    }
    let mut text = String::new();
    for p in ports {
        let kind = match &p.port_type {
            serialport::SerialPortType::UsbPort(u) => {
                let mut kind = format!("USB {:04x}:{:04x}", u.vid, u.pid);
                if let Some(product) = u.product.as_deref().filter(|p| !p.is_empty()) {
                    kind += &format!(" {product}");
                }
                if (u.vid, u.pid) == BOARD_USB_ID {
                    kind += &format!("  <- a ringpod board: {}", identify(&p.port_name));
                }
                kind
            }
            serialport::SerialPortType::PciPort => "PCI".into(),
            serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
            serialport::SerialPortType::Unknown => "unknown".into(),
        };
        text += &format!("{}  {kind}\n", p.port_name);
    }
    text
}

/// A state as one word (a run record's CSV field, the monitor, the web page): its name, and a fault's reason after
/// a colon (no commas).
pub fn state_name(state: State) -> String {
    match state {
        State::Off => "Off".into(),
        State::LogicOn => "LogicOn".into(),
        State::PowerOn { .. } => "PowerOn".into(),
        State::Homing => "Homing".into(),
        State::Ready => "Ready".into(),
        State::Running => "Running".into(),
        State::Jogging => "Jogging".into(),
        State::Stopping => "Stopping".into(),
        State::Fault(reason, _) => format!("Fault: {reason}").replace(',', ";"),
        State::ShuttingDown(_) => "ShuttingDown".into(),
    }
}

#[cfg(test)]
mod tests {
    use serialport::{SerialPortInfo, SerialPortType, UsbPortInfo};

    fn usb(name: &str, vid: u16, pid: u16, product: Option<&str>) -> SerialPortInfo {
        SerialPortInfo {
            port_name: name.into(),
            port_type: SerialPortType::UsbPort(UsbPortInfo {
                vid,
                pid,
                serial_number: None,
                manufacturer: None,
                product: product.map(Into::into),
            }),
        }
    }

    #[test]
    fn the_board_is_found_by_its_vid_and_pid_under_any_name() {
        let ports = [
            usb("COM3", 0x0403, 0x6001, Some("FT232R")),
            usb("COM5", 0x1209, 0x0001, None),
            SerialPortInfo {
                port_name: "COM1".into(),
                port_type: SerialPortType::PciPort,
            },
        ];
        let asked = std::cell::RefCell::new(Vec::new());
        let identify = |port: &str| {
            asked.borrow_mut().push(port.to_owned());
            "ringpod 0.1.0".to_owned()
        };
        let text = super::port_list(&ports, &identify);
        assert_eq!(
            text,
            "COM3  USB 0403:6001 FT232R\nCOM5  USB 1209:0001  <- a ringpod board: ringpod 0.1.0\nCOM1  PCI\n"
        );
        assert_eq!(*asked.borrow(), ["COM5"], "only the board is asked");
        // Another product of the same vendor is not the board.
        assert!(!super::port_list(&[usb("/dev/ttyACM0", 0x1209, 0x0002, None)], &identify).contains("board"));
        assert_eq!(super::port_list(&[], &identify), "no serial ports found\n");
    }
}
