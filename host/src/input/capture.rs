//! Packet captures of a game's telemetry: `stream --capture` writes one, `cue --input` reads one back (or one that
//! tcpdump or Wireshark wrote).
//!
//! Written: a classic pcap file (the format of `tcpdump -w`), link type `LINKTYPE_RAW` (101, raw IP): each datagram
//! that arrived on the socket, from any sender, with an IPv4 (or IPv6) and a UDP header synthesised from its source
//! address and the socket's address (a socket bound to `0.0.0.0` is written as the loopback address when the sender
//! is local, else as `0.0.0.0`), checksums computed, and its arrival time (the host's clock, microseconds).
//! Wireshark shows them as the UDP packets they were, with their ports.
//!
//! Read: pcap (either byte order, micro- or nanosecond times) and pcapng (Wireshark's default: Enhanced Packet
//! Blocks, with each interface's `if_tsresol` and `if_tsoffset`), on the link types Ethernet (VLAN tags too), raw
//! IP, raw IPv4, raw IPv6, BSD loopback (`NULL`, `LOOP`: a capture on macOS's `lo0`) and Linux cooked (`SLL`,
//! `SLL2`: `tcpdump -i any`). Other link types are refused by name. The UDP payloads are taken; packets that are not
//! UDP, fragments of IP datagrams (not reassembled) and packets cut short by the snap length are skipped and counted.

use std::collections::BTreeMap;
use std::net::{IpAddr, Ipv6Addr, SocketAddr};
use std::time::Duration;

use pcap_file::pcap::PcapParser;
use pcap_file::pcapng::blocks::interface_description::InterfaceDescriptionOption;
use pcap_file::pcapng::{Block, PcapNgParser};
use pcap_file::{DataLink, PcapError};

mod write;
#[cfg(test)]
use write::checksum;
#[cfg(test)]
pub(crate) use write::udp_packet;
pub use write::CaptureWriter;

/// A UDP datagram of a capture.
#[derive(Debug, Clone)]
pub struct Datagram {
    /// Its packet's number in the file (1-based, as Wireshark numbers them).
    pub number: usize,
    /// Its capture time (since 1970).
    pub time: Duration,
    /// Its sender.
    pub from: SocketAddr,
    /// Its destination.
    pub to: SocketAddr,
    /// The UDP payload.
    pub payload: Vec<u8>,
}

/// What a capture holds.
#[derive(Debug, Default)]
pub struct Capture {
    /// `pcap` or `pcapng`.
    pub format: &'static str,
    /// Packets in the file.
    pub packets: usize,
    /// The UDP datagrams, in the file's order.
    pub datagrams: Vec<Datagram>,
    /// Packets that were not taken, by why (not UDP, a fragment, cut short...).
    pub skipped: BTreeMap<String, usize>,
    /// The file ends in the middle of a packet (a capture that was cut off): the packets before it are read.
    pub cut_short: bool,
}

/// Whether `bytes` start as a pcap or pcapng file.
pub fn is_capture(bytes: &[u8]) -> bool {
    matches!(
        bytes.get(..4),
        Some([0xa1, 0xb2, 0xc3, 0xd4] | [0xd4, 0xc3, 0xb2, 0xa1] | [0xa1, 0xb2, 0x3c, 0x4d] | [0x4d, 0x3c, 0xb2, 0xa1])
            | Some([0x0a, 0x0d, 0x0d, 0x0a])
    )
}

/// The link types read.
fn link_supported(link: DataLink) -> bool {
    matches!(
        link,
        DataLink::ETHERNET
            | DataLink::RAW
            | DataLink::IPV4
            | DataLink::IPV6
            | DataLink::NULL
            | DataLink::LOOP
            | DataLink::LINUX_SLL
            | DataLink::LINUX_SLL2
    )
}

fn unsupported(link: DataLink) -> String {
    format!(
        "link type {link:?} ({}) is not read: captures on Ethernet, raw IP, loopback or Linux cooked (`any`) \
         interfaces are",
        u32::from(link)
    )
}

/// Reads a capture: its UDP datagrams, or why the file is not one that can be read.
pub fn read(bytes: &[u8]) -> Result<Capture, String> {
    match bytes.get(..4) {
        Some([0x0a, 0x0d, 0x0d, 0x0a]) => read_pcapng(bytes),
        _ if is_capture(bytes) => read_pcap(bytes),
        _ => Err("not a packet capture (neither pcap nor pcapng)".into()),
    }
}

