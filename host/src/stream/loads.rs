//! `stream --check-loads`: the drive demand of a file's or built-in motion's poses on the platform the device runs,
//! against that platform's drives, before anything moves.

use ringpod_core::kinematics::{Mechanism, Payload, Pose, RingPlatform};
use ringpod_core::protocol::MotionSettings;

use super::source::{motion_pose, Source};
use crate::link::client::{Client, ClientError, Transport};
use crate::rig::{Drive, Rig, RigError};

/// Why the loads could not be checked.
#[derive(Debug, thiserror::Error)]
pub enum LoadsError {
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// The preset's drive data do not fit its axes.
    #[error(transparent)]
    Drives(#[from] RigError),
    /// The device runs a rig of its own and no rig file was given.
    #[error(
        "--check-loads: the device runs {0}, whose drives this host does not know: give its rig file with --geometry"
    )]
    UnknownDrives(String),
    /// A built-in motion longer than a check takes.
    #[error(
        "--check-loads: {} s at {} Hz is {} poses, more than the {MAX_POSES} it checks: shorten --duration or lower \
         --rate",
        crate::input::numbers::readable(*seconds),
        crate::input::numbers::readable(*rate_hz),
        crate::input::numbers::readable(*poses)
    )]
    TooLong {
        /// The motion's length (s).
        seconds: f64,
        /// Its rate (Hz).
        rate_hz: f64,
        /// Poses it would take.
        poses: f64,
    },
    /// A UDP source's poses are not known beforehand.
    #[error("--check-loads needs the poses beforehand (--input or --motion)")]
    Live,
    /// The payload's mass or inertia.
    #[error(transparent)]
    Payload(#[from] crate::input::numbers::BadNumber),
    /// The demand could not be computed (a pose out of reach, a bad payload).
    #[error("--check-loads: {0}")]
    Demand(String),
}

/// The platform whose drives are checked: the device's rig, with motor data from the rig file or the preset.
pub struct LoadPlatform {
    /// The geometry and home pose the device runs.
    ring: RingPlatform<f64>,
    home: [f64; 6],
    /// The device's pose limits (the built-in motions scale to them).
    limits: MotionSettings,
    /// Motor data per axis.
    drives: [Option<Drive>; 6],
}

/// The platform the device runs (`GetRig`), with the drives of `rig` (the file given with `--geometry`, which the
/// simulated device then runs) or, where the device runs a preset, the preset's. A rig of the device's own whose
/// drives the host does not know cannot be checked: the error says to give its file.
pub fn platform<T: Transport>(client: &mut Client<T>, rig: Option<&Rig>) -> Result<LoadPlatform, LoadsError> {
    let device = client.hello()?;
    let (record, _, _) = client.rig()?;
    let geometry = record
        .geometry()
        .map_err(|e| ClientError::Unexpected(format!("the device's rig does not check: {e}")))?;
    let ring = RingPlatform::new(&geometry);
    let drives = match (rig, device.preset) {
        (Some(rig), _) => rig.drives.clone(),
        (None, Some(preset)) => crate::rig::drives::check(&crate::rig::drives::of_preset(preset), &ring.axes())?,
        (None, None) => return Err(LoadsError::UnknownDrives(record.name().to_owned())),
    };
    Ok(LoadPlatform {
        ring,
        home: record.home,
        limits: record.machine.motion,
        drives,
    })
}

/// The most poses a check takes from a built-in motion (a file is bounded by its size): 2.8 hours at 100 Hz, 33 min
/// at 1 kHz, about 400 MB of profile.
const MAX_POSES: usize = 2_000_000;

/// The demand of `source`'s poses on `platform` for `payload`.
pub fn check_loads(
    source: &Source,
    payload: &Payload<f64>,
    platform: &LoadPlatform,
) -> Result<crate::analysis::demand::Preflight, LoadsError> {
    let rows: Vec<(usize, f64, Pose<f64>)> = match source {
        Source::Poses(p) => p.iter().map(|(line, t, pose, _)| (*line, *t, *pose)).collect(),
        Source::Motion {
            motion,
            sine,
            seconds,
            rate_hz,
        } => {
            let n = (seconds * rate_hz).round();
            if n > MAX_POSES as f64 {
                return Err(LoadsError::TooLong {
                    seconds: *seconds,
                    rate_hz: *rate_hz,
                    poses: n,
                });
            }
            let n = n as usize;
            (0..=n)
                .map(|k| {
                    let t = k as f64 / rate_hz;
                    (
                        k + 1,
                        t,
                        motion_pose(*motion, sine.as_ref(), t, platform.home, &platform.limits),
                    )
                })
                .collect()
        }
        Source::Live(_) => return Err(LoadsError::Live),
    };
    crate::analysis::demand::preflight(&platform.ring, &platform.drives, &rows, payload).map_err(LoadsError::Demand)
}
