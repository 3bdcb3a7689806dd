//! A model of the STM32F411's ROM bootloader as a DfuSe device (AN2606, AN3156, UM0424), for the tests: its
//! internal flash (sectors of 16, 64 and 128 KiB, erased cells 0xFF, programming only clears bits), the DFU state
//! machine with its poll timeouts and its own clock, the erase and write times of the datasheet, and the leave
//! request that starts the program. What it is asked is recorded, so that a test sees every erase and every early
//! poll; the cable can be pulled after any number of requests.

use std::time::Duration;

use super::dfuse::{Control, Layout, State, Status, UsbError};

/// The F411's internal flash as its bootloader describes it (UM0424 6.1.2).
pub const F411_LAYOUT: &str = "@Internal Flash  /0x08000000/04*016Kg,01*064Kg,03*128Kg";
/// The ROM bootloader's `wTransferSize` (AN3156: 2048 bytes).
pub const TRANSFER_SIZE: u16 = 2048;
const FLASH: u32 = 0x0800_0000;
const FLASH_SIZE: usize = 512 * 1024;

/// DFU 1.1 table 6.1.
const ERR_TARGET: u8 = 0x01;
const ERR_ADDRESS: u8 = 0x08;
const ERR_STALLEDPKT: u8 = 0x0F;

/// An operation a download started, carried out at the next GETSTATUS (DFU 1.1: dfuDNLOAD-SYNC).
#[derive(Debug, Clone, PartialEq)]
enum Op {
    SetAddress(u32),
    Erase(u32),
    Write(u32, Vec<u8>),
    Leave,
}

/// The bootloader.
pub struct RomModel {
    /// The internal flash, from 0x0800_0000.
    pub flash: Vec<u8>,
    layout: Layout,
    state: State,
    status: u8,
    pointer: u32,
    pending: Option<Op>,
    /// Until when the device is busy (its clock).
    busy_until: Duration,
    /// Its clock.
    pub now: Duration,
    /// Every sector erase, by start address.
    pub erased: Vec<u32>,
    /// GETSTATUS requests that came before the poll timeout had passed.
    pub early_polls: u32,
    /// Where the program was started by a leave request, once.
    pub started: Option<u32>,
    /// Requests left before the cable is pulled (`None`: never).
    pub cable: Option<usize>,
    /// Every request, as (request, value).
    pub requests: Vec<(u8, u16)>,
}

impl Default for RomModel {
    fn default() -> Self {
        Self::new()
    }
}

impl RomModel {
    /// Erased flash, in dfuIDLE.
    pub fn new() -> Self {
        Self {
            flash: vec![0xFF; FLASH_SIZE],
            layout: Layout::parse(F411_LAYOUT).unwrap_or(Layout {
                name: String::new(),
                start: FLASH,
                pages: Vec::new(),
            }),
            state: State::Idle,
            status: 0,
            pointer: FLASH,
            pending: None,
            busy_until: Duration::ZERO,
            now: Duration::ZERO,
            erased: Vec::new(),
            early_polls: 0,
            started: None,
            cable: None,
            requests: Vec::new(),
        }
    }

    /// The bytes of flash at `address`.
    pub fn read(&self, address: u32, len: usize) -> &[u8] {
        let at = (address - FLASH) as usize;
        &self.flash[at..at + len]
    }

    /// The sector erase times (datasheet t_ERASE16KB, t_ERASE64KB, t_ERASE128KB at x32 parallelism, maximum) and
    /// the word programming time (t_PROG, 16 us a word at x32).
    fn time(&self, op: &Op) -> Duration {
        match op {
            Op::Erase(at) => match self.sector(*at).map(|s| s.1) {
                Some(16_384) => Duration::from_millis(500),
                Some(65_536) => Duration::from_millis(1_100),
                _ => Duration::from_millis(2_000),
            },
            Op::Write(_, data) => Duration::from_millis((data.len() as u64 / 4 * 16).div_ceil(1000)),
            Op::SetAddress(_) | Op::Leave => Duration::from_millis(1),
        }
    }

    fn sector(&self, address: u32) -> Option<(u32, u32)> {
        self.layout
            .each_page()
            .into_iter()
            .find(|&(at, size, _)| at <= address && address - at < size)
            .map(|(at, size, _)| (at, size))
    }

    fn fail(&mut self, status: u8) {
        self.status = status;
        self.state = State::Error;
        self.pending = None;
    }

    /// The operation's effect, or its error status.
    fn carry_out(&mut self, op: Op) -> Result<(), u8> {
        match op {
            Op::SetAddress(at) => self.pointer = at,
            Op::Erase(at) => {
                let (start, size) = self.sector(at).ok_or(ERR_ADDRESS)?;
                let from = (start - FLASH) as usize;
                self.flash[from..from + size as usize].fill(0xFF);
                self.erased.push(start);
            }
            Op::Write(at, data) => {
                let from = at.checked_sub(FLASH).ok_or(ERR_ADDRESS)? as usize;
                let cells = self.flash.get_mut(from..from + data.len()).ok_or(ERR_ADDRESS)?;
                // Programming clears bits only: a cell not erased keeps its zeros.
                for (cell, byte) in cells.iter_mut().zip(&data) {
                    *cell &= byte;
                }
            }
            Op::Leave => {}
        }
        Ok(())
    }

