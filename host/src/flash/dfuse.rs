//! ST's DfuSe protocol (UM0424, over USB DFU 1.1) as the STM32's ROM bootloader speaks it (AN3156), on any
//! [`Control`] pipe: the real USB device (`usb`), or the bootloader model the tests flash.
//!
//! Every request is a class request to the DFU interface. A download (DNLOAD) with block 0 carries a command:
//! Set Address Pointer (0x21) or Erase (0x41), each followed by an address; a download with block `n >= 2` writes
//! `transfer size` bytes at `pointer + (n - 2) x transfer size`, and an upload (UPLOAD) with block `n >= 2` reads
//! there. After a download the device is busy: GETSTATUS says how long to wait before asking again
//! (`bwPollTimeout`), until it is idle again (dfuDNLOAD-IDLE) or reports an error. A zero-length download then a
//! GETSTATUS leaves DFU: the bootloader starts the program at the address pointer.

use std::time::Duration;

/// DFU 1.1 table 3.2: the class requests.
const DNLOAD: u8 = 1;
const UPLOAD: u8 = 2;
const GETSTATUS: u8 = 3;
const CLRSTATUS: u8 = 4;
const ABORT: u8 = 6;

/// UM0424 6.1.3: the DfuSe commands of a block-0 download.
const SET_ADDRESS: u8 = 0x21;
const ERASE: u8 = 0x41;

/// How long a device may stay busy on one operation before it counts as gone (the F411's largest sector, 128 KiB,
/// erases in at most 2 s, datasheet t_ERASE128KB).
const BUSY_LIMIT: Duration = Duration::from_secs(10);

/// DFU 1.1 6.1.2: the device states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    AppIdle = 0,
    AppDetach = 1,
    Idle = 2,
    DownloadSync = 3,
    DownloadBusy = 4,
    DownloadIdle = 5,
    ManifestSync = 6,
    Manifest = 7,
    ManifestWaitReset = 8,
    UploadIdle = 9,
    Error = 10,
}

impl State {
    fn from_byte(b: u8) -> Option<State> {
        use State::*;
        [
            AppIdle,
            AppDetach,
            Idle,
            DownloadSync,
            DownloadBusy,
            DownloadIdle,
            ManifestSync,
            Manifest,
            ManifestWaitReset,
            UploadIdle,
            Error,
        ]
        .get(usize::from(b))
        .copied()
    }
}

/// A GETSTATUS answer (DFU 1.1 6.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Status {
    /// `bStatus`: 0 OK, else the error (DFU 1.1 table 6.1: 0x03 errWRITE, 0x04 errERASE, 0x08 errADDRESS, ...).
    pub status: u8,
    /// How long to wait before the next GETSTATUS.
    pub poll: Duration,
    /// The state the device will be in once the poll time has passed.
    pub state: State,
}

impl Status {
    /// The six bytes of a GETSTATUS answer.
    pub fn parse(bytes: &[u8]) -> Result<Status, DfuError> {
        let &[status, p0, p1, p2, state, _] = bytes else {
            return Err(DfuError::Protocol(format!(
                "GETSTATUS answered {} bytes, not 6",
                bytes.len()
            )));
        };
        let state = State::from_byte(state).ok_or_else(|| DfuError::Protocol(format!("unknown DFU state {state}")))?;
        Ok(Status {
            status,
            poll: Duration::from_millis(u64::from(u32::from_le_bytes([p0, p1, p2, 0]))),
            state,
        })
    }

    /// The six bytes of this answer (the model's side).
    #[cfg(test)]
    pub fn bytes(&self) -> [u8; 6] {
        let ms = u32::try_from(self.poll.as_millis())
            .unwrap_or(0xFF_FFFF)
            .min(0xFF_FFFF)
            .to_le_bytes();
        [self.status, ms[0], ms[1], ms[2], self.state as u8, 0]
    }
}

/// Why a USB control transfer failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UsbError {
    /// The device is no longer on the bus (the cable pulled, the board reset).
    #[error("the device left the bus")]
    Gone,
    /// The device refused the request (a STALL: DFU 1.1 says a request out of its state is stalled).
    #[error("the device stalled the request")]
    Stall,
    /// Anything else the USB stack said.
    #[error("{0}")]
    Other(String),
}

