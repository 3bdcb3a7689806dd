//! The ROM bootloader reached over TCP instead of USB: the emulated board's harness serves the DfuSe device its USB
//! host enumerated (`tests/rehost/dfu_bridge.py`), one request a line, time passing on the emulator's clock:
//! `FIND` (`NONE`, or `FOUND <transfer size> <layout>`), `IN <request> <value> <length>` (`OK <hex>`),
//! `OUT <request> <value> [<hex>]` (`OK`), `SLEEP <ms>` (`OK`); a failed transfer is `STALL` or `GONE`.

use std::cell::RefCell;
use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;
use std::rc::Rc;
use std::time::Duration;

use super::dfuse::{Control, DfuSe, UsbError};
use super::{Bootloader, Bus};

/// One connection to the bridge, shared by the bus and the pipe it hands out (requests go one at a time).
struct Conn {
    reader: BufReader<TcpStream>,
    writer: TcpStream,
}

impl Conn {
    fn ask(&mut self, line: &str) -> Result<String, UsbError> {
        let gone = |e: std::io::Error| UsbError::Other(format!("the DFU bridge: {e}"));
        self.writer.write_all(format!("{line}\n").as_bytes()).map_err(gone)?;
        let mut answer = String::new();
        if self.reader.read_line(&mut answer).map_err(gone)? == 0 {
            return Err(UsbError::Gone);
        }
        let answer = answer.trim_end().to_owned();
        match answer.as_str() {
            "STALL" => Err(UsbError::Stall),
            "GONE" => Err(UsbError::Gone),
            _ => Ok(answer),
        }
    }

    fn sleep(&mut self, wait: Duration) {
        let ms = wait.as_micros().div_ceil(1000);
        // A bridge that went away ends the next request with its error.
        let _ = self.ask(&format!("SLEEP {ms}"));
    }
}

/// The bridge at `tcp://HOST:PORT`.
pub struct TcpBus {
    conn: Rc<RefCell<Conn>>,
}

impl TcpBus {
    /// Connects to the bridge.
    pub fn connect(address: &str) -> std::io::Result<TcpBus> {
        let writer = TcpStream::connect(address)?;
        let reader = BufReader::new(writer.try_clone()?);
        Ok(TcpBus {
            conn: Rc::new(RefCell::new(Conn { reader, writer })),
        })
    }
}

/// The bootloader's DFU interface through the bridge.
pub struct TcpPipe {
    conn: Rc<RefCell<Conn>>,
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Result<Vec<u8>, UsbError> {
    let bad = || UsbError::Other(format!("the DFU bridge answered {text:?}"));
    if !text.len().is_multiple_of(2) {
        return Err(bad());
    }
    (0..text.len())
        .step_by(2)
        .map(|i| {
            text.get(i..i + 2)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(bad)
        })
        .collect()
}

impl Control for TcpPipe {
    fn control_in(&mut self, request: u8, value: u16, length: u16) -> Result<Vec<u8>, UsbError> {
        let answer = self.conn.borrow_mut().ask(&format!("IN {request} {value} {length}"))?;
        match answer.split_once(' ') {
            Some(("OK", data)) => unhex(data),
            _ if answer == "OK" => Ok(Vec::new()),
            _ => Err(UsbError::Other(format!("the DFU bridge answered {answer:?}"))),
        }
    }

    fn control_out(&mut self, request: u8, value: u16, data: &[u8]) -> Result<(), UsbError> {
        let answer = self
            .conn
            .borrow_mut()
            .ask(&format!("OUT {request} {value} {}", hex(data)))?;
        if answer == "OK" {
            Ok(())
        } else {
            Err(UsbError::Other(format!("the DFU bridge answered {answer:?}")))
        }
    }

    fn sleep(&mut self, wait: Duration) {
        self.conn.borrow_mut().sleep(wait);
    }
}

impl Bus for TcpBus {
    type Pipe = TcpPipe;

