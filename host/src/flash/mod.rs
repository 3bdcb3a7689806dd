//! `ringpod flash`: the firmware written over the USB cable by the STM32F411's ROM bootloader (USB DFU with ST's
//! DfuSe extension: UM0424, AN3156; the F411's bootloader in AN2606), no probe needed.
//!
//! The image is checked first (`image`); the board is found (a bootloader already on the bus, 0483:df11, or the
//! running firmware on its serial port, asked to restart into its bootloader: `HostMessage::EnterBootloader`,
//! taken only with the supplies off); the sectors the image covers are erased, the image written, read back and
//! compared (`program`, over `dfuse`); DFU is left, and the new firmware must enumerate and name the image it
//! runs. `usb` is the real bus (nusb); `tcp` reaches the emulated board's bootloader through its harness; the unit
//! tests flash `model`, a model of the ROM bootloader.

pub mod command;
pub mod dfuse;
pub mod image;
#[cfg(test)]
pub mod model;
pub mod program;
pub mod tcp;
pub mod usb;

use std::path::{Path, PathBuf};
use std::time::Duration;

use ringpod_core::protocol::Image;

use crate::link::client::{Client, ClientError, Transport};
use dfuse::{Control, DfuSe, Layout, UsbError};
use image::{FirmwareImage, ImageError};
use program::{Phase, ProgramError};

/// The ROM bootloader's USB id (AN2606: ST's DFU device).
pub const BOOTLOADER_USB_ID: (u16, u16) = (0x0483, 0xDF11);

/// Exit codes of `ringpod flash`, one a class of failure.
pub mod exit {
    /// The image was refused (not a firmware, or one that would reach the settings): nothing was done.
    pub const IMAGE: u8 = 3;
    /// No board was found, or it did not enter its bootloader (refused while not at rest): nothing was erased.
    pub const BOARD: u8 = 4;
    /// The transfer failed half way: the board waits in its bootloader (or needs BOOT0): flash again.
    pub const TRANSFER: u8 = 5;
    /// The image read back differs: flash again.
    pub const VERIFY: u8 = 6;
    /// Written and verified, but the new firmware did not come back, or names another image.
    pub const RESTART: u8 = 7;
}

