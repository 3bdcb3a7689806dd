//! Settings over the protocol: the running configuration, the stored one (what the next start runs), and the
//! changes the firmware has yet to store.

use super::{ConfigError, Controller, ControllerConfig};
use crate::protocol::{ConfigKey, DeviceMessage, NackReason, RigRecord, RigSource};
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

    /// A setting changed over the protocol that the firmware has not stored yet, with its value; each change is
    /// handed out once. Nothing is lost: a key changed twice before it is taken is stored once, with its last value.
    ///
    /// Only while the power relay and the drivers are off: writing flash can stall the CPU (a sector erase on an
    /// STM32F4 for up to 2 s), which must never happen while anything could move.
    pub fn take_unsaved(&mut self) -> Option<(ConfigKey, f32)> {
        let o = self.supervisor.outputs();
        if o.power_relay || o.driver_enable {
            return None;
        }
        while self.unsaved != 0 {
            let code = self.unsaved.trailing_zeros();
            self.unsaved &= !(1u64 << code);
            if let Some(key) = ConfigKey::from_code(code as u8) {
                if let Some(value) = self.saved.get(key) {
                    return Some((key, value));
                }
            }
        }
        None
    }

    /// Whether settings wait to be stored.
    pub fn has_unsaved(&self) -> bool {
        self.unsaved != 0
    }

    pub(super) fn get_config(&self, key: ConfigKey) -> Option<f32> {
        self.saved.get(key)
    }

    pub(super) fn set_config(&mut self, key: ConfigKey, value: f32) -> Result<(), NackReason> {
        if !matches!(self.supervisor.outputs().motion, Motion::None) {
            return Err(NackReason::Refused(crate::safety::Refusal::WrongState));
        }
        let mut saved = self.saved;
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
        saved.set(key, value).map_err(refused)?;
        saved.validate().map_err(refused)?;
        if key.is_live() {
            let mut live = self.config;
            live.set(key, value).map_err(refused)?;
            self.config = live;
            self.pipeline.set_config(live.pipeline);
        }
        self.saved = saved;
        self.unsaved |= 1u64 << key.code();
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
            pending: self.rig_pending,
        }
    }

    /// Takes a rig for the next start, after the checks that will restore it. Only in `Off`: a new geometry voids
    /// everything the platform knows.
    pub(super) fn set_rig(&mut self, record: &RigRecord) -> Result<(), NackReason> {
        if self.supervisor.state() != State::Off {
            return Err(NackReason::Refused(Refusal::WrongState));
        }
        let refused = |e: ConfigError| NackReason::BadConfig(e.refusal());
        ControllerConfig::from_record(record).map_err(refused)?;
        self.unsaved_rig = Some(*record);
        self.rig_pending = true;
        Ok(())
    }

    /// A loaded rig the firmware has not stored yet; handed out once, only with the supplies off (as
    /// [`Self::take_unsaved`]).
    pub fn take_unsaved_rig(&mut self) -> Option<RigRecord> {
        let o = self.supervisor.outputs();
        if o.power_relay || o.driver_enable {
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
