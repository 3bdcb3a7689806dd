//! Homing: each axis finds its home switch by approach, back-off and slow re-approach, then moves off the switch
//! again (an end switch used for homing is an end-of-travel limit afterwards); one axis at a time.
//!
//! Before homing nothing is known of the absolute positions, so the plan rests on one stated assumption: the
//! platform was parked near its home pose, each carriage within its search travel of its home switch. Given that,
//! [`HomingPlan::new`] proves before anything moves that no carriage can come closer than the minimum spacing
//! (KINEMATICS.md 4.2) to a neighbour: a carriage may travel its whole search distance, a neighbour that is
//! already homed sits at its home angle, and one that is not yet homed may be anywhere within its own travel.
//! The order matters: homing carriages that are not neighbours first (1, 3, then 2, 4) needs the least room.
//! Linear actuators home first, to their end switches, so the platform height is known before carriages move.

use core::fmt;

/// How one axis homes (steps and steps per second of the axis's motor).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct AxisHoming {
    /// Direction toward the switch: +1 or -1.
    pub toward: i8,
    /// Maximum travel while searching for the switch (steps).
    pub search_steps: u32,
    /// Distance to back off the switch before the slow approach (steps).
    pub backoff_steps: u32,
    /// Search speed (steps/s).
    pub fast_rate: u32,
    /// Final approach speed (steps/s).
    pub slow_rate: u32,
    /// Axis position assigned where the switch trips on the slow approach (steps).
    pub home_position: i64,
}

/// Homing of all six axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct HomingConfig {
    /// Per axis, in actuator order.
    pub axes: [AxisHoming; 6],
    /// The order in which the axes home.
    pub order: [u8; 6],
}

/// The ring facts the plan needs to prove carriage spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingHoming {
    /// How many of the axes (the first ones) are ring carriages, in ring order.
    pub carriages: usize,
    /// Angle of each carriage's home switch on the ring (rad).
    pub home_angles: [f64; 6],
    /// Minimum central angle between neighbours (rad).
    pub min_spacing: f64,
    /// Motor steps per radian of carriage travel.
    pub steps_per_rad: f64,
}

/// Why a homing configuration is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum HomingError {
    /// `order` is not a permutation of the six axes.
    BadOrder,
    /// An axis has a zero speed, zero travel, or a direction other than +-1.
    BadAxis(u8),
    /// Homing this carriage could bring it closer than the minimum spacing to a neighbour.
    Spacing(u8),
}

impl fmt::Display for HomingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadOrder => f.write_str("homing order is not a permutation of the axes"),
            Self::BadAxis(a) => write!(f, "axis {a}: homing speeds, travel and direction must be set"),
            Self::Spacing(a) => write!(
                f,
                "homing carriage {a} could come closer than the minimum spacing to a neighbour"
            ),
        }
    }
}

/// A homing configuration checked for order, axis settings and carriage spacing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingPlan {
    config: HomingConfig,
}

impl HomingPlan {
    /// Checks a configuration; `ring` proves the carriage spacing (see the module documentation).
    pub fn new(config: HomingConfig, ring: &RingHoming) -> Result<Self, HomingError> {
        let mut seen = [false; 6];
        for &a in &config.order {
            match seen.get_mut(usize::from(a)) {
                Some(s) if !*s => *s = true,
                _ => return Err(HomingError::BadOrder),
            }
        }
        for (i, a) in config.axes.iter().enumerate() {
            let ok = (a.toward == 1 || a.toward == -1)
                && a.search_steps > 0
                && a.fast_rate > 0
                && a.slow_rate > 0
                && a.backoff_steps < a.search_steps;
            if !ok {
                return Err(HomingError::BadAxis(i as u8));
            }
        }
        let n = ring.carriages.min(6);
        let travel = |axis: usize| {
            config
                .axes
                .get(axis)
                .map_or(0.0, |a| a.search_steps as f64 / ring.steps_per_rad)
        };
        let mut homed = [false; 6];
        for &axis in &config.order {
            let axis = usize::from(axis);
            if axis < n {
                for neighbour in [(axis + 1) % n, (axis + n - 1) % n] {
                    let (a, b) = if neighbour == (axis + 1) % n {
                        (axis, neighbour)
                    } else {
                        (neighbour, axis)
                    };
                    let gap = crate::real::wrap_turn(ring.home_angles[b] - ring.home_angles[a]);
                    let other = if homed[neighbour] { 0.0 } else { travel(neighbour) };
                    if n > 1 && gap - travel(axis) - other < ring.min_spacing {
                        return Err(HomingError::Spacing(axis as u8));
                    }
                }
            }
            if let Some(h) = homed.get_mut(axis) {
                *h = true;
            }
        }
        Ok(Self { config })
    }

    /// The checked configuration.
    pub fn config(&self) -> &HomingConfig {
        &self.config
    }
}

