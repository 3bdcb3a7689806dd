//! `ringpod stream --udp --pose-format`: the pose strings of motion front ends (FlyPT Mover, SimTools, SimHub),
//! sent over UDP as they send them, followed by the simulated controller.

use crate::common::{numbers, spawn_live_stream};

/// The trainer model's home pose (the neutral the strings' offsets are taken from).
const HOME: [f64; 6] = [0.0, 0.0, 0.227, 0.0, 0.0, 0.0];

/// Each preset's strings, written byte by byte as its front end's settings in the book make them: a heave of
/// +20 mm (the range's middle is 40 mm) and a roll of -10 degrees, eased in over half a second and held; one
/// string cut short on the way is counted unreadable. The report ends at that pose and the record shows the
/// platform following it, with the poses commanded rising to it.
#[test]
fn each_preset_streams_its_front_ends_strings() {
    for (preset, heave, roll) in [
        // Heave +20 mm: half the 40 mm range, fixed-point 3/4 of 0..65535; roll -10 degrees: a quarter.
        ("simtools", b"49151".to_vec(), b"16384".to_vec()),
        ("flypt", vec![0xbf, 0xff], vec![0x40, 0x00]),
        ("simhub", b"BFFF".to_vec(), b"4000".to_vec()),
    ] {
        let record = std::env::temp_dir().join(format!("ringpod-front-{preset}-{}.csv", std::process::id()));
        let record_arg = record.to_str().unwrap();
        // The session ends with STOP, which brings the platform to rest where it is: the pause before it lets the
        // platform reach the last pose, also when a loaded machine delivers the datagrams in a burst.
        let (child, mut stderr, addr) = spawn_live_stream(&[
            "--udp",
            "127.0.0.1:0",
            "--fast",
            "--udp-idle",
            "1",
            "--pose-format",
            preset,
            "--record",
            record_arg,
        ]);
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        for k in 0..=60u32 {
            let share = (f64::from(k) / 50.0).min(1.0);
            let string = string(preset, share, &heave, &roll);
            socket.send_to(&string, &addr).unwrap();
            if k == 20 {
                socket.send_to(&string[..string.len() - 2], &addr).unwrap();
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        let out = child.wait_with_output().unwrap();
        let mut said = String::new();
        std::io::Read::read_to_string(&mut stderr, &mut said).unwrap();
        let report: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{preset}: {e}: {said}"));
        assert_eq!(report["state"], "Ready", "{preset}: {report}");
        assert_eq!(
            report["input_errors"].as_array().unwrap().len(),
            1,
            "{preset}: {report}"
        );
        let last = numbers(&report["last_applied_pose"]);
        let want = [0.0, 0.0, HOME[2] + 0.020, -10f64.to_radians(), 0.0, 0.0];
        // Within a 16-bit step of each axis's range (50, 50, 40 mm; 20 degrees) either way: 32768 is a step
        // above the middle of 0..65535.
        let ranges = [
            0.050,
            0.050,
            0.040,
            20f64.to_radians(),
            20f64.to_radians(),
            20f64.to_radians(),
        ];
        for k in 0..6 {
            let step = 2.0 * ranges[k] / 65535.0;
            assert!((last[k] - want[k]).abs() <= step, "{preset} axis {k}: {last:?}");
        }
        let text = std::fs::read_to_string(&record).unwrap();
        std::fs::remove_file(&record).unwrap();
        let followed = followed(&text);
        assert!(followed.len() > 10, "{preset}: {} rows", followed.len());
        let (cmd, at) = followed.last().unwrap();
        assert!(
            (cmd[2] - want[2]).abs() < 1e-5 && (cmd[3] - want[3]).abs() < 1e-5,
            "{preset}: {cmd:?}"
        );
        assert!(
            (at[2] - want[2]).abs() < 2e-4 && (at[3] - want[3]).abs() < 2e-3,
            "{preset}: {at:?}"
        );
        assert!(
            followed.windows(2).all(|w| w[1].0[2] >= w[0].0[2] - 1e-9),
            "{preset}: the heave commanded only rises"
        );
    }
}

/// The string `preset` sends for `share` of the heave and roll values (the other axes at neutral; the heave and
/// roll fields written as given once `share` is 1).
fn string(preset: &str, share: f64, heave: &[u8], roll: &[u8]) -> Vec<u8> {
    let mid = 32768.0;
    let fixed = |full: &[u8]| -> u64 {
        if share >= 1.0 {
            return match preset {
                "simtools" => std::str::from_utf8(full).unwrap().parse().unwrap(),
                "simhub" => u64::from_str_radix(std::str::from_utf8(full).unwrap(), 16).unwrap(),
                _ => u64::from(full[0]) << 8 | u64::from(full[1]),
            };
        }
        let end = match preset {
            "simtools" => std::str::from_utf8(full).unwrap().parse::<f64>().unwrap(),
            "simhub" => u64::from_str_radix(std::str::from_utf8(full).unwrap(), 16).unwrap() as f64,
            _ => f64::from(u16::from(full[0]) << 8 | u16::from(full[1])),
        };
        (mid + share * (end - mid)).round() as u64
    };
    let axes = [32768, 32768, fixed(heave), fixed(roll), 32768, 32768];
    match preset {
        "simtools" => axes.iter().map(|v| format!("{v}~")).collect::<String>().into_bytes(),
        "simhub" => {
            let fields: Vec<String> = axes.iter().map(|v| format!("{v:X}")).collect();
            format!("P{}\n", fields.join(";")).into_bytes()
        }
        _ => {
            let mut s = vec![255, 255];
            for v in axes {
                s.extend((v as u16).to_be_bytes());
            }
            s.extend([10, 13]);
            s
        }
    }
}

/// A record's commanded and followed poses, row by row.
fn followed(text: &str) -> Vec<([f64; 6], [f64; 6])> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let cmd = ["cmd_x", "cmd_y", "cmd_z", "cmd_alpha", "cmd_beta", "cmd_gamma"].map(col);
    let at = ["x", "y", "z", "alpha", "beta", "gamma"].map(col);
    lines
        .filter_map(|line| {
            let v: Vec<&str> = line.split(',').collect();
            let get = |i: usize| v[i].parse::<f64>().ok();
            let c: Option<Vec<f64>> = cmd.iter().map(|i| get(*i)).collect();
            let a: Option<Vec<f64>> = at.iter().map(|i| get(*i)).collect();
            Some((c?.try_into().ok()?, a?.try_into().ok()?))
        })
        .collect()
}

/// A template that cannot be read is a usage error naming the character, before anything starts; `--pose-range`
/// needs `--pose-format`, and six ranges above 0.
#[test]
fn bad_templates_and_ranges_are_usage_errors() {
    for (args, words) in [
        (
            &["--pose-format", "dec8:<Axis1a>~<Axis7a>"][..],
            "pose format, character 15: `<Axis7a>` names axis 7",
        ),
        (
            &["--pose-format", "simtool"],
            "neither a preset (simtools, flypt, simhub)",
        ),
        (&["--pose-range", "1,2,3,4,5,6"], "--pose-format"),
        (
            &["--pose-format", "simtools", "--pose-range", "1,2,3"],
            "expected 6 ranges",
        ),
        (&["--pose-format", "simtools", "--degrees"], "--degrees"),
    ] {
        let out = assert_cmd::Command::cargo_bin("ringpod")
            .unwrap()
            .args(["stream", "--sim", "--udp", "127.0.0.1:0"])
            .args(args)
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {said}");
        assert!(said.contains(words), "{args:?}: {said}");
    }
}
