//! Capture files written field by field from their specifications, independently of the reader and of `pcap-file`:
//! the classic pcap format (IETF draft-ietf-opsawg-pcap, "PCAP Capture File Format": a 24-byte file header of magic
//! `0xA1B2C3D4`, version 2.4, two reserved words, snap length and link type, then per packet its seconds,
//! microseconds, captured and original lengths and data) and pcapng (IETF draft-ietf-opsawg-pcapng, "PCAP Next
//! Generation Dump File Format": a Section Header Block with the byte-order magic `0x1A2B3C4D`, Interface
//! Description Blocks with options such as `if_tsresol` (9) and `if_tsoffset` (14), and Enhanced Packet Blocks,
//! each block padded to 32 bits and its total length repeated at its end). Both are written in either byte order,
//! as the capturing host wrote them.

/// The link types of tcpdump.org's registry ("Link-layer header types") the tests use.
pub const LINKTYPE_NULL: u32 = 0;
/// OpenBSD's loopback: the family in network byte order.
pub const LINKTYPE_LOOP: u32 = 108;

/// A writer of 16-, 32- and 64-bit fields in one byte order.
struct Fields {
    big: bool,
    out: Vec<u8>,
}

impl Fields {
    fn u16(&mut self, v: u16) {
        self.out
            .extend(if self.big { v.to_be_bytes() } else { v.to_le_bytes() });
    }
    fn u32(&mut self, v: u32) {
        self.out
            .extend(if self.big { v.to_be_bytes() } else { v.to_le_bytes() });
    }
    fn u64(&mut self, v: u64) {
        self.out
            .extend(if self.big { v.to_be_bytes() } else { v.to_le_bytes() });
    }
}

/// The link-layer header of a BSD loopback frame: the address family (2 IPv4, 30 IPv6 as on macOS), in the
/// capturing host's byte order for NULL, in network byte order for LOOP.
pub fn loopback_frame(link: u32, big_endian_host: bool, ipv6: bool, ip_packet: &[u8]) -> Vec<u8> {
    let family: u32 = if ipv6 { 30 } else { 2 };
    let mut frame = if link == LINKTYPE_LOOP || big_endian_host {
        family.to_be_bytes().to_vec()
    } else {
        family.to_le_bytes().to_vec()
    };
    frame.extend(ip_packet);
    frame
}

/// A pcap file of `frames` (each with its time in microseconds since 1970), link type `link`.
pub fn pcap(big: bool, link: u32, frames: &[(u64, Vec<u8>)]) -> Vec<u8> {
    let mut f = Fields { big, out: Vec::new() };
    f.u32(0xA1B2_C3D4);
    f.u16(2);
    f.u16(4);
    f.u32(0);
    f.u32(0);
    f.u32(65_535);
    f.u32(link);
    for (micros, data) in frames {
        f.u32((micros / 1_000_000) as u32);
        f.u32((micros % 1_000_000) as u32);
        f.u32(data.len() as u32);
        f.u32(data.len() as u32);
        f.out.extend(data);
    }
    f.out
}

/// One pcapng block: its type, total length, body padded to 32 bits, total length again.
fn block(f: &mut Fields, kind: u32, body: &[u8]) {
    let padded = body.len().div_ceil(4) * 4;
    let total = (12 + padded) as u32;
    f.u32(kind);
    f.u32(total);
    f.out.extend(body);
    f.out.resize(f.out.len() + padded - body.len(), 0);
    f.u32(total);
}

/// A pcapng file: one interface of link type `link` with the options `if_tsresol` and `if_tsoffset` when given,
/// and `frames` as Enhanced Packet Blocks, their timestamps in the interface's units.
pub fn pcapng(big: bool, link: u32, tsresol: Option<u8>, tsoffset: Option<u64>, frames: &[(u64, Vec<u8>)]) -> Vec<u8> {
    let mut f = Fields { big, out: Vec::new() };
    let mut body = Fields { big, out: Vec::new() };
    body.u32(0x1A2B_3C4D);
    body.u16(1);
    body.u16(0);
    body.u64(u64::MAX);
    let shb = std::mem::take(&mut body.out);
    block(&mut f, 0x0A0D_0D0A, &shb);
    body.u16(link as u16);
    body.u16(0);
    body.u32(65_535);
    if let Some(r) = tsresol {
        body.u16(9);
        body.u16(1);
        body.out.extend([r, 0, 0, 0]);
    }
    if let Some(o) = tsoffset {
        body.u16(14);
        body.u16(8);
        body.u64(o);
    }
    body.u16(0);
    body.u16(0);
    let idb = std::mem::take(&mut body.out);
    block(&mut f, 1, &idb);
    for (units, data) in frames {
        body.u32(0);
        body.u32((units >> 32) as u32);
        body.u32(*units as u32);
        body.u32(data.len() as u32);
        body.u32(data.len() as u32);
        body.out.extend(data);
        body.out.resize(body.out.len().div_ceil(4) * 4, 0);
        let epb = std::mem::take(&mut body.out);
        block(&mut f, 6, &epb);
    }
    f.out
}
