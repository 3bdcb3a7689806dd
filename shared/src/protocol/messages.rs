//! Message types. Every host request gets exactly one response with the same `id`; a device also sends
//! unsolicited messages (faults) with `id` 0.

use crate::kinematics::presets::Preset;
use crate::kinematics::Pose;

use super::rig::{RigRecord, RigSource};
use super::settings::{Settings, SettingsKind};
use super::ConfigRefusal;
use crate::motion::{LimitCounters, LimitReport, RejectCounters, RejectReason, Setpoint};
use crate::safety::{Command, FaultReason, Refusal, State};

/// Protocol version; host and device must agree exactly. 8: the motion section carries the actuator limits, the
/// operator's commands switch the auxiliary outputs and setpoints carry their levels. 9: the status counts the
/// periods the step generator played empty and the control periods passed. 10: the hello and a version mismatch
/// name the firmware ([`super::Firmware`]); the bootloader request. 11: the stream section carries the time after
/// which a host silent since its stream was lost is taken as gone (`host_gone_ms`). 12: setpoints carry the spare
/// axes' targets (`axis7`, `axis8`), the settings their section and the status their steps.
pub const PROTOCOL_VERSION: u16 = 12;

/// The supervisor state, as reported.
pub type StateCode = State;

/// A host request.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Request {
    /// Correlation id, echoed in the response.
    pub id: u32,
    /// What is asked.
    pub body: HostMessage,
}

/// What the host asks of the device.
// A rig record (about 560 bytes) makes `SetRig` the largest variant by far. No heap to box it in: a request lives on
// the stack for one dispatch, and the stream's setpoints are read without it ([`setpoint_request`]).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum HostMessage {
    /// Version handshake; must come first.
    Hello {
        /// The host's [`PROTOCOL_VERSION`].
        version: u16,
    },
    /// A command to the supervisor (enable, disable, home, start, stop, clear a fault, switch an auxiliary output):
    /// acknowledged, or refused with the supervisor's reason.
    Command(Command),
    /// A pose setpoint.
    Setpoint(Setpoint),
    /// Ask for the status.
    GetStatus,
    /// Read a section of settings: the value the next start runs ([`DeviceMessage::Settings`]).
    GetSettings(SettingsKind),
    /// Write a section of settings (not while moving): checked whole with the rest of the configuration, refused
    /// with its cause ([`NackReason::BadConfig`]); a live section takes effect at once, every section is stored.
    SetSettings(Settings),
    /// The input levels now ([`DeviceMessage::Inputs`]).
    GetInputs,
    /// Commissioning: move one axis (0-5) by a step count at its slow homing rate, the others holding; stops at
    /// the axis's home switch (an end switch latches its fault). Powered and settled, or Ready; homing is void
    /// afterwards. At most the homing back-off for a carriage, the homing search travel for a linear axis.
    Jog {
        /// Axis, 0-5.
        axis: u8,
        /// Signed steps.
        steps: i32,
    },
    /// Commissioning: ten short back-and-forth moves of one axis at its fast homing rate (half its homing back-off
    /// each way), as Klipper's STEPPER_BUZZ: a motor that hums but does not move, or moves one way only, shows.
    Buzz {
        /// Axis, 0-5.
        axis: u8,
    },
    /// Send telemetry on this connection (`true`) at the stream settings' `telemetry_hz`, or stop (`false`). Every Hello
    /// starts a connection without it: a host that only commands gets only answers.
    Telemetry(bool),
    /// The rig it runs ([`DeviceMessage::Rig`]).
    GetRig,
    /// Store this rig for the next start (state `Off` only): checked by the same code that restores it, refused
    /// with its cause ([`NackReason::BadConfig`]); [`HostMessage::Restart`] then runs it.
    SetRig(RigRecord),
    /// Restart the controller once every setting and rig is stored (state `Off` only): a board resets its MCU.
    Restart,
    /// Restart into the MCU's ROM bootloader (USB DFU) once every setting and rig is stored, to be flashed (state
    /// `Off` only: supplies and drivers off). Taken without a handshake, at its fixed tag
    /// ([`super::firmware::BOOTLOADER_TAG`]), so that a host of any protocol version can update the board. The
    /// simulated controller has no bootloader: it restarts.
    EnterBootloader,
}

