//! The rig file's controller sections, the device's own settings sections by their field names: `[[axes]]` (each
//! motor's steps per unit and direction, in actuator order), `[motion]` (pose limits, and the actuators' limits,
//! each actuator its kind's on the trainer model's drives when the file gives none), `[inputs]` (which inputs are
//! active low, by name, and debouncing), `[supervisor]` (supply sensing and sequencing delays) and `[homing]` (each
//! axis's switch and search in the axis's units, and the order). Each is optional and takes the trainer model's
//! values on this rig when omitted; together with the geometry they make the [`RigRecord`] a device stores.

use ringpod_core::protocol::MotionSettings;
#[cfg(doc)]
use ringpod_core::protocol::RigRecord;
use ringpod_core::safety::debounce::{InputBit, InputConfig};
use serde::{Deserialize, Serialize};

use super::{err, RigError};

/// Input wiring.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputsSpec {
    /// Inputs active when their pin is low, by name: e_stop, home1-home6, end1-end6, logic_ok, power_ok.
    pub active_low: Vec<String>,
    /// Equal samples, 1 ms apart, before a level counts (1-50).
    pub debounce_ms: u8,
}

/// `[motion]`: the pose limits, and optionally the actuators' (a rig that says nothing of its motors' speeds gets
/// the trainer model's for each actuator's kind, as a device gives them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Velocity limit per pose axis x, y, z (m/s), roll, pitch, yaw (rad/s).
    #[serde(deserialize_with = "super::exact::array")]
    pub pose_velocity: [f32; 6],
    /// Acceleration limit per pose axis (m/s^2, rad/s^2).
    #[serde(deserialize_with = "super::exact::array")]
    pub pose_acceleration: [f32; 6],
    /// Velocity limit per actuator in actuator order: rad/s for carriages and shoulders, m/s for linear actuators.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::exact::option"
    )]
    pub actuator_velocity: Option<[f32; 6]>,
    /// Acceleration limit per actuator (rad/s^2, m/s^2).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::exact::option"
    )]
    pub actuator_acceleration: Option<[f32; 6]>,
}

impl MotionSpec {
    /// The device's section: this file's limits over `defaults` (the rig's default record's).
    pub(super) fn settings(&self, defaults: &MotionSettings) -> MotionSettings {
        MotionSettings {
            pose_velocity: self.pose_velocity,
            pose_acceleration: self.pose_acceleration,
            actuator_velocity: self.actuator_velocity.unwrap_or(defaults.actuator_velocity),
            actuator_acceleration: self.actuator_acceleration.unwrap_or(defaults.actuator_acceleration),
        }
    }

    /// The section written out in full.
    pub(super) fn of(m: &MotionSettings) -> Self {
        Self {
            pose_velocity: m.pose_velocity,
            pose_acceleration: m.pose_acceleration,
            actuator_velocity: Some(m.actuator_velocity),
            actuator_acceleration: Some(m.actuator_acceleration),
        }
    }
}