/// What the homing sequence asks for in one control period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HomingStep {
    /// Move `axis` at `rate` steps/s (signed); every other axis holds.
    Move {
        /// Axis index.
        axis: u8,
        /// Signed speed (steps/s).
        rate: i32,
    },
    /// The switch of `axis` tripped on the slow approach at position `at` (steps): this is its origin. The axis
    /// then backs off the switch before the next one starts.
    Homed {
        /// Axis index.
        axis: u8,
        /// Axis position (steps) where the switch tripped.
        at: i64,
    },
    /// Every axis is homed.
    Done,
    /// `axis` did not find its switch within its travel, or the switch did not release on back-off.
    Failed(u8),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    BackOff,
    Slow,
    /// Off the switch again, so that an end switch used for homing is free to act as a limit afterwards.
    Clear,
}

/// Runs a [`HomingPlan`]: call [`HomingSequencer::update`] every control period with the axis positions and the
/// home switch levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingSequencer {
    plan: HomingPlan,
    index: usize,
    phase: Phase,
    start: i64,
    finished: bool,
    failed: bool,
}

impl HomingSequencer {
    /// Starts at the first axis of the plan's order; `position` is where the axes are now (steps).
    pub fn new(plan: HomingPlan, position: &[i64; 6]) -> Self {
        let start = position[usize::from(plan.config.order[0] % 6)];
        Self {
            plan,
            index: 0,
            phase: Phase::Approach,
            start,
            finished: false,
            failed: false,
        }
    }

    /// The axis homing now, if any.
    pub fn current_axis(&self) -> Option<u8> {
        if self.finished || self.failed {
            None
        } else {
            self.plan.config.order.get(self.index).copied()
        }
    }

    /// One control period: `position` of every axis (steps) and `switches` (bit `i` set = home switch of axis
    /// `i` active). The first call for an axis records where it starts.
    pub fn update(&mut self, position: &[i64; 6], switches: u16) -> HomingStep {
        if self.finished {
            return HomingStep::Done;
        }
        let Some(axis) = self.current_axis() else {
            return HomingStep::Failed(self.plan.config.order.get(self.index).copied().unwrap_or(0));
        };
        let cfg = self.plan.config.axes[usize::from(axis)];
        let pos = position[usize::from(axis)];
        let active = switches & (1 << axis) != 0;
        let toward = i64::from(cfg.toward);
        let travelled = (pos - self.start) * toward;
        match self.phase {
            Phase::Approach => {
                if active {
                    self.phase = Phase::BackOff;
                    self.start = pos;
                } else if travelled.unsigned_abs() >= u64::from(cfg.search_steps) {
                    return self.fail(axis);
                } else {
                    return HomingStep::Move {
                        axis,
                        rate: cfg.fast_rate as i32 * i32::from(cfg.toward),
                    };
                }
                self.back_off(axis, &cfg, pos, active)
            }
            Phase::BackOff => self.back_off(axis, &cfg, pos, active),
            Phase::Slow => {
                if active {
                    // The controller calls this position `home_position`.
                    self.phase = Phase::Clear;
                    self.start = cfg.home_position;
                    return HomingStep::Homed { axis, at: pos };
                }
                if (pos - self.start) * toward > i64::from(cfg.backoff_steps) * 2 {
                    return self.fail(axis);
                }
                HomingStep::Move {
                    axis,
                    rate: cfg.slow_rate as i32 * i32::from(cfg.toward),
                }
            }
            Phase::Clear => {
                if (self.start - pos) * toward < i64::from(cfg.backoff_steps) {
                    return HomingStep::Move {
                        axis,
                        rate: -(cfg.slow_rate as i32) * i32::from(cfg.toward),
                    };
                }
                self.next_axis(position);
                match self.current_axis() {
                    Some(_) => self.update(position, switches),
                    None => HomingStep::Done,
                }
            }
        }
    }

    fn back_off(&mut self, axis: u8, cfg: &AxisHoming, pos: i64, active: bool) -> HomingStep {
        let away = (self.start - pos) * i64::from(cfg.toward);
        if away < i64::from(cfg.backoff_steps) {
            return HomingStep::Move {
                axis,
                rate: -(cfg.fast_rate as i32) * i32::from(cfg.toward),
            };
        }
        if active {
            // Backed off the whole distance and the switch is still made: a stuck or miswired switch.
            return self.fail(axis);
        }
        self.phase = Phase::Slow;
        self.start = pos;
        HomingStep::Move {
            axis,
            rate: cfg.slow_rate as i32 * i32::from(cfg.toward),
        }
    }

    fn next_axis(&mut self, position: &[i64; 6]) {
        self.index += 1;
        self.phase = Phase::Approach;
        match self.plan.config.order.get(self.index) {
            Some(&a) => self.start = position[usize::from(a % 6)],
            None => self.finished = true,
        }
    }

    fn fail(&mut self, axis: u8) -> HomingStep {
        self.failed = true;
        HomingStep::Failed(axis)
    }
}