/// The position of [`HostMessage::Setpoint`] among the variants: its tag on the wire.
const SETPOINT_TAG: u32 = 2;

/// A setpoint request read straight from its payload, `(id, setpoint)`, or `None` for any other request. The
/// stream's hot path: a [`Request`] holds room for the largest request (a rig record, over 600 bytes), which a
/// setpoint of 40 bytes need not be decoded into and moved through.
pub fn setpoint_request(payload: &[u8]) -> Option<(u32, Setpoint)> {
    let (id, rest) = postcard::take_from_bytes::<u32>(payload).ok()?;
    let (tag, rest) = postcard::take_from_bytes::<u32>(rest).ok()?;
    if tag != SETPOINT_TAG {
        return None;
    }
    match postcard::take_from_bytes::<Setpoint>(rest) {
        Ok((setpoint, [])) => Some((id, setpoint)),
        _ => None,
    }
}

/// A device message: the response to request `id`, or unsolicited with `id` 0.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Response {
    /// The request's id, or 0.
    pub id: u32,
    /// The message.
    pub body: DeviceMessage,
}

/// What the device says.
// `Rig` carries a rig record (about 560 bytes), the largest variant by far; as with `HostMessage`, no heap to box it.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum DeviceMessage {
    /// Handshake answer.
    Hello {
        /// The device's [`PROTOCOL_VERSION`].
        version: u16,
        /// The firmware it runs.
        firmware: super::Firmware,
        /// The preset it drives, if its geometry is one.
        preset: Option<Preset>,
        /// What each of its actuator coordinates measures.
        axes: [crate::kinematics::AxisKind; 6],
    },
    /// Done.
    Ack,
    /// The setpoint was taken, limited into the envelope: by which check and how much.
    Limited(LimitReport),
    /// Not done, and why.
    Nack(NackReason),
    /// Status and telemetry.
    Status(Status),
    /// A section of settings as the next start runs it.
    Settings {
        /// The section.
        settings: Settings,
        /// It differs from what runs now (a section that takes effect at the next start was changed).
        pending: bool,
    },
    /// A fault was latched (unsolicited).
    Fault(FaultReason),
    /// Every input's electrical level and its debounced state.
    Inputs(InputReport),
    /// What the device is doing (unsolicited, at the stream settings' `telemetry_hz` while the host asks for it).
    Telemetry(Telemetry),
    /// The rig it runs, where that came from, and whether another one is stored for the next start.
    Rig {
        /// The rig running now.
        rig: RigRecord,
        /// Where it came from.
        source: RigSource,
        /// A rig loaded since the start waits for a restart.
        pending: bool,
    },
}

/// Telemetry: one sample of the device's state, sent unsolicited (id 0).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Telemetry {
    /// Device time since the controller started (us, control ticks times their period).
    pub time_us: u64,
    /// Supervisor state.
    pub state: StateCode,
    /// Commanded pose (where the platform is being driven now).
    pub pose: Pose<f32>,
    /// Where it is heading: the last accepted setpoint as limited.
    pub target: Pose<f32>,
    /// Step position of every axis.
    pub steps: [i64; 6],
    /// What happened since the previous sample ([`TelemetryFlags`] bits).
    pub flags: u8,
    /// Setpoints accepted so far (limited ones included).
    pub applied: u32,
    /// Setpoints limited into the envelope so far.
    pub limited: u32,
    /// Setpoints refused so far (every reason).
    pub refused: u32,
    /// Cost of the last control tick (CPU cycles on the MCU, ns in the simulator).
    pub tick_cost: u32,
    /// Every input after debouncing and polarity, a bit per `safety::debounce::InputBit` (1: active).
    pub inputs: u16,
    /// The outputs: bit 0 LOGIC_EN relay, bit 1 POWER_EN relay, bit 2 driver enable, bit 3 AUX1, bit 4 AUX2.
    pub outputs: u8,
}

