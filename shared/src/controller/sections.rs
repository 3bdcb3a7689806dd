//! The configuration as typed sections ([`Settings`]): each read whole from the running configuration and changed
//! whole, after checking its values' ranges; the checks of the whole configuration (home pose, homing plan, step
//! timing) are [`ControllerConfig::validate`]'s. Homing is kept in the axes' own units and turned into steps here,
//! so that a motor's steps per unit or direction changes its homing with it.

use super::config::supervisor_fields;
use super::{ConfigError, ControllerConfig};
use crate::kinematics::{AxisKind, Mechanism, RingPlatform};
use crate::motion::{AxisScale, MotionLimits, SpareAxisSettings, SPARE_AXES};
use crate::protocol::{
    AxisSettings, ControlSettings, Field, FieldName, MachineSettings, MotionSettings, Settings, SettingsKind,
    StreamSettings, SwitchSettings, Toward,
};
use crate::safety::homing::{AxisHoming, HomingConfig};

/// Most steps a count or rate may take (they are `u32` in the step scheduler; 2^31 leaves room to add).
const MOST_STEPS: f64 = 2_147_483_647.0;

impl ControllerConfig {
    /// A section as this configuration has it.
    pub fn settings(&self, kind: SettingsKind) -> Settings {
        match kind {
            SettingsKind::Stream => Settings::Stream(self.stream()),
            SettingsKind::Control => Settings::Control(self.control()),
            SettingsKind::Motion => Settings::Motion(self.motion()),
            SettingsKind::Inputs => Settings::Inputs(self.inputs),
            SettingsKind::Axes => Settings::Axes(self.axes()),
            SettingsKind::Homing => Settings::Homing(self.switches),
            SettingsKind::Supervisor => Settings::Supervisor(self.supervisor),
            SettingsKind::Spare => Settings::Spare(self.pipeline.spare),
        }
    }

    /// The stream section.
    pub fn stream(&self) -> StreamSettings {
        let c = &self.pipeline;
        StreamSettings {
            timeout_ms: (c.stream_timeout_us / 1000) as u16,
            gross_jump_ms: (c.gross_jump_us / 1000) as u16,
            follow: c.follow,
            margins: c.margins.0,
            telemetry_hz: self.telemetry_hz,
            host_gone_ms: self.host_gone_ms,
        }
    }

    /// The control section.
    pub fn control(&self) -> ControlSettings {
        ControlSettings {
            tick_hz: (1_000_000 / self.pipeline.tick_us.max(1)) as u16,
        }
    }

    /// The sections a rig record carries.
    pub fn machine(&self) -> MachineSettings {
        MachineSettings {
            axes: self.axes(),
            motion: self.motion(),
            inputs: self.inputs,
            supervisor: self.supervisor,
            homing: self.switches,
        }
    }

    fn axes(&self) -> [AxisSettings; 6] {
        let kinds = self.axis_kinds();
        core::array::from_fn(|a| {
            let s = &self.scales[a];
            AxisSettings {
                steps_per_unit: match kinds[a] {
                    AxisKind::Ring => s.steps_per_turn as f32,
                    AxisKind::Angle => s.steps_per_unit * core::f32::consts::TAU,
                    AxisKind::Linear => s.steps_per_unit,
                },
                reverse: s.invert,
            }
        })
    }

    fn motion(&self) -> MotionSettings {
        let limits = &self.pipeline.limits;
        MotionSettings {
            pose_velocity: limits.pose_velocity,
            pose_acceleration: limits.pose_acceleration,
            actuator_velocity: limits.actuator_velocity,
            actuator_acceleration: limits.actuator_acceleration,
        }
    }

