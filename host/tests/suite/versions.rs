//! The board's version, always known: `device status` names the firmware, and a board of another protocol version
//! (an older board, or one flashed by a newer ringpod) is named by what it runs and refused before anything is
//! asked of it, with the way out: `ringpod flash`.

use std::io::{Read, Write};
use std::net::TcpListener;
use std::sync::{Arc, Mutex};

use assert_cmd::Command;
use ringpod_core::protocol::{self, Firmware, FrameReader, HostMessage, Image, Request, MAX_FRAME, PROTOCOL_VERSION};

fn ringpod() -> Command {
    Command::cargo_bin("ringpod").unwrap()
}

/// A board of another protocol version on `tcp://`: every frame it reads is recorded as the request this host
/// meant, and answered by `answer(id)`, its own message as its version encodes it.
fn foreign_board(answer: fn(u32) -> Vec<u8>) -> (String, Arc<Mutex<Vec<HostMessage>>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = format!("tcp://{}", listener.local_addr().unwrap());
    let asked = Arc::new(Mutex::new(Vec::new()));
    let seen = asked.clone();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { return };
            let mut reader = FrameReader::default();
            let mut buf = [0u8; 512];
            while let Ok(n @ 1..) = stream.read(&mut buf) {
                for &b in &buf[..n] {
                    let Some(frame) = reader.push(b) else { continue };
                    let Ok(request) = protocol::decode::<Request>(frame) else {
                        continue;
                    };
                    seen.lock().unwrap().push(request.body);
                    if stream.write_all(&answer(request.id)).is_err() {
                        return;
                    }
                }
            }
        }
    });
    (port, asked)
}

/// A frame of `message` (any serializable shape: a tuple encodes as another version's enum would).
fn frame<M: serde::Serialize>(message: &M) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = protocol::encode(message, &mut out).unwrap();
    out[..n].to_vec()
}

/// A board of protocol 9: its version mismatch carried the version alone (id, Nack, VersionMismatch, 9).
fn protocol_9(id: u32) -> Vec<u8> {
    frame(&(id, 3u32, 0u32, 9u16))
}

const NEWER: Firmware = Firmware {
    version: [0, 2, 0],
    image: Some(Image {
        size: 180_224,
        crc: 0x00c0_ffee,
    }),
};

/// A board flashed by a newer ringpod: its mismatch names its firmware.
fn newer(id: u32) -> Vec<u8> {
    frame(&(id, 3u32, 0u32, PROTOCOL_VERSION + 1, Some(NEWER)))
}

#[test]
fn a_stream_to_an_older_board_is_refused_before_anything_moves() {
    let (port, asked) = foreign_board(protocol_9);
    let out = ringpod()
        .args([
            "stream",
            "--port",
            &port,
            "--motion",
            "demo",
            "--duration",
            "1",
            "--quiet",
        ])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{said}");
    assert!(said.contains("run `ringpod flash`"), "{said}");
    assert!(said.contains("older firmware (firmware of protocol 9)"), "{said}");
    let asked = asked.lock().unwrap();
    assert!(!asked.is_empty());
    assert!(
        asked.iter().all(|m| matches!(m, HostMessage::Hello { .. })),
        "only the handshake was sent: {asked:?}"
    );
}

#[test]
fn a_newer_board_is_named_by_its_firmware_and_nothing_is_asked_of_it() {
    let (port, asked) = foreign_board(newer);
    for args in [
        &["device", "status", "--port", &port][..],
        &["device", "enable", "--port", &port],
        &["stream", "--port", &port, "--motion", "demo", "--quiet"],
    ] {
        let out = ringpod().args(args).output().unwrap();
        let said = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {said}");
        let named = format!(
            "newer firmware (ringpod 0.2.0 (image 180224 B, CRC-32C 00c0ffee), protocol {})",
            PROTOCOL_VERSION + 1
        );
        assert!(said.contains(&named), "{args:?}: {said}");
        assert!(said.contains("run `ringpod flash`"), "{args:?}: {said}");
    }
    let asked = asked.lock().unwrap();
    assert!(
        asked.iter().all(|m| matches!(m, HostMessage::Hello { .. })),
        "{asked:?}"
    );
}

#[test]
fn device_status_names_the_firmware() {
    let out = ringpod().args(["device", "status", "--sim"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let status: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        status["firmware"],
        serde_json::json!({
            "version": env!("CARGO_PKG_VERSION"),
            "protocol": PROTOCOL_VERSION,
            "image": null,
        })
    );
}
