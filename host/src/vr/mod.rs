//! VR motion compensation: the pose the seat is in, written where OpenXR-MotionCompensation (OXRMC) and its OpenVR
//! sibling read a motion rig's pose, so that the headset's view is held to the moving cockpit.
//!
//! The layout is the one OXRMC's virtual trackers read (BuzzteeBear/OpenXR-MotionCompensation,
//! `XR_APILAYER_NOVENDOR_motion_compensation/tracker.h` and `tracker.cpp`, `SixDofTracker::ReadSource`,
//! `ExtractTranslationVector`, `FlyPtTracker`/`SrsTracker::ExtractRotationQuaternion`, at commit 1416c2ea of
//! 2025-07-19): six `double`s at the start of a named file mapping, in the order sway, surge, heave, yaw, roll,
//! pitch; translations in millimetres, angles in degrees. OXRMC builds the rig's orientation as DirectXMath's
//! `XMQuaternionRotationRollPitchYaw(pitch, yaw, -roll)` for FlyPT Mover (`Local\motionRigPose`) and
//! `(-pitch, yaw, roll)` for SimRacingStudio (`Local\SimRacingStudioMotionRigPose`) in OpenXR's frame (x right, y up,
//! z back), then the translation `(sway, heave, -surge) / 1000` rotated by that orientation (so it is read in the
//! rig's own axes). So, in ringpod's base frame (x forward, y left, z up; `R = Rz(gamma) Ry(beta) Rx(alpha)`):
//! FlyPT's yaw is `gamma`, its pitch `-beta` (nose up positive), its roll `alpha` (right side down positive), in the
//! same yaw-pitch-roll order as ringpod's; SimRacingStudio's pitch and roll have the opposite signs. The layout has
//! no update counter: a stalled source is one whose pose stops changing, which is what a lost link leaves.
//!
//! The pose is that of the rig's centre of rotation (the rig file's `[motion_compensation] centre_of_rotation`,
//! platform coordinates from the platform origin), relative to where it is at the home pose, from each telemetry
//! sample's followed pose: what the seat did, not what was asked of it.

#[cfg(windows)]
pub(crate) mod mapping;

use nalgebra::{Matrix3, Vector3};
use ringpod_core::kinematics::Pose;

/// Which motion software's file the pose is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Tracker {
    /// FlyPT Mover's `Local\motionRigPose` (OXRMC's tracker type `flypt`).
    Flypt,
    /// SimRacingStudio's `Local\SimRacingStudioMotionRigPose` (OXRMC's tracker type `srs`).
    Srs,
}

impl Tracker {
    /// The mapping's name, as OXRMC opens it.
    pub fn mapping_name(self) -> &'static str {
        match self {
            Tracker::Flypt => "Local\\motionRigPose",
            Tracker::Srs => "Local\\SimRacingStudioMotionRigPose",
        }
    }
}

/// The six values in the file, in its order and units (mm, degrees).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SixDof {
    /// Right (mm), in the rig's axes.
    pub sway: f64,
    /// Forward (mm), in the rig's axes.
    pub surge: f64,
    /// Up (mm), in the rig's axes.
    pub heave: f64,
    /// About up, counter-clockwise seen from above (degrees, (-180, 180]).
    pub yaw: f64,
    /// Degrees; sign per [`Tracker`].
    pub roll: f64,
    /// Degrees; sign per [`Tracker`].
    pub pitch: f64,
}

/// The file's size in bytes: six little-endian `double`s.
#[cfg_attr(not(windows), allow(dead_code))]
pub const SIX_DOF_BYTES: usize = 48;

