//! Pulse rendering: one period's [`AxisMove`]s as a buffer of GPIO set/reset words, one word per time slot.
//!
//! The firmware's step generator is a timer that, every `slot_ns`, triggers a DMA transfer of the next word of
//! this buffer into the port's set/reset register (STM32 `BSRR`: bits 0-15 set pins, bits 16-31 reset them). All
//! STEP and DIR pins sit on one port, so one word per slot drives all six axes at once, and no CPU work is done
//! per step: the CPU renders one buffer per control period, the timer and the DMA do the timing.
//!
//! Times are quantised down to the slot grid (`floor(t / slot)`). Flooring keeps every distance the scheduler
//! guarantees: `floor(a + d) - floor(a) >= floor(d)`, so two steps `min_spacing_ns` apart land at least
//! `floor(min_spacing / slot)` slots apart, and a DIR change `dir_setup_ns` before a step lands at least
//! `floor(dir_setup / slot)` slots before it. [`PulseTiming::new`] refuses a slot that would shorten a pulse, a
//! low time or a DIR setup/hold below the driver's minimum. A STEP pulse that ends after the period's last slot
//! ends in the first slot of the next buffer (carried by the renderer), so the pins never stay high.

use super::scheduler::{AxisMove, Direction, SchedulerConfig};

/// Slot of the boards' step generators (ns): their timers emit one GPIO set/reset word per slot. 2.5 us is the
/// shortest STEP pulse of FIRMWARE.md.
pub const STEP_SLOT_NS: u32 = 2_500;
/// Longest step buffer a board holds (slots): one period of 2 ms at [`STEP_SLOT_NS`].
pub const MAX_STEP_SLOTS: usize = 800;

/// Which pin of the port each axis's STEP and DIR signal is on (0-15), and the DIR level that means forward.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PortMap {
    /// STEP pin of each axis.
    pub step: [u8; 6],
    /// DIR pin of each axis.
    pub dir: [u8; 6],
    /// Bit per axis: DIR low means forward (a motor wired the other way round).
    pub dir_forward_low: u8,
}

impl PortMap {
    /// Whether every pin is on the port (0-15) and no pin is used twice.
    pub fn is_valid(&self) -> bool {
        let mut used = 0u32;
        for &pin in self.step.iter().chain(self.dir.iter()) {
            if pin > 15 || used & (1 << pin) != 0 {
                return false;
            }
            used |= 1 << pin;
        }
        true
    }

    /// All STEP and DIR pins as a mask.
    pub fn pins(&self) -> u16 {
        self.step
            .iter()
            .chain(self.dir.iter())
            .fold(0, |m, &p| m | 1u16.checked_shl(u32::from(p)).unwrap_or(0))
    }

    fn dir_word(&self, axis: usize, direction: Direction) -> u32 {
        let high = (direction == Direction::Forward) != (self.dir_forward_low & (1 << axis) != 0);
        let bit = 1u32 << (self.dir[axis] & 15);
        if high {
            bit
        } else {
            bit << 16
        }
    }

    /// The word that sets the idle state: STEP low, DIR at the forward level (the scheduler's initial direction).
    /// The firmware writes it once at reset, before the drivers are enabled.
    pub fn idle_word(&self) -> u32 {
        let mut w = 0u32;
        for a in 0..6 {
            w |= 1u32 << (16 + u32::from(self.step[a] & 15));
            w |= self.dir_word(a, Direction::Forward);
        }
        w
    }
}

/// Why a slot timing cannot render the scheduler's pulses faithfully.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PulseTimingError {
    /// The slot does not divide the period, or the period has more slots than the buffer.
    Slots,
    /// Quantised to slots, the low time between two steps would be shorter than the pulse.
    Spacing,
    /// Quantised to slots, DIR setup or hold would be shorter than required.
    Direction,
    /// The pin map uses a pin twice or a pin above 15.
    Pins,
}

impl core::fmt::Display for PulseTimingError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Slots => "the slot does not divide the period, or the period does not fit the buffer",
            Self::Spacing => "on the slot grid, the low time between steps would be shorter than required",
            Self::Direction => "on the slot grid, DIR setup or hold would be shorter than required",
            Self::Pins => "the pin map uses a pin twice or a pin above 15",
        })
    }
}

impl core::error::Error for PulseTimingError {}

/// Slot grid of the step generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PulseTiming {
    /// Length of one slot (ns): the timer's update period.
    pub slot_ns: u32,
    /// Slots per control period: the buffer length.
    pub slots: usize,
    /// Slots a STEP pulse stays high.
    pub pulse_slots: usize,
}