impl core::fmt::Display for NackReason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::VersionMismatch { device, .. } => write!(f, "the device speaks protocol version {device}"),
            Self::NotConnected => f.write_str("no handshake yet"),
            Self::Refused(r) => write!(f, "refused: {r}"),
            Self::Rejected(r) => write!(f, "setpoint rejected: {r}"),
            Self::BadConfig(r) => write!(f, "setting refused (BadConfig): {r}"),
            Self::OutOfRange => f.write_str("an argument is out of range (OutOfRange)"),
            Self::Malformed => f.write_str("the frame could not be decoded"),
        }
    }
}

/// Every input, a bit per `safety::debounce::InputBit`: what a person wiring a board checks switch by switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct InputReport {
    /// Electrical level of each pin (1: high), as last sampled.
    pub raw: u16,
    /// Whether `raw` was sampled from the pins (a board), or derived from the debounced state and the polarity (a
    /// simulated machine, which has no pins).
    pub sampled: bool,
    /// Debounced and polarity-corrected state (1: active: switch made, e-stop open, supply good).
    pub active: u16,
    /// The polarity setting: inputs active when low.
    pub active_low: u16,
    /// Equal samples needed before a level counts (ms).
    pub debounce_ms: u8,
}

/// Bits of [`Telemetry::flags`].
pub struct TelemetryFlags;

impl TelemetryFlags {
    /// A setpoint was limited into the envelope since the previous sample.
    pub const LIMITED: u8 = 1;
    /// A setpoint was refused since the previous sample.
    pub const REFUSED: u8 = 2;
    /// The path failed a check and the platform held since the previous sample.
    pub const HELD: u8 = 4;
}

/// Why a request was not carried out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum NackReason {
    /// The versions differ; the device's is given, and its firmware.
    VersionMismatch {
        /// The device's version.
        device: u16,
        /// The firmware it runs: always there from a device of this version; `None` where a host read the answer
        /// of a device of protocol 9 or older, which did not name it ([`super::firmware::version_mismatch`]).
        firmware: Option<super::Firmware>,
    },
    /// No successful hello yet.
    NotConnected,
    /// The supervisor refused the command.
    Refused(Refusal),
    /// The setpoint was rejected.
    Rejected(RejectReason),
    /// The setting was not taken, and why.
    BadConfig(ConfigRefusal),
    /// A command's argument is out of its range (an axis that does not exist, a jog too long).
    OutOfRange,
    /// The frame could not be decoded (id unknown, so the response has id 0).
    Malformed,
}

/// Status and telemetry.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Status {
    /// Supervisor state.
    pub state: StateCode,
    /// Whether the axes are homed.
    pub homed: bool,
    /// The auxiliary outputs that are on: bit 0 AUX1, bit 1 AUX2.
    pub aux: u8,
    /// Step position of every axis.
    pub steps: [i64; 6],
    /// Commanded pose.
    pub pose: Pose<f32>,
    /// Where the commanded pose is heading: the last accepted setpoint as limited (the commanded pose itself
    /// outside streaming).
    pub target: Pose<f32>,
    /// Setpoints accepted (limited ones included).
    pub applied: u32,
    /// Setpoints limited into the envelope.
    pub limited: LimitCounters,
    /// Setpoints rejected, per reason.
    pub rejected: RejectCounters,
    /// Ticks on which the path failed a check and the platform held.
    pub held: u32,
    /// Periods in which an axis had to carry steps over.
    pub carried: u32,
    /// Frames that failed to decode.
    pub bad_frames: u32,
    /// Cost of the last control tick (CPU cycles on the MCU, ns in the simulator).
    pub tick_cost: u32,
    /// Step-queue depth of the pulse generator.
    pub queue_depth: u16,
    /// Periods the step generator played without moves because the queue was empty: a tick that came late (the
    /// axes paused for a period, no step lost).
    pub idle_periods: u32,
    /// Control periods passed rather than ticked because a period was still queued: the catch-up after a hold-up
    /// of the control loop (the clocks ran on, the motion resumed a period later).
    pub passed_periods: u32,
    /// Step position of the spare axes 7 and 8 (0 when not fitted).
    pub spare_steps: [i64; 2],
}