    /// The stream section after checking its values' ranges (`StreamSettings` documents them).
    fn apply_stream(&mut self, s: &StreamSettings) -> Result<(), ConfigError> {
        let field = |name| ConfigError::Value(Field::of(SettingsKind::Stream, name));
        if !(1..=10_000).contains(&s.timeout_ms) {
            return Err(field(FieldName::TimeoutMs));
        }
        if !(10..=10_000).contains(&s.gross_jump_ms) {
            return Err(field(FieldName::GrossJumpMs));
        }
        if let Some(i) = s.margins.iter().position(|m| !(0.0..=0.1).contains(m)) {
            return Err(ConfigError::Value(Field::at(
                SettingsKind::Stream,
                i,
                FieldName::Margins,
            )));
        }
        if s.telemetry_hz > 2_000 {
            return Err(field(FieldName::TelemetryHz));
        }
        if !(1_000..=60_000).contains(&s.host_gone_ms) {
            return Err(field(FieldName::HostGoneMs));
        }
        let c = &mut self.pipeline;
        c.stream_timeout_us = u32::from(s.timeout_ms) * 1000;
        c.gross_jump_us = u32::from(s.gross_jump_ms) * 1000;
        c.follow = s.follow;
        c.margins.0 = s.margins;
        self.telemetry_hz = s.telemetry_hz;
        self.host_gone_ms = s.host_gone_ms;
        Ok(())
    }

    /// Changes a section after checking its values' ranges (each section documents them); the configuration as a
    /// whole is checked by [`Self::validate`]. On an error nothing has changed.
    pub fn apply(&mut self, settings: &Settings) -> Result<(), ConfigError> {
        let mut next = *self;
        let c = &mut next.pipeline;
        match *settings {
            Settings::Stream(s) => next.apply_stream(&s)?,
            Settings::Control(s) => {
                if !matches!(s.tick_hz, 500 | 1_000 | 2_000) {
                    return Err(ConfigError::Value(Field::of(SettingsKind::Control, FieldName::TickHz)));
                }
                c.tick_us = 1_000_000 / u32::from(s.tick_hz);
                next.scheduler.period_ns = c.tick_us * 1000;
            }
            Settings::Motion(s) => {
                for (values, name) in [
                    (&s.pose_velocity, FieldName::PoseVelocity),
                    (&s.pose_acceleration, FieldName::PoseAcceleration),
                    (&s.actuator_velocity, FieldName::ActuatorVelocity),
                    (&s.actuator_acceleration, FieldName::ActuatorAcceleration),
                ] {
                    if let Some(i) = values.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                        return Err(ConfigError::Value(Field::at(SettingsKind::Motion, i, name)));
                    }
                }
                c.limits = MotionLimits {
                    pose_velocity: s.pose_velocity,
                    pose_acceleration: s.pose_acceleration,
                    actuator_velocity: s.actuator_velocity,
                    actuator_acceleration: s.actuator_acceleration,
                };
            }
            Settings::Inputs(s) => {
                if !(1..=50).contains(&s.debounce_samples) {
                    return Err(ConfigError::Value(Field::of(
                        SettingsKind::Inputs,
                        FieldName::DebounceMs,
                    )));
                }
                next.inputs = s;
            }
            Settings::Axes(axes) => {
                let kinds = next.axis_kinds();
                for (a, ((scale, axis), kind)) in next.scales.iter_mut().zip(&axes).zip(kinds).enumerate() {
                    *scale = axis_scale(axis, kind).ok_or(ConfigError::Value(Field::at(
                        SettingsKind::Axes,
                        a,
                        FieldName::StepsPerUnit,
                    )))?;
                }
            }
            Settings::Homing(h) => {
                let order = ConfigError::Value(Field::of(SettingsKind::Homing, FieldName::Order));
                let mut seen = [false; 6];
                for a in h.order {
                    let slot = seen.get_mut(usize::from(a)).ok_or(order)?;
                    if core::mem::replace(slot, true) {
                        return Err(order);
                    }
                }
                for (a, s) in h.axes.iter().enumerate() {
                    if let Some(name) = invalid_switch(s) {
                        return Err(ConfigError::Value(Field::at(SettingsKind::Homing, a, name)));
                    }
                }
                next.switches = h;
            }
            Settings::Supervisor(s) => {
                supervisor_fields(&s)?;
                next.supervisor = s;
            }
            Settings::Spare(axes) => {
                spare_fields(&axes, next.top_step_rate())?;
                next.pipeline.spare = axes;
            }
        }
        if matches!(settings.kind(), SettingsKind::Axes | SettingsKind::Homing) {
            // A step count out of range is a value out of range.
            next.homing()?;
        }
        *self = next;
        Ok(())
    }

    /// Homing of every axis in motor steps: the homing section with each axis's steps per unit and direction.
    pub fn homing(&self) -> Result<HomingConfig, ConfigError> {
        let kinds = self.axis_kinds();
        let mut axes = [AxisHoming {
            toward: 1,
            search_steps: 0,
            backoff_steps: 0,
            fast_rate: 0,
            slow_rate: 0,
            home_position: 0,
        }; 6];
        for (a, slot) in axes.iter_mut().enumerate() {
            let s = &self.switches.axes[a];
            let scale = &self.scales[a];
            let per_unit = f64::from(scale.per_unit(kinds[a]));
            let steps = |v: f32, name| {
                let n = libm::round(f64::from(v) * per_unit);
                if n.is_finite() && libm::fabs(n) <= MOST_STEPS {
                    Ok(n)
                } else {
                    Err(ConfigError::Value(Field::at(SettingsKind::Homing, a, name)))
                }
            };
            let sign: i8 = if scale.invert { -1 } else { 1 };
            *slot = AxisHoming {
                toward: sign
                    * match s.toward {
                        Toward::Plus => 1,
                        Toward::Minus => -1,
                    },
                search_steps: steps(s.search, FieldName::Search)? as u32,
                backoff_steps: steps(s.backoff, FieldName::Backoff)? as u32,
                fast_rate: steps(s.fast, FieldName::Fast)?.max(1.0) as u32,
                slow_rate: steps(s.slow, FieldName::Slow)?.max(1.0) as u32,
                home_position: i64::from(sign) * steps(s.switch, FieldName::Switch)? as i64,
            };
        }
        Ok(HomingConfig {
            axes,
            order: self.switches.order,
        })
    }

    /// What each actuator coordinate measures, in chain order.
    pub(super) fn axis_kinds(&self) -> [AxisKind; 6] {
        RingPlatform::<f32>::new(&self.geometry).axes()
    }
}

