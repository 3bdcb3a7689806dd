//! Supply sequencing: the [`SupervisorConfig`] a rig's `[supervisor]` section gives, its checks, and the cap that
//! keeps the supervisor's timer (and so its state space) finite.

/// Supply sequencing and sensing. A rig file's `[supervisor]` section is this type, by its field names (an unknown
/// key is an error there; postcard, which has no names, is not affected).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupervisorConfig {
    /// The board has a LOGIC_OK input; without it, timing alone sequences.
    pub logic_sense: bool,
    /// The board has a POWER_OK input.
    pub power_sense: bool,
    /// Wait after the logic relay closes (and LOGIC_OK, if sensed) before the power relay may close (ms).
    pub logic_settle_ms: u32,
    /// Wait after the power relay closes (and POWER_OK, if sensed) before the drivers may be enabled (ms).
    pub power_settle_ms: u32,
    /// A sensed supply that is not up this long after its relay closed is a fault (ms).
    pub supply_timeout_ms: u32,
    /// Drivers disabled this long before the power relay opens on shutdown (ms).
    pub driver_off_ms: u32,
    /// Power supply discharge time before the logic relay opens on shutdown (ms).
    pub discharge_ms: u32,
}

impl Default for SupervisorConfig {
    fn default() -> Self {
        Self {
            logic_sense: true,
            power_sense: true,
            logic_settle_ms: 100,
            power_settle_ms: 200,
            supply_timeout_ms: 1000,
            driver_off_ms: 20,
            discharge_ms: 500,
        }
    }
}

impl SupervisorConfig {
    /// Longest delay a configuration may set (ms): a supply that takes longer to come up or discharge is not one
    /// this controller should sequence blind.
    pub const LONGEST_MS: u32 = 60_000;

    /// Every delay at most [`Self::LONGEST_MS`], and a sensed supply given time to come up.
    pub fn is_valid(&self) -> bool {
        let delays = [
            self.logic_settle_ms,
            self.power_settle_ms,
            self.supply_timeout_ms,
            self.driver_off_ms,
            self.discharge_ms,
        ];
        delays.iter().all(|d| *d <= Self::LONGEST_MS)
            && (self.supply_timeout_ms > 0 || !(self.logic_sense || self.power_sense))
    }

    /// The timer's saturation point: just past the longest configured delay, so every timed transition is still
    /// reached and the enumeration in the tests sees finitely many timer values.
    pub(super) fn timer_cap(&self) -> u32 {
        let longest = self
            .logic_settle_ms
            .max(self.power_settle_ms)
            .max(self.supply_timeout_ms);
        longest.max(self.driver_off_ms).max(self.discharge_ms).saturating_add(1)
    }
}
