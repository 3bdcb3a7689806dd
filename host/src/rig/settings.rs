//! The rig file's controller sections: `[[axes]]` (each motor's steps per unit and direction, in actuator order),
//! `[motion]` (pose limits), `[inputs]` (which inputs are active low, debouncing) and `[supervisor]` (supply
//! sensing and sequencing delays, the core's `SupervisorConfig` by its field names). Each is optional and takes the
//! trainer model's values when omitted; together with the geometry they make the [`RigRecord`] a device stores.

use ringpod_core::controller::ControllerConfig;
use ringpod_core::kinematics::{AxisKind, Mechanism, RingPlatform};
use ringpod_core::protocol::RigRecord;
use ringpod_core::safety::debounce::InputBit;
use ringpod_core::safety::SupervisorConfig;
use serde::{Deserialize, Serialize};

use super::{err, RigError, RigFile};

/// One motor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// Motor steps per carriage turn (ring axes, an integer) or per metre (linear axes).
    pub steps_per_unit: f64,
    /// The motor turns the other way round (its steps, homing direction and switch position are mirrored).
    #[serde(default)]
    pub reverse: bool,
}

/// Pose limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Velocity limit per pose axis x, y, z (m/s), roll, pitch, yaw (rad/s); the device holds them as `f32`.
    pub pose_velocity: [f64; 6],
    /// Acceleration limit per pose axis (m/s^2, rad/s^2).
    pub pose_acceleration: [f64; 6],
}

/// Input wiring.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputsSpec {
    /// Inputs active when their pin is low, by name: e_stop, home1-home6, end1-end6, logic_ok, power_ok.
    pub active_low: Vec<String>,
    /// Equal samples, 1 ms apart, before a level counts (1-50).
    pub debounce_ms: u8,
}

/// Every input by its name in the file.
fn inputs() -> impl Iterator<Item = (String, InputBit)> {
    let axes = (0..6u8).flat_map(|a| {
        [
            (format!("home{}", a + 1), InputBit::Home(a)),
            (format!("end{}", a + 1), InputBit::Limit(a)),
        ]
    });
    [("e_stop".to_owned(), InputBit::EStop)].into_iter().chain(axes).chain([
        ("logic_ok".to_owned(), InputBit::LogicOk),
        ("power_ok".to_owned(), InputBit::PowerOk),
    ])
}

