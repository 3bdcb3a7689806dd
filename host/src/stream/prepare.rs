//! Before a stream: the device greeted (nothing moves until the input is checked), then brought to `Ready` (power,
//! homing), and its telemetry rate set for a record taken at another rate (`--record-hz`), set back after the run.

use std::time::Duration;

use ringpod_core::kinematics::presets::Preset;
use ringpod_core::protocol::{Settings, SettingsKind, Status};
use ringpod_core::safety::State;

use crate::link::client::{Client, ClientError, Transport};
use crate::out::console;

/// Sets the device's telemetry rate (its stream section's `telemetry_hz`, a live setting) and returns the one it
/// had, to set back after the run; `None` when it was the rate asked already.
pub(super) fn telemetry_rate<T: Transport>(client: &mut Client<T>, hz: u16) -> Result<Option<u16>, ClientError> {
    let (Settings::Stream(mut stream), _) = client.settings(SettingsKind::Stream)? else {
        return Err(ClientError::Unexpected(
            "the device answered another settings section".into(),
        ));
    };
    let before = stream.telemetry_hz;
    if before == hz {
        return Ok(None);
    }
    stream.telemetry_hz = hz;
    client.set_settings(Settings::Stream(stream))?;
    Ok(Some(before))
}

/// Greets the device (the protocol version checked) and says which platform it drives when it is not the trainer
/// model. Nothing moves.
pub(super) fn greet<T: Transport>(client: &mut Client<T>) -> Result<(), ClientError> {
    let device = client.hello()?;
    if device.preset != Some(Preset::TrainerModel) {
        console::err(&format!(
            "note: the device drives {}",
            device.preset.map_or("a geometry of its own", |p| p.name())
        ));
    }
    Ok(())
}

/// Brings the greeted device to `Ready`: the telemetry rate asked (the rate it had is returned), power up, home if
/// needed. Errors here mean the stream never started.
pub(super) fn prepare<T: Transport>(
    client: &mut Client<T>,
    home: bool,
    telemetry: bool,
    telemetry_hz: Option<u16>,
) -> Result<(Status, Option<u16>), ClientError> {
    let restore = match telemetry_hz {
        Some(hz) => telemetry_rate(client, hz)?,
        None => None,
    };
    let status = ready(client, home, telemetry);
    if let (Err(_), Some(before)) = (&status, restore) {
        // The stream never starts: leave the device's rate as it was.
        let _ = telemetry_rate(client, before);
    }
    Ok((status?, restore))
}

/// Telemetry on if asked, power up, home if needed, and `Ready`.
fn ready<T: Transport>(client: &mut Client<T>, home: bool, telemetry: bool) -> Result<Status, ClientError> {
    if telemetry {
        // From here on: the record covers powering up and homing too.
        client.telemetry(true)?;
    }
    let mut status = client.status()?;
    if matches!(status.state, State::Fault(..)) {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}: clear the fault first",
            status.state
        )));
    }
    if matches!(status.state, State::Running | State::Stopping) {
        client.stop()?;
        status = client.wait_for(Duration::from_secs(10), |s| !matches!(s.state, State::Stopping))?;
    }
    if matches!(status.state, State::ShuttingDown(_)) {
        // Powering down (a disable just before): it must reach Off before it can power up again.
        status = client.wait_for(Duration::from_secs(10), |s| !matches!(s.state, State::ShuttingDown(_)))?;
    }
    if status.state == State::Off {
        client.enable()?;
    }
    if matches!(
        status.state,
        State::Off | State::LogicOn | State::PowerOn { settled: false }
    ) {
        // Powering up (now, or by an enable just before): homing is refused until the supplies have settled.
        status = client.wait_for(Duration::from_secs(5), |s| {
            matches!(s.state, State::PowerOn { settled: true } | State::Fault(..))
        })?;
    }
    if !status.homed || home {
        client.home()?;
        let homed = client.wait_for(Duration::from_secs(120), |s| {
            matches!(s.state, State::Ready | State::Fault(..))
        });
        status = match homed {
            Ok(s) => s,
            Err(e) => {
                // Ctrl-C or a timeout during homing: abort it before saying so.
                let _ = client.stop();
                return Err(e);
            }
        };
    }
    if status.state != State::Ready {
        return Err(ClientError::Unexpected(format!(
            "device is in {:?}, not ready",
            status.state
        )));
    }
    Ok(status)
}