impl PulseTiming {
    /// The grid for `scheduler`'s timing with `slot_ns` slots, into buffers of at most `max_slots` words.
    pub fn new(scheduler: &SchedulerConfig, slot_ns: u32, max_slots: usize) -> Result<Self, PulseTimingError> {
        if scheduler.period_ns.checked_rem(slot_ns) != Some(0) {
            return Err(PulseTimingError::Slots);
        }
        let slots = (scheduler.period_ns / slot_ns) as usize;
        if slots > max_slots || slots < 2 {
            return Err(PulseTimingError::Slots);
        }
        let pulse_slots = scheduler.pulse_ns.div_ceil(slot_ns).max(1);
        // Two steps at least `min_spacing` apart land at least `spacing` slots apart; the pin must then stay low
        // for at least the low time the scheduler asks for (`min_spacing - pulse`).
        let spacing = scheduler.min_spacing_ns / slot_ns;
        let low_ns = scheduler.min_spacing_ns.saturating_sub(scheduler.pulse_ns);
        if spacing <= pulse_slots || (spacing - pulse_slots).saturating_mul(slot_ns) < low_ns {
            return Err(PulseTimingError::Spacing);
        }
        // A DIR change `dir_setup` before a step lands at least `setup` slots before it; one `dir_hold` after a
        // step lands at least `hold` slots after it, and never while that step's pulse is still high.
        let setup = scheduler.dir_setup_ns / slot_ns;
        let hold = scheduler.dir_hold_ns / slot_ns;
        if setup.saturating_mul(slot_ns) < scheduler.dir_setup_ns
            || setup == 0
            || hold.saturating_mul(slot_ns) < scheduler.dir_hold_ns
            || hold < pulse_slots
        {
            return Err(PulseTimingError::Direction);
        }
        Ok(Self {
            slot_ns,
            slots,
            pulse_slots: pulse_slots as usize,
        })
    }
}

/// What one rendered period holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RenderReport {
    /// STEP pulses started in this buffer, per axis.
    pub steps: [u32; 6],
    /// Steps that fell into a slot already holding a step of the same axis (never happens with a timing that
    /// [`PulseTiming::new`] accepted; counted so that it could not go unnoticed).
    pub collisions: u32,
}

/// Renders periods into slot buffers, carrying pulse ends across buffer boundaries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PulseRenderer {
    map: PortMap,
    timing: PulseTiming,
    /// Resets that fall into the first slots of the next buffer (one word per slot of carry).
    carry: [u32; 4],
}

impl PulseRenderer {
    /// A renderer for this pin map and grid.
    pub fn new(map: PortMap, timing: PulseTiming) -> Result<Self, PulseTimingError> {
        if !map.is_valid() {
            return Err(PulseTimingError::Pins);
        }
        if timing.pulse_slots > 4 || timing.pulse_slots >= timing.slots {
            return Err(PulseTimingError::Slots);
        }
        Ok(Self {
            map,
            timing,
            carry: [0; 4],
        })
    }

    /// The grid.
    pub fn timing(&self) -> &PulseTiming {
        &self.timing
    }

    /// The pin map.
    pub fn map(&self) -> &PortMap {
        &self.map
    }

    /// Fills `out` (at least [`PulseTiming::slots`] words; only those are written) with the words of one period.
    /// A buffer too short renders nothing and reports `None`: the caller's buffer is sized from the same timing.
    ///
    /// Never inlined: its machine code is then the same in every program that links it (the firmware, the QEMU
    /// measurements), instead of depending on the registers free at each caller after LTO.
    #[inline(never)]
    pub fn render(&mut self, moves: &[AxisMove; 6], out: &mut [u32]) -> Option<RenderReport> {
        let slots = self.timing.slots;
        let out = out.get_mut(..slots)?;
        out.fill(0);
        for (w, c) in out.iter_mut().zip(self.carry.iter_mut()) {
            *w |= *c;
            *c = 0;
        }
        let mut report = RenderReport::default();
        // u32 divisions: one instruction each on the M4F (u64 ones are software), one per step rendered.
        let slot_ns = self.timing.slot_ns.max(1);
        for (a, m) in moves.iter().enumerate() {
            match m.dir_change_ns {
                Some(t) => {
                    let s = ((t / slot_ns) as usize).min(slots - 1);
                    out[s] |= self.map.dir_word(a, m.direction);
                }
                // Rewriting the level DIR already has keeps a missed buffer from leaving it wrong; it is no edge.
                None if m.count > 0 => out[0] |= self.map.dir_word(a, m.direction),
                None => {}
            }
            if m.count == 0 {
                continue;
            }
            let axis = AxisPins {
                step: 1u32 << (self.map.step[a] & 15),
                slot_ns,
                pulse_slots: self.timing.pulse_slots,
            };
            // Steps at least a slot apart land in distinct slots (`floor(a + d) - floor(a) >= floor(d)`), so a
            // collision is impossible and the loop need not look for one; closer steps take the checked loop.
            let (steps, collisions) = if m.spacing_ns() >= slot_ns {
                axis.render::<false>(m, out, &mut self.carry)
            } else {
                axis.render::<true>(m, out, &mut self.carry)
            };
            report.steps[a] = steps;
            report.collisions += collisions;
        }
        Some(report)
    }
}

