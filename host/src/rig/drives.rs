//! `[[drives]]` of a rig file: what each axis's motor gives at a speed, through its gear or screw, so that a motion's
//! demand can be set against it.
//!
//! ```toml
//! [[drives]]
//! axes = [1, 2, 3, 4]              # axis numbers, 1-based, in actuator order
//! motor = "FL20, 8:1 ring gear"    # for reports
//! pull_out = [[0, 0.016], [300, 0.014], [900, 0.008], [1800, 0]]   # [motor rpm, N m], rising speeds from 0
//! gear_ratio = 8                   # rotary axes: motor turns per axis turn
//! efficiency = 0.9
//!
//! [[drives]]
//! axes = [5, 6]
//! pull_out = [[0, 0.016], [1800, 0]]
//! lead = 0.002                     # linear axes: axis travel per motor turn (m)
//! efficiency = 0.35
//! ```
//!
//! An axis takes at most one drive; axes without one are reported without a margin. Between table points the
//! torque is interpolated linearly; beyond the last speed the motor gives nothing (it cannot turn that fast).

use std::f64::consts::TAU;

use ringpod_core::kinematics::presets::Preset;
use ringpod_core::kinematics::AxisKind;
use serde::{Deserialize, Serialize};

use super::{err, RigError};

/// The largest values a drive's numbers can take: far past any motor, gear or screw a platform uses, and where a
/// number stops being a drive's and is a broken one.
const MAX_RPM: f64 = 1e6;
const MAX_TORQUE: f64 = 1e4;
const MAX_GEAR: f64 = 1e4;
const MAX_LEAD: f64 = 1.0;

/// One `[[drives]]` entry as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// Axis numbers (1-based, actuator order) this drive moves.
    pub axes: Vec<usize>,
    /// What it is, for reports.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub motor: String,
    /// Pull-out torque of the motor: `[rpm, N m]` pairs, speeds rising from 0.
    pub pull_out: Vec<[f64; 2]>,
    /// Rotary axes: motor turns per axis turn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gear_ratio: Option<f64>,
    /// Linear axes: axis travel per motor turn (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead: Option<f64>,
    /// Share of the motor's power that reaches the axis (0 to 1].
    pub efficiency: f64,
    /// Where the numbers come from.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub source: String,
}

/// How a motor turn becomes axis motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transmission {
    /// Motor turns per axis turn.
    Gear(f64),
    /// Axis metres per motor turn.
    Lead(f64),
}

/// A checked drive of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// Description for reports.
    pub motor: String,
    /// `(rpm, N m)`, speeds rising from 0.
    pub pull_out: Vec<(f64, f64)>,
    /// Gear or lead.
    pub transmission: Transmission,
    /// (0, 1].
    pub efficiency: f64,
}

impl Drive {
    /// The motor speed (rpm) at an axis speed (rad/s or m/s).
    pub fn motor_rpm(&self, axis_speed: f64) -> f64 {
        let turns_per_s = match self.transmission {
            Transmission::Gear(ratio) => axis_speed.abs() * ratio / TAU,
            Transmission::Lead(lead) => axis_speed.abs() / lead,
        };
        turns_per_s * 60.0
    }

    /// The motor's pull-out torque at `rpm` (N m): linear between the table's points, 0 beyond its last speed.
    pub fn motor_torque(&self, rpm: f64) -> f64 {
        let table = &self.pull_out;
        match table.iter().position(|&(s, _)| s >= rpm) {
            Some(0) => table[0].1,
            Some(i) => {
                let ((s0, t0), (s1, t1)) = (table[i - 1], table[i]);
                t0 + (t1 - t0) * (rpm - s0) / (s1 - s0)
            }
            None => 0.0,
        }
    }

    /// What the drive gives at the axis at an axis speed: N m for a rotary axis, N for a linear one.
    pub fn available(&self, axis_speed: f64) -> f64 {
        let torque = self.motor_torque(self.motor_rpm(axis_speed)) * self.efficiency;
        match self.transmission {
            Transmission::Gear(ratio) => torque * ratio,
            Transmission::Lead(lead) => torque * TAU / lead,
        }
    }
}

