//! What the supervisor drives: its [`Outputs`] for each state (relays, driver enable, what may move, the
//! auxiliary outputs), and the two transitions every other one goes through, so the relay sequencing and the
//! outputs' switching off live in one place: `go` (the one place a state changes) and `fault` (which supplies a
//! latched fault keeps).

use super::{FaultReason, Shutdown, State, Supervisor, Supplies};

/// What the supervisor lets the motion pipeline do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Motion {
    /// Nothing moves.
    None,
    /// Only the homing sequence moves axes.
    Homing,
    /// The pose stream (and its stopping ramp) moves the platform.
    Stream,
    /// One axis jogs or buzzes (commissioning).
    Jog,
}

/// The supervisor's outputs: relays, driver enable, and what may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Outputs {
    /// LOGIC_EN relay.
    pub logic_relay: bool,
    /// POWER_EN relay.
    pub power_relay: bool,
    /// Stepper driver enable.
    pub driver_enable: bool,
    /// What may move.
    pub motion: Motion,
    /// The auxiliary outputs: bit 0 AUX1, bit 1 AUX2 (`Aux::bit`).
    pub aux: u8,
}

impl Outputs {
    /// Everything off.
    pub const OFF: Outputs = Outputs {
        logic_relay: false,
        power_relay: false,
        driver_enable: false,
        motion: Motion::None,
        aux: 0,
    };
}

/// The states an auxiliary output may stay on in: homed, drivers enabled, holding, streaming or braking.
fn keeps_aux(state: State) -> bool {
    matches!(state, State::Ready | State::Running | State::Stopping)
}

impl Supervisor {
    /// Outputs of the current state.
    pub fn outputs(&self) -> Outputs {
        let (logic, power, enable, motion) = match self.state {
            State::Off => (false, false, false, Motion::None),
            State::LogicOn => (true, false, false, Motion::None),
            State::PowerOn { .. } | State::ShuttingDown(Shutdown::Drivers) => (true, true, false, Motion::None),
            State::Homing => (true, true, true, Motion::Homing),
            State::Jogging => (true, true, true, Motion::Jog),
            State::Ready => (true, true, true, Motion::None),
            State::Running | State::Stopping => (true, true, true, Motion::Stream),
            State::Fault(_, supplies) => (
                supplies != Supplies::None,
                supplies == Supplies::Both,
                false,
                Motion::None,
            ),
            State::ShuttingDown(Shutdown::Discharge) => (true, false, false, Motion::None),
        };
        Outputs {
            logic_relay: logic,
            power_relay: power,
            driver_enable: enable,
            motion,
            aux: self.aux,
        }
    }

    /// Which auxiliary outputs are on (`Aux::bit`).
    pub fn aux(&self) -> u8 {
        self.aux
    }

    /// Enters `state` (its timer restarts unless it is the same state) and switches the auxiliary outputs off
    /// where it does not keep them.
    pub(super) fn go(&mut self, state: State) {
        if state != self.state {
            self.state = state;
            self.timer_ms = 0;
        }
        // The one place a state changes: whatever leads out of the states that keep them, the outputs go off.
        if !keeps_aux(state) {
            self.aux = 0;
        }
    }

    /// Latches a fault, keeping only the supplies that are safe to keep for that reason.
    pub(super) fn fault(&mut self, reason: FaultReason) {
        let out = self.outputs();
        let supplies = match reason {
            // Losing the e-stop chain, a supply or the MCU's health removes power; logic stays as it was.
            FaultReason::EStop
            | FaultReason::LogicLost
            | FaultReason::PowerLost
            | FaultReason::SupplyTimeout
            | FaultReason::Watchdog => {
                if out.logic_relay {
                    Supplies::Logic
                } else {
                    Supplies::None
                }
            }
            // Motion faults keep the supplies: the drivers are disabled, nothing else needs to drop.
            FaultReason::Limit(_) | FaultReason::HomingFailed | FaultReason::MotionFault => {
                match (out.logic_relay, out.power_relay) {
                    (true, true) => Supplies::Both,
                    (true, false) => Supplies::Logic,
                    _ => Supplies::None,
                }
            }
        };
        self.homed = false;
        self.go(State::Fault(reason, supplies));
    }
}