    fn status_answer(&mut self) -> Status {
        if self.state == State::DownloadBusy {
            if self.now < self.busy_until {
                self.early_polls += 1;
                return Status {
                    status: 0,
                    poll: self.busy_until - self.now,
                    state: State::DownloadBusy,
                };
            }
            if let Some(op) = self.pending.take() {
                if let Err(status) = self.carry_out(op) {
                    self.fail(status);
                }
            }
            if self.state != State::Error {
                self.state = State::DownloadIdle;
            }
        } else if self.state == State::DownloadSync && self.pending == Some(Op::Leave) {
            // UM0424 6.1.4: the GETSTATUS after the zero-length download manifests: the program starts at the
            // pointer, the device leaves the bus.
            self.pending = None;
            self.started = Some(self.pointer);
            self.state = State::Manifest;
        } else if self.state == State::DownloadSync {
            let op = self.pending.clone();
            let poll = op.as_ref().map_or(Duration::ZERO, |op| self.time(op));
            self.busy_until = self.now + poll;
            self.state = State::DownloadBusy;
            return Status {
                status: 0,
                poll,
                state: State::DownloadBusy,
            };
        }
        Status {
            status: self.status,
            poll: Duration::ZERO,
            state: self.state,
        }
    }

    fn download(&mut self, block: u16, data: &[u8]) -> Result<(), UsbError> {
        if !matches!(self.state, State::Idle | State::DownloadIdle) {
            self.fail(ERR_STALLEDPKT);
            return Err(UsbError::Stall);
        }
        let op = match (block, data) {
            (_, []) => Op::Leave,
            (0, [0x21, a @ ..]) if a.len() == 4 => Op::SetAddress(u32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            (0, [0x41, a @ ..]) if a.len() == 4 => Op::Erase(u32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            (0, _) | (1, _) => {
                self.fail(ERR_TARGET);
                return Err(UsbError::Stall);
            }
            (n, data) => Op::Write(
                self.pointer + u32::from(n - 2) * u32::from(TRANSFER_SIZE),
                data.to_vec(),
            ),
        };
        self.pending = Some(op);
        self.state = State::DownloadSync;
        Ok(())
    }

    fn upload(&mut self, block: u16, length: u16) -> Result<Vec<u8>, UsbError> {
        if !matches!(self.state, State::Idle | State::UploadIdle) || block < 2 {
            self.fail(ERR_STALLEDPKT);
            return Err(UsbError::Stall);
        }
        let at = self.pointer + u32::from(block - 2) * u32::from(TRANSFER_SIZE);
        let Some(from) = at.checked_sub(FLASH).map(|a| a as usize) else {
            self.fail(ERR_ADDRESS);
            return Err(UsbError::Stall);
        };
        let Some(bytes) = self.flash.get(from..from + usize::from(length)) else {
            self.fail(ERR_ADDRESS);
            return Err(UsbError::Stall);
        };
        self.state = State::UploadIdle;
        Ok(bytes.to_vec())
    }

    /// The cable: gone once pulled, or once the program started.
    fn on_bus(&mut self, request: u8, value: u16) -> Result<(), UsbError> {
        if self.started.is_some() {
            return Err(UsbError::Gone);
        }
        match &mut self.cable {
            Some(0) => return Err(UsbError::Gone),
            Some(n) => *n -= 1,
            None => {}
        }
        self.requests.push((request, value));
        Ok(())
    }
}

impl Control for RomModel {
    fn control_in(&mut self, request: u8, value: u16, length: u16) -> Result<Vec<u8>, UsbError> {
        self.on_bus(request, value)?;
        match request {
            3 => Ok(self.status_answer().bytes()[..usize::from(length).min(6)].to_vec()),
            2 => self.upload(value, length),
            _ => Err(UsbError::Stall),
        }
    }

    fn control_out(&mut self, request: u8, value: u16, data: &[u8]) -> Result<(), UsbError> {
        self.on_bus(request, value)?;
        match request {
            1 => self.download(value, data),
            4 => {
                self.status = 0;
                self.state = State::Idle;
                Ok(())
            }
            6 => {
                if matches!(self.state, State::DownloadBusy | State::DownloadSync) {
                    return Err(UsbError::Stall);
                }
                self.state = State::Idle;
                Ok(())
            }
            _ => Err(UsbError::Stall),
        }
    }

    fn sleep(&mut self, wait: Duration) {
        self.now += wait;
    }
}
