//! The device's settings as typed sections: each travels whole (`GetSettings`, `SetSettings`), is checked whole by
//! the controller, and is stored whole. The same types are the rig file's sections on the host, so a value means
//! the same thing in a TOML file, on the wire and in flash.
//!
//! Sections marked *live* take effect at once; the others are stored and take effect at the next start (a reset of
//! the board). Sections that describe the machine ([`SettingsKind::in_rig`]) are part of the [`super::RigRecord`];
//! a device stores the rig and the other sections together, as one record.

use crate::motion::{FollowMode, SpareAxisSettings, SPARE_AXES};
use crate::safety::debounce::InputConfig;
use crate::safety::SupervisorConfig;

/// How setpoints are taken (live).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StreamSettings {
    /// No valid setpoint for this long while streaming is a stream loss (ms, 1-10,000).
    pub timeout_ms: u16,
    /// A setpoint further from the previous one than any axis travels at its velocity limit in this window is
    /// refused as a broken source (ms, 10-10,000).
    pub gross_jump_ms: u16,
    /// How the reference moves toward a new setpoint: `"interpolate"` over each setpoint's interval, or `"direct"`.
    pub follow: FollowMode,
    /// Room a limited setpoint leaves inside each workspace check, in the order of `Check::ALL`, in the check's
    /// unit (at most 0.1 each).
    pub margins: [f32; 6],
    /// Telemetry samples per second while a host asks for them (0: none; at most the control rate).
    pub telemetry_hz: u16,
    /// After a stream is lost, no frame from any host for this long powers the machine down (ms, 1,000-60,000):
    /// the host is gone, not late.
    pub host_gone_ms: u16,
}

/// The control rate (next start).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlSettings {
    /// Control ticks per second: 500, 1,000 or 2,000.
    pub tick_hz: u16,
}

/// Pose and actuator limits (live).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSettings {
    /// Velocity limit per pose axis x, y, z (m/s), roll, pitch, yaw (rad/s); each above 0.
    pub pose_velocity: [f32; 6],
    /// Acceleration limit per pose axis (m/s^2, rad/s^2); each above 0.
    pub pose_acceleration: [f32; 6],
    /// Velocity limit per actuator, in actuator order and its own unit: rad/s for carriages and shoulders, m/s for
    /// linear actuators; each above 0, and at most what the step generator can pulse at the axis's steps per unit.
    /// What the motor and its drive can follow without losing steps: the pose limits are the platform's, these the
    /// motors'.
    pub actuator_velocity: [f32; 6],
    /// Acceleration limit per actuator (rad/s^2, m/s^2); each above 0.
    pub actuator_acceleration: [f32; 6],
}

/// One motor (next start).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSettings {
    /// Motor steps per carriage turn (ring axes, a whole number), per metre (linear axes) or per shoulder turn
    /// (elbow chains' shoulders), 1 to 2^24.
    pub steps_per_unit: f32,
    /// The motor turns the other way round: its steps and its homing (direction, switch) are mirrored.
    #[serde(default)]
    pub reverse: bool,
}

/// Which way an axis searches for its home switch, in its actuator coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Toward {
    /// Toward larger coordinates (counter-clockwise on the ring, longer for a linear actuator).
    Plus,
    /// Toward smaller coordinates.
    Minus,
}

/// One axis's home switch and how it is searched for, in the axis's own units (rad on the ring, m for a linear
/// actuator): the controller turns them into steps with the axis's steps per unit and direction, so that changing
/// a motor keeps every homing distance and speed the same physical length.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwitchSettings {
    /// Which way the switch is.
    pub toward: Toward,
    /// Where the switch trips, relative to the axis's coordinate in the home pose (rad or m).
    pub switch: f32,
    /// Longest travel searching for it (rad or m, above 0).
    pub search: f32,
    /// Back-off before the slow approach (rad or m, above 0).
    pub backoff: f32,
    /// Search speed (rad/s or m/s, above 0).
    pub fast: f32,
    /// Final approach speed (rad/s or m/s, above 0).
    pub slow: f32,
}

/// Homing of every axis (next start).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomingSettings {
    /// The axes in the order they home (0-based actuator numbers, each once).
    pub order: [u8; 6],
    /// Per axis, in actuator order.
    pub axes: [SwitchSettings; 6],
}

/// A section of settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Settings {
    /// How setpoints are taken (live).
    Stream(StreamSettings),
    /// The control rate (next start).
    Control(ControlSettings),
    /// Pose limits (live).
    Motion(MotionSettings),
    /// Input polarity and debouncing (live).
    Inputs(InputConfig),
    /// Every motor, in actuator order (next start).
    Axes([AxisSettings; 6]),
    /// Every axis's homing (next start).
    Homing(HomingSettings),
    /// Supply sensing and sequencing delays (next start).
    Supervisor(SupervisorConfig),
    /// The spare axes 7 and 8 (next start: a board gives them the pins of its optional link and supply senses).
    Spare([SpareAxisSettings; SPARE_AXES]),
}

/// Which section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SettingsKind {
    /// [`Settings::Stream`].
    Stream,
    /// [`Settings::Control`].
    Control,
    /// [`Settings::Motion`].
    Motion,
    /// [`Settings::Inputs`].
    Inputs,
    /// [`Settings::Axes`].
    Axes,
    /// [`Settings::Homing`].
    Homing,
    /// [`Settings::Supervisor`].
    Supervisor,
    /// [`Settings::Spare`].
    Spare,
}

impl SettingsKind {
    /// Every section.
    pub const ALL: [SettingsKind; 8] = [
        Self::Stream,
        Self::Control,
        Self::Motion,
        Self::Inputs,
        Self::Axes,
        Self::Homing,
        Self::Supervisor,
        Self::Spare,
    ];

    /// Whether a new value takes effect at once (otherwise at the next start).
    pub const fn is_live(self) -> bool {
        matches!(self, Self::Stream | Self::Motion | Self::Inputs)
    }

    /// Whether the section is part of the rig record. The spare axes are stored beside it, with the stream and
    /// control sections (a rig file's `[[spare]]` entries are sent as this section after the rig).
    pub const fn in_rig(self) -> bool {
        !matches!(self, Self::Stream | Self::Control | Self::Spare)
    }

    /// The section's name: its table in a rig file and on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Stream => "stream",
            Self::Control => "control",
            Self::Motion => "motion",
            Self::Inputs => "inputs",
            Self::Axes => "axes",
            Self::Homing => "homing",
            Self::Supervisor => "supervisor",
            Self::Spare => "spare",
        }
    }
}

impl Settings {
    /// Which section this is.
    pub const fn kind(&self) -> SettingsKind {
        match self {
            Self::Stream(_) => SettingsKind::Stream,
            Self::Control(_) => SettingsKind::Control,
            Self::Motion(_) => SettingsKind::Motion,
            Self::Inputs(_) => SettingsKind::Inputs,
            Self::Axes(_) => SettingsKind::Axes,
            Self::Homing(_) => SettingsKind::Homing,
            Self::Supervisor(_) => SettingsKind::Supervisor,
            Self::Spare(_) => SettingsKind::Spare,
        }
    }
}

/// The sections that describe a machine rather than how it is fed: what a rig record carries besides its geometry.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MachineSettings {
    /// Every motor, in actuator order.
    pub axes: [AxisSettings; 6],
    /// Pose limits.
    pub motion: MotionSettings,
    /// Input polarity and debouncing.
    pub inputs: InputConfig,
    /// Supply sensing and sequencing delays.
    pub supervisor: SupervisorConfig,
    /// Every axis's homing.
    pub homing: HomingSettings,
}