/// Why a DfuSe operation failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DfuError {
    /// The transfer failed.
    #[error(transparent)]
    Usb(#[from] UsbError),
    /// The device reported an error status (DFU 1.1 table 6.1) in a state.
    #[error("the bootloader reported error status {status:#04x} ({}) in {state:?}", status_name(.status))]
    Status {
        /// `bStatus`.
        status: u8,
        /// `bState`.
        state: State,
    },
    /// The device stayed busy too long.
    #[error("the bootloader stayed busy for more than {0:?}")]
    Busy(Duration),
    /// An answer that does not fit the protocol.
    #[error("{0}")]
    Protocol(String),
}

/// DFU 1.1 table 6.1's names of the error statuses.
fn status_name(status: &u8) -> &'static str {
    match *status {
        0x01 => "errTARGET",
        0x02 => "errFILE",
        0x03 => "errWRITE",
        0x04 => "errERASE",
        0x05 => "errCHECK_ERASED",
        0x06 => "errPROG",
        0x07 => "errVERIFY",
        0x08 => "errADDRESS",
        0x09 => "errNOTDONE",
        0x0A => "errFIRMWARE",
        0x0B => "errVENDOR",
        0x0C => "errUSBR",
        0x0D => "errPOR",
        0x0E => "errUNKNOWN",
        0x0F => "errSTALLEDPKT",
        _ => "not a DFU status",
    }
}

/// Class requests to the DFU interface: the one thing a backend provides. Time passes through it too, so that a
/// model runs on its own clock.
pub trait Control {
    /// A class request from the device (`bmRequestType` 0xA1) of at most `length` bytes.
    fn control_in(&mut self, request: u8, value: u16, length: u16) -> Result<Vec<u8>, UsbError>;
    /// A class request to the device (`bmRequestType` 0x21) with `data`.
    fn control_out(&mut self, request: u8, value: u16, data: &[u8]) -> Result<(), UsbError>;
    /// Lets `wait` pass (a poll timeout).
    fn sleep(&mut self, wait: Duration);
}

/// The DfuSe operations on one device, with its transfer size (`wTransferSize` of its DFU functional descriptor).
pub struct DfuSe<C: Control> {
    /// The pipe.
    pub control: C,
    /// Bytes per download or upload block.
    pub transfer_size: u16,
}

impl<C: Control> DfuSe<C> {
    /// The device's status now.
    pub fn status(&mut self) -> Result<Status, DfuError> {
        Status::parse(&self.control.control_in(GETSTATUS, 0, 6)?)
    }

    /// Brings the device to dfuIDLE from wherever it is: an operation in progress waited out (ABORT is not taken
    /// while busy, DFU 1.1 A.1), an error cleared (CLRSTATUS), a transfer aborted (ABORT).
    pub fn idle(&mut self) -> Result<(), DfuError> {
        for _ in 0..8 {
            let status = self.status()?;
            match status.state {
                State::Idle if status.status == 0 => return Ok(()),
                State::Error => self.control.control_out(CLRSTATUS, 0, &[])?,
                State::DownloadBusy | State::DownloadSync => self.control.sleep(status.poll),
                _ => self.control.control_out(ABORT, 0, &[])?,
            }
        }
        let Status { status, state, .. } = self.status()?;
        Err(DfuError::Status { status, state })
    }

    /// After a download: GETSTATUS, waiting each poll timeout, until the device is no longer busy; an error status
    /// is the operation's failure.
    fn settle(&mut self) -> Result<Status, DfuError> {
        let mut waited = Duration::ZERO;
        loop {
            let status = self.status()?;
            if status.status != 0 {
                return Err(DfuError::Status {
                    status: status.status,
                    state: status.state,
                });
            }
            if !matches!(status.state, State::DownloadBusy | State::DownloadSync) {
                return Ok(status);
            }
            if waited > BUSY_LIMIT {
                return Err(DfuError::Busy(BUSY_LIMIT));
            }
            self.control.sleep(status.poll);
            waited += status.poll;
        }
    }

    /// A block-0 command with its address, carried out.
    fn command(&mut self, command: u8, address: u32) -> Result<(), DfuError> {
        let mut data = [command, 0, 0, 0, 0];
        data[1..].copy_from_slice(&address.to_le_bytes());
        self.control.control_out(DNLOAD, 0, &data)?;
        match self.settle()?.state {
            State::DownloadIdle => Ok(()),
            other => Err(DfuError::Protocol(format!("after command {command:#04x}: {other:?}"))),
        }
    }

