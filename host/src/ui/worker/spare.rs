//! The spare axes 7 and 8 from the workbench. The device has no jog of its own for them (its jog moves one of the
//! six actuators while commissioning): a jog or a value is a short stream that holds the platform at the pose it is
//! commanded to and carries the axis's target in its column, as a pose file's `axis7`/`axis8` do, so the device's
//! limits, STOP and supervisor apply to it as to any stream. Their positions, the status's counted steps in each
//! axis's unit, go to the pages while an axis is fitted.

use std::time::{Duration, Instant};

use ringpod_core::kinematics::Pose;
use ringpod_core::motion::{SpareAxisSettings, SPARE_AXES};
use ringpod_core::protocol::{Settings, SettingsKind, Status};
use ringpod_core::safety::State;
use serde_json::json;

use super::{Device, WorkerError, STOPPED_BEFORE_START};
use crate::link::client::ClientError;
use crate::stream::{self, Source, NO_AUX};

/// How often the pages are told the spare axes' positions while one is fitted (a status request each).
pub(super) const POSITION_EVERY: Duration = Duration::from_millis(200);

/// Where a spare axis is asked to go, in its own unit.
#[derive(Debug, Clone, Copy)]
pub(super) enum Goal {
    /// By this far from where its counted steps are.
    By(f64),
    /// To this position.
    To(f64),
}

/// The spare axes' settings the device runs.
pub(super) fn fitted(
    client: &mut crate::link::client::Client<crate::link::transport::AnyTransport>,
) -> Result<[SpareAxisSettings; SPARE_AXES], ClientError> {
    match client.settings(SettingsKind::Spare)?.0 {
        Settings::Spare(axes) => Ok(axes),
        // The device answered another section: none is taken as fitted.
        _ => Ok([SpareAxisSettings::NONE; SPARE_AXES]),
    }
}

/// The pages' message of the spare axes: which are fitted, their counted steps and positions (units).
pub(super) fn message(axes: &[SpareAxisSettings; SPARE_AXES], status: &Status) -> serde_json::Value {
    let position: Vec<f64> = axes
        .iter()
        .zip(status.spare_steps)
        .map(|(a, s)| s as f64 / f64::from(a.steps_per_unit))
        .collect();
    json!({
        "type": "spare",
        "fitted": axes.iter().map(|a| a.enabled).collect::<Vec<_>>(),
        "steps": status.spare_steps,
        "position": position,
    })
}

impl Device {
    /// Tells the pages where the fitted spare axes are, at most every [`POSITION_EVERY`].
    pub(super) fn publish_spare(&mut self, last: &mut Instant) {
        if !self.spare.iter().any(|a| a.enabled) || last.elapsed() < POSITION_EVERY {
            return;
        }
        *last = Instant::now();
        if let Ok(status) = self.client.status() {
            self.hub.publish(&message(&self.spare, &status));
        }
    }

    /// Moves spare axis `axis` (7 or 8) toward `goal`, the platform held: powering up and homing first if needed,
    /// as any stream does.
    pub(super) fn spare(&mut self, page: u64, axis: u8, goal: Goal) -> Result<String, WorkerError> {
        let index = match axis {
            7 | 8 => usize::from(axis - 7),
            _ => return Err(WorkerError::NoSuch(format!("the spare axes are 7 and 8, not {axis}"))),
        };
        self.spare = fitted(&mut self.client)?;
        let settings = self.spare[index];
        if !settings.enabled {
            return Err(WorkerError::NoSuch(format!(
                "axis {axis} is not fitted (a rig file's [[spare]] fits it)"
            )));
        }
        let status = self.client.status()?;
        let steps_per_unit = f64::from(settings.steps_per_unit);
        let at = status.spare_steps[index] as f64 / steps_per_unit;
        let target = match goal {
            Goal::By(d) => at + d,
            Goal::To(v) => v,
        };
        if !target.is_finite() {
            return Err(WorkerError::NoSuch(format!(
                "axis {axis}: a position is a finite number"
            )));
        }
        // The platform stays where it is commanded; until a stream can start there (not powered or not homed),
        // the stream's homing takes it home, and it stays there.
        let pose = if matches!(status.state, State::Ready | State::Running) && status.homed {
            status.pose.cast::<f64>()
        } else {
            let (record, _, _) = self.client.rig()?;
            Pose::from_array(record.home)
        };
        // The setpoint with the target comes when the axis could be there at its limits (the device interpolates
        // its column over the interval), and one more holds it until it stops.
        let (v, a) = (f64::from(settings.velocity), f64::from(settings.acceleration));
        let travel = (target - at).abs() / v + v / a;
        let mut columns = NO_AUX;
        columns.spare[index] = Some(target as f32);
        let poses = vec![
            (1, 0.0, pose, NO_AUX),
            (2, travel.max(0.05), pose, columns),
            (3, travel.max(0.05) + (v / a).max(0.25), pose, columns),
        ];
        let report = match self.run(page, Source::Poses(poses), Vec::new()) {
            Err(WorkerError::NotStarted(ClientError::Interrupted)) => {
                return Ok(format!("axis {axis}: {STOPPED_BEFORE_START}"))
            }
            r => r?,
        };
        let status = self.client.status()?;
        self.hub.publish(&message(&self.spare, &status));
        if report.exit_code != stream::exit::FOLLOWED {
            return Err(WorkerError::Ended(format!(
                "axis {axis}: {}",
                report.reason.as_deref().unwrap_or(report.outcome)
            )));
        }
        let steps = status.spare_steps[index];
        Ok(format!(
            "axis {axis} at {:.4} ({steps} steps)",
            steps as f64 / steps_per_unit
        ))
    }
}
