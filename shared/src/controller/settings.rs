//! Settings over the protocol: the running configuration, the stored one (what the next start runs), and the
//! sections and rig the firmware has yet to store.

use super::{ConfigError, Controller, ControllerConfig};
use crate::protocol::{DeviceMessage, NackReason, RigRecord, RigSource, Settings, SettingsKind};
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

    /// A section stored on its own (one a rig does not carry) changed over the protocol that the firmware has not
    /// stored yet, as the next start is to run it; each change is handed out once. Nothing is lost: a section
    /// changed twice before it is taken is stored once, with its last value. Changes to the sections a rig carries
    /// are handed out as the whole rig ([`Self::take_unsaved_rig`]).
    ///
    /// Only while the power relay and the drivers are off: writing flash can stall the CPU (a sector erase on an
    /// STM32F4 for up to 2 s), which must never happen while anything could move.
    pub fn take_unsaved(&mut self) -> Option<Settings> {
        if self.moving_possible() {
            return None;
        }
        let kind = SettingsKind::ALL
            .into_iter()
            .find(|k| self.unsaved & (1 << k.code()) != 0)?;
        self.unsaved &= !(1 << kind.code());
        Some(self.saved.settings(kind))
    }

    /// Whether settings or a rig wait to be stored.
    pub fn has_unsaved(&self) -> bool {
        self.unsaved != 0 || self.unsaved_rig.is_some()
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
    /// section changes the running configuration too. Every change is stored: a section a rig carries as part of
    /// the stored rig.
    pub(super) fn set_settings(&mut self, settings: &Settings) -> Result<(), NackReason> {
        if !matches!(self.supervisor.outputs().motion, Motion::None) {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
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
        if kind.in_rig() {
            self.unsaved_rig = Some(saved.rig());
        } else {
            self.unsaved |= 1 << kind.code();
        }
        Ok(())
    }

    /// The board says where the running rig came from (at boot, from what its settings store restored).
    pub fn set_rig_source(&mut self, source: RigSource) {
        self.rig_source = source;
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
            if kept.apply(&self.saved.settings(kind)).is_ok() && kept.validate().is_ok() {
                saved = kept;
            } else {
                // The new rig runs this section's defaults: stored, so that flash says what runs.
                self.unsaved |= 1 << kind.code();
            }
        }
        self.saved = saved;
        self.unsaved_rig = Some(*record);
        Ok(())
    }

    /// A loaded or changed rig the firmware has not stored yet; handed out once, only with the supplies off (as
    /// [`Self::take_unsaved`]).
    pub fn take_unsaved_rig(&mut self) -> Option<RigRecord> {
        if self.moving_possible() {
            return None;
        }
        self.unsaved_rig.take()
    }

    /// Asks for a restart (only in `Off`): the firmware restarts once everything is stored.
    pub(super) fn request_restart(&mut self) -> Result<(), NackReason> {
        if self.supervisor.state() != State::Off {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        self.restart = true;
        Ok(())
    }

    /// The host asked for a restart and every setting and rig is stored: the board resets now.
    pub fn restart_due(&self) -> bool {
        self.restart && self.unsaved == 0 && self.unsaved_rig.is_none() && self.supervisor.state() == State::Off
    }
}