    /// Set Address Pointer.
    pub fn set_address(&mut self, address: u32) -> Result<(), DfuError> {
        self.command(SET_ADDRESS, address)
    }

    /// Erases the page (sector) that holds `address`.
    pub fn erase(&mut self, address: u32) -> Result<(), DfuError> {
        self.command(ERASE, address)
    }

    /// Writes `data` (at most a transfer size) as block `block` (>= 2) after the address pointer.
    pub fn write_block(&mut self, block: u16, data: &[u8]) -> Result<(), DfuError> {
        self.control.control_out(DNLOAD, block, data)?;
        match self.settle()?.state {
            State::DownloadIdle => Ok(()),
            other => Err(DfuError::Protocol(format!("after writing block {block}: {other:?}"))),
        }
    }

    /// Reads block `block` (>= 2) after the address pointer: `length` bytes (the device must be in dfuIDLE or
    /// dfuUPLOAD-IDLE, UM0424 6.2: abort after setting the pointer).
    pub fn read_block(&mut self, block: u16, length: u16) -> Result<Vec<u8>, DfuError> {
        let data = self.control.control_in(UPLOAD, block, length)?;
        if data.len() != usize::from(length) {
            return Err(DfuError::Protocol(format!(
                "block {block} read {} bytes, not {length}",
                data.len()
            )));
        }
        Ok(data)
    }

    /// Leaves DFU: the program at `address` starts (UM0424 6.1.4: the pointer set, a zero-length download, and the
    /// GETSTATUS that makes the device manifest). The device may leave the bus before answering that GETSTATUS.
    pub fn leave(&mut self, address: u32) -> Result<(), DfuError> {
        self.set_address(address)?;
        self.control.control_out(DNLOAD, 2, &[])?;
        match self.status() {
            Ok(Status { status: 0, .. }) | Err(DfuError::Usb(UsbError::Gone)) => Ok(()),
            Ok(Status { status, state, .. }) => Err(DfuError::Status { status, state }),
            Err(e) => Err(e),
        }
    }
}

/// One kind of page of a memory: `count` pages of `size` bytes, readable, erasable, writable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pages {
    /// How many.
    pub count: u32,
    /// Bytes each.
    pub size: u32,
    /// UM0424 table 9's type letter: `a` + readable (1) + erasable (2) + writable (4) - 1.
    pub access: u8,
}

/// A memory as an alternate setting's string describes it (UM0424 6.1.2:
/// `@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg`: name, start, then pages `N*SIZE[K|M]TYPE`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Its name ("Internal Flash").
    pub name: String,
    /// Where it starts.
    pub start: u32,
    /// Its pages in address order.
    pub pages: Vec<Pages>,
}

