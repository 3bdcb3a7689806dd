use std::time::SystemTime;

use super::*;

#[test]
fn a_written_capture_reads_back_with_its_addresses_times_and_checksums() {
    let dir = std::env::temp_dir().join(format!("ringpod-capture-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("w.pcap");
    let local: SocketAddr = "0.0.0.0:4123".parse().unwrap();
    let mut w = CaptureWriter::create(&path, local).unwrap();
    let t0 = SystemTime::UNIX_EPOCH + Duration::from_micros(1_700_000_000_123_456);
    w.write(b"hello", "127.0.0.1:5000".parse().unwrap(), t0);
    w.write(b"odd", "[::1]:5001".parse().unwrap(), t0 + Duration::from_millis(10));
    assert_eq!(w.finish(), (2, None));
    let c = read(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!((c.format, c.packets, c.datagrams.len()), ("pcap", 2, 2));
    let d = &c.datagrams[0];
    assert_eq!(d.payload, b"hello");
    assert_eq!(d.from, "127.0.0.1:5000".parse().unwrap());
    assert_eq!(d.to, "127.0.0.1:4123".parse().unwrap());
    assert_eq!(d.time, Duration::from_micros(1_700_000_000_123_456));
    assert_eq!(c.datagrams[1].to, "[::1]:4123".parse().unwrap());
    assert_eq!(c.datagrams[1].payload, b"odd");
    // The checksums verify: a packet summed with its checksum gives zero.
    let p = udp_packet("10.0.0.2:7".parse().unwrap(), "10.0.0.1:9".parse().unwrap(), b"abc");
    assert_eq!(checksum(&[&p[..20]]), 0);
    let mut pseudo = p[12..20].to_vec();
    pseudo.extend([0, 17, 0, 11]);
    assert_eq!(checksum(&[&pseudo, &p[20..]]), 0);
}

#[test]
fn pcapng_times_follow_the_interface_resolution() {
    assert_eq!(pcapng_time(1_500_000, 6, 0), Some(Duration::from_millis(1500)));
    assert_eq!(pcapng_time(1_500_000_000, 9, 0), Some(Duration::from_millis(1500)));
    assert_eq!(pcapng_time(3 << 19, 0x80 | 20, 1), Some(Duration::from_millis(2500)));
}

#[test]
fn any_bytes_are_read_or_refused_without_panic() {
    let base = {
        let mut v = vec![
            0xd4, 0xc3, 0xb2, 0xa1, 2, 0, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0, 0, 1, 0, 0, 0,
        ];
        v.extend([0; 8]);
        v.extend(60u32.to_le_bytes());
        v.extend(60u32.to_le_bytes());
        v.extend([0u8; 60]);
        v
    };
    let mut seed = 1u64;
    for _ in 0..3000 {
        let mut v = base.clone();
        for _ in 0..4 {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let i = (seed >> 33) as usize % v.len();
            v[i] = (seed >> 17) as u8;
        }
        let _ = read(&v);
        let _ = read(&v[..(seed as usize % v.len())]);
    }
}

/// BSD loopback captures (`lo0` on macOS and the BSDs: NULL, its family in the capturing host's byte order; OpenBSD's
/// LOOP, in network byte order), pcap and pcapng, written on a little- and a big-endian host, IPv4 and IPv6: every
/// datagram is read with its addresses, payload and time.
#[test]
fn loopback_captures_of_either_byte_order_are_read() {
    for big in [false, true] {
        for link in [spec::LINKTYPE_NULL, spec::LINKTYPE_LOOP] {
            for ipv6 in [false, true] {
                let (from, to): (SocketAddr, SocketAddr) = if ipv6 {
                    ("[::1]:5000".parse().unwrap(), "[::1]:4123".parse().unwrap())
                } else {
                    ("127.0.0.1:5000".parse().unwrap(), "127.0.0.1:4123".parse().unwrap())
                };
                let frame = spec::loopback_frame(link, big, ipv6, &udp_packet(from, to, b"telemetry"));
                let micros = 1_700_000_000_250_000u64;
                for (file, bytes) in [
                    ("pcap", spec::pcap(big, link, &[(micros, frame.clone())])),
                    (
                        "pcapng",
                        spec::pcapng(big, link, None, None, &[(micros, frame.clone())]),
                    ),
                ] {
                    let what = format!("{file}, link {link}, big endian {big}, IPv6 {ipv6}");
                    let c = read(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
                    assert!(c.skipped.is_empty(), "{what}: {:?}", c.skipped);
                    assert_eq!((c.format, c.packets, c.datagrams.len()), (file, 1, 1), "{what}");
                    let d = &c.datagrams[0];
                    assert_eq!(
                        (d.from, d.to, d.payload.as_slice()),
                        (from, to, &b"telemetry"[..]),
                        "{what}"
                    );
                    assert_eq!(d.time, Duration::from_micros(micros), "{what}");
                }
            }
        }
    }
    // A family that is not IP is skipped, named in either byte order's reading of the writer's.
    let frame = spec::loopback_frame(spec::LINKTYPE_NULL, false, false, &[]);
    let mut other = frame.clone();
    other[0] = 7;
    let c = read(&spec::pcap(false, spec::LINKTYPE_NULL, &[(0, other)])).unwrap();
    assert_eq!(c.skipped.keys().collect::<Vec<_>>(), ["not IP (loopback family 7)"]);
}

/// An interface's `if_tsoffset` of 2^64 - 1 s cannot make a time: its packets are skipped and counted, not a panic.
#[test]
fn a_time_offset_beyond_any_time_skips_its_packets() {
    let frame = udp_packet("10.0.0.2:7".parse().unwrap(), "10.0.0.1:9".parse().unwrap(), b"x");
    let bytes = spec::pcapng(
        false,
        101,
        Some(6),
        Some(u64::MAX),
        &[(1_000_000, frame.clone()), (2_500_000, frame.clone())],
    );
    let c = read(&bytes).unwrap();
    assert_eq!((c.packets, c.datagrams.len()), (2, 0));
    assert_eq!(c.skipped.get(TIME_OVERFLOWS), Some(&2), "{:?}", c.skipped);
    // The largest offset that is a time reads.
    let bytes = spec::pcapng(true, 101, Some(9), Some(1 << 40), &[(5, frame)]);
    let d = &read(&bytes).unwrap().datagrams[0];
    assert_eq!(d.time, Duration::from_secs(1 << 40) + Duration::from_nanos(5));
    assert_eq!(pcapng_time(1_000_000_000, 9, u64::MAX), None);
    assert_eq!(pcapng_time(999_999_999, 9, u64::MAX), Some(Duration::MAX));
}