/// Checks the `[[drives]]` of a rig against its axes: one drive per axis at most, a gear ratio for rotary axes and a
/// lead for linear ones, a pull-out table with rising speeds from 0 and torques >= 0.
pub fn check(specs: &[DriveSpec], axes: &[AxisKind; 6]) -> Result<[Option<Drive>; 6], RigError> {
    let mut out: [Option<Drive>; 6] = Default::default();
    for (i, d) in specs.iter().enumerate() {
        let key = |k: &str| format!("drives[{i}].{k}");
        if d.axes.is_empty() {
            return err(key("axes"), "names at least one axis (1 to 6)");
        }
        if !(d.efficiency.is_finite() && d.efficiency > 0.0 && d.efficiency <= 1.0) {
            return err(key("efficiency"), format!("{} is not in (0, 1]", d.efficiency));
        }
        if d.pull_out.len() < 2 {
            return err(key("pull_out"), "at least two [rpm, N m] points");
        }
        if d.pull_out[0][0] != 0.0 {
            return err(
                key("pull_out"),
                "the first point is at 0 rpm (the holding end of the curve)",
            );
        }
        for (j, p) in d.pull_out.iter().enumerate() {
            if !((0.0..=MAX_RPM).contains(&p[0]) && (0.0..=MAX_TORQUE).contains(&p[1])) {
                return err(
                    key("pull_out"),
                    format!("point {}: speed 0 to 1e6 rpm, torque 0 to 1e4 N m", j + 1),
                );
            }
            if j > 0 && p[0] <= d.pull_out[j - 1][0] {
                return err(key("pull_out"), format!("point {}: speeds must rise", j + 1));
            }
        }
        // Positive and at most `most`: a gear of 1e300 or a lead of a kilometre a turn is a broken number.
        let positive = |v: Option<f64>, most: f64| v.filter(|x| *x > 0.0 && *x <= most);
        for &axis in &d.axes {
            if !(1..=6).contains(&axis) {
                return err(key("axes"), format!("{axis} is not an axis (1 to 6)"));
            }
            let transmission = match (axes[axis - 1], d.gear_ratio, d.lead) {
                (_, Some(_), Some(_)) => return err(key("lead"), "a drive has a gear_ratio or a lead, not both"),
                (AxisKind::Ring | AxisKind::Angle, Some(g), None) => Transmission::Gear(
                    positive(Some(g), MAX_GEAR)
                        .ok_or_else(|| RigError::new(key("gear_ratio"), "a positive number, at most 1e4"))?,
                ),
                (AxisKind::Ring | AxisKind::Angle, _, _) => {
                    return err(key("gear_ratio"), format!("axis {axis} turns: give its gear_ratio"))
                }
                (AxisKind::Linear, None, Some(l)) => Transmission::Lead(
                    positive(Some(l), MAX_LEAD)
                        .ok_or_else(|| RigError::new(key("lead"), "a positive length (m), at most 1 m a turn"))?,
                ),
                (AxisKind::Linear, _, _) => {
                    return err(
                        key("lead"),
                        format!("axis {axis} is linear: give its lead (m per turn)"),
                    )
                }
            };
            let slot = &mut out[axis - 1];
            if slot.is_some() {
                return err(key("axes"), format!("axis {axis} already has a drive"));
            }
            *slot = Some(Drive {
                motor: d.motor.clone(),
                pull_out: d.pull_out.iter().map(|p| (p[0], p[1])).collect(),
                transmission,
                efficiency: d.efficiency,
            });
        }
    }
    Ok(out)
}

/// The drives of a preset: the trainer model's FL20s; none for the reference geometries.
pub fn of_preset(preset: Preset) -> Vec<DriveSpec> {
    match preset {
        Preset::TrainerModel => trainer_model(),
        Preset::TrainerElbow => trainer_elbow(),
        _ => Vec::new(),
    }
}

/// The 1:20 trainer model's FL20 drives, as far as the sources give them (see `source`).
fn trainer_model() -> Vec<DriveSpec> {
    // NEMA 8 (20 mm) hybrid stepper, FL20STH30 size: 0.018 N m holding. The sources give the motor family and its
    // 200 steps/rev, no gearing and no torque curve: the 8:1 ring gear and the 2 mm lead are the specification's
    // assumptions (FIRMWARE.md, "Step rates"), and the curve's shape is assumed from NEMA 8 catalogue curves on a
    // 24 V chopper driver (a small, low-inductance motor: slow fall, nothing left near 3,600 rpm).
    let pull_out = vec![
        [0.0, 0.016],
        [300.0, 0.015],
        [600.0, 0.013],
        [1200.0, 0.009],
        [1800.0, 0.006],
        [2400.0, 0.0035],
        [3000.0, 0.0015],
        [3600.0, 0.0],
    ];
    let source =
        "assumed: FL20STH30 size (0.018 N m holding), NEMA 8 curve shape at 24 V, 8:1 ring gear and 2 mm lead \
                  (the sources give no gearing); measure yours"
            .to_owned();
    vec![
        DriveSpec {
            axes: vec![1, 2, 3, 4],
            motor: "FL20 on the 8:1 ring gear".into(),
            pull_out: pull_out.clone(),
            gear_ratio: Some(8.0),
            lead: None,
            efficiency: 0.9,
            source: source.clone(),
        },
        DriveSpec {
            axes: vec![5, 6],
            motor: "FL20 on a 2 mm lead screw".into(),
            pull_out,
            gear_ratio: None,
            lead: Some(0.002),
            efficiency: 0.35,
            source,
        },
    ]
}

