//! The spare stepper axes 7 and 8: two motors beside the platform's six for test equipment (the source's ch. 5.3.2,
//! the PLC002 box's point a). Each is a single coordinate in its own unit (mm, degrees, whatever its steps per unit
//! say), commanded by a stream's `axis7`/`axis8` columns, interpolated over the setpoint's interval like the pose,
//! and followed under its own velocity and acceleration limits by an [`AxisTracker`], the pose axes' tracker. They
//! are outside the mechanism: no IK, no workspace check, so the tick pays two trackers and nothing for an axis that
//! is not fitted.
//!
//! A target outside the axis's travel is limited into it (limit, don't stall). A setpoint without a column keeps
//! that axis's target, as it keeps the auxiliary outputs: a source that sends the column only when it changes, or a
//! gap in the stream, holds the axis where it was sent. There is no home switch (the board has no pin for one): an
//! axis's zero is where it stands when the controller starts, and its travel is counted from there.

use super::limits::AxisTracker;
use crate::Real;

/// How many spare axes there are.
pub const SPARE_AXES: usize = 2;
/// Most steps per unit (as the platform's axes: an `f32` holds every whole step up to 2^24).
const MAX_STEPS_PER_UNIT: f32 = 16_777_216.0;

/// One spare axis: whether it is fitted, its scale and its limits (the rig's `[[spare]]` entries).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpareAxisSettings {
    /// The axis is fitted and driven; a spare axis that is not fitted never steps.
    pub enabled: bool,
    /// Motor steps per unit of the axis's coordinate (1 to 2^24).
    pub steps_per_unit: f32,
    /// Velocity limit (units/s, above 0; at most what the step generator pulses at `steps_per_unit`).
    pub velocity: f32,
    /// Acceleration limit (units/s^2, above 0).
    pub acceleration: f32,
    /// Travel from the start position: least and most coordinate (units; least <= 0 <= most).
    pub travel: [f32; 2],
}

impl SpareAxisSettings {
    /// Not fitted (the default of both axes).
    pub const NONE: Self = Self {
        enabled: false,
        steps_per_unit: 1_000.0,
        velocity: 1.0,
        acceleration: 1.0,
        travel: [0.0, 0.0],
    };

    /// Whether the values are in range; `max_step_rate` is the step generator's top rate (steps/s).
    pub fn is_valid(&self, max_step_rate: f32) -> bool {
        let [least, most] = self.travel;
        (1.0..=MAX_STEPS_PER_UNIT).contains(&self.steps_per_unit)
            && self.velocity > 0.0
            && self.velocity * self.steps_per_unit <= max_step_rate
            && self.acceleration > 0.0
            && self.acceleration.is_finite()
            && least <= 0.0
            && most >= 0.0
            && least.is_finite()
            && most.is_finite()
    }
}

/// A coordinate per spare axis in a setpoint: `None` keeps the axis's target.
pub type SpareTargets = [Option<f32>; SPARE_AXES];

/// One axis's straight line from where its reference was to its newest target, over a number of ticks.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Line {
    from: f32,
    to: f32,
    ticks: u32,
    done: u32,
}

impl Line {
    fn reference(&self) -> f32 {
        if self.done >= self.ticks {
            self.to
        } else {
            // A convex combination: never past `to`, so the tracker behind it does not overshoot.
            self.from + (self.to - self.from) * (self.done as f32 / self.ticks as f32)
        }
    }
}

/// The two spare axes' commanded positions, references and trackers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpareAxes {
    settings: [SpareAxisSettings; SPARE_AXES],
    /// Bit per fitted axis: nothing is done for the others.
    fitted: u8,
    /// Commanded position (units).
    position: [f32; SPARE_AXES],
    trackers: [AxisTracker; SPARE_AXES],
    lines: [Line; SPARE_AXES],
}

impl SpareAxes {
    /// Both axes at zero and at rest.
    pub fn new(settings: [SpareAxisSettings; SPARE_AXES]) -> Self {
        let fitted = settings
            .iter()
            .enumerate()
            .fold(0, |m, (i, s)| m | u8::from(s.enabled) << i);
        Self {
            settings,
            fitted,
            position: [0.0; SPARE_AXES],
            trackers: [AxisTracker::default(); SPARE_AXES],
            lines: [Line::default(); SPARE_AXES],
        }
    }

    /// New settings, the positions kept (an axis's counted steps stay where they are), every axis held.
    pub fn configure(&mut self, settings: [SpareAxisSettings; SPARE_AXES]) {
        let position = self.position;
        *self = Self::new(settings);
        self.position = position;
        self.hold();
    }

    /// The settings.
    pub fn settings(&self) -> &[SpareAxisSettings; SPARE_AXES] {
        &self.settings
    }

    /// Whether any axis is fitted.
    pub fn any(&self) -> bool {
        self.fitted != 0
    }

