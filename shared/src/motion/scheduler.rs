//! Step scheduling: per-period step targets to timed step pulses that a hardware timer can emit.
//!
//! For each period and axis the scheduler plans one [`AxisMove`]: a direction, the time of a DIR change if the
//! direction reverses, and `count` steps spread evenly over a window `[start, period)`: step `k` at
//! `start + (2k + 1) (period - start) / (2 count)` ns, integer arithmetic that a timer interrupt evaluates exactly,
//! with no accumulated rounding. The window starts late enough that the first step is at least the minimum spacing
//! after the previous period's last step, and, on a reversal, that DIR changes at least `dir_hold` after that last
//! step and at least `dir_setup` before the next one. Every step of a period lies inside it, so the position at
//! each period boundary is exactly the target. A target beyond what fits in one period (over the axis's top rate)
//! is not lost: the rest is carried into the next periods and counted.

/// Timing of the step signals (ns).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SchedulerConfig {
    /// Control period.
    pub period_ns: u32,
    /// STEP high time.
    pub pulse_ns: u32,
    /// Smallest time between two step edges of one axis (pulse plus low time).
    pub min_spacing_ns: u32,
    /// DIR must be stable this long before a step.
    pub dir_setup_ns: u32,
    /// DIR must stay this long after a step.
    pub dir_hold_ns: u32,
}

impl Default for SchedulerConfig {
    /// 1 kHz; 2.5 us pulses at 5 us spacing (200 k steps/s per axis at most); 5 us DIR setup and hold.
    fn default() -> Self {
        Self {
            period_ns: 1_000_000,
            pulse_ns: 2_500,
            min_spacing_ns: 5_000,
            dir_setup_ns: 5_000,
            dir_hold_ns: 5_000,
        }
    }
}

impl SchedulerConfig {
    /// Whether the timing is consistent: a low time at least as long as the pulse, room for a reversal, and a
    /// period of at most a second (times within a period are then `i32`: hardware arithmetic on the M4F).
    pub fn is_valid(&self) -> bool {
        self.pulse_ns > 0
            && self.period_ns <= 1_000_000_000
            && self.min_spacing_ns >= self.pulse_ns.saturating_mul(2)
            && self
                .dir_hold_ns
                .saturating_add(self.dir_setup_ns)
                .saturating_add(self.min_spacing_ns)
                < self.period_ns
    }

    /// The most steps one axis can make in one period without a reversal.
    pub fn max_steps_per_period(&self) -> u32 {
        self.period_ns / self.min_spacing_ns.max(1)
    }
}

/// Step direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(serde::Serialize, serde::Deserialize)]
pub enum Direction {
    /// Steps increase the position.
    Forward,
    /// Steps decrease the position.
    Backward,
}

/// The pulses of one axis in one period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisMove {
    /// Direction of every step in this period.
    pub direction: Direction,
    /// When DIR changes (ns from the period start), if it does in this period.
    pub dir_change_ns: Option<u32>,
    /// Start of the window the steps are spread over (ns from the period start).
    pub start_ns: u32,
    /// Number of steps.
    pub count: u32,
    /// Period length (ns): the window is `[start_ns, period_ns)`.
    pub period_ns: u32,
}

impl AxisMove {
    /// Time of step `k` (ns from the period start), `k < count`.
    pub fn step_ns(&self, k: u32) -> u32 {
        let span = self.period_ns.saturating_sub(self.start_ns);
        let n = self.count.max(1);
        // In u32 whenever the product fits (any period up to about 4 ms at the default step spacing): the M4F
        // divides u32 in one instruction and u64 in software (about 100 instructions, for every step rendered).
        let narrow = k
            .checked_mul(2)
            .and_then(|k2| k2.checked_add(1))
            .and_then(|odd| odd.checked_mul(span))
            .zip(n.checked_mul(2));
        let offset = match narrow {
            Some((num, den)) => num / den,
            None => ((2 * u64::from(k) + 1) * u64::from(span) / (2 * u64::from(n))) as u32,
        };
        self.start_ns.saturating_add(offset)
    }

    /// Time of the last step (ns from the period start), `step_ns(count - 1)` for a count of at least 1 by one
    /// division and no overflow tests: with `c = count`, `floor((2c - 1) span / 2c) = span - ceil(span / 2c)`, and
    /// `span + 2c - 1` fits in `u32` for any count a valid period holds (the span is at most 1e9 ns and the count at
    /// most the period over the step spacing). The scheduler works it out for every axis that steps, every period.
    pub fn last_step_ns(&self) -> u32 {
        let span = self.period_ns.saturating_sub(self.start_ns);
        let den = self.count.max(1).saturating_mul(2);
        let up = span.saturating_add(den - 1) / den;
        self.start_ns.saturating_add(span - up)
    }