impl RigFile {
    /// The record a device stores: geometry and home pose with the file's sections (or the defaults), checked by
    /// the controller's own code; each error names its key.
    pub(super) fn record(&self, record: RigRecord) -> Result<RigRecord, RigError> {
        let mut record = record;
        let geometry = record.geometry().or_else(|e| err("rig", e.to_string()))?;
        let kinds = RingPlatform::<f64>::new(&geometry).axes();
        if !self.axes.is_empty() && self.axes.len() != 6 {
            return err(
                "axes",
                format!("{} entries: one per actuator (6), or none", self.axes.len()),
            );
        }
        for (i, (spec, kind)) in self.axes.iter().zip(kinds).enumerate() {
            let key = format!("axes[{i}].steps_per_unit");
            let v = spec.steps_per_unit;
            if !(v.is_finite() && (1.0..=16_777_216.0).contains(&v)) {
                return err(key, format!("{v} is not a step count from 1 to 16,777,216"));
            }
            let scale = &mut record.scales[i];
            match kind {
                AxisKind::Ring if v.fract() != 0.0 => {
                    return err(key, "steps per carriage turn are a whole number");
                }
                AxisKind::Ring => {
                    scale.steps_per_turn = v as i64;
                    scale.steps_per_unit = v as f32 / core::f32::consts::TAU;
                }
                AxisKind::Linear | AxisKind::Angle => scale.steps_per_unit = v as f32,
            }
            scale.invert = spec.reverse;
        }
        if let Some(m) = &self.motion {
            for (name, values) in [
                ("pose_velocity", &m.pose_velocity),
                ("pose_acceleration", &m.pose_acceleration),
            ] {
                if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                    return err(
                        format!("motion.{name}"),
                        format!("value {} is not a positive number", i + 1),
                    );
                }
            }
            record.pose_velocity = m.pose_velocity.map(|v| v as f32);
            record.pose_acceleration = m.pose_acceleration.map(|v| v as f32);
        }
        if let Some(spec) = &self.inputs {
            let mut mask = 0u16;
            for name in &spec.active_low {
                let Some((_, bit)) = inputs().find(|(n, _)| n == name) else {
                    let names: Vec<String> = inputs().map(|(n, _)| n).collect();
                    return err(
                        "inputs.active_low",
                        format!("no input {name:?}; inputs: {}", names.join(", ")),
                    );
                };
                mask |= bit.mask();
            }
            if !(1..=50).contains(&spec.debounce_ms) {
                return err("inputs.debounce_ms", format!("{} is not 1 to 50 ms", spec.debounce_ms));
            }
            record.inputs.active_low = mask;
            record.inputs.debounce_samples = spec.debounce_ms;
        }
        if let Some(s) = self.supervisor {
            if !s.is_valid() {
                return err(
                    "supervisor",
                    format!(
                        "every delay at most {} ms, and supply_timeout_ms above 0 with a sensed supply",
                        SupervisorConfig::LONGEST_MS
                    ),
                );
            }
            record.supervisor = s;
        }
        ControllerConfig::from_record(&record)
            .or_else(|e| err("rig", format!("the controller cannot drive it: {e}")))?;
        Ok(record)
    }

    /// This file with the sections of `record` written out (what `device rig show` prints).
    pub fn with_sections(mut self, record: &RigRecord) -> Self {
        let kinds = record
            .geometry()
            .map(|g| RingPlatform::<f64>::new(&g).axes())
            .unwrap_or([AxisKind::Ring; 6]);
        self.axes = record
            .scales
            .iter()
            .zip(kinds)
            .map(|(s, k)| AxisSpec {
                steps_per_unit: match k {
                    AxisKind::Ring => s.steps_per_turn as f64,
                    AxisKind::Linear | AxisKind::Angle => f64::from(s.steps_per_unit),
                },
                reverse: s.invert,
            })
            .collect();
        // The f32's shortest decimal: 0.05, not 0.05000000074505806.
        let decimal = |v: f32| v.to_string().parse::<f64>().unwrap_or(f64::from(v));
        self.motion = Some(MotionSpec {
            pose_velocity: record.pose_velocity.map(decimal),
            pose_acceleration: record.pose_acceleration.map(decimal),
        });
        self.inputs = Some(InputsSpec {
            active_low: inputs()
                .filter(|(_, b)| record.inputs.active_low & b.mask() != 0)
                .map(|(n, _)| n)
                .collect(),
            debounce_ms: record.inputs.debounce_samples,
        });
        self.supervisor = Some(record.supervisor);
        self
    }
}

#[cfg(test)]
mod tests {
    use embassy_futures::block_on;
    use ringpod_core::store::{restore, store_rig, RamFlash};

    use super::super::{from_text, RigFile};
    use super::*;