/// The elbow trainer's drives: the model's carriages, and an FL20 on a 20:1 gear at each shoulder (64,000 steps
/// per shoulder turn at 1/16 microstepping, `model::MODEL_SHOULDER`).
fn trainer_elbow() -> Vec<DriveSpec> {
    let mut drives = trainer_model();
    drives[1] = DriveSpec {
        axes: vec![5, 6],
        motor: "FL20 on a 20:1 shoulder gear".into(),
        gear_ratio: Some(20.0),
        lead: None,
        efficiency: 0.7,
        source: "assumed: FL20STH30 size, NEMA 8 curve shape at 24 V, a 20:1 two-stage gear at 70 % (the source \
                 builds no such arm); measure yours"
            .to_owned(),
        ..drives[1].clone()
    };
    drives
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRAINER_AXES: [AxisKind; 6] = [
        AxisKind::Ring,
        AxisKind::Ring,
        AxisKind::Ring,
        AxisKind::Ring,
        AxisKind::Linear,
        AxisKind::Linear,
    ];

    #[test]
    fn torque_interpolates_and_ends_at_the_last_speed() {
        let d = check(&trainer_model(), &TRAINER_AXES).unwrap()[0].clone().unwrap();
        assert_eq!(d.motor_torque(0.0), 0.016);
        assert!((d.motor_torque(150.0) - 0.0155).abs() < 1e-15);
        assert_eq!(d.motor_torque(3600.0), 0.0);
        assert_eq!(d.motor_torque(5000.0), 0.0);
        // 1 rad/s at the carriage is 8 rad/s at the motor: 76.4 rpm.
        assert!((d.motor_rpm(-1.0) - 8.0 * 60.0 / TAU).abs() < 1e-12);
        assert!((d.available(0.0) - 0.016 * 0.9 * 8.0).abs() < 1e-15);
    }

    #[test]
    fn a_lead_screw_turns_torque_into_force() {
        let d = check(&trainer_model(), &TRAINER_AXES).unwrap()[4].clone().unwrap();
        // 0.016 N m through 2 mm per turn at 35 %: 17.6 N.
        assert!((d.available(0.0) - 0.016 * 0.35 * TAU / 0.002).abs() < 1e-12);
        // 0.05 m/s is 25 turns/s = 1,500 rpm.
        assert!((d.motor_rpm(0.05) - 1500.0).abs() < 1e-9);
    }

    #[test]
    fn every_bad_drive_names_its_key() {
        let good = trainer_model();
        type Spoil = fn(&mut Vec<DriveSpec>);
        let cases: [(&str, Spoil); 10] = [
            ("drives[0].axes", |d| d[0].axes = vec![]),
            ("drives[0].axes", |d| d[0].axes = vec![7]),
            ("drives[1].axes", |d| d[1].axes = vec![5, 5]),
            ("drives[0].efficiency", |d| d[0].efficiency = 1.5),
            ("drives[0].pull_out", |d| d[0].pull_out = vec![[0.0, 0.1]]),
            ("drives[0].pull_out", |d| d[0].pull_out[0][0] = 10.0),
            ("drives[0].pull_out", |d| d[0].pull_out[2][0] = 100.0),
            ("drives[0].pull_out", |d| d[0].pull_out[1][1] = -1.0),
            ("drives[0].gear_ratio", |d| d[0].gear_ratio = None),
            ("drives[1].lead", |d| d[1].lead = Some(0.0)),
        ];
        for (key, spoil) in cases {
            let mut d = good.clone();
            spoil(&mut d);
            let e = check(&d, &TRAINER_AXES).unwrap_err();
            assert_eq!(e.key, key, "{e}");
        }
        let mut both = good.clone();
        both[0].lead = Some(0.002);
        assert_eq!(check(&both, &TRAINER_AXES).unwrap_err().key, "drives[0].lead");
    }
}
