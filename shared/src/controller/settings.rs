//! Settings over the protocol: the running configuration, the stored one (what the next start runs), and the
//! changes the firmware has yet to store.

use super::{ConfigError, Controller, ControllerConfig};
use crate::motion::{SpareAxisSettings, SPARE_AXES};
use crate::protocol::{
    ConfigRefusal, DeviceMessage, Firmware, NackReason, RigRecord, RigSource, Settings, SettingsKind,
};
use crate::safety::{Motion, Refusal, State};

impl Controller {
    /// The configuration running now.
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// The configuration as stored (what the next start runs).
    pub fn saved_config(&self) -> &ControllerConfig {
        &self.saved
    }

    /// The configuration the next start is to run, when it changed since it was last handed out (a section set,
    /// a rig loaded): the firmware stores it as one record. Nothing is lost: changes made before it is taken are
    /// in it, and a change made after is handed out again.
    ///
    /// Only while the power relay and the drivers are off: writing flash can stall the CPU (a sector erase on an
    /// STM32F4 for up to 2 s), which must never happen while anything could move.
    pub fn take_unsaved(&mut self) -> Option<ControllerConfig> {
        if self.moving_possible() || !self.unsaved {
            return None;
        }
        self.unsaved = false;
        Some(self.saved)
    }

    /// Whether a change waits to be stored.
    pub fn has_unsaved(&self) -> bool {
        self.unsaved
    }

    /// The power relay or the drivers are on: flash must not be written.
    fn moving_possible(&self) -> bool {
        let o = self.supervisor.outputs();
        o.power_relay || o.driver_enable
    }

    /// A section as the next start runs it, and whether that differs from what runs now.
    pub(super) fn settings_report(&self, kind: SettingsKind) -> DeviceMessage {
        let settings = self.saved.settings(kind);
        DeviceMessage::Settings {
            settings,
            pending: settings != self.config.settings(kind),
        }
    }

    /// Changes a section (not while anything moves): checked whole with the configuration it joins; a live
    /// section changes the running configuration too. Every change is stored.
    pub(super) fn set_settings(&mut self, settings: &Settings) -> Result<(), NackReason> {
        if !matches!(self.supervisor.outputs().motion, Motion::None) {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
        if let Settings::Spare(axes) = settings {
            if !self.spare_outputs && axes.iter().any(|a| a.enabled) {
                return Err(NackReason::BadConfig(ConfigRefusal::NoSpareOutputs));
            }
        }
        let mut saved = self.saved;
        saved.apply(settings).map_err(refused)?;
        saved.validate().map_err(refused)?;
        let kind = settings.kind();
        if kind.is_live() {
            let mut live = self.config;
            live.apply(settings).map_err(refused)?;
            live.validate().map_err(refused)?;
            self.config = live;
            self.pipeline.set_config(live.pipeline);
        }
        self.saved = saved;
        self.unsaved = true;
        Ok(())
    }

    /// The board says where the running rig came from (at boot, from what its settings store restored).
    pub fn set_rig_source(&mut self, source: RigSource) {
        self.rig_source = source;
    }

    /// The board says it drives no spare axes (at boot): a section that fits one is refused
    /// ([`ConfigRefusal::NoSpareOutputs`]), and a stored one that fits one runs with none fitted, so that no step
    /// is counted that no motor makes.
    pub fn no_spare_outputs(&mut self) {
        self.spare_outputs = false;
        let none = [SpareAxisSettings::NONE; SPARE_AXES];
        self.config.pipeline.spare = none;
        self.saved.pipeline.spare = none;
        self.pipeline.set_config(self.config.pipeline);
    }

    /// The board says which firmware it runs (at boot, with the image it checksummed in its flash).
    pub fn set_firmware(&mut self, firmware: Firmware) {
        self.firmware = firmware;
    }

    /// The firmware it runs, as the hello says.
    pub fn firmware(&self) -> Firmware {
        self.firmware
    }

    /// The running rig, where it came from, and whether another waits for the next start.
    pub fn rig_report(&self) -> DeviceMessage {
        DeviceMessage::Rig {
            rig: self.config.rig(),
            source: self.rig_source,
            pending: self.saved.rig() != self.config.rig(),
        }
    }

    /// Takes a rig for the next start, after the checks that will restore it, keeping the sections a rig does not
    /// carry (stream, control) where the new rig can run with them. Only in `Off`: a new geometry voids everything
    /// the platform knows.
    pub(super) fn set_rig(&mut self, record: &RigRecord) -> Result<(), NackReason> {
        if self.supervisor.state() != State::Off {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
        let mut saved = ControllerConfig::from_record(record).map_err(refused)?;
        for kind in SettingsKind::ALL.into_iter().filter(|k| !k.in_rig()) {
            let mut kept = saved;
            // A section the new rig cannot run with takes its default.
            if kept.apply(&self.saved.settings(kind)).is_ok() && kept.validate().is_ok() {
                saved = kept;
            }
        }
        self.saved = saved;
        self.unsaved = true;
        Ok(())
    }

    /// Asks for a restart into `into` (only in `Off`: supplies and drivers off, nothing moves): the firmware
    /// restarts once everything is stored.
    pub(super) fn request_restart(&mut self, into: Restart) -> Result<(), NackReason> {
        if self.supervisor.state() != State::Off {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        self.restart = Some(into);
        Ok(())
    }

    /// The host asked for a restart and every setting and rig is stored: the board resets now, into what it says.
    pub fn restart_due(&self) -> Option<Restart> {
        self.restart
            .filter(|_| !self.unsaved && self.supervisor.state() == State::Off)
    }
}

/// What a restart the host asked for starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Restart {
    /// The controller again, the stored settings and rig restored ([`crate::protocol::HostMessage::Restart`]).
    Controller,
    /// The MCU's ROM bootloader, to be flashed ([`crate::protocol::HostMessage::EnterBootloader`]).
    Bootloader,
}
