//! A field of a settings section, as a refused configuration names it on the wire and in words
//! (`axes[2].steps_per_unit`, `motion.pose_velocity[4]`, `homing.axes[0].search`), and the cause of a refusal
//! ([`ConfigRefusal`]): the device's checks are the only ones, and a host prints their verdict instead of repeating them.

use super::SettingsKind;

/// One field of one section, with the element it concerns: an axis (`axes`, `homing`) or a position in an array
/// value (`stream.margins`, the pose limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Field {
    /// The section.
    pub section: SettingsKind,
    /// The axis or array position, from 0.
    pub index: Option<u8>,
    /// The field.
    pub name: FieldName,
}

/// The fields that have a range, by their names in the settings sections and rig files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)] // Each is named by `as_str` and ranged by `Field::must`.
pub enum FieldName {
    TimeoutMs,
    GrossJumpMs,
    Margins,
    TelemetryHz,
    TickHz,
    PoseVelocity,
    PoseAcceleration,
    ActuatorVelocity,
    ActuatorAcceleration,
    DebounceMs,
    StepsPerUnit,
    Order,
    Search,
    Backoff,
    Fast,
    Slow,
    Switch,
    LogicSettleMs,
    PowerSettleMs,
    SupplyTimeoutMs,
    DriverOffMs,
    DischargeMs,
    HostGoneMs,
    Velocity,
    Acceleration,
    Travel,
    Enabled,
}

impl FieldName {
    /// The field's name in its section.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::TimeoutMs => "timeout_ms",
            Self::GrossJumpMs => "gross_jump_ms",
            Self::Margins => "margins",
            Self::TelemetryHz => "telemetry_hz",
            Self::TickHz => "tick_hz",
            Self::PoseVelocity => "pose_velocity",
            Self::PoseAcceleration => "pose_acceleration",
            Self::ActuatorVelocity => "actuator_velocity",
            Self::ActuatorAcceleration => "actuator_acceleration",
            Self::DebounceMs => "debounce_ms",
            Self::StepsPerUnit => "steps_per_unit",
            Self::Order => "order",
            Self::Search => "search",
            Self::Backoff => "backoff",
            Self::Fast => "fast",
            Self::Slow => "slow",
            Self::Switch => "switch",
            Self::LogicSettleMs => "logic_settle_ms",
            Self::PowerSettleMs => "power_settle_ms",
            Self::SupplyTimeoutMs => "supply_timeout_ms",
            Self::DriverOffMs => "driver_off_ms",
            Self::DischargeMs => "discharge_ms",
            Self::HostGoneMs => "host_gone_ms",
            Self::Velocity => "velocity",
            Self::Acceleration => "acceleration",
            Self::Travel => "travel",
            Self::Enabled => "enabled",
        }
    }
}

impl Field {
    /// A field of `section` that concerns no single element.
    pub const fn of(section: SettingsKind, name: FieldName) -> Self {
        Self {
            section,
            index: None,
            name,
        }
    }

    /// A field of `section` for element `index` (an axis, or a position in an array value).
    pub const fn at(section: SettingsKind, index: usize, name: FieldName) -> Self {
        Self {
            section,
            // Every section has at most six elements.
            index: Some(index as u8),
            name,
        }
    }

    /// What the field must be.
    pub const fn must(&self) -> &'static str {
        match self.name {
            FieldName::TimeoutMs => "1 to 10,000 ms",
            FieldName::GrossJumpMs => "10 to 10,000 ms",
            FieldName::Margins => "0 to 0.1, in its check's unit",
            FieldName::TelemetryHz => "0 to 2,000 samples a second",
            FieldName::HostGoneMs => "1,000 to 60,000 ms",
            FieldName::TickHz => "500, 1,000 or 2,000 ticks a second",
            FieldName::PoseVelocity | FieldName::PoseAcceleration | FieldName::ActuatorAcceleration => {
                "a positive number"
            }
            FieldName::ActuatorVelocity => {
                "a positive number, and no more steps a second at the axis's steps per unit than the step generator \
                 makes (one per minimum step spacing)"
            }
            FieldName::DebounceMs => "1 to 50 ms",
            FieldName::StepsPerUnit => "1 to 16,777,216 steps, and a whole number per carriage turn",
            FieldName::Order => "every axis 0 to 5 once",
            FieldName::Search | FieldName::Backoff | FieldName::Fast | FieldName::Slow => {
                "a positive number, at most 2^31 motor steps"
            }
            FieldName::Switch => "a finite number, at most 2^31 motor steps either way",
            FieldName::SupplyTimeoutMs => "above 0 while a supply is sensed, and at most 60,000 ms",
            FieldName::LogicSettleMs | FieldName::PowerSettleMs | FieldName::DriverOffMs | FieldName::DischargeMs => {
                "at most 60,000 ms"
            }
            FieldName::Velocity => {
                "a positive number, and no more steps a second at the axis's steps per unit than the step generator \
                 makes"
            }
            FieldName::Acceleration => "a positive number",
            FieldName::Travel => "[least, most] with least <= 0 <= most, both finite",
            FieldName::Enabled => {
                "off while the supervisor senses a supply: a fitted spare axis takes the pins of LOGIC_OK, POWER_OK \
                 and the USART1 link"
            }
        }
    }
}

impl core::fmt::Display for Field {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (section, name) = (self.section.name(), self.name.as_str());
        match (self.section, self.name, self.index) {
            (SettingsKind::Homing, FieldName::Order, _) | (_, _, None) => write!(f, "{section}.{name}"),
            (SettingsKind::Axes, _, Some(i)) => write!(f, "axes[{i}].{name}"),
            (SettingsKind::Homing, _, Some(i)) => write!(f, "homing.axes[{i}].{name}"),
            (SettingsKind::Spare, _, Some(i)) => write!(f, "spare[{i}].{name}"),
            (_, _, Some(i)) => write!(f, "{section}.{name}[{i}]"),
        }
    }
}

/// Why a setting was refused: the cause, named (the controller's `ConfigError`, flattened for the wire).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigRefusal {
    /// A field is outside its range ([`Field::must`] says what it must be).
    OutOfRange(Field),
    /// With it the home pose would have no solution.
    HomePose,
    /// With it the homing plan would be unsafe or inconsistent (searches, spacing proof).
    Homing,
    /// With it the step scheduler's timing would be inconsistent.
    StepTiming,
    /// With it the step generator's slots could not render the pulses faithfully.
    PulseSlots,
    /// The geometry is not a valid ring platform (lengths, chains, joint limits).
    Geometry,
    /// It fits a spare axis, and this board drives none.
    NoSpareOutputs,
}

impl core::fmt::Display for ConfigRefusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::OutOfRange(field) => return write!(f, "{field}: must be {}", field.must()),
            Self::HomePose => "the home pose would have no solution",
            Self::Homing => "the homing plan would no longer be safe (searches or spacing)",
            Self::StepTiming => "the step timing would be inconsistent",
            Self::PulseSlots => "the step generator could not render the pulses faithfully",
            Self::Geometry => "the geometry is not a valid ring platform",
            Self::NoSpareOutputs => "it fits a spare axis, and this board's firmware drives none",
        })
    }
}
