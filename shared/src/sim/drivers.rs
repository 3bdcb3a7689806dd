//! The stepper drivers' side of the step port: the port's levels slot by slot as the DMA writes the rendered
//! set/reset words, a step counted at each rising STEP edge in the direction its DIR pin gives, and every edge held
//! to the drivers' timing (pulse width, low time, DIR setup and hold).
//!
//! The QEMU controller's plant moves by what this counts, so that the step generator's words, not the controller's
//! intended moves, are what the emulated machine follows; the host tests replay rendered trajectories through it.

use core::fmt;

use crate::motion::pulse::PortMap;
use crate::motion::SchedulerConfig;

/// An edge the drivers would not have taken as meant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TimingViolation {
    /// Axis (0-5).
    pub axis: u8,
    /// Slot of the word that made the edge (counted from the first word played).
    pub slot: u64,
    /// Which rule.
    pub rule: TimingRule,
}

/// The driver timing rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TimingRule {
    /// DIR changed while STEP was high or rose with it.
    DirWhileStepHigh,
    /// DIR changed sooner than the hold time after a rising STEP edge.
    DirHold,
    /// STEP rose sooner than the setup time after a DIR change.
    DirSetup,
    /// STEP rose sooner than the low time after it fell.
    LowTime,
    /// STEP fell sooner than the pulse width after it rose.
    PulseWidth,
}

impl fmt::Display for TimingViolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rule = match self.rule {
            TimingRule::DirWhileStepHigh => "DIR changed while STEP was high",
            TimingRule::DirHold => "DIR hold time violated",
            TimingRule::DirSetup => "DIR setup time violated",
            TimingRule::LowTime => "STEP low time too short",
            TimingRule::PulseWidth => "STEP pulse too short",
        };
        write!(f, "axis {}: {rule} at slot {}", self.axis, self.slot)
    }
}

impl core::error::Error for TimingViolation {}

/// Long ago, in slots: no edge yet.
const NEVER: i64 = -1_000_000;

/// Six step/dir driver inputs on one port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DriverInputs {
    map: PortMap,
    slot_ns: i64,
    timing: SchedulerConfig,
    level: u16,
    slot: i64,
    dir_changed: [i64; 6],
    rose: [i64; 6],
    fell: [i64; 6],
    position: [i64; 6],
    edges: [u64; 6],
}

impl DriverInputs {
    /// Drivers on `map`'s pins, held to `timing`, the port at its idle word, a word played every `slot_ns`.
    pub fn new(map: PortMap, slot_ns: u32, timing: SchedulerConfig) -> Self {
        Self {
            map,
            slot_ns: i64::from(slot_ns),
            timing,
            level: (map.idle_word() & 0xffff) as u16,
            slot: 0,
            dir_changed: [NEVER; 6],
            rose: [NEVER; 6],
            fell: [NEVER; 6],
            position: [0; 6],
            edges: [0; 6],
        }
    }

    /// Plays one word (set bits win over reset bits, as in the STM32's BSRR). The word always takes effect; the
    /// first rule it breaks, if any, is returned.
    pub fn play(&mut self, word: u32) -> Option<TimingViolation> {
        let set = (word & 0xffff) as u16;
        let reset = (word >> 16) as u16 & !set;
        let next = (self.level | set) & !reset;
        let mut broken = None;
        for a in 0..6 {
            let step = 1u16 << (self.map.step[a] & 15);
            let dir = 1u16 << (self.map.dir[a] & 15);
            let rises = self.level & step == 0 && next & step != 0;
            let falls = self.level & step != 0 && next & step == 0;
            let mut rule = None;
            if (self.level ^ next) & dir != 0 {
                if next & step != 0 || self.level & step != 0 {
                    rule = Some(TimingRule::DirWhileStepHigh);
                } else if self.since(self.rose[a]) < i64::from(self.timing.dir_hold_ns) {
                    rule = Some(TimingRule::DirHold);
                }
                self.dir_changed[a] = self.slot;
            }
            if rises {
                if self.since(self.dir_changed[a]) < i64::from(self.timing.dir_setup_ns) {
                    rule = rule.or(Some(TimingRule::DirSetup));
                }
                let low_ns = self.timing.min_spacing_ns.saturating_sub(self.timing.pulse_ns);
                if self.since(self.fell[a]) < i64::from(low_ns) {
                    rule = rule.or(Some(TimingRule::LowTime));
                }
                let forward = (next & dir != 0) != (self.map.dir_forward_low & (1 << a) != 0);
                self.position[a] += if forward { 1 } else { -1 };
                self.edges[a] += 1;
                self.rose[a] = self.slot;
            }
            if falls {
                if self.since(self.rose[a]) < i64::from(self.timing.pulse_ns) {
                    rule = rule.or(Some(TimingRule::PulseWidth));
                }
                self.fell[a] = self.slot;
            }
            if broken.is_none() {
                broken = rule.map(|rule| TimingViolation {
                    axis: a as u8,
                    slot: self.slot.max(0) as u64,
                    rule,
                });
            }
        }
        self.level = next;
        self.slot += 1;
        broken
    }

    /// Plays a buffer of words; the first violation in it, if any (every word takes effect).
    pub fn play_all(&mut self, words: &[u32]) -> Option<TimingViolation> {
        words.iter().fold(None, |first, &w| {
            if w == 0 {
                // No pin set or reset: no level changes and no rule can break, only time passes. Most words of a
                // buffer are such, and the QEMU board plays a buffer a period in emulated time (where the model's
                // instructions count as the device's).
                self.slot += 1;
                return first;
            }
            let v = self.play(w);
            first.or(v)
        })
    }

    /// Nanoseconds from the slot `then` to the current one.
    fn since(&self, then: i64) -> i64 {
        (self.slot - then).saturating_mul(self.slot_ns)
    }

    /// Net steps counted per axis since the start (forward positive).
    pub fn position(&self) -> [i64; 6] {
        self.position
    }

    /// Rising STEP edges per axis since the start.
    pub fn edges(&self) -> [u64; 6] {
        self.edges
    }

    /// The port's levels now.
    pub fn level(&self) -> u16 {
        self.level
    }

    /// Whether any STEP pin is high now.
    pub fn step_high(&self) -> bool {
        self.map.step.iter().any(|&p| self.level & (1 << (p & 15)) != 0)
    }
}
