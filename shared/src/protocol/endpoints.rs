//! Which answer each request gets, as types: an [`Endpoint`] is a request that knows the value its answer carries,
//! so a client asks `call(GetStatus)` and gets a [`Status`] or an error, instead of matching on every
//! [`DeviceMessage`] at every call site. The table below is the whole set of request/answer pairs; a
//! [`DeviceMessage::Nack`] is the same refusal for all of them and is left to the client. (postcard-rpc's
//! `endpoints!` table is the model; the frames stay ringpod's, so a board needs nothing new.)
//!
//! | request | answer |
//! |---|---|
//! | [`HostMessage::Hello`] | [`Hello`]'s [`DeviceHello`] (any version: the client compares) |
//! | [`HostMessage::Command`], `SetSettings`, `SetRig`, `Restart`, `EnterBootloader`, `Telemetry`, `Jog`, `Buzz` | `Ack`: `()` |
//! | [`HostMessage::GetStatus`] | [`Status`] |
//! | [`HostMessage::GetInputs`] | [`InputReport`] |
//! | [`HostMessage::GetSettings`] | [`SettingsAnswer`] (the section asked for, and whether one waits) |
//! | [`HostMessage::GetRig`] | [`RigAnswer`] |
//!
//! Setpoints are not here: their answer is `Ack`, `Limited` or a refusal with its reason, taken apart by the
//! streaming code itself.

use super::{
    DeviceMessage, Firmware, HostMessage, InputReport, RigRecord, RigSource, Settings, SettingsKind, Status,
    PROTOCOL_VERSION,
};
use crate::kinematics::presets::Preset;
use crate::kinematics::AxisKind;
use crate::safety::Command;

/// A request whose answer carries an [`Endpoint::Answer`].
// A wrong answer comes back whole so that the caller can name it (a `Nack`'s reason, or what came instead): it is
// the message just received, moved, not a copy kept anywhere.
#[allow(clippy::result_large_err)]
pub trait Endpoint {
    /// What a right answer carries.
    type Answer;
    /// The request as sent.
    fn request(&self) -> HostMessage;
    /// The answer's value, or the message back when it is not this request's answer (a `Nack` included).
    fn answer(&self, message: DeviceMessage) -> Result<Self::Answer, DeviceMessage>;
}

/// An endpoint answered by a plain `Ack`, its request built by `$request` from `$e` (the endpoint).
macro_rules! acked {
    ($($name:ident: |$e:ident| $request:expr;)*) => {$(
        impl Endpoint for $name {
            type Answer = ();
            fn request(&self) -> HostMessage {
                let $e = self;
                $request
            }
            fn answer(&self, message: DeviceMessage) -> Result<(), DeviceMessage> {
                match message {
                    DeviceMessage::Ack => Ok(()),
                    other => Err(other),
                }
            }
        }
    )*};
}

/// One of the supervisor's commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Do(pub Command);

/// Changes a section of settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetSettings(pub Settings);

/// Stores a rig for the next start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetRig(pub RigRecord);

/// Restarts the controller once everything is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Restart;

/// Restarts into the MCU's ROM bootloader once everything is stored (taken without a handshake).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EnterBootloader;

/// Turns the telemetry stream on or off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TelemetryOn(pub bool);

/// A commissioning move of one axis (0-5) by whole steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Jog {
    /// The axis.
    pub axis: u8,
    /// Motor steps, signed.
    pub steps: i32,
}

/// Short moves back and forth of one axis (0-5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Buzz(pub u8);

acked! {
    Do: |e| HostMessage::Command(e.0);
    SetSettings: |e| HostMessage::SetSettings(e.0);
    SetRig: |e| HostMessage::SetRig(e.0);
    Restart: |_e| HostMessage::Restart;
    EnterBootloader: |_e| HostMessage::EnterBootloader;
    TelemetryOn: |e| HostMessage::Telemetry(e.0);
    Jog: |e| HostMessage::Jog { axis: e.axis, steps: e.steps };
    Buzz: |e| HostMessage::Buzz { axis: e.0 };
}

/// The handshake, at this side's [`PROTOCOL_VERSION`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hello;

/// What a device says of itself in the handshake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceHello {
    /// Its protocol version.
    pub version: u16,
    /// The firmware it runs.
    pub firmware: Firmware,
    /// The preset it drives, if its geometry is one.
    pub preset: Option<Preset>,
    /// What each actuator coordinate measures.
    pub axes: [AxisKind; 6],
}

