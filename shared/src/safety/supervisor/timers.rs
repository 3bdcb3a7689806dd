//! Time: the settle delays, the supply timeout and the shutdown sequence's waits, advanced by `Event::Elapsed`.

use super::{FaultReason, Shutdown, State, Supervisor};

impl Supervisor {
    /// Advances the state's timer by `ms` (saturating at the configuration's cap) and takes the timed transition
    /// that is due, if any.
    pub(super) fn elapse(&mut self, ms: u32) {
        self.timer_ms = self.timer_ms.saturating_add(ms).min(self.config.timer_cap());
        let c = self.config;
        let t = self.timer_ms;
        match self.state {
            State::LogicOn => {
                let up = self.inputs.logic_ok || !c.logic_sense;
                if up && t >= c.logic_settle_ms {
                    self.go(State::PowerOn { settled: false });
                } else if !up && t >= c.supply_timeout_ms {
                    self.fault(FaultReason::SupplyTimeout);
                }
            }
            State::PowerOn { settled: false } => {
                let up = self.inputs.power_ok || !c.power_sense;
                if up && t >= c.power_settle_ms {
                    self.go(State::PowerOn { settled: true });
                } else if !up && t >= c.supply_timeout_ms {
                    self.fault(FaultReason::SupplyTimeout);
                }
            }
            State::ShuttingDown(Shutdown::Drivers) if t >= c.driver_off_ms => {
                self.go(State::ShuttingDown(Shutdown::Discharge));
            }
            State::ShuttingDown(Shutdown::Discharge) if t >= c.discharge_ms => self.go(State::Off),
            _ => {}
        }
    }
}