/// The first field of a switch's homing that is not a positive (the switch: finite) number.
fn invalid_switch(s: &SwitchSettings) -> Option<FieldName> {
    let positive = [
        (s.search, FieldName::Search),
        (s.backoff, FieldName::Backoff),
        (s.fast, FieldName::Fast),
        (s.slow, FieldName::Slow),
    ];
    match positive.iter().find(|(x, _)| !(x.is_finite() && *x > 0.0)) {
        Some((_, name)) => Some(*name),
        None => (!s.switch.is_finite()).then_some(FieldName::Switch),
    }
}

/// A motor's scale, checked: 1 to 2^24 steps per unit, whole steps per carriage turn on the ring; a shoulder's
/// (an angle axis) is given per turn too, not necessarily whole (a gear's ratio need not be).
pub fn axis_scale(axis: &AxisSettings, kind: AxisKind) -> Option<AxisScale> {
    let v = axis.steps_per_unit;
    if !(v.is_finite() && (1.0..=16_777_216.0).contains(&v)) {
        return None;
    }
    Some(match kind {
        AxisKind::Ring if v != libm::floorf(v) => return None,
        AxisKind::Ring => AxisScale {
            steps_per_turn: v as i64,
            steps_per_unit: v / core::f32::consts::TAU,
            invert: axis.reverse,
        },
        AxisKind::Angle => AxisScale {
            steps_per_turn: 0,
            steps_per_unit: v / core::f32::consts::TAU,
            invert: axis.reverse,
        },
        AxisKind::Linear => AxisScale {
            steps_per_turn: 0,
            steps_per_unit: v,
            invert: axis.reverse,
        },
    })
}

/// Each fitted spare axis's ranges (an axis not fitted is not checked: its values are never used).
fn spare_fields(axes: &[SpareAxisSettings; SPARE_AXES], top_rate: f32) -> Result<(), ConfigError> {
    for (i, a) in axes.iter().enumerate().filter(|(_, a)| a.enabled) {
        let [least, most] = a.travel;
        let name = if !(1.0..=16_777_216.0).contains(&a.steps_per_unit) {
            FieldName::StepsPerUnit
        } else if !(a.velocity > 0.0 && a.velocity * a.steps_per_unit <= top_rate) {
            FieldName::Velocity
        } else if !(a.acceleration > 0.0 && a.acceleration.is_finite()) {
            FieldName::Acceleration
        } else if !(least <= 0.0 && most >= 0.0 && least.is_finite() && most.is_finite()) {
            FieldName::Travel
        } else {
            continue;
        };
        return Err(ConfigError::Value(Field::at(SettingsKind::Spare, i, name)));
    }
    Ok(())
}