impl Endpoint for Hello {
    type Answer = DeviceHello;
    fn request(&self) -> HostMessage {
        HostMessage::Hello {
            version: PROTOCOL_VERSION,
        }
    }
    fn answer(&self, message: DeviceMessage) -> Result<DeviceHello, DeviceMessage> {
        match message {
            DeviceMessage::Hello {
                version,
                firmware,
                preset,
                axes,
            } => Ok(DeviceHello {
                version,
                firmware,
                preset,
                axes,
            }),
            other => Err(other),
        }
    }
}

/// The device's status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GetStatus;

impl Endpoint for GetStatus {
    type Answer = Status;
    fn request(&self) -> HostMessage {
        HostMessage::GetStatus
    }
    fn answer(&self, message: DeviceMessage) -> Result<Status, DeviceMessage> {
        match message {
            DeviceMessage::Status(status) => Ok(status),
            other => Err(other),
        }
    }
}

/// Every input's level and debounced state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GetInputs;

impl Endpoint for GetInputs {
    type Answer = InputReport;
    fn request(&self) -> HostMessage {
        HostMessage::GetInputs
    }
    fn answer(&self, message: DeviceMessage) -> Result<InputReport, DeviceMessage> {
        match message {
            DeviceMessage::Inputs(report) => Ok(report),
            other => Err(other),
        }
    }
}

/// A section of settings as the next start runs it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GetSettings(pub SettingsKind);

/// A section of settings and whether it differs from what runs now (it takes effect at the next start).
#[derive(Debug, Clone, PartialEq)]
pub struct SettingsAnswer {
    /// The section.
    pub settings: Settings,
    /// It waits for the next start.
    pub pending: bool,
}

impl Endpoint for GetSettings {
    type Answer = SettingsAnswer;
    fn request(&self) -> HostMessage {
        HostMessage::GetSettings(self.0)
    }
    fn answer(&self, message: DeviceMessage) -> Result<SettingsAnswer, DeviceMessage> {
        match message {
            // Another section than the one asked for is not this answer.
            DeviceMessage::Settings { settings, pending } if settings.kind() == self.0 => {
                Ok(SettingsAnswer { settings, pending })
            }
            other => Err(other),
        }
    }
}

/// The rig the device runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GetRig;

/// The rig a device runs, where it came from, and whether another waits for the next start.
#[derive(Debug, Clone, PartialEq)]
pub struct RigAnswer {
    /// The rig.
    pub rig: RigRecord,
    /// Where it came from.
    pub source: RigSource,
    /// Another rig is stored for the next start.
    pub pending: bool,
}

impl Endpoint for GetRig {
    type Answer = RigAnswer;
    fn request(&self) -> HostMessage {
        HostMessage::GetRig
    }
    fn answer(&self, message: DeviceMessage) -> Result<RigAnswer, DeviceMessage> {
        match message {
            DeviceMessage::Rig { rig, source, pending } => Ok(RigAnswer { rig, source, pending }),
            other => Err(other),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::NackReason;

    #[test]
    fn each_request_takes_its_own_answer_only() -> Result<(), crate::controller::ConfigError> {
        let config = crate::controller::ControllerConfig::trainer_model();
        let status = crate::controller::Controller::new(config)?.status();
        assert_eq!(GetStatus.answer(DeviceMessage::Status(status)), Ok(status));
        assert_eq!(Do(Command::Home).request(), HostMessage::Command(Command::Home));
        assert_eq!(Do(Command::Home).answer(DeviceMessage::Ack), Ok(()));
        assert_eq!(
            Jog { axis: 2, steps: -40 }.request(),
            HostMessage::Jog { axis: 2, steps: -40 }
        );
        // The section asked for, not another.
        let stream = config.settings(SettingsKind::Stream);
        let answer = |settings| DeviceMessage::Settings {
            settings,
            pending: true,
        };
        assert_eq!(
            GetSettings(SettingsKind::Stream).answer(answer(stream)),
            Ok(SettingsAnswer {
                settings: stream,
                pending: true
            })
        );
        let motion = config.settings(SettingsKind::Motion);
        assert_eq!(
            GetSettings(SettingsKind::Stream).answer(answer(motion)),
            Err(answer(motion))
        );
        // A refusal and an answer of another kind come back for the client to name.
        let nack = DeviceMessage::Nack(NackReason::NotConnected);
        assert_eq!(GetStatus.answer(nack), Err(nack));
        assert_eq!(
            Do(Command::Start).answer(DeviceMessage::Status(status)),
            Err(DeviceMessage::Status(status))
        );
        assert_eq!(GetInputs.answer(DeviceMessage::Ack), Err(DeviceMessage::Ack));
        assert_eq!(GetRig.answer(nack), Err(nack));
        assert_eq!(Hello.answer(DeviceMessage::Ack), Err(DeviceMessage::Ack));
        Ok(())
    }
}