impl Layout {
    /// Parses the alternate setting's string.
    pub fn parse(text: &str) -> Result<Layout, String> {
        let rest = text
            .strip_prefix('@')
            .ok_or_else(|| format!("{text:?} is not a DfuSe memory layout"))?;
        let mut parts = rest.split('/');
        let (Some(name), Some(start), Some(pages)) = (parts.next(), parts.next(), parts.next()) else {
            return Err(format!("{text:?}: not name/start/pages"));
        };
        let start = u32::from_str_radix(start.trim().trim_start_matches("0x").trim_start_matches("0X"), 16)
            .map_err(|_| format!("{text:?}: the start {start:?} is not an address"))?;
        let pages = pages
            .split(',')
            .map(|p| Self::pages(p.trim()).ok_or_else(|| format!("{text:?}: {p:?} is not N*SIZE[K|M]TYPE")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Layout {
            name: name.trim().to_owned(),
            start,
            pages,
        })
    }

    fn pages(text: &str) -> Option<Pages> {
        let (count, size) = text.split_once('*')?;
        let access = *size.as_bytes().last()?;
        if !(b'a'..=b'g').contains(&access) {
            return None;
        }
        let size = &size[..size.len() - 1];
        let (digits, unit) = match size.as_bytes().last()? {
            b'K' => (&size[..size.len() - 1], 1024),
            b'M' => (&size[..size.len() - 1], 1024 * 1024),
            _ => (size.trim_end(), 1),
        };
        Some(Pages {
            count: count.parse().ok()?,
            size: digits.trim().parse::<u32>().ok()?.checked_mul(unit)?,
            access,
        })
    }

    /// Every page as (start address, size, erasable and writable).
    pub fn each_page(&self) -> Vec<(u32, u32, bool)> {
        let mut at = self.start;
        let mut all = Vec::new();
        for p in &self.pages {
            let bits = p.access - b'a' + 1;
            for _ in 0..p.count {
                all.push((at, p.size, bits & 6 == 6));
                at = at.wrapping_add(p.size);
            }
        }
        all
    }

    /// The pages `[from, from + len)` touches, or why it cannot be written: outside the memory, or a page that is
    /// not erasable and writable.
    pub fn pages_for(&self, from: u32, len: u32) -> Result<Vec<(u32, u32)>, String> {
        let end = u64::from(from) + u64::from(len);
        let pages: Vec<_> = self
            .each_page()
            .into_iter()
            .filter(|&(at, size, _)| u64::from(at) < end && u64::from(at) + u64::from(size) > u64::from(from))
            .collect();
        let covered: u64 = pages.iter().map(|&(_, size, _)| u64::from(size)).sum();
        let first = pages.first().map_or(u64::MAX, |p| u64::from(p.0));
        if len == 0 || first > u64::from(from) || first + covered < end {
            return Err(format!(
                "{len} B at {from:#010x} is not inside {} ({:#010x}, {} B)",
                self.name,
                self.start,
                self.each_page().iter().map(|p| u64::from(p.1)).sum::<u64>()
            ));
        }
        if let Some(&(at, _, _)) = pages.iter().find(|p| !p.2) {
            return Err(format!(
                "the page at {at:#010x} of {} cannot be erased and written",
                self.name
            ));
        }
        Ok(pages.into_iter().map(|(at, size, _)| (at, size)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The STM32F411's internal flash as its ROM bootloader describes it (AN2606, UM0424 6.1.2).
    pub const F411: &str = "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg";

    #[test]
    fn the_f411_layout_is_its_eight_sectors() {
        let layout = Layout::parse(F411).unwrap();
        assert_eq!(layout.name, "Internal Flash");
        assert_eq!(layout.start, 0x0800_0000);
        let pages = layout.each_page();
        let starts: Vec<u32> = pages.iter().map(|p| p.0).collect();
        assert_eq!(
            starts,
            [
                0x0800_0000,
                0x0800_4000,
                0x0800_8000,
                0x0800_C000,
                0x0801_0000,
                0x0802_0000,
                0x0804_0000,
                0x0806_0000
            ]
        );
        assert!(pages.iter().all(|p| p.2));
        // A 195,580-byte image covers sectors 0-5 and never the settings' 6 and 7.
        let covered = layout.pages_for(0x0800_0000, 195_580).unwrap();
        assert_eq!(covered.len(), 6);
        assert_eq!(covered.last(), Some(&(0x0802_0000, 128 * 1024)));
        // One byte into sector 1: sectors 0 and 1.
        assert_eq!(layout.pages_for(0x0800_0000, 0x4001).unwrap().len(), 2);
        assert!(layout.pages_for(0x0800_0000, 0).is_err());
        assert!(layout.pages_for(0x0808_0000, 4).is_err(), "past the end");
        assert!(layout.pages_for(0x07FF_FFFC, 8).is_err(), "before the start");
        // The option bytes' read-only pages cannot be written.
        let ro = Layout::parse("@Option Bytes  /0x1FFFC000/01*016 e").unwrap();
        assert_eq!(
            ro.pages,
            [Pages {
                count: 1,
                size: 16,
                access: b'e'
            }]
        );
        assert!(ro.pages_for(0x1FFF_C000, 4).is_err());
        for bad in [
            "Internal Flash/0x08000000/04*016Kg",
            "@x/zz/04*016Kg",
            "@x/0x0/04*016Kz",
            "@x/0x0/4x16Kg",
            "@x",
        ] {
            assert!(Layout::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_status_round_trips_and_a_short_one_is_refused() {
        let s = Status {
            status: 0,
            poll: Duration::from_millis(0x01_2345),
            state: State::DownloadBusy,
        };
        assert_eq!(Status::parse(&s.bytes()), Ok(s));
        assert!(Status::parse(&[0, 0, 0, 0, 2]).is_err());
        assert!(Status::parse(&[0, 0, 0, 0, 11, 0]).is_err());
        let error = DfuError::Status {
            status: 0x08,
            state: State::Error,
        };
        assert_eq!(
            error.to_string(),
            "the bootloader reported error status 0x08 (errADDRESS) in Error"
        );
    }
}