    /// The least time between two consecutive steps (ns): `span / count`, since the times of
    /// [`AxisMove::step_ns`] are `floor` of points exactly `span / count` apart and
    /// `floor(x + d) - floor(x) >= floor(d)`. 0 when the window is empty (a start at or past the period's end puts
    /// every step at the start).
    pub fn spacing_ns(&self) -> u32 {
        self.period_ns.saturating_sub(self.start_ns) / self.count.max(1)
    }

    /// Times of all steps (ns from the period start), the values of [`AxisMove::step_ns`] without a division
    /// each: the numerator `(2k + 1) span` grows by `2 span` a step, so its quotient by `2 count` grows by
    /// `span / count` and its remainder by `2 (span % count)`, carried when it reaches `2 count`. The pulse
    /// renderer runs this for every step of every axis.
    pub fn times(&self) -> StepTimes {
        let span = self.period_ns.saturating_sub(self.start_ns);
        let n = self.count.max(1);
        // 2n and the remainders stay below 2^32 for any count a valid period holds (at most 2e5 steps); larger
        // counts fall back to step_ns.
        let den = n.checked_mul(2).filter(|d| *d <= u32::MAX / 2);
        StepTimes {
            axis: *self,
            k: 0,
            quotient: den.map_or(0, |d| span / d),
            remainder: den.map_or(0, |d| span % d),
            step: span / n,
            carry: 2 * (span % n),
            den: den.unwrap_or(0),
        }
    }

    /// Signed step count.
    pub fn signed(&self) -> i64 {
        match self.direction {
            Direction::Forward => i64::from(self.count),
            Direction::Backward => -i64::from(self.count),
        }
    }
}

/// A last step this long ago (ns) constrains nothing: every spacing, hold and setup is shorter than a valid period.
const LONG_AGO: i32 = -(1 << 30);

/// The step times of one [`AxisMove`], in order (see [`AxisMove::times`]).
#[derive(Debug, Clone)]
pub struct StepTimes {
    axis: AxisMove,
    k: u32,
    quotient: u32,
    remainder: u32,
    step: u32,
    carry: u32,
    /// `2 count`, or 0 when it is too large for the increments (then each time is computed).
    den: u32,
}

impl Iterator for StepTimes {
    type Item = u32;

    fn next(&mut self) -> Option<u32> {
        if self.k >= self.axis.count {
            return None;
        }
        let k = self.k;
        self.k += 1;
        if self.den == 0 {
            return Some(self.axis.step_ns(k));
        }
        let t = self.axis.start_ns.saturating_add(self.quotient);
        // A step's quotient is at most the span; only the one past the last step can exceed u32 (a span near
        // 2^32), and it is never returned, so it wraps.
        self.quotient = self.quotient.wrapping_add(self.step);
        self.remainder += self.carry;
        if self.remainder >= self.den {
            self.remainder -= self.den;
            self.quotient = self.quotient.wrapping_add(1);
        }
        Some(t)
    }
}

/// Turns per-period step targets of `N` axes into timed pulses: the platform's six, and the two spare axes with a
/// scheduler of their own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepScheduler<const N: usize = 6> {
    config: SchedulerConfig,
    /// The configuration's times in `i32`, worked out once rather than each period.
    timing: Timing,
    position: [i64; N],
    direction: [Direction; N],
    /// Time of each axis's last step relative to the start of the next period (ns, negative = in the past; never
    /// before [`LONG_AGO`]).
    last_step: [i32; N],
    carried: u32,
}

impl<const N: usize> StepScheduler<N> {
    /// A scheduler whose axes are at `position` (steps).
    pub fn new(config: SchedulerConfig, position: [i64; N]) -> Self {
        Self {
            config,
            timing: Timing::of(&config),
            position,
            direction: [Direction::Forward; N],
            last_step: [LONG_AGO; N],
            carried: 0,
        }
    }

    /// Scheduled position of every axis at the end of the last planned period.
    pub fn position(&self) -> [i64; N] {
        self.position
    }

    /// Redefines the positions (homing sets an axis's origin); no pulses.
    pub fn set_position(&mut self, position: [i64; N]) {
        self.position = position;
    }

    /// Periods in which some axis could not reach its target (steps carried over).
    pub fn carried(&self) -> u32 {
        self.carried
    }

    /// The configuration.
    pub fn config(&self) -> &SchedulerConfig {
        &self.config
    }