    fn bootloader(&mut self) -> Result<Option<Bootloader<TcpPipe>>, UsbError> {
        let answer = self.conn.borrow_mut().ask("FIND")?;
        if answer == "NONE" {
            return Ok(None);
        }
        let mut words = answer.splitn(3, ' ');
        let (Some("FOUND"), Some(size), Some(layout)) = (words.next(), words.next(), words.next()) else {
            return Err(UsbError::Other(format!("the DFU bridge answered {answer:?}")));
        };
        let transfer_size = size
            .parse()
            .map_err(|_| UsbError::Other(format!("the DFU bridge answered {answer:?}")))?;
        Ok(Some(Bootloader {
            dfu: DfuSe {
                control: TcpPipe {
                    conn: self.conn.clone(),
                },
                transfer_size,
            },
            layout: layout.to_owned(),
        }))
    }

    fn sleep(&mut self, wait: Duration) {
        self.conn.borrow_mut().sleep(wait);
    }
}

#[cfg(test)]
mod tests {
    use super::super::image::{tests::program, FirmwareImage};
    use super::super::model::{RomModel, F411_LAYOUT, TRANSFER_SIZE};
    use super::*;
    use std::io::BufRead;

    /// A bridge as the harness serves it, in front of the bootloader model: the line protocol, from the other side.
    fn bridge(mut model: RomModel) -> (String, std::thread::JoinHandle<RomModel>) {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let address = listener.local_addr().unwrap().to_string();
        let serve = std::thread::spawn(move || {
            let (stream, _) = listener.accept().unwrap();
            let mut out = stream.try_clone().unwrap();
            for line in BufReader::new(stream).lines() {
                let line = line.unwrap();
                let words: Vec<&str> = line.split(' ').collect();
                let n = |i: usize| words[i].parse::<u16>().unwrap();
                let failed = |e: UsbError| if e == UsbError::Stall { "STALL" } else { "GONE" }.to_owned();
                let answer = match words[0] {
                    "FIND" => format!("FOUND {TRANSFER_SIZE} {F411_LAYOUT}"),
                    "SLEEP" => {
                        model.sleep(Duration::from_millis(words[1].parse().unwrap()));
                        "OK".into()
                    }
                    "IN" => match model.control_in(n(1) as u8, n(2), n(3)) {
                        Ok(data) => format!("OK {}", hex(&data)),
                        Err(e) => failed(e),
                    },
                    "OUT" => match model.control_out(n(1) as u8, n(2), &unhex(words.get(3).unwrap_or(&"")).unwrap()) {
                        Ok(()) => "OK".into(),
                        Err(e) => failed(e),
                    },
                    _ => "ERROR".into(),
                };
                writeln!(out, "{answer}").unwrap();
            }
            model
        });
        (address, serve)
    }

    #[test]
    fn an_image_is_flashed_through_the_bridge() {
        let image = FirmwareImage::from_file_bytes(&program(20_000)).unwrap();
        let (address, serve) = bridge(RomModel::new());
        let mut bus = TcpBus::connect(&address).unwrap();
        let mut found = bus.bootloader().unwrap().unwrap();
        assert_eq!(found.layout, F411_LAYOUT);
        assert_eq!(found.dfu.transfer_size, TRANSFER_SIZE);
        super::super::write(&mut found, &image, &mut |_, _, _| {}).unwrap();
        drop((found, bus));
        let model = serve.join().unwrap();
        assert_eq!(model.read(0x0800_0000, 20_000), &image.bytes[..]);
        assert_eq!(model.erased, [0x0800_0000, 0x0800_4000]);
        assert_eq!(model.early_polls, 0);
        assert_eq!(model.started, Some(0x0800_0000));
    }

    #[test]
    fn hex_round_trips_and_garbage_is_refused() {
        let bytes = [0x00, 0x21, 0xFF, 0x7F];
        assert_eq!(hex(&bytes), "0021ff7f");
        assert_eq!(unhex("0021ff7f"), Ok(bytes.to_vec()));
        assert_eq!(unhex(""), Ok(Vec::new()));
        assert!(unhex("0").is_err());
        assert!(unhex("zz").is_err());
    }
}