/// Why `flash` stopped.
#[derive(Debug, thiserror::Error)]
pub enum FlashError {
    /// The image could not be had.
    #[error("{0}")]
    Build(String),
    /// The image was refused.
    #[error("the image is refused, nothing was erased: {0}")]
    Image(#[from] ImageError),
    /// No board, or it would not enter its bootloader.
    #[error("{0}")]
    Board(String),
    /// Writing failed.
    #[error("{0}")]
    Program(#[from] ProgramError),
    /// The new firmware did not come back as flashed.
    #[error("{0}")]
    Restart(String),
}

impl FlashError {
    /// The exit code of its class ([`exit`]).
    pub fn code(&self) -> u8 {
        match self {
            FlashError::Build(_) => crate::out::EXIT_ERROR,
            FlashError::Image(_) => exit::IMAGE,
            FlashError::Board(_) => exit::BOARD,
            FlashError::Program(ProgramError::Verify { .. }) => exit::VERIFY,
            FlashError::Program(ProgramError::Layout(_)) => exit::IMAGE,
            FlashError::Program(ProgramError::Dfu { .. }) => exit::TRANSFER,
            FlashError::Restart(_) => exit::RESTART,
        }
    }

    /// What the user does next, when a failure leaves the board without a complete program.
    pub fn advice(&self) -> Option<&'static str> {
        match self {
            FlashError::Program(ProgramError::Dfu { .. } | ProgramError::Verify { .. }) => Some(
                "the board has no complete program now and cannot start one: run `ringpod flash` again (if the \
                 board was unplugged or reset meanwhile, hold its BOOT0 button while plugging it in or pressing \
                 NRST: the ROM bootloader then waits for it)",
            ),
            _ => None,
        }
    }
}

/// The bootloader on a bus: its DFU pipe, its memory's layout string and its transfer size.
pub struct Bootloader<C: Control> {
    /// The pipe.
    pub dfu: DfuSe<C>,
    /// The alternate setting's string (UM0424 6.1.2).
    pub layout: String,
}

/// Where `flash` finds the ROM bootloader: the USB bus, or the tests' model.
pub trait Bus {
    /// The pipe to a found bootloader.
    type Pipe: Control;
    /// The bootloader (0483:df11) if it is on the bus now.
    fn bootloader(&mut self) -> Result<Option<Bootloader<Self::Pipe>>, UsbError>;
    /// Lets `wait` pass.
    fn sleep(&mut self, wait: Duration);
}

/// Waits up to `limit` for the bootloader to enumerate.
pub fn await_bootloader<B: Bus>(bus: &mut B, limit: Duration) -> Result<Bootloader<B::Pipe>, FlashError> {
    let step = Duration::from_millis(100);
    let mut waited = Duration::ZERO;
    loop {
        match bus.bootloader() {
            Ok(Some(found)) => return Ok(found),
            Ok(None) | Err(UsbError::Gone) => {}
            Err(e) => return Err(FlashError::Board(format!("the ROM bootloader (0483:df11): {e}"))),
        }
        if waited >= limit {
            return Err(FlashError::Board(format!(
                "the ROM bootloader (USB 0483:df11) did not appear within {limit:?}{}",
                if cfg!(windows) {
                    " (on Windows it needs the WinUSB driver: see the book's Hardware chapter, Zadig)"
                } else {
                    ""
                }
            )));
        }
        bus.sleep(step);
        waited += step;
    }
}

/// Asks the running firmware to restart into its ROM bootloader (no handshake: any protocol version takes it);
/// its refusal (not at rest, supplies on) is said with the way out. Returns what it said it ran, when it did.
pub fn enter_bootloader<T: Transport>(client: &mut Client<T>) -> Result<Option<String>, FlashError> {
    let was = match client.hello() {
        Ok(device) => Some(device.firmware.to_string()),
        Err(ClientError::VersionMismatch { device, firmware, .. }) => {
            Some(firmware.map_or_else(|| format!("firmware of protocol {device}"), |f| f.to_string()))
        }
        Err(_) => None,
    };
    match client.enter_bootloader() {
        Ok(()) => Ok(was),
        Err(ClientError::Device(reason)) => Err(FlashError::Board(format!(
            "the board did not enter its bootloader ({reason}): it must be at rest with the supplies off; run \
             `ringpod device stop` and `ringpod device disable`, then flash again"
        ))),
        Err(ClientError::Timeout(_)) => Err(FlashError::Board(
            "the board did not answer the bootloader request (firmware older than protocol 10 has none): hold \
             its BOOT0 button while pressing NRST (or plugging it in), then run `ringpod flash` again"
                .into(),
        )),
        Err(e) => Err(FlashError::Board(format!("the board: {e}"))),
    }
}

/// Writes `image` into the bootloader found and starts it; `progress` as [`program::program`] tells.
pub fn write<C: Control>(
    found: &mut Bootloader<C>,
    image: &FirmwareImage,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<(), FlashError> {
    let layout =
        Layout::parse(&found.layout).map_err(|e| FlashError::Board(format!("the bootloader's memory layout: {e}")))?;
    // Checked before anything is erased.
    program::sectors(&layout, image)?;
    program::program(&mut found.dfu, &layout, image, progress)?;
    Ok(())
}

/// The end line: what was flashed, and what the board says it runs now.
pub fn end_line(image: &FirmwareImage, runs: &ringpod_core::protocol::Firmware) -> Result<String, FlashError> {
    let flashed: Image = image.id();
    if runs.image != Some(flashed) {
        return Err(FlashError::Restart(format!(
            "flashed and verified {} B (CRC-32C {:08x}), but the board now says it runs {runs}",
            flashed.size, flashed.crc
        )));
    }
    Ok(format!(
        "flashed {} B, verified, settings kept; the board runs {runs}",
        group(u64::from(flashed.size))
    ))
}

/// A count with thousands separated by commas (195,580).
fn group(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The image of `--image`, or the firmware built from this source tree (`cargo build -p ringpod-firmware --target
/// thumbv7em-none-eabihf --profile firmware`, the toolchain of `rust-toolchain.toml`), checked.
pub fn load(path: Option<&Path>) -> Result<FirmwareImage, FlashError> {
    let path = match path {
        Some(p) => p.to_owned(),
        None => build()?,
    };
    let bytes = std::fs::read(&path).map_err(|e| FlashError::Build(format!("{}: {e}", path.display())))?;
    Ok(FirmwareImage::from_file_bytes(&bytes)?)
}

/// Builds the firmware in the source tree this ringpod was built from; its ELF's path.
fn build() -> Result<PathBuf, FlashError> {
    let tree = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    if !tree.join("firmware").join("Cargo.toml").is_file() {
        return Err(FlashError::Build(format!(
            "no ringpod source tree at {} to build the firmware in: give the image with --image FILE (.elf or .bin)",
            tree.display()
        )));
    }
    crate::out::console::err("building the firmware (cargo build -p ringpod-firmware --profile firmware) ...");
    let out = std::process::Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .current_dir(&tree)
        .args([
            "build",
            "-p",
            "ringpod-firmware",
            "--target",
            "thumbv7em-none-eabihf",
            "--profile",
            "firmware",
        ])
        .args(["--message-format", "json-render-diagnostics"])
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| FlashError::Build(format!("cargo: {e}")))?;
    if !out.status.success() {
        return Err(FlashError::Build(
            "the firmware did not build (cargo's messages above)".into(),
        ));
    }
    executable(&String::from_utf8_lossy(&out.stdout))
        .ok_or_else(|| FlashError::Build("cargo built no ringpod-firmware executable".into()))
}

/// The firmware's ELF from cargo's JSON messages.
fn executable(messages: &str) -> Option<PathBuf> {
    messages
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == "ringpod-firmware")
        .filter_map(|m| m["executable"].as_str().map(PathBuf::from))
        .next_back()
}

/// A progress bar per phase on stderr (hidden when stderr is not a terminal).
pub fn progress_bar() -> impl FnMut(Phase, u64, u64) {
    let mut current: Option<(Phase, indicatif::ProgressBar)> = None;
    move |phase, done, total| {
        if current.as_ref().map(|c| c.0) != Some(phase) {
            if let Some((_, bar)) = current.take() {
                bar.finish();
            }
            let bar = indicatif::ProgressBar::new(total);
            let verb = match phase {
                Phase::Erase => "erasing  ",
                Phase::Write => "writing  ",
                Phase::Verify => "verifying",
            };
            bar.set_style(
                indicatif::ProgressStyle::with_template(&format!("{verb} {{bar:40}} {{bytes}}/{{total_bytes}}"))
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            current = Some((phase, bar));
        }
        if let Some((_, bar)) = &current {
            bar.set_position(done);
            if done >= total {
                bar.finish();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::model::{RomModel, F411_LAYOUT, TRANSFER_SIZE};
    use super::*;
    use ringpod_core::protocol::Firmware;

    /// A bus on which the bootloader model appears after `after` looks.
    struct ModelBus {
        model: Option<RomModel>,
        after: usize,
        slept: Duration,
    }

    impl Bus for ModelBus {
        type Pipe = RomModel;
        fn bootloader(&mut self) -> Result<Option<Bootloader<RomModel>>, UsbError> {
            if self.after > 0 {
                self.after -= 1;
                return Ok(None);
            }
            Ok(self.model.take().map(|control| Bootloader {
                dfu: DfuSe {
                    control,
                    transfer_size: TRANSFER_SIZE,
                },
                layout: F411_LAYOUT.into(),
            }))
        }
        fn sleep(&mut self, wait: Duration) {
            self.slept += wait;
        }
    }

    #[test]
    fn the_board_found_late_is_flashed_and_the_end_line_names_what_it_runs() {
        let image = FirmwareImage::from_file_bytes(&image::tests::program(50_000)).unwrap();
        let mut bus = ModelBus {
            model: Some(RomModel::new()),
            after: 12,
            slept: Duration::ZERO,
        };
        let mut found = await_bootloader(&mut bus, Duration::from_secs(10)).unwrap();
        assert_eq!(bus.slept, Duration::from_millis(1_200));
        write(&mut found, &image, &mut |_, _, _| {}).unwrap();
        assert_eq!(found.dfu.control.read(0x0800_0000, 50_000), &image.bytes[..]);
        let runs = Firmware {
            image: Some(image.id()),
            ..Firmware::BUILT
        };
        let line = end_line(&image, &runs).unwrap();
        assert!(
            line.starts_with("flashed 50,000 B, verified, settings kept; the board runs ringpod "),
            "{line}"
        );
        let other = Firmware {
            image: Some(Image { size: 50_000, crc: 1 }),
            ..Firmware::BUILT
        };
        assert_eq!(end_line(&image, &other).unwrap_err().code(), exit::RESTART);
        // No bootloader at all: said, with nothing done.
        let mut empty = ModelBus {
            model: None,
            after: 0,
            slept: Duration::ZERO,
        };
        let err = await_bootloader(&mut empty, Duration::from_secs(2)).err().unwrap();
        assert_eq!(err.code(), exit::BOARD);
    }

    #[test]
    fn the_simulated_board_enters_only_at_rest() {
        use crate::link::sim::SimDevice;
        let mut client = Client::new(SimDevice::new(false));
        client.hello().unwrap();
        client.enable().unwrap();
        let refused = enter_bootloader(&mut client).unwrap_err();
        assert_eq!(refused.code(), exit::BOARD);
        assert!(refused.to_string().contains("ringpod device disable"), "{refused}");
        let mut client = Client::new(SimDevice::new(false));
        let was = enter_bootloader(&mut client).unwrap();
        assert!(was.unwrap().starts_with("ringpod "));
    }

    #[test]
    fn cargo_names_the_firmware_executable() {
        let messages = concat!(
            r#"{"reason":"compiler-artifact","target":{"name":"ringpod-core"},"executable":null}"#,
            "\n",
            r#"{"reason":"compiler-artifact","target":{"name":"ringpod-firmware"},"executable":"/t/ringpod-firmware"}"#,
            "\n",
            r#"{"reason":"build-finished","success":true}"#
        );
        assert_eq!(executable(messages), Some(PathBuf::from("/t/ringpod-firmware")));
        assert_eq!(executable(""), None);
        assert_eq!(group(195_580), "195,580");
        assert_eq!(group(1_048_576), "1,048,576");
        assert_eq!(group(12), "12");
    }
}