    /// Plans one axis of a period and counts a period whose targets some axis could not reach (once a period).
    #[inline(always)]
    fn plan_counted(&mut self, timing: &Timing, i: usize, target: i64, counted: &mut bool) -> AxisMove {
        let (m, short) = self.plan_axis(timing, i, target);
        if short && !*counted {
            self.carried = self.carried.saturating_add(1);
            *counted = true;
        }
        m
    }
    #[inline(always)]
    fn plan_axis(&mut self, t: &Timing, i: usize, target: i64) -> (AxisMove, bool) {
        let want = target.saturating_sub(self.position[i]);
        let last = self.last_step[i];
        let forget = |at: i32| (at - t.period).max(LONG_AGO);
        let idle = AxisMove {
            direction: self.direction[i],
            dir_change_ns: None,
            start_ns: 0,
            count: 0,
            period_ns: t.period as u32,
        };
        if want == 0 {
            self.last_step[i] = forget(last);
            return (idle, false);
        }
        let direction = if want > 0 {
            Direction::Forward
        } else {
            Direction::Backward
        };
        let mut earliest = last + t.spacing;
        let mut dir_change_ns = None;
        if direction != self.direction[i] {
            let change = (last + t.hold).max(0);
            earliest = earliest.max(change + t.setup);
            dir_change_ns = Some(change as u32);
        }
        // The first step sits half a gap into the window, so a window starting at `earliest` is always late enough.
        // Not `clamp`: it asserts its bounds are ordered, a test and a panic path (the period is at least 1).
        let start = earliest.max(0).min(t.period - 1);
        let room = (t.period - start) as u32 / t.spacing as u32;
        let magnitude = want.unsigned_abs();
        let (count, short) = if magnitude <= u64::from(room) {
            (magnitude as u32, false)
        } else {
            (room, true)
        };
        if count == 0 {
            // No room (a step is wanted): short.
            self.last_step[i] = forget(last);
            return (idle, short);
        }
        let m = AxisMove {
            direction,
            dir_change_ns,
            start_ns: start as u32,
            count,
            period_ns: t.period as u32,
        };
        self.direction[i] = direction;
        // Never wraps: the count is at most the steps wanted, so the new position lies between the old one and the
        // target (a target beyond i64's reach saturated `want` toward it). A saturating i64 addition is a dozen
        // instructions on the M4F.
        self.position[i] = self.position[i].wrapping_add(m.signed());
        // The last step's time as [`AxisMove::last_step_ns`], in wrapping arithmetic that never wraps here: the span is
        // at most 1e9 ns and the count at most the span over the spacing, so `span + 2 count - 1 < 2^32`.
        let span = (t.period - start) as u32;
        let den = count.wrapping_mul(2);
        let last_step = (start as u32).wrapping_add(span.wrapping_sub(span.wrapping_add(den - 1) / den));
        self.last_step[i] = forget(last_step as i32);
        (m, short)
    }
}

impl StepScheduler<6> {
    /// Plans one period toward `targets` (steps at the end of the period).
    ///
    /// Never inlined, and the moves made as the array it returns: the caller's result is then its own return
    /// slot, where moves built apart (`array::from_fn`, or an array filled in a loop) would be copied out (a 144-byte
    /// `memcpy`, 134 instructions on the M4F a period).
    #[inline(never)]
    pub fn plan(&mut self, targets: &[i64; 6]) -> [AxisMove; 6] {
        let timing = self.timing;
        let mut c = false;
        let counted = &mut c;
        // Each axis in line (the per-axis planner is always inlined): a call an axis, saving and restoring the
        // registers and reloading the timing, costs about 20 instructions an axis.
        [
            self.plan_counted(&timing, 0, targets[0], counted),
            self.plan_counted(&timing, 1, targets[1], counted),
            self.plan_counted(&timing, 2, targets[2], counted),
            self.plan_counted(&timing, 3, targets[3], counted),
            self.plan_counted(&timing, 4, targets[4], counted),
            self.plan_counted(&timing, 5, targets[5], counted),
        ]
    }
}

impl StepScheduler<2> {
    /// Plans one period of the spare axes toward `targets`, as [`StepScheduler::plan`] the platform's. The two
    /// axes are planned in line, not through a call each as the six are: a call's saving and restoring of registers
    /// costs more than the second copy of the code (flash) for two axes.
    #[inline(never)]
    pub fn plan(&mut self, targets: &[i64; 2]) -> [AxisMove; 2] {
        let timing = self.timing;
        let mut counted = false;
        let first = self.plan_counted(&timing, 0, targets[0], &mut counted);
        let second = self.plan_counted(&timing, 1, targets[1], &mut counted);
        [first, second]
    }
}

/// The timing of a period in `i32` ns (the M4F's own width), worked out once with the scheduler. A valid
/// configuration has a period of at most 1e9 ns and every other time shorter; out-of-range values are capped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Timing {
    period: i32,
    spacing: i32,
    hold: i32,
    setup: i32,
}

impl Timing {
    fn of(c: &SchedulerConfig) -> Self {
        let ns = |v: u32| v.min(1_000_000_000) as i32;
        Self {
            period: ns(c.period_ns).max(1),
            spacing: ns(c.min_spacing_ns).max(1),
            hold: ns(c.dir_hold_ns),
            setup: ns(c.dir_setup_ns),
        }
    }
}
