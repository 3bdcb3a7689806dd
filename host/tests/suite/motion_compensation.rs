//! VR motion compensation as OpenXR-MotionCompensation sees it: a reader opens `Local\motionRigPose` by name while
//! `ringpod stream --sim --motion-compensation flypt` runs, and the six values it reads are the followed poses of
//! the run record, converted as the reader converts them back (Windows only: the mapping is a Windows object; on
//! Linux CI this runs under Wine).

#![cfg(windows)]

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use windows_sys::Win32::Foundation::CloseHandle;
use windows_sys::Win32::System::Memory::{MapViewOfFile, OpenFileMappingW, UnmapViewOfFile, FILE_MAP_READ};

/// The six doubles at the start of the mapping, if it exists now.
fn read(name: &str) -> Option<[f64; 6]> {
    let wide: Vec<u16> = name.encode_utf16().chain(std::iter::once(0)).collect();
    // SAFETY: a NUL-terminated name; every handle and view is checked and released.
    unsafe {
        let handle = OpenFileMappingW(FILE_MAP_READ, 0, wide.as_ptr());
        if handle.is_null() {
            return None;
        }
        let view = MapViewOfFile(handle, FILE_MAP_READ, 0, 0, 48);
        let out = (!view.Value.is_null()).then(|| {
            let mut v = [0.0f64; 6];
            std::ptr::copy_nonoverlapping(view.Value.cast::<f64>(), v.as_mut_ptr(), 6);
            UnmapViewOfFile(view);
            v
        });
        CloseHandle(handle);
        out
    }
}

#[test]
fn a_reader_sees_the_followed_pose_track_the_device() {
    let name = r"Local\motionRigPose";
    assert!(read(name).is_none(), "another writer holds the mapping");
    let record = std::env::temp_dir().join(format!("ringpod-mc-{}.csv", std::process::id()));
    let mut child = Command::new(env!("CARGO_BIN_EXE_ringpod"))
        .args(["stream", "--sim", "--motion", "demo", "--duration", "3", "--quiet"])
        .args(["--motion-compensation", "flypt", "--record-hz", "100", "--record"])
        .arg(&record)
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut seen: Vec<[f64; 6]> = Vec::new();
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() && started.elapsed() < Duration::from_secs(60) {
        if let Some(v) = read(name) {
            if seen.last() != Some(&v) {
                seen.push(v);
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(child.wait().unwrap().success());
    // Gone with the writer: a reader then reports the source lost, as OXRMC does.
    assert!(read(name).is_none());
    let text = std::fs::read_to_string(&record).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (alpha, beta, gamma) = (col("alpha"), col("beta"), col("gamma"));
    // Each row's followed angles as the file holds them: yaw = gamma, pitch = -beta, roll = alpha (degrees).
    let rows: Vec<[f64; 3]> = lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect();
            let wrap = |d: f64| {
                let d = d.rem_euclid(360.0);
                if d > 180.0 {
                    d - 360.0
                } else {
                    d
                }
            };
            [
                wrap(f[gamma].to_degrees()),
                wrap(-f[beta].to_degrees()),
                wrap(f[alpha].to_degrees()),
            ]
        })
        .collect();
    // The pose moved while the reader watched: many distinct poses, each one a pose the record has.
    assert!(seen.len() >= 20, "only {} distinct poses seen", seen.len());
    let moving: Vec<&[f64; 6]> = seen.iter().filter(|v| v[3].abs() > 0.5).collect();
    assert!(!moving.is_empty(), "the yaw never moved: {seen:?}");
    for v in &seen[1..] {
        // The record prints 6 decimals of radians; f32 on the wire.
        let matched = rows
            .iter()
            .any(|r| (r[0] - v[3]).abs() < 1e-3 && (r[1] - v[5]).abs() < 1e-3 && (r[2] - v[4]).abs() < 1e-3);
        assert!(matched, "{v:?} is no followed pose of the record");
    }
    let _ = std::fs::remove_file(&record);
}

#[test]
fn the_workbench_holds_the_mapping_at_the_home_pose() {
    let name = r"Local\SimRacingStudioMotionRigPose";
    assert!(read(name).is_none(), "another writer holds the mapping");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ringpod"))
        .args(["ui", "--sim", "--listen", "127.0.0.1:0", "--motion-compensation", "srs"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let mut seen = None;
    while seen.is_none() && started.elapsed() < Duration::from_secs(60) {
        seen = read(name);
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    // The simulated trainer at rest in its home pose: no offset from home in any of the six values.
    let pose = seen.expect("the workbench never wrote the mapping");
    assert!(pose.iter().all(|v| v.abs() < 1e-3), "{pose:?} is not the home pose");
}
