//! The order in which a board writes its output pins. A tick's outputs change up to three pins (driver enable,
//! LOGIC_EN, POWER_EN), one write at a time: between two writes the machine is in an intermediate state, which
//! must keep the interlocks too: never power without logic, never drivers enabled without power.

use super::Outputs;

/// An output pin the supervisor drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OutputPin {
    /// Stepper driver enable (`true`: enabled; the pin's electrical polarity is the board's business).
    DriverEnable,
    /// LOGIC_EN relay (`true`: closed).
    LogicRelay,
    /// POWER_EN relay (`true`: closed).
    PowerRelay,
}

/// The writes that take the pins from any state that keeps the interlocks to `target`, in an order every
/// intermediate state of which keeps them too: drivers disabled first (before power can drop), logic closed before
/// power and opened after it, drivers enabled last (after power is there).
pub fn writes(target: &Outputs) -> [(OutputPin, bool); 3] {
    let supplies = if target.logic_relay {
        [
            (OutputPin::LogicRelay, true),
            (OutputPin::PowerRelay, target.power_relay),
        ]
    } else {
        [(OutputPin::PowerRelay, false), (OutputPin::LogicRelay, false)]
    };
    if target.driver_enable {
        [supplies[0], supplies[1], (OutputPin::DriverEnable, true)]
    } else {
        [(OutputPin::DriverEnable, false), supplies[0], supplies[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::safety::Motion;

    fn outputs(bits: u8) -> Outputs {
        Outputs {
            logic_relay: bits & 1 != 0,
            power_relay: bits & 2 != 0,
            driver_enable: bits & 4 != 0,
            motion: Motion::None,
        }
    }

    fn safe(o: &Outputs) -> bool {
        (!o.power_relay || o.logic_relay) && (!o.driver_enable || o.power_relay)
    }

    /// From every safe pin state to every safe target, every intermediate state is safe and the last is the target.
    #[test]
    fn every_intermediate_state_keeps_the_interlocks() {
        let states: Vec<Outputs> = (0..8).map(outputs).filter(safe).collect();
        assert_eq!(states.len(), 4, "off, logic, logic + power, all three");
        for from in &states {
            for to in &states {
                let mut now = *from;
                for (pin, on) in writes(to) {
                    match pin {
                        OutputPin::DriverEnable => now.driver_enable = on,
                        OutputPin::LogicRelay => now.logic_relay = on,
                        OutputPin::PowerRelay => now.power_relay = on,
                    }
                    assert!(safe(&now), "{from:?} -> {to:?}: {now:?} after writing {pin:?} = {on}");
                }
                assert_eq!(now, *to);
            }
        }
    }
}
