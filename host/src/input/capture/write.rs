//! A live source's datagrams written to a classic pcap file as they arrive (`stream --capture`), each inside the
//! IP and UDP headers it came in, synthesised.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::SystemTime;

use pcap_file::pcap::{PcapHeader, PcapPacket, PcapWriter};
use pcap_file::{DataLink, PcapError, TsResolution};

/// The datagrams of a live source written to a pcap file as they arrive.
pub struct CaptureWriter {
    writer: PcapWriter<std::fs::File>,
    /// The file beside the target, renamed to it by [`CaptureWriter::finish`].
    pending: crate::out::file::Pending,
    /// The socket's address (the packets' destination).
    local: SocketAddr,
    /// Packets written to the file (unbuffered: a packet counted is in it).
    pub packets: u64,
    /// The first write error: nothing more is written after it.
    pub error: Option<String>,
}

/// A pcap error in words: an I/O error says its own (pcap-file calls every one "Error reading bytes").
fn words(e: PcapError) -> String {
    if let PcapError::IoError(e) = e {
        e.to_string()
    } else {
        e.to_string()
    }
}

impl CaptureWriter {
    /// Opens a file beside `path` (its header written; `path` replaced when finished) for datagrams to `local`.
    pub fn create(path: &std::path::Path, local: SocketAddr) -> Result<Self, String> {
        let mut pending = crate::out::file::Pending::beside(path).map_err(|e| e.to_string())?;
        let file = pending.file().try_clone().map_err(|e| e.to_string())?;
        let header = PcapHeader {
            datalink: DataLink::RAW,
            ts_resolution: TsResolution::MicroSecond,
            ..PcapHeader::default()
        };
        let writer = PcapWriter::with_header(file, header).map_err(words)?;
        Ok(Self {
            writer,
            pending,
            local,
            packets: 0,
            error: None,
        })
    }

    /// Writes a datagram from `from` that arrived at `at`; a failure is kept in `error` and ends the capture.
    pub fn write(&mut self, payload: &[u8], from: SocketAddr, at: SystemTime) {
        if self.error.is_some() {
            return;
        }
        let data = udp_packet(from, self.local, payload);
        let time = at.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
        let packet = PcapPacket::new(time, data.len() as u32, &data);
        match self.writer.write_packet(&packet).map_err(words) {
            Ok(_) => self.packets += 1,
            Err(e) => self.error = Some(e),
        }
    }

    /// Puts the file in place: the packets written, or the first error (the target then left as it was).
    pub fn finish(self) -> (u64, Option<String>) {
        if let Some(e) = self.error {
            return (0, Some(e));
        }
        drop(self.writer);
        match self.pending.commit() {
            Ok(()) => (self.packets, None),
            Err(e) => (0, Some(e.to_string())),
        }
    }
}

/// The Internet checksum (RFC 1071) of the 16-bit words of `parts`, each part of even length but the last.
pub(super) fn checksum(parts: &[&[u8]]) -> u16 {
    let mut sum: u64 = 0;
    for part in parts {
        for pair in part.chunks(2) {
            let hi = u64::from(pair[0]) << 8;
            sum += hi | pair.get(1).map_or(0, |&b| u64::from(b));
        }
    }
    while sum > 0xffff {
        sum = (sum & 0xffff) + (sum >> 16);
    }
    !(sum as u16)
}

/// A raw IP packet (IPv4 for an IPv4 sender, IPv6 otherwise) carrying `payload` in a UDP datagram from `from` to
/// `to`, with its checksums. A destination of the other family is mapped into the sender's; an unspecified one is
/// the loopback address when the sender is local.
pub fn udp_packet(from: SocketAddr, to: SocketAddr, payload: &[u8]) -> Vec<u8> {
    let to_ip = match to.ip() {
        ip if ip.is_unspecified() && from.ip().is_loopback() => from.ip(),
        ip => ip,
    };
    let udp_len = (8 + payload.len()).min(0xffff) as u16;
    let mut udp = Vec::with_capacity(8 + payload.len());
    udp.extend(from.port().to_be_bytes());
    udp.extend(to.port().to_be_bytes());
    udp.extend(udp_len.to_be_bytes());
    udp.extend([0, 0]);
    udp.extend(payload);
    let ports_and_data = |pseudo: &[u8], udp: &mut Vec<u8>| {
        let sum = match checksum(&[pseudo, udp]) {
            // A computed zero is sent as all ones (zero means "no checksum").
            0 => 0xffff,
            s => s,
        };
        udp[6..8].copy_from_slice(&sum.to_be_bytes());
    };
    match from.ip() {
        IpAddr::V4(src) => {
            let dst = match to_ip {
                IpAddr::V4(d) => d,
                IpAddr::V6(d) => d.to_ipv4_mapped().unwrap_or(Ipv4Addr::UNSPECIFIED),
            };
            let mut pseudo = Vec::with_capacity(12);
            pseudo.extend(src.octets());
            pseudo.extend(dst.octets());
            pseudo.extend([0, 17]);
            pseudo.extend(udp_len.to_be_bytes());
            ports_and_data(&pseudo, &mut udp);
            let total = (20 + udp.len()).min(0xffff) as u16;
            let mut ip = vec![0x45, 0];
            ip.extend(total.to_be_bytes());
            // Identification 0, "don't fragment", TTL 64, UDP, checksum filled in below.
            ip.extend([0, 0, 0x40, 0, 64, 17, 0, 0]);
            ip.extend(src.octets());
            ip.extend(dst.octets());
            let sum = checksum(&[&ip]);
            ip[10..12].copy_from_slice(&sum.to_be_bytes());
            ip.extend(udp);
            ip
        }
        IpAddr::V6(src) => {
            let dst = match to_ip {
                IpAddr::V6(d) => d,
                IpAddr::V4(d) => d.to_ipv6_mapped(),
            };
            let mut pseudo = Vec::with_capacity(40);
            pseudo.extend(src.octets());
            pseudo.extend(dst.octets());
            pseudo.extend(u32::from(udp_len).to_be_bytes());
            pseudo.extend([0, 0, 0, 17]);
            ports_and_data(&pseudo, &mut udp);
            let mut ip = vec![0x60, 0, 0, 0];
            ip.extend(udp_len.to_be_bytes());
            ip.extend([17, 64]);
            ip.extend(src.octets());
            ip.extend(dst.octets());
            ip.extend(udp);
            ip
        }
    }
}