    /// Commanded positions (units).
    pub fn position(&self) -> [f32; SPARE_AXES] {
        self.position
    }

    /// Speeds (units/s).
    pub fn velocity(&self) -> [f32; SPARE_AXES] {
        self.trackers.map(|t| t.velocity)
    }

    /// The targets the references head for (units).
    pub fn target(&self) -> [f32; SPARE_AXES] {
        self.lines.map(|l| l.to)
    }

    /// Whether both axes are at rest.
    pub fn at_rest(&self) -> bool {
        self.trackers.iter().all(|t| t.velocity == 0.0)
    }

    /// Whether every value is finite or absent (a setpoint with a NaN column is garbage, refused whole).
    pub fn finite(targets: &SpareTargets) -> bool {
        targets.iter().flatten().all(|v| v.is_finite())
    }

    /// Takes a setpoint's columns: each axis with a value heads for it (limited into its travel) on a straight line
    /// over `ticks` from where its reference is; an axis without one keeps its target. Values must be finite
    /// ([`Self::finite`]).
    pub fn take(&mut self, targets: &SpareTargets, ticks: u32) {
        for (i, value) in targets.iter().enumerate() {
            if let (Some(v), true) = (value, self.fitted & (1 << i) != 0) {
                let [least, most] = self.settings[i].travel;
                let line = &mut self.lines[i];
                *line = Line {
                    from: line.reference(),
                    to: v.max(least).min(most),
                    ticks: ticks.max(1),
                    done: 0,
                };
            }
        }
    }

    /// One tick following the references under the limits (`brake`: braking to rest instead, the references
    /// left behind).
    pub fn tick(&mut self, dt: f32, brake: bool) {
        if self.fitted == 0 {
            return;
        }
        for i in 0..SPARE_AXES {
            if self.fitted & (1 << i) == 0 {
                continue;
            }
            let s = &self.settings[i];
            let line = &mut self.lines[i];
            let tracker = &mut self.trackers[i];
            let v = if brake {
                tracker.brake(dt, s.acceleration)
            } else {
                if line.done < line.ticks {
                    line.done += 1;
                }
                let error = line.reference() - self.position[i];
                tracker.step(error, line.to - self.position[i], dt, s.velocity, s.acceleration)
            };
            self.position[i] += v * dt;
        }
    }

    /// Rests where the axes are: no speed, and the references there, so nothing moves until a new target.
    pub fn hold(&mut self) {
        self.trackers = [AxisTracker::default(); SPARE_AXES];
        for (line, p) in self.lines.iter_mut().zip(self.position) {
            *line = Line {
                from: p,
                to: p,
                ticks: 1,
                done: 1,
            };
        }
    }

    /// The axes are at `steps` (counted by the step scheduler), at rest there.
    pub fn at_steps(&mut self, steps: [i64; SPARE_AXES]) {
        for (i, s) in steps.iter().enumerate() {
            self.position[i] = *s as f32 / self.settings[i].steps_per_unit;
        }
        self.hold();
    }