fn read_pcap(bytes: &[u8]) -> Result<Capture, String> {
    let (mut rest, parser) = PcapParser::new(bytes).map_err(|e| match e {
        PcapError::IncompleteBuffer => "the pcap header is cut short".to_string(),
        e => format!("not a pcap file: {e}"),
    })?;
    let link = parser.header().datalink;
    if !link_supported(link) {
        return Err(unsupported(link));
    }
    let mut capture = Capture {
        format: "pcap",
        ..Capture::default()
    };
    while !rest.is_empty() {
        match parser.next_packet(rest) {
            Ok((next, packet)) => {
                rest = next;
                capture.packets += 1;
                let number = capture.packets;
                let cut = (packet.data.len() as u32) < packet.orig_len;
                capture.take(number, packet.timestamp, link, &packet.data, cut);
            }
            Err(PcapError::IncompleteBuffer) => {
                capture.cut_short = true;
                break;
            }
            Err(e) => return Err(format!("packet {}: {e}", capture.packets + 1)),
        }
    }
    Ok(capture)
}

/// An interface's time: its `if_tsresol` (10^-n s, or 2^-n s with the high bit; microseconds without) and
/// `if_tsoffset` (s), or `None` when the sum is beyond what a [`Duration`] holds (an offset of 2^64 - 1 s).
fn pcapng_time(units: u128, tsresol: u8, offset_s: u64) -> Option<Duration> {
    let nanos = if tsresol & 0x80 != 0 {
        let shift = u32::from(tsresol & 0x7f).min(127);
        units.checked_mul(1_000_000_000)? >> shift
    } else {
        let n = u32::from(tsresol).min(30);
        if n <= 9 {
            units.saturating_mul(10u128.pow(9 - n))
        } else {
            units / 10u128.pow(n - 9)
        }
    };
    let nanos = u64::try_from(nanos).ok()?;
    Duration::from_nanos(nanos).checked_add(Duration::from_secs(offset_s))
}

/// Why a pcapng packet whose time cannot be a time is skipped.
const TIME_OVERFLOWS: &str = "its time, with its interface's if_tsoffset, is beyond any time (about 5.8e11 years)";

fn read_pcapng(bytes: &[u8]) -> Result<Capture, String> {
    let (mut rest, mut parser) = PcapNgParser::new(bytes).map_err(|e| match e {
        PcapError::IncompleteBuffer => "the pcapng section header is cut short".to_string(),
        e => format!("not a pcapng file: {e}"),
    })?;
    let mut capture = Capture {
        format: "pcapng",
        ..Capture::default()
    };
    while !rest.is_empty() {
        let block = match parser.next_block(rest) {
            Ok((next, block)) => {
                rest = next;
                block
            }
            Err(PcapError::IncompleteBuffer) => {
                capture.cut_short = true;
                break;
            }
            Err(e) => return Err(format!("block after packet {}: {e}", capture.packets)),
        };
        match block {
            Block::InterfaceDescription(idb) if !link_supported(idb.linktype) => {
                return Err(unsupported(idb.linktype));
            }
            Block::EnhancedPacket(epb) => {
                capture.packets += 1;
                let number = capture.packets;
                let idb = parser
                    .packet_interface(&epb)
                    .ok_or_else(|| format!("packet {number}: no interface {} described", epb.interface_id))?;
                let (mut tsresol, mut offset) = (6u8, 0u64);
                for option in &idb.options {
                    match option {
                        InterfaceDescriptionOption::IfTsResol(r) => tsresol = *r,
                        InterfaceDescriptionOption::IfTsOffset(o) => offset = *o,
                        _ => {}
                    }
                }
                // pcap-file 2 takes the timestamp's units for nanoseconds whatever the interface says: the units
                // back, then the interface's resolution.
                let Some(time) = pcapng_time(epb.timestamp.as_nanos(), tsresol, offset) else {
                    *capture.skipped.entry(TIME_OVERFLOWS.into()).or_default() += 1;
                    continue;
                };
                let cut = (epb.data.len() as u32) < epb.original_len;
                capture.take(number, time, idb.linktype, &epb.data, cut);
            }
            Block::SimplePacket(_) | Block::Packet(_) => {
                capture.packets += 1;
                *capture
                    .skipped
                    .entry("a simple or obsolete packet block (no time)".into())
                    .or_default() += 1;
            }
            _ => {}
        }
    }
    Ok(capture)
}

impl Capture {
    /// Takes packet `number`'s UDP datagram, or counts why not.
    fn take(&mut self, number: usize, time: Duration, link: DataLink, data: &[u8], cut: bool) {
        match udp_of(link, data, cut) {
            Ok((from, to, payload)) => self.datagrams.push(Datagram {
                number,
                time,
                from,
                to,
                payload: payload.to_vec(),
            }),
            Err(why) => *self.skipped.entry(why).or_default() += 1,
        }
    }
}

const ETHERTYPE_IPV4: u16 = 0x0800;
const ETHERTYPE_IPV6: u16 = 0x86dd;

