//! The wire protocol between host and controller: one definition for both sides.
//!
//! Messages are serde types encoded with postcard; a frame is `COBS(postcard(message) ++ CRC-32C(payload))`
//! followed by a `0x00` delimiter. CRC-32 rather than CRC-16: a fuzz run feeds tens of millions of corrupted
//! frames, and a 16-bit check would let about one in 65,536 random corruptions through. The first exchange is
//! [`HostMessage::Hello`] with [`PROTOCOL_VERSION`]; a device answers any other request before a matching hello with
//! [`NackReason::NotConnected`], and a different version with [`NackReason::VersionMismatch`] naming its firmware.
//! What every version keeps in its place, so that a host names a board of any version and can update it, is in
//! [`firmware`].

pub mod endpoints;
mod field;
pub mod firmware;
mod frame;
mod messages;
mod rig;
mod settings;
pub(crate) mod wire;

pub use field::{ConfigRefusal, Field, FieldName};
pub use firmware::{Firmware, Image};
pub use frame::{decode, encode, parse, unframe, FrameError, FrameReader, MAX_FRAME, MAX_PAYLOAD};
pub use messages::{
    setpoint_request, DeviceMessage, HostMessage, InputReport, NackReason, Request, Response, StateCode, Status,
    Telemetry, TelemetryFlags, PROTOCOL_VERSION,
};
pub use rig::{RigRecord, RigSource, RIG_NAME_LEN};
pub use settings::{
    AxisSettings, ControlSettings, HomingSettings, MachineSettings, MotionSettings, Settings, SettingsKind,
    StreamSettings, SwitchSettings, Toward,
};