    /// Motor step targets of the commanded positions (round to nearest; saturating far outside any travel).
    pub fn steps(&self) -> [i64; SPARE_AXES] {
        core::array::from_fn(|i| (self.position[i] * self.settings[i].steps_per_unit).round_to_i64())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const DT: f32 = 0.001;

    fn axis(velocity: f32, acceleration: f32) -> SpareAxisSettings {
        SpareAxisSettings {
            enabled: true,
            steps_per_unit: 200.0,
            velocity,
            acceleration,
            travel: [-500.0, 500.0],
        }
    }

    /// Runs `ticks` ticks, returning each tick's positions.
    fn run(s: &mut SpareAxes, ticks: usize, brake: bool) -> std::vec::Vec<[f32; 2]> {
        (0..ticks)
            .map(|_| {
                s.tick(DT, brake);
                s.position()
            })
            .collect()
    }

    #[test]
    fn an_axis_interpolates_to_its_column_and_holds_there_through_a_gap() {
        let mut s = SpareAxes::new([axis(50.0, 500.0), axis(50.0, 500.0)]);
        s.take(&[Some(1.0), None], 20);
        let path = run(&mut s, 400, false);
        // The reference walks 1/20 per tick: the tracker stays behind it, never ahead, and arrives.
        for (k, p) in path.iter().enumerate().take(20) {
            assert!(p[0] <= (k as f32 + 1.0) / 20.0 + 1e-6, "tick {k}: {p:?}");
        }
        assert!((s.position()[0] - 1.0).abs() < 1e-5, "{:?}", s.position());
        assert_eq!(s.position()[1], 0.0, "no column, no motion");
        assert_eq!(s.steps(), [200, 0]);
        // A setpoint without the column (a gap in it) keeps the target.
        s.take(&[None, None], 20);
        run(&mut s, 100, false);
        assert_eq!(s.steps(), [200, 0]);
        assert!(s.at_rest());
    }

    #[test]
    fn a_target_outside_the_travel_is_limited_to_its_end() {
        let mut s = SpareAxes::new([axis(100.0, 1_000.0), SpareAxisSettings::NONE]);
        s.take(&[Some(1e9), Some(3.0)], 1);
        run(&mut s, 20_000, false);
        assert_eq!(s.target(), [500.0, 0.0]);
        assert_eq!(s.steps(), [100_000, 0], "an axis not fitted never steps");
    }

    #[test]
    fn an_axis_not_fitted_takes_no_time() {
        let mut s = SpareAxes::new([SpareAxisSettings::NONE; 2]);
        assert!(!s.any());
        s.take(&[Some(1.0), Some(1.0)], 1);
        run(&mut s, 10, false);
        assert_eq!((s.position(), s.steps()), ([0.0; 2], [0; 2]));
    }

    #[test]
    fn the_settings_ranges() {
        let good = axis(50.0, 500.0);
        assert!(good.is_valid(200_000.0));
        let bad = [
            SpareAxisSettings {
                steps_per_unit: 0.5,
                ..good
            },
            SpareAxisSettings {
                steps_per_unit: f32::NAN,
                ..good
            },
            SpareAxisSettings { velocity: 0.0, ..good },
            SpareAxisSettings {
                velocity: 2_000.0,
                ..good
            },
            SpareAxisSettings {
                acceleration: -1.0,
                ..good
            },
            SpareAxisSettings {
                acceleration: f32::INFINITY,
                ..good
            },
            SpareAxisSettings {
                travel: [1.0, 2.0],
                ..good
            },
            SpareAxisSettings {
                travel: [-1.0, -0.5],
                ..good
            },
            SpareAxisSettings {
                travel: [f32::NEG_INFINITY, 1.0],
                ..good
            },
        ];
        for b in bad {
            assert!(!b.is_valid(200_000.0), "{b:?}");
        }
        assert!(!SpareAxes::finite(&[Some(f32::NAN), None]));
        assert!(SpareAxes::finite(&[None, Some(-3.0)]));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Whatever the targets, each axis's speed and acceleration stay within its own limits, its position within
        /// its travel, and braking (STOP) brings both to rest within v/a plus a tick, moving no further than
        /// v^2/(2a) plus a tick's travel.
        #[test]
        fn limits_hold_and_a_stop_stops(
            v in [0.5f32..200.0, 0.5f32..200.0],
            a in [1.0f32..5_000.0, 1.0f32..5_000.0],
            targets in proptest::collection::vec(([-800.0f32..800.0, -800.0f32..800.0], 1u32..60, 1usize..80), 1..12),
            stop_after in 0usize..400,
        ) {
            let settings = [axis(v[0], a[0]), axis(v[1], a[1])];
            let mut s = SpareAxes::new(settings);
            let mut prev_v = [0.0f32; 2];
            let mut ticks = 0;
            let check = |s: &SpareAxes, prev_v: &mut [f32; 2]| -> Result<(), TestCaseError> {
                for i in 0..2 {
                    let vel = s.velocity()[i];
                    prop_assert!(vel.abs() <= v[i] * (1.0 + 1e-5), "axis {i}: speed {vel} over {}", v[i]);
                    let acc = (vel - prev_v[i]) / DT;
                    prop_assert!(acc.abs() <= a[i] * (1.0 + 1e-3) + 1e-2, "axis {i}: acceleration {acc} over {}", a[i]);
                    let p = s.position()[i];
                    prop_assert!((-500.0 - 1e-3..=500.0 + 1e-3).contains(&p), "axis {i} at {p}");
                }
                *prev_v = s.velocity();
                Ok(())
            };
            'stream: for (target, interval, hold) in &targets {
                s.take(&[Some(target[0]), Some(target[1])], *interval);
                for _ in 0..*hold {
                    s.tick(DT, false);
                    check(&s, &mut prev_v)?;
                    ticks += 1;
                    if ticks >= stop_after {
                        break 'stream;
                    }
                }
            }
            let (at, speed) = (s.position(), s.velocity());
            let most = [0, 1].map(|i| (speed[i].abs() / a[i] / DT) as usize + 2);
            for t in 0..most[0].max(most[1]) {
                s.tick(DT, true);
                check(&s, &mut prev_v)?;
                for (i, &last) in most.iter().enumerate() {
                    if t >= last {
                        prop_assert_eq!(s.velocity()[i], 0.0, "axis {} still moving", i);
                    }
                }
            }
            prop_assert!(s.at_rest());
            for i in 0..2 {
                let travel = (s.position()[i] - at[i]).abs();
                let bound = speed[i] * speed[i] / (2.0 * a[i]) + speed[i].abs() * DT + 1e-3;
                prop_assert!(travel <= bound, "axis {i}: braked over {travel}, bound {bound}");
            }
        }
    }
}
