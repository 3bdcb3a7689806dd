//! The order in which a board writes its output pins. A tick's outputs change up to five pins (driver enable,
//! LOGIC_EN, POWER_EN, AUX1, AUX2), one write at a time: between two writes the machine is in an intermediate state,
//! which must keep the interlocks too: never power without logic, never drivers enabled without power, never an
//! auxiliary output on without the drivers enabled.

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
    /// AUX1 output (`true`: on).
    Aux1,
    /// AUX2 output (`true`: on).
    Aux2,
}

/// The writes that take the pins from any state that keeps the interlocks to `target`, in an order every
/// intermediate state of which keeps them too: auxiliary outputs switched off first (the equipment stops before
/// anything else drops), then drivers disabled (before power can drop), logic closed before power and opened after
/// it, drivers enabled after power is there, and auxiliary outputs switched on last.
pub fn writes(target: &Outputs) -> [(OutputPin, bool); 5] {
    let aux = [
        (OutputPin::Aux1, target.aux & 1 != 0),
        (OutputPin::Aux2, target.aux & 2 != 0),
    ];
    let [a, b, c] = relays(target);
    if target.aux == 0 {
        [aux[0], aux[1], a, b, c]
    } else {
        // Some output on: the target keeps the drivers enabled (the supervisor's invariant), so the relays and the
        // enable go first; an output that goes off is written before any that goes on.
        let (first, second) = if aux[0].1 { (aux[1], aux[0]) } else { (aux[0], aux[1]) };
        [a, b, c, first, second]
    }
}

/// The relay and driver-enable writes of [`writes`].
fn relays(target: &Outputs) -> [(OutputPin, bool); 3] {
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
            aux: bits >> 3,
        }
    }

    fn safe(o: &Outputs) -> bool {
        (!o.power_relay || o.logic_relay) && (!o.driver_enable || o.power_relay) && (o.aux == 0 || o.driver_enable)
    }

    /// From every safe pin state to every safe target, every intermediate state is safe and the last is the target.
    #[test]
    fn every_intermediate_state_keeps_the_interlocks() {
        let states: Vec<Outputs> = (0..32).map(outputs).filter(safe).collect();
        assert_eq!(
            states.len(),
            7,
            "off, logic, logic + power, all three, and all three with each of the 3 aux combinations"
        );
        for from in &states {
            for to in &states {
                let mut now = *from;
                for (pin, on) in writes(to) {
                    match pin {
                        OutputPin::DriverEnable => now.driver_enable = on,
                        OutputPin::LogicRelay => now.logic_relay = on,
                        OutputPin::PowerRelay => now.power_relay = on,
                        OutputPin::Aux1 => now.aux = (now.aux & !1) | u8::from(on),
                        OutputPin::Aux2 => now.aux = (now.aux & !2) | u8::from(on) << 1,
                    }
                    assert!(safe(&now), "{from:?} -> {to:?}: {now:?} after writing {pin:?} = {on}");
                }
                assert_eq!(now, *to);
            }
        }
    }
}