fn be16(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

/// The IP packet in a link-layer frame.
fn ip_of(link: DataLink, data: &[u8]) -> Result<&[u8], String> {
    let short = || "cut short in its link header".to_string();
    let by_ethertype = |ty: u16| match ty {
        ETHERTYPE_IPV4 | ETHERTYPE_IPV6 => Ok(()),
        other => Err(format!("not IP (ethertype 0x{other:04x})")),
    };
    match link {
        DataLink::RAW | DataLink::IPV4 | DataLink::IPV6 => Ok(data),
        DataLink::ETHERNET => {
            let mut at = 12;
            let mut ty = be16(data, at).ok_or_else(short)?;
            // 802.1Q and 802.1ad tags.
            while matches!(ty, 0x8100 | 0x88a8) {
                at += 4;
                ty = be16(data, at).ok_or_else(short)?;
            }
            by_ethertype(ty)?;
            Ok(&data[at + 2..])
        }
        DataLink::LINUX_SLL => {
            let ty = be16(data, 14).ok_or_else(short)?;
            by_ethertype(ty)?;
            Ok(&data[16..])
        }
        DataLink::LINUX_SLL2 => {
            let ty = be16(data, 0).ok_or_else(short)?;
            by_ethertype(ty)?;
            data.get(20..).ok_or_else(short)
        }
        DataLink::NULL | DataLink::LOOP => {
            let word: [u8; 4] = data.get(..4).ok_or_else(short)?.try_into().unwrap_or_default();
            // LOOP's family is in network byte order; NULL's in the capturing host's, which a file read elsewhere
            // does not tell (tcpdump.org's link-layer header types; Wireshark's NullLoopback page). The families
            // are small numbers: of NULL's two readings the smaller is the one written.
            let (big, little) = (u32::from_be_bytes(word), u32::from_le_bytes(word));
            let family = if link == DataLink::LOOP { big } else { big.min(little) };
            match family {
                2 | 24 | 28 | 30 => Ok(&data[4..]),
                other => Err(format!("not IP (loopback family {other})")),
            }
        }
        other => Err(unsupported(other)),
    }
}

/// The sender, destination and payload of the UDP datagram in a frame, or why there is none.
fn udp_of(link: DataLink, data: &[u8], cut: bool) -> Result<(SocketAddr, SocketAddr, &[u8]), String> {
    let ip = ip_of(link, data)?;
    let (src, dst, udp) = match ip.first().map(|b| b >> 4) {
        Some(4) => {
            let ihl = usize::from(ip[0] & 0x0f) * 4;
            if ip.len() < ihl.max(20) {
                return Err("cut short in its IPv4 header".into());
            }
            let frag = u16::from_be_bytes([ip[6], ip[7]]);
            if frag & 0x3fff != 0 {
                return Err("an IPv4 fragment (fragments are not reassembled)".into());
            }
            if ip[9] != 17 {
                return Err(format!("not UDP (IP protocol {})", ip[9]));
            }
            let total = usize::from(u16::from_be_bytes([ip[2], ip[3]]));
            let end = if (ihl..=ip.len()).contains(&total) {
                total
            } else {
                ip.len()
            };
            let src: [u8; 4] = ip[12..16].try_into().unwrap_or_default();
            let dst: [u8; 4] = ip[16..20].try_into().unwrap_or_default();
            (IpAddr::from(src), IpAddr::from(dst), &ip[ihl..end])
        }
        Some(6) => {
            if ip.len() < 40 {
                return Err("cut short in its IPv6 header".into());
            }
            let src: [u8; 16] = ip[8..24].try_into().unwrap_or_default();
            let dst: [u8; 16] = ip[24..40].try_into().unwrap_or_default();
            let mut next = ip[6];
            let mut rest = &ip[40..];
            // Hop-by-hop, routing and destination options headers; a fragment header ends the search.
            loop {
                match next {
                    17 => break,
                    0 | 43 | 60 => {
                        let len = rest
                            .get(1)
                            .map(|l| (usize::from(*l) + 1) * 8)
                            .ok_or("cut short in its IPv6 headers")?;
                        next = rest[0];
                        rest = rest.get(len..).ok_or("cut short in its IPv6 headers")?;
                    }
                    44 => return Err("an IPv6 fragment (fragments are not reassembled)".into()),
                    other => return Err(format!("not UDP (IPv6 next header {other})")),
                }
            }
            (
                IpAddr::from(Ipv6Addr::from(src)),
                IpAddr::from(Ipv6Addr::from(dst)),
                rest,
            )
        }
        Some(v) => return Err(format!("not IP (version {v})")),
        None => return Err("empty".into()),
    };
    if udp.len() < 8 {
        return Err("cut short in its UDP header".into());
    }
    let len = usize::from(u16::from_be_bytes([udp[4], udp[5]]));
    if len < 8 || len > udp.len() {
        return Err(if cut {
            "cut short by the capture's snap length".into()
        } else {
            "its UDP length does not fit the packet".into()
        });
    }
    let from = SocketAddr::new(src, u16::from_be_bytes([udp[0], udp[1]]));
    let to = SocketAddr::new(dst, u16::from_be_bytes([udp[2], udp[3]]));
    Ok((from, to, &udp[8..len]))
}

/// Captures built byte by byte from the file formats' specifications, for the tests.
#[cfg(test)]
pub(crate) mod spec;
#[cfg(test)]
mod tests;
