//! Settings over the protocol: the running configuration, the stored one (what the next start runs), and the
//! changes the firmware has yet to store.

use super::{ConfigError, Controller, ControllerConfig};
use crate::protocol::{ConfigKey, NackReason};
use crate::safety::Motion;

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
}