/// What one axis's step loop needs, kept in registers.
#[derive(Clone, Copy)]
struct AxisPins {
    /// The STEP pin's set bit (its reset bit is 16 higher).
    step: u32,
    slot_ns: u32,
    pulse_slots: usize,
}

impl AxisPins {
    /// Sets the STEP bit at each step's slot and resets it `pulse_slots` later (in `carry` past the buffer's end);
    /// returns the steps rendered and the collisions (a step past the buffer's end, or with `CHECK`, into a slot
    /// that already holds one). Without `CHECK` the caller has proved that no two steps share a slot.
    #[inline(always)]
    fn render<const CHECK: bool>(self, m: &AxisMove, out: &mut [u32], carry: &mut [u32; 4]) -> (u32, u32) {
        let mut tally = Tally::default();
        let Some(mut steps) = StepSlots::new(m, self.slot_ns) else {
            for t in m.times() {
                self.place::<CHECK>((t / self.slot_ns) as usize, out, carry, &mut tally);
            }
            return (m.count - tally.missed, tally.missed + tally.doubled);
        };
        // The steps whose pulse ends inside the buffer, in a loop that keeps neither the carry nor a count of
        // missed steps in a register: all steps but the last few, since the slots are in order.
        let slots = out.len();
        let mut left = m.count;
        let mut doubled = 0u32;
        while left > 0 {
            let s = steps.advance();
            left -= 1;
            let end = s.wrapping_add(self.pulse_slots);
            let (Some(word), true) = (out.get_mut(s), end < slots) else {
                self.place::<CHECK>(s, out, carry, &mut tally);
                break;
            };
            if CHECK && *word & self.step != 0 {
                doubled += 1;
            }
            *word |= self.step;
            if let Some(w) = out.get_mut(end) {
                *w |= self.step << 16;
            }
        }
        for _ in 0..left {
            self.place::<CHECK>(steps.advance(), out, carry, &mut tally);
        }
        (m.count - tally.missed, tally.missed + tally.doubled + doubled)
    }

    /// One step at slot `s` with every case: its pulse ending in the next buffer (`carry`), or no slot for it.
    #[inline(always)]
    fn place<const CHECK: bool>(self, s: usize, out: &mut [u32], carry: &mut [u32; 4], tally: &mut Tally) {
        let slots = out.len();
        let Some(word) = out.get_mut(s) else {
            tally.missed += 1;
            return;
        };
        if CHECK && *word & self.step != 0 {
            tally.doubled += 1;
        }
        *word |= self.step;
        let end = s + self.pulse_slots;
        match out.get_mut(end) {
            Some(w) => *w |= self.step << 16,
            None => {
                if let Some(c) = carry.get_mut(end - slots) {
                    *c |= self.step << 16;
                }
            }
        }
    }
}

/// Steps of one axis that found no slot, and steps into a slot already holding one.
#[derive(Default)]
struct Tally {
    missed: u32,
    doubled: u32,
}

/// The slots of a move's steps, one division each. Step `k` is at `start + floor((2k + 1) span / 2n)` ns
/// ([`AxisMove::step_ns`]), in slot `floor(that / slot)`; an integer added to a floor is the floor of the sum, and
/// nested floors of integer quotients are the floor of one quotient, so the slot is
/// `floor((2n start + (2k + 1) span) / (2n slot))`: a numerator growing by `2 span` a step over a fixed
/// denominator, where the times would need a quotient, a remainder and a division by the slot each.
struct StepSlots {
    numerator: u32,
    increment: u32,
    denominator: u32,
}

impl StepSlots {
    /// `None` when a numerator or the denominator exceeds `u32` (about 2,000 steps in a 1 ms period), so that
    /// the M4F divides in one instruction.
    fn new(m: &AxisMove, slot_ns: u32) -> Option<Self> {
        let span = m.period_ns.saturating_sub(m.start_ns);
        let twice = m.count.max(1).checked_mul(2)?;
        // Every numerator of a step is below `2n period` (or is `2n start`, the window empty).
        twice.checked_mul(m.period_ns.max(m.start_ns))?;
        Some(Self {
            numerator: twice * m.start_ns + span,
            increment: 2 * span,
            denominator: twice.checked_mul(slot_ns)?,
        })
    }

    /// The next step's slot; past the last step, meaningless slots.
    #[inline(always)]
    fn advance(&mut self) -> usize {
        let s = self.numerator / self.denominator;
        // Wraps only past the last step, whose numerator is never divided.
        self.numerator = self.numerator.wrapping_add(self.increment);
        s as usize
    }
}
