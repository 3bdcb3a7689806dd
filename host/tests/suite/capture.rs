//! Captures: `stream --telemetry-udp --capture FILE.pcap` records what the game sent, `cue --input FILE.pcap` cues
//! it again as the live run did; pcapng files as Wireshark saves them read the same way; damaged files are refused.

use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ringpod-capture-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `ringpod cue --json --input FILE ARGS`: the exit code, the summary and stderr.
fn cue(input: &Path, out: &Path, args: &[&str]) -> (Option<i32>, serde_json::Value, String) {
    let o = std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
        .args(["cue", "--json", "--input"])
        .arg(input)
        .arg("--out")
        .arg(out)
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    let summary = serde_json::from_slice(&o.stdout).unwrap_or(serde_json::Value::Null);
    (o.status.code(), summary, stderr)
}

/// The last row of a pose CSV.
fn last_pose(path: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let last = text.lines().last().unwrap();
    last.split(',').skip(1).map(|v| v.parse().unwrap()).collect()
}

/// A drive in OutSim packets to `stream --sim --telemetry-udp --capture`, a stranger's datagram among them; the
/// capture cued offline gives the live run's poses: one per readable datagram, the same last pose.
#[test]
fn a_captured_drive_cues_offline_as_it_was_cued_live() {
    let d = dir("live");
    let pcap = d.join("drive.pcap");
    let pcap_arg = pcap.display().to_string();
    let (child, _stderr, addr) = crate::common::spawn_live_stream(&[
        "--fast",
        "--telemetry-udp",
        "127.0.0.1:0",
        "--telemetry-format",
        "outsim",
        "--udp-idle",
        "0.3",
        "--capture",
        &pcap_arg,
    ]);
    let game = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let stranger = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    // Heading 0 faces world +y: braking at 3 m/s^2 for 0.8 s, then a left turn (yaw rate 0.3 rad/s, 2 m/s^2 to
    // the left, world -x).
    for k in 0..120u32 {
        let (rate, accel) = if k < 80 {
            ([0.0, 0.0, 0.0], [0.0, -3.0, 0.0])
        } else {
            ([0.0, 0.0, 0.3], [-2.0, 0.0, 0.0])
        };
        game.send_to(
            &crate::common::packets::outsim::packet(10 * k, rate, [0.0; 3], accel, false),
            &addr,
        )
        .unwrap();
        if k == 40 {
            stranger.send_to(b"not telemetry", &addr).unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let out = child.wait_with_output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        out.status.code(),
        Some(3),
        "the stranger's datagram is unreadable: {report}"
    );
    assert_eq!(report["setpoints_applied"], 120, "{report}");
    assert_eq!(
        report["capture"]["packets"], 121,
        "every datagram that arrived: {report}"
    );
    assert_eq!(report["capture"]["error"], serde_json::Value::Null);
    let live: Vec<f64> = report["last_applied_pose"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for format in ["outsim", "auto"] {
        let poses = d.join(format!("poses-{format}.csv"));
        let (code, summary, said) = cue(&pcap, &poses, &["--telemetry-format", format]);
        assert_eq!(code, Some(3), "{summary} {said}");
        assert_eq!(summary["rows"], 120, "{summary}");
        assert_eq!(summary["poses"], 120);
        assert_eq!(summary["capture"]["file_format"], "pcap");
        assert_eq!(summary["capture"]["packets"], 121);
        assert_eq!(summary["capture"]["telemetry_format"], "outsim");
        let errors = summary["input_errors"].as_array().unwrap();
        assert_eq!(errors.len(), 1, "{summary}");
        assert_eq!(errors[0]["line"], 42, "the stranger's datagram, packet 42");
        let offline = last_pose(&poses);
        for (a, b) in live.iter().zip(&offline) {
            assert!((a - b).abs() < 1e-6, "live {live:?} offline {offline:?}");
        }
        assert!(
            offline[3] != 0.0 || offline[4] != 0.0,
            "the drive moved the platform: {offline:?}"
        );
    }
    // The stranger's port only: nothing readable, said by the exit code.
    let stranger_port = stranger.local_addr().unwrap().port().to_string();
    let game_port = addr.rsplit(':').next().unwrap().to_owned();
    let (code, summary, _) = cue(&pcap, &d.join("p.csv"), &["--udp-port", &stranger_port]);
    assert_eq!(
        (code, summary["rows"].as_u64()),
        (Some(3), Some(0)),
        "no datagram to that port: {summary}"
    );
    let (code, summary, _) = cue(&pcap, &d.join("p.csv"), &["--udp-port", &game_port]);
    assert_eq!((code, summary["rows"].as_u64()), (Some(3), Some(120)), "{summary}");
}

/// An Ethernet frame: IPv4, protocol `proto`, fragment field `frag`, from 192.168.1.20:9000 to 192.168.1.10:4123.
fn ethernet_ipv4(proto: u8, frag: u16, payload: &[u8]) -> Vec<u8> {
    let mut f = vec![0x02, 0, 0, 0, 0, 1, 0x02, 0, 0, 0, 0, 2, 0x08, 0x00];
    let udp_len = (8 + payload.len()) as u16;
    f.extend([0x45, 0]);
    f.extend((20 + udp_len).to_be_bytes());
    f.extend([0, 1]);
    f.extend(frag.to_be_bytes());
    f.extend([64, proto, 0, 0, 192, 168, 1, 20, 192, 168, 1, 10]);
    f.extend(9000u16.to_be_bytes());
    f.extend(4123u16.to_be_bytes());
    f.extend(udp_len.to_be_bytes());
    f.extend([0, 0]);
    f.extend(payload);
    f
}

/// A pcapng block: type, body, length before and after.
fn block(kind: u32, body: &[u8]) -> Vec<u8> {
    let mut body = body.to_vec();
    while !body.len().is_multiple_of(4) {
        body.push(0);
    }
    let len = (12 + body.len()) as u32;
    let mut b = kind.to_le_bytes().to_vec();
    b.extend(len.to_le_bytes());
    b.extend(body);
    b.extend(len.to_le_bytes());
    b
}

/// The capture's first packet time, ns since the epoch.
const T0_NS: u64 = 1_700_000_000_000_000_000;

/// A pcapng section header and one Ethernet interface with nanosecond times, as Wireshark writes them.
fn pcapng_header() -> Vec<u8> {
    let mut shb = 0x1a2b_3c4du32.to_le_bytes().to_vec();
    shb.extend([1, 0, 0, 0]);
    shb.extend(u64::MAX.to_le_bytes());
    let mut file = block(0x0a0d_0d0a, &shb);
    // Interface: Ethernet, snap length 262144, option if_tsresol = 9, end of options.
    let mut idb = vec![1, 0, 0, 0];
    idb.extend(262_144u32.to_le_bytes());
    idb.extend([9, 0, 1, 0, 9, 0, 0, 0, 0, 0, 0, 0]);
    file.extend(block(1, &idb));
    file
}

/// An enhanced packet block of interface 0: `frame` at `ns`.
fn epb(ns: u64, frame: &[u8]) -> Vec<u8> {
    let mut b = 0u32.to_le_bytes().to_vec();
    b.extend(((ns >> 32) as u32).to_le_bytes());
    b.extend((ns as u32).to_le_bytes());
    b.extend((frame.len() as u32).to_le_bytes());
    b.extend((frame.len() as u32).to_le_bytes());
    b.extend(frame);
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    block(6, &b)
}

/// A pcapng file as Wireshark saves one (section header, an Ethernet interface with nanosecond times, enhanced
/// packet blocks): text telemetry without a time at 100 Hz, and among it an ARP frame, a TCP segment and an IPv4
/// fragment, skipped and counted.
#[test]
fn a_wireshark_pcapng_capture_is_cued() {
    let d = dir("pcapng");
    let mut file = pcapng_header();
    let t0 = T0_NS;
    let g = 9.80665;
    for k in 0..50u64 {
        let text = format!("-4 0 {g} 0 0 0");
        file.extend(epb(t0 + k * 10_000_000, &ethernet_ipv4(17, 0, text.as_bytes())));
        if k == 10 {
            let mut arp = vec![0xff; 6];
            arp.extend([0x02, 0, 0, 0, 0, 2, 0x08, 0x06]);
            arp.extend([0u8; 28]);
            file.extend(epb(t0 + k * 10_000_000 + 1, &arp));
            file.extend(epb(t0 + k * 10_000_000 + 2, &ethernet_ipv4(6, 0, b"tcp")));
            file.extend(epb(t0 + k * 10_000_000 + 3, &ethernet_ipv4(17, 0x2000, b"1 2 3")));
        }
    }
    let path = d.join("wireshark.pcapng");
    std::fs::write(&path, &file).unwrap();
    let poses = d.join("poses.csv");
    let (code, summary, said) = cue(&path, &poses, &["--telemetry-format", "text"]);
    assert_eq!(code, Some(0), "{summary} {said}");
    assert_eq!(summary["rows"], 50);
    let c = &summary["capture"];
    assert_eq!(c["file_format"], "pcapng");
    assert_eq!(c["packets"], 53);
    assert_eq!(c["datagrams"], 50);
    assert_eq!(c["ports"]["4123"], 50, "{c}");
    assert_eq!(c["skipped"]["not IP (ethertype 0x0806)"], 1, "{c}");
    assert_eq!(c["skipped"]["not UDP (IP protocol 6)"], 1, "{c}");
    assert_eq!(
        c["skipped"]["an IPv4 fragment (fragments are not reassembled)"], 1,
        "{c}"
    );
    // No time in the datagrams: the capture's, from the first one, at the interface's nanosecond resolution.
    let text = std::fs::read_to_string(&poses).unwrap();
    let t: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(t.len(), 50);
    assert!((t[0]).abs() < 1e-12 && (t[49] - 0.49).abs() < 1e-9, "{:?}", &t[..3]);
    // Braking: the platform moves back.
    assert!(last_pose(&poses)[0] < 0.0);
}

/// A Forza drive with a 20 s pause in the game's menu, as Wireshark saves it: Forza keeps sending at 60 Hz with
/// `IsRaceOn` 0 and its clock running. Both parts of the drive are cued, the menu's packets skipped and counted,
/// the pause reported, exit 0.
#[test]
fn a_forza_drive_with_a_pause_in_the_menu_is_cued_whole() {
    use crate::common::packets::forza;
    let d = dir("forza-pause");
    let mut file = pcapng_header();
    // 2 s braking at 4 m/s^2 (car space Z forward), 20 s in the menu, 2 s braking again.
    let parts = [(1, 0u32, 120u32), (0, 120, 1320), (1, 1320, 1440)];
    for (race_on, from, to) in parts {
        for k in from..to {
            let ms = k * 1000 / 60;
            let packet = forza::packet(forza::SLED, race_on, ms, [0.0, 0.0, -4.0], [0.0; 3], [0.0; 3]);
            file.extend(epb(T0_NS + u64::from(ms) * 1_000_000, &ethernet_ipv4(17, 0, &packet)));
        }
    }
    let path = d.join("forza.pcapng");
    std::fs::write(&path, &file).unwrap();
    let poses = d.join("poses.csv");
    for format in ["forza", "auto"] {
        let (code, summary, said) = cue(&path, &poses, &["--telemetry-format", format]);
        assert_eq!(code, Some(0), "{format}: {summary} {said}");
        assert_eq!(summary["rows"], 240, "{format}: {summary}");
        assert_eq!(summary["input_errors"], serde_json::json!([]), "{format}: {summary}");
        let c = &summary["capture"];
        assert_eq!(
            c["skipped"]["the game's packets without motion (other types, menus)"], 1200,
            "{c}"
        );
        let pauses = summary["pauses"].as_array().unwrap();
        assert_eq!(pauses.len(), 1, "{format}: {summary}");
        assert_eq!(
            pauses[0]["line"], 1321,
            "{format}: the packet after the menu: {summary}"
        );
        assert!(
            (pauses[0]["seconds"].as_f64().unwrap() - 20.0).abs() < 0.02,
            "{summary}"
        );
        // Braking after the pause: the platform moves back again.
        assert!(last_pose(&poses)[0] < 0.0, "{format}");
    }
}

/// A Forza row's motion fields: `TimestampMS`, acceleration, angular velocity, yaw, pitch and roll.
type ForzaRow = (u32, [f32; 3], [f32; 3], [f32; 3]);

/// The first 14 rows of a real Forza Motorsport 7 lap of Laguna Seca: forza-telemetry (Austin Baccus, MIT License,
/// "Copyright (c) 2021 Austin Baccus"), `github.com/austinbaccus/forza-telemetry`, `data/laguna-seca.csv` at commit
/// a0dff69: `TimestampMS`, `AccelerationX/Y/Z`, `AngularVelocityX/Y/Z`, `Yaw`, `Pitch`, `Roll`, as logged from the
/// game's Data Out. After its first row the game paused for 20.3 s; then the car climbs to Turn 1, a left kink,
/// at 56-64 m/s (its heading turns 0.21 rad left, `Yaw` falling as it does over the anticlockwise lap).
#[rustfmt::skip]
const LAGUNA_SECA: [ForzaRow; 14] = [
    (105962421, [-2.1221318, 0.26743877, -2.733962], [0.007933499, 0.002314907, 0.047476143], [-2.5394783, -0.043695558, -0.0018316997]),
    (105982718, [-0.1516254, 3.939925, -4.28901], [-0.051847145, -0.0009081103, -0.0014404207], [-2.5394187, -0.050641254, 0.0014512936]),
    (105982828, [-0.08327532, -1.0727226, -3.6704316], [-0.011708598, -2.7091883e-6, -0.009476445], [-2.5394907, -0.05006072, 0.0012305158]),
    (105982937, [-5.7388973, 3.8094172, -0.23267293], [-0.063534506, -0.22932602, -0.09312778], [-2.5501423, -0.057508823, -0.0053437985]),
    (105983046, [-15.221707, 3.9150503, 3.1514926], [-0.0692549, -0.42893708, -0.051040106], [-2.5879524, -0.0664587, -0.0107511375]),
    (105983140, [-15.657779, 2.8247707, 5.3592577], [-0.074907385, -0.086303085, 0.0326446], [-2.6247241, -0.07236691, -0.009702182]),
    (105983265, [-4.720371, 4.5331306, 7.5716405], [-0.11756057, 0.010523499, 0.054731183], [-2.62385, -0.08313476, -0.00320681]),
    (105983375, [-1.319216, 3.3794131, 9.253114], [-0.032351527, -0.03387612, -0.010494449], [-2.6242628, -0.089737415, -0.0012174621]),
    (105983484, [-6.6353736, 4.390136, 10.774042], [-0.101385176, -0.22956549, -0.02913884], [-2.6389403, -0.0970247, -0.002472094]),
    (105983593, [-10.349028, 2.2927942, 10.7442465], [0.08370036, -0.19475761, -0.018750433], [-2.6632643, -0.10172155, -0.0034456807]),
    (105983687, [-10.879368, -3.8616219, 11.114133], [-0.0006026947, -0.27840155, -0.04235768], [-2.6875415, -0.092995495, 0.0002917871]),
    (105983796, [-16.110498, 3.729642, 10.532394], [-0.046206262, -0.22342199, -0.004531618], [-2.7145724, -0.09791153, -0.0014752041]),
    (105983921, [-12.654116, -2.2237518, 9.732622], [-0.010193082, -0.19198637, -0.0013354998], [-2.7395246, -0.09974552, 0.0016728309]),
    (105984031, [-8.961039, 1.2503269, 4.2490206], [0.059324585, 0.0039602052, 0.09544514], [-2.7485256, -0.09792113, 0.0056137103]),
];

/// The real lap's start, its motion fields as the recording has them in Sled packets (the other fields the
/// builder's): cued whole, the 20.3 s pause reported, exit 0; through Turn 1 the platform turns and tilts left.
#[test]
fn a_real_forza_lap_with_a_pause_is_cued_whole_and_turns_left() {
    use crate::common::packets::forza;
    let d = dir("forza-laguna-seca");
    let mut file = pcapng_header();
    for (ms, accel, ang_vel, ypr) in LAGUNA_SECA {
        let packet = forza::packet(forza::SLED, 1, ms, accel, ang_vel, ypr);
        file.extend(epb(T0_NS + u64::from(ms) * 1_000_000, &ethernet_ipv4(17, 0, &packet)));
    }
    let path = d.join("laguna-seca.pcapng");
    std::fs::write(&path, &file).unwrap();
    let poses = d.join("poses.csv");
    let (code, summary, said) = cue(&path, &poses, &["--telemetry-format", "forza"]);
    assert_eq!(code, Some(0), "{summary} {said}");
    assert_eq!(summary["rows"], 14, "{summary}");
    let pauses = summary["pauses"].as_array().unwrap();
    assert_eq!(pauses.len(), 1, "{summary}");
    assert_eq!(pauses[0]["line"], 2, "{summary}");
    assert!(
        (pauses[0]["seconds"].as_f64().unwrap() - 20.297).abs() < 1e-6,
        "{summary}"
    );
    // x, y, z, alpha (roll), beta (pitch), gamma (yaw): turned left with the car's heading, right side down for
    // the force to the left.
    let last = last_pose(&poses);
    assert!(last[5] > 0.1, "turned left: {last:?}");
    assert!(last[3] > 0.0, "tilted for a force to the left: {last:?}");
}

/// An F1 session's capture: each frame's motion packet among the other packet types the game sends to the same
/// port (session, lap data, car telemetry). Every motion packet is cued, the others skipped and counted, exit 0.
#[test]
fn an_f1_capture_with_every_packet_type_is_cued_whole() {
    let d = dir("f1-session");
    let mut file = pcapng_header();
    for k in 0..60u64 {
        let t = k as f32 / 60.0;
        for (id, len) in [(1u8, 753), (2, 1285), (0, 1349), (6, 1352)] {
            let mut p =
                crate::common::packets::f1::packet(2024, id, 3, t, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -0.4, 0.0]);
            p.resize(len, 0);
            file.extend(epb(T0_NS + k * 16_666_667 + u64::from(id), &ethernet_ipv4(17, 0, &p)));
        }
    }
    let path = d.join("f1.pcapng");
    std::fs::write(&path, &file).unwrap();
    let poses = d.join("poses.csv");
    for format in ["f1", "auto"] {
        let (code, summary, said) = cue(&path, &poses, &["--telemetry-format", format]);
        assert_eq!(code, Some(0), "{format}: {summary} {said}");
        assert_eq!(summary["rows"], 60, "{format}: {summary}");
        let c = &summary["capture"];
        assert_eq!(
            c["skipped"]["the game's packets without motion (other types, menus)"], 180,
            "{c}"
        );
        assert!(last_pose(&poses)[0] < 0.0, "{format}: braking moves the platform back");
    }
}

/// Damaged or foreign captures: refused with a message (or, cut off in a packet, cued up to it and said).
#[test]
fn damaged_captures_are_refused_with_a_message() {
    let d = dir("damaged");
    let out = d.join("p.csv");
    let header = |link: u32| {
        let mut h = vec![0xd4, 0xc3, 0xb2, 0xa1, 2, 0, 4, 0];
        h.extend([0u8; 8]);
        h.extend(65_535u32.to_le_bytes());
        h.extend(link.to_le_bytes());
        h
    };
    let cases: [(&str, Vec<u8>, &str); 3] = [
        ("cut.pcap", header(101)[..10].to_vec(), "cut short"),
        ("wifi.pcap", header(105), "IEEE802_11 (105) is not read"),
        ("ng.pcapng", vec![0x0a, 0x0d, 0x0d, 0x0a, 1, 2, 3], "pcapng"),
    ];
    for (name, bytes, says) in cases {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        let (code, _, said) = cue(&path, &out, &["--telemetry-format", "outsim"]);
        assert_eq!(code, Some(1), "{name}: {said}");
        assert!(said.contains(says) && said.contains(name), "{name}: {said}");
    }
    // A raw-IP capture cut off in its second packet: the first is cued, the cut is an input error.
    let mut file = header(101);
    let packet = {
        let mut p = ethernet_ipv4(17, 0, b"0 0 9.8 0 0 0.1");
        p.drain(..14);
        p
    };
    for k in 0..2u32 {
        file.extend([0, 0, 0, 0]);
        file.extend((k * 10_000).to_le_bytes());
        file.extend((packet.len() as u32).to_le_bytes());
        file.extend((packet.len() as u32).to_le_bytes());
        file.extend(&packet);
    }
    file.truncate(file.len() - 5);
    let path = d.join("cutoff.pcap");
    std::fs::write(&path, file).unwrap();
    let (code, summary, said) = cue(&path, &out, &["--telemetry-format", "text"]);
    assert_eq!(code, Some(3), "{said}");
    assert_eq!(summary["rows"], 1, "{summary}");
    assert!(summary["input_errors"][0]["reason"]
        .as_str()
        .unwrap()
        .contains("middle of this packet"));
    // A CSV given a capture's options is told so.
    let csv = d.join("t.csv");
    std::fs::write(&csv, "t,ax,ay,az,wx,wy,wz\n0,0,0,9.8,0,0,0\n").unwrap();
    let (code, _, said) = cue(&csv, &out, &["--telemetry-format", "outsim"]);
    assert_eq!(code, Some(1));
    assert!(said.contains("not one"), "{said}");
}

/// `--capture` without a UDP source is refused; a capture that cannot be created stops the stream before it starts.
#[test]
fn capture_needs_a_udp_source_and_a_writable_file() {
    let run = |args: &[&str]| {
        std::process::Command::new(assert_cmd::cargo::cargo_bin("ringpod"))
            .args(["stream", "--sim", "--fast", "--quiet"])
            .args(args)
            .output()
            .unwrap()
    };
    let o = run(&["--motion", "heave", "--duration", "0.1", "--capture", "x.pcap"]);
    assert_ne!(o.status.code(), Some(0));
    let o = run(&["--telemetry-udp", "127.0.0.1:0", "--capture", "/nonexistent/dir/x.pcap"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/dir/x.pcap"));
}

/// Live for Speed with `OutSim Opts 19` (header, main section, inputs: 84 bytes, the size of `2f` too, which
/// places ID and Time before the main section): the size alone cannot tell, so the capture is read only with the
/// option set, from the command line or from the cueing file (its base or a game's profile); an option set for a
/// format that never reads OutSimPack2 is refused.
#[test]
fn outsim2_options_come_from_the_command_line_or_the_cueing_file() {
    let d = dir("outsim-opts");
    let mut file = pcapng_header();
    for k in 0..50u32 {
        // Heading 0 faces world +y: braking at 3 m/s^2.
        let packet = crate::common::packets::outsim2::packet(0x19, k * 10, [0.0; 3], [0.0; 3], [0.0, -3.0, 0.0]);
        assert_eq!(packet.len(), 84);
        file.extend(epb(T0_NS + u64::from(k) * 10_000_000, &ethernet_ipv4(17, 0, &packet)));
    }
    let path = d.join("lfs.pcapng");
    std::fs::write(&path, &file).unwrap();
    let poses = d.join("poses.csv");
    let base = d.join("base.toml");
    std::fs::write(&base, "outsim_opts = \"19\"\n").unwrap();
    let profiled = d.join("profiled.toml");
    std::fs::write(&profiled, "[profiles.lfs]\noutsim_opts = \"0x19\"\n").unwrap();
    let (code, summary, said) = cue(&path, &poses, &["--telemetry-format", "outsim2"]);
    assert_ne!(
        summary["rows"], 50,
        "read without the option set: {code:?} {summary} {said}"
    );
    assert!(summary.to_string().contains("--outsim-opts"), "{summary} {said}");
    for args in [
        &["--outsim-opts", "19"][..],
        &["--config", base.to_str().unwrap()],
        &["--config", profiled.to_str().unwrap(), "--profile", "lfs"],
        // The command line's set wins over the file's.
        &[
            "--config",
            base.to_str().unwrap(),
            "--outsim-opts",
            "19",
            "--telemetry-format",
            "auto",
        ],
    ] {
        let (code, summary, said) = cue(&path, &poses, args);
        assert_eq!(
            (code, &summary["rows"]),
            (Some(0), &serde_json::json!(50)),
            "{args:?}: {said}"
        );
        assert!(last_pose(&poses)[0] < 0.0, "braking moves the platform back");
    }
    let (code, _, said) = cue(&path, &poses, &["--config", profiled.to_str().unwrap()]);
    assert_ne!(code, Some(0), "the base has no option set: {said}");
    std::fs::write(&base, "outsim_opts = 409\n").unwrap();
    let (code, _, said) = cue(&path, &poses, &["--config", base.to_str().unwrap()]);
    assert!(code != Some(0) && said.contains("outsim_opts"), "{said}");
    std::fs::write(&base, "outsim_opts = \"7\"\n").unwrap();
    let (code, _, said) = cue(&path, &poses, &["--config", base.to_str().unwrap()]);
    assert!(
        code != Some(0) && said.contains("outsim_opts") && said.contains("main section"),
        "{said}"
    );
    let (code, _, said) = cue(&path, &poses, &["--telemetry-format", "f1", "--outsim-opts", "19"]);
    assert!(code != Some(0) && said.contains("outsim2 or auto"), "{said}");
}
