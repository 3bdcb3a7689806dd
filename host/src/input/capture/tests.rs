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
    assert_eq!(pcapng_time(1_500_000, 6, 0), Duration::from_millis(1500));
    assert_eq!(pcapng_time(1_500_000_000, 9, 0), Duration::from_millis(1500));
    assert_eq!(pcapng_time(3 << 19, 0x80 | 20, 1), Duration::from_millis(2500));
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