    /// The trainer model's rig file with every controller section written out and changed from the defaults.
    fn with_sections() -> String {
        let model = RigFile::of(
            &ringpod_core::kinematics::presets::TRAINER_MODEL,
            ringpod_core::kinematics::presets::Preset::TrainerModel.home(),
            None,
            Vec::new(),
        );
        let mut text = toml::to_string(&model).unwrap();
        for (steps, reverse) in [(25_600, false), (12_800, true), (25_600, false), (25_600, false)] {
            text += &format!("\n[[axes]]\nsteps_per_unit = {steps}\nreverse = {reverse}\n");
        }
        text += "\n[[axes]]\nsteps_per_unit = 3200000\n\n[[axes]]\nsteps_per_unit = 1600000\nreverse = true\n";
        text += "\n[motion]\npose_velocity = [0.04, 0.04, 0.03, 0.8, 0.8, 1.5]\npose_acceleration = [1, 1, 1, 10, 10, 10]\n";
        text += "\n[inputs]\nactive_low = [\"home1\", \"home2\", \"home3\", \"home4\", \"end5\", \"end6\"]\ndebounce_ms = 5\n";
        text +=
            "\n[supervisor]\nlogic_sense = true\npower_sense = false\nlogic_settle_ms = 150\npower_settle_ms = 400\n";
        text += "supply_timeout_ms = 2000\ndriver_off_ms = 30\ndischarge_ms = 1500\n";
        text
    }

    /// TOML -> typed -> postcard record in flash -> typed, exactly; and back to a file that gives the same record.
    #[test]
    fn a_rig_file_round_trips_through_the_device_record_exactly() {
        let record = from_text(&with_sections()).unwrap().check().unwrap().record;
        assert_eq!(record.scales[1].steps_per_turn, 12_800);
        assert!(record.scales[1].invert && record.scales[5].invert && !record.scales[0].invert);
        assert_eq!(record.scales[4].steps_per_unit, 3.2e6);
        assert_eq!(record.pose_velocity[5], 1.5);
        assert_eq!(record.inputs.debounce_samples, 5);
        assert_eq!(record.inputs.active_low, 0b1_1000_0001_1110);
        assert!(!record.supervisor.power_sense);
        assert_eq!(record.supervisor.discharge_ms, 1_500);

        let mut bytes = vec![0xff; 8 * 1024];
        let mut flash = RamFlash::<2048>::new(&mut bytes);
        let range = flash.range();
        block_on(store_rig(&mut flash, range.clone(), &record)).unwrap();
        let (config, report) = block_on(restore(&mut flash, range, ControllerConfig::trainer_model()));
        assert_eq!(report.rig, ringpod_core::protocol::RigSource::Stored);
        assert_eq!(config.rig(), record);

        let geometry = record.geometry().unwrap();
        let mut shown = RigFile::of(&geometry, record.home, None, Vec::new()).with_sections(&record);
        shown.name = record.name().to_owned();
        let again = from_text(&toml::to_string(&shown).unwrap())
            .unwrap()
            .check()
            .unwrap()
            .record;
        assert_eq!(again, record);
    }

    #[test]
    fn every_bad_section_names_its_key() {
        let good = with_sections();
        let cases = [
            (
                "steps_per_unit = 3200000\n",
                "steps_per_unit = 0\n",
                "axes[4].steps_per_unit",
            ),
            (
                "steps_per_unit = 12800\n",
                "steps_per_unit = 12800.5\n",
                "axes[1].steps_per_unit",
            ),
            ("0.8, 0.8, 1.5]", "0.8, 0.8, -1.5]", "motion.pose_velocity"),
            ("\"end6\"]", "\"end7\"]", "inputs.active_low"),
            ("debounce_ms = 5", "debounce_ms = 0", "inputs.debounce_ms"),
            ("discharge_ms = 1500", "discharge_ms = 600000", "supervisor"),
        ];
        for (from, to, key) in cases {
            assert!(good.contains(from), "{from}");
            let bad = good.replacen(from, to, 1);
            let e = from_text(&bad).unwrap().check().unwrap_err();
            assert!(e.to_string().starts_with(key), "{key}: {e}");
        }
        // Five motors for six actuators.
        let five = good.replacen("[[axes]]\nsteps_per_unit = 3200000\n", "", 1);
        let e = from_text(&five).unwrap().check().unwrap_err();
        assert!(e.to_string().starts_with("axes"), "{e}");
        // An unknown key in a section.
        let typo = good.replacen("reverse = true", "reversed = true", 1);
        assert!(from_text(&typo).is_err());
    }
}