// Written on Windows only; the layout is tested everywhere.
#[cfg_attr(not(windows), allow(dead_code))]
impl SixDof {
    /// The bytes as the reader's `struct SixDof` has them (x86-64: little-endian, no padding).
    pub fn to_bytes(self) -> [u8; SIX_DOF_BYTES] {
        let mut out = [0u8; SIX_DOF_BYTES];
        let values = [self.sway, self.surge, self.heave, self.yaw, self.roll, self.pitch];
        for (chunk, v) in out.chunks_exact_mut(8).zip(values) {
            chunk.copy_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Reads the bytes back (the reader's side, for tests).
    #[cfg(test)]
    pub fn from_bytes(bytes: &[u8; SIX_DOF_BYTES]) -> Self {
        let mut v = [0.0; 6];
        for (slot, chunk) in v.iter_mut().zip(bytes.chunks_exact(8)) {
            let mut b = [0u8; 8];
            b.copy_from_slice(chunk);
            *slot = f64::from_le_bytes(b);
        }
        Self {
            sway: v[0],
            surge: v[1],
            heave: v[2],
            yaw: v[3],
            roll: v[4],
            pitch: v[5],
        }
    }
}

/// An angle in degrees within (-180, 180]: ringpod's yaw is multi-turn, a reader's is an angle.
fn wrapped_degrees(rad: f64) -> f64 {
    let d = rad.to_degrees().rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

/// The centre of rotation's pose at `pose`, relative to where it is at `home`, in `tracker`'s layout.
pub fn six_dof(tracker: Tracker, pose: &Pose<f64>, home: &Pose<f64>, centre: [f64; 3]) -> SixDof {
    let c = Vector3::from(centre);
    let r: Matrix3<f64> = pose.rotation();
    // Displacement of the centre in the base frame, then in the rig's own axes (as the reader rotates it back).
    let moved = (r * c + pose.position()) - (home.rotation() * c + home.position());
    let local = r.transpose() * moved;
    // ringpod: x forward, y left, z up; the file: right, forward, up.
    let (sway, surge, heave) = (-local.y * 1000.0, local.x * 1000.0, local.z * 1000.0);
    let (roll, pitch) = match tracker {
        Tracker::Flypt => (pose.alpha, -pose.beta),
        Tracker::Srs => (-pose.alpha, pose.beta),
    };
    SixDof {
        sway,
        surge,
        heave,
        yaw: wrapped_degrees(pose.gamma),
        roll: wrapped_degrees(roll),
        pitch: wrapped_degrees(pitch),
    }
}

/// The rig file's `[motion_compensation]` table.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompensationSpec {
    /// The rig's centre of rotation (the point the seat turns about, near the driver's hips), in platform
    /// coordinates from the platform origin (m): OXRMC's virtual tracker takes this point's pose.
    pub centre_of_rotation: [f64; 3],
}

/// Farther than this from the platform origin (m) a centre of rotation is a unit slip (mm for m), not a rig.
const CENTRE_MAX_M: f64 = 5.0;

impl CompensationSpec {
    /// The centre, when it is a point on or near the rig.
    pub fn checked(&self) -> Result<[f64; 3], String> {
        let c = self.centre_of_rotation;
        if c.iter().any(|v| !v.is_finite()) {
            return Err("must be three finite numbers (m)".into());
        }
        if c.iter().map(|v| v * v).sum::<f64>().sqrt() > CENTRE_MAX_M {
            return Err(format!(
                "is more than {CENTRE_MAX_M} m from the platform origin: metres, not millimetres"
            ));
        }
        Ok(c)
    }
}

/// Why motion compensation could not start.
#[derive(Debug, thiserror::Error)]
pub enum VrError {
    /// Not on Windows.
    #[cfg(not(windows))]
    #[error(
        "--motion-compensation writes a Windows named file mapping ({0}), which OpenXR-MotionCompensation reads on \
         Windows only: run ringpod on the game PC"
    )]
    Unsupported(&'static str),
    /// The mapping could not be created.
    #[cfg(windows)]
    #[error("{name}: {reason}")]
    Mapping {
        /// Its name.
        name: &'static str,
        /// Why.
        reason: std::io::Error,
    },
}

/// The mapping's size: one page. The pose takes 48 bytes; readers that map a larger fixed view (up to a page) find
/// it too, and a section is page-sized whatever is asked.
#[cfg(windows)]
const MAPPING_SIZE: usize = 4096;

/// The writer: one named mapping, kept open (readers find it only while it is) until dropped.
pub struct Compensation {
    tracker: Tracker,
    home: Pose<f64>,
    centre: [f64; 3],
    #[cfg(windows)]
    mapping: mapping::Mapping,
    /// Samples written.
    pub written: u64,
}

impl Compensation {
    /// Creates the mapping (or opens the one a reader or a previous writer left), holding the home pose (zero).
    pub fn open(tracker: Tracker, home: Pose<f64>, centre: [f64; 3]) -> Result<Self, VrError> {
        #[cfg(windows)]
        {
            let name = tracker.mapping_name();
            let mapping =
                mapping::Mapping::create(name, MAPPING_SIZE).map_err(|reason| VrError::Mapping { name, reason })?;
            let mut out = Self {
                tracker,
                home,
                centre,
                mapping,
                written: 0,
            };
            out.write(&home);
            out.written = 0;
            Ok(out)
        }
        #[cfg(not(windows))]
        {
            let _ = (home, centre);
            Err(VrError::Unsupported(tracker.mapping_name()))
        }
    }

    /// Writes the seat's pose. A lost link writes nothing: the file keeps the last pose the seat was seen in.
    pub fn write(&mut self, followed: &Pose<f64>) {
        let values = six_dof(self.tracker, followed, &self.home, self.centre);
        #[cfg(windows)]
        // 48 bytes at the start of a page: always inside.
        self.mapping.write(0, &values.to_bytes());
        #[cfg(not(windows))]
        let _ = values;
        self.written += 1;
    }
}

/// What the client calls with each telemetry sample (its `TelemetryTap`).
pub type PoseTap = Box<dyn FnMut(&ringpod_core::protocol::Telemetry) + Send>;

/// The client's telemetry tap for `stream --motion-compensation`: each sample's followed pose written as it
/// arrives. `rig` is the simulated rig's home and centre of rotation; none for a board (the trainer model's home,
/// the platform origin): OXRMC takes its reference where the user calibrates, so another home only shifts what it
/// subtracts.
pub fn tap(tracker: Tracker, rig: Option<(Pose<f64>, [f64; 3])>) -> Result<PoseTap, VrError> {
    let trainer = || Pose::from_array(ringpod_core::kinematics::presets::Preset::TrainerModel.home());
    let (home, centre) = rig.unwrap_or_else(|| (trainer(), [0.0; 3]));
    let mut out = Compensation::open(tracker, home, centre)?;
    Ok(Box::new(move |sample| out.write(&sample.pose.cast())))
}

#[cfg(test)]
mod tests;