/// Every input by its name in the file.
fn names() -> impl Iterator<Item = (String, InputBit)> {
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

impl InputsSpec {
    /// The inputs section these names make (the device checks the debouncing).
    pub fn config(&self) -> Result<InputConfig, RigError> {
        let mut mask = 0u16;
        for name in &self.active_low {
            let Some((_, bit)) = names().find(|(n, _)| n == name) else {
                let all: Vec<String> = names().map(|(n, _)| n).collect();
                return err(
                    "inputs.active_low",
                    format!("no input {name:?}; inputs: {}", all.join(", ")),
                );
            };
            mask |= bit.mask();
        }
        Ok(InputConfig {
            active_low: mask,
            debounce_samples: self.debounce_ms,
        })
    }

    /// The inputs section by names.
    pub fn of(inputs: &InputConfig) -> Self {
        Self {
            active_low: names()
                .filter(|(_, b)| inputs.active_low & b.mask() != 0)
                .map(|(n, _)| n)
                .collect(),
            debounce_ms: inputs.debounce_samples,
        }
    }
}

#[cfg(test)]
mod tests {
    use embassy_futures::block_on;
    use ringpod_core::sim::RamFlash;
    use ringpod_core::store::{restore, store};

    use super::super::{parse, RigFile};
    use ringpod_core::controller::ControllerConfig;

    /// The trainer model's rig file with every controller section written out and changed from the defaults.
    fn with_sections() -> String {
        let model = RigFile::of(
            &ringpod_core::kinematics::presets::TRAINER_MODEL,
            ringpod_core::kinematics::presets::Preset::TrainerModel.home(),
            None,
            Vec::new(),
        );
        let mut text = model.to_toml().unwrap();
        for (steps, reverse) in [(25_600, false), (12_800, true), (25_600, false), (25_600, false)] {
            text += &format!("\n[[axes]]\nsteps_per_unit = {steps}\nreverse = {reverse}\n");
        }
        text += "\n[[axes]]\nsteps_per_unit = 3200000\n\n[[axes]]\nsteps_per_unit = 1600000\nreverse = true\n";
        text += "\n[motion]\npose_velocity = [0.04, 0.04, 0.03, 0.8, 0.8, 1.5]\npose_acceleration = [1, 1, 1, 10, 10, 10]\n";
        text += "\n[inputs]\nactive_low = [\"home1\", \"home2\", \"home3\", \"home4\", \"end5\", \"end6\"]\ndebounce_ms = 5\n";
        text +=
            "\n[supervisor]\nlogic_sense = true\npower_sense = false\nlogic_settle_ms = 150\npower_settle_ms = 400\n";
        text += "supply_timeout_ms = 2000\ndriver_off_ms = 30\ndischarge_ms = 1500\n";
        text += "\n[homing]\norder = [5, 4, 0, 2, 1, 3]\n";
        for a in 0..6 {
            let (toward, switch, search) = if a < 4 {
                ("plus", 0.01, 0.35)
            } else {
                ("minus", -0.05, 0.04)
            };
            text += &format!(
                "\n[[homing.axes]]\ntoward = \"{toward}\"\nswitch = {switch}\nsearch = {search}\nbackoff = 0.002\nfast = 0.02\nslow = 0.0025\n"
            );
        }
        text
    }

    /// TOML -> typed -> postcard record in flash -> typed, exactly; and back to a file that gives the same record.
    #[test]
    fn a_rig_file_round_trips_through_the_device_record_exactly() {
        let record = parse(&with_sections()).unwrap().check().unwrap().record;
        let m = &record.machine;
        assert_eq!(m.axes[1].steps_per_unit, 12_800.0);
        assert!(m.axes[1].reverse && m.axes[5].reverse && !m.axes[0].reverse);
        assert_eq!(m.axes[4].steps_per_unit, 3.2e6);
        assert_eq!(m.motion.pose_velocity[5], 1.5);
        assert_eq!(m.inputs.debounce_samples, 5);
        assert_eq!(m.inputs.active_low, 0b1_1000_0001_1110);
        assert!(!m.supervisor.power_sense);
        assert_eq!(m.supervisor.discharge_ms, 1_500);
        assert_eq!(m.homing.order, [5, 4, 0, 2, 1, 3]);
        assert_eq!(m.homing.axes[4].switch, -0.05);
        assert_eq!(m.homing.axes[0].toward, ringpod_core::protocol::Toward::Plus);

        let mut bytes = vec![0xff; 8 * 1024];
        let mut flash = RamFlash::<2048>::new(&mut bytes);
        let range = flash.range();
        let config = ControllerConfig::from_record(&record).unwrap();
        block_on(store(&mut flash, range.clone(), &config)).unwrap();
        let (config, report) = block_on(restore(&mut flash, range, ControllerConfig::trainer_model()));
        assert_eq!(report.rig, ringpod_core::protocol::RigSource::Stored);
        assert_eq!(config.rig(), record);

        let geometry = record.geometry().unwrap();
        let mut shown = RigFile::of(&geometry, record.home, None, Vec::new()).with_sections(&record);
        shown.name = record.name().to_owned();
        let text = shown.to_toml().unwrap();
        assert!(
            text.contains("pose_velocity = [0.04, 0.04, 0.03, 0.8, 0.8, 1.5]"),
            "{text}"
        );
        let again = parse(&text).unwrap().check().unwrap().record;
        assert_eq!(again, record);
    }

    /// `[motion]` without actuator limits gives each actuator its kind's (the rig file's and the device's defaults
    /// agree); with them, they travel to the device; beyond the step generator at the axis's steps per unit, the
    /// device's check names the actuator.
    #[test]
    fn actuator_limits_default_by_kind_and_are_checked_against_the_step_rate() {
        let text = with_sections();
        let record = parse(&text).unwrap().check().unwrap().record;
        let m = record.machine.motion;
        assert_eq!(m.actuator_velocity, [2.4, 2.4, 2.4, 2.4, 0.06, 0.06]);
        assert_eq!(m.actuator_acceleration, [100.0, 100.0, 100.0, 100.0, 5.0, 5.0]);
        let pose = "pose_acceleration = [1, 1, 1, 10, 10, 10]\n";
        let own = text.replace(
            pose,
            &format!(
                "{pose}actuator_velocity = [3, 3, 3, 3, 0.05, 0.1]\nactuator_acceleration = [50, 50, 50, 50, 2, 2]\n"
            ),
        );
        let record = parse(&own).unwrap().check().unwrap().record;
        let m = record.machine.motion;
        assert_eq!(m.actuator_velocity, [3.0, 3.0, 3.0, 3.0, 0.05, 0.1]);
        assert_eq!(m.actuator_acceleration[5], 2.0);
        // Axis 4 has 3.2 M steps/m: 0.07 m/s asks 224 k steps/s of a generator that makes 200 k.
        let fast = own.replace("0.05, 0.1]", "0.07, 0.1]");
        let e = parse(&fast).unwrap().check().expect_err("refused");
        assert_eq!(e.key, "motion.actuator_velocity[4]", "{e}");
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
            (
                "order = [5, 4, 0, 2, 1, 3]",
                "order = [5, 4, 0, 2, 1, 1]",
                "homing.order",
            ),
            ("search = 0.35", "search = 0", "homing.axes[0].search"),
            ("slow = 0.0025", "slow = -1", "homing.axes[0].slow"),
        ];
        for (from, to, key) in cases {
            assert!(good.contains(from), "{from}");
            let bad = good.replacen(from, to, 1);
            let e = parse(&bad).unwrap().check().unwrap_err();
            assert!(e.to_string().starts_with(key), "{key}: {e}");
        }
        // Five motors for six actuators.
        let five = good.replacen("[[axes]]\nsteps_per_unit = 3200000\n", "", 1);
        let e = parse(&five).unwrap().check().unwrap_err();
        assert!(e.to_string().starts_with("axes"), "{e}");
        // An unknown key in a section.
        let typo = good.replacen("reverse = true", "reversed = true", 1);
        assert!(parse(&typo).is_err());
    }
}
