//! The rig the device runs: told to the pages at the start, and a rig file from the Rig panel loaded onto the
//! device (then restarted to run it).

use ringpod_core::kinematics::RingPlatform;
use ringpod_core::protocol::RigSource;
use ringpod_core::safety::State;
use serde_json::json;

use super::super::frame::RigView;
use super::super::hub::Hub;
use super::{spare, Device, WorkerError};
use crate::link::client::Client;
use crate::link::transport::AnyTransport;

/// Reads the rig the device runs, tells the pages, and gives its mechanism.
pub(super) fn announce_rig(client: &mut Client<AnyTransport>, hub: &Hub) -> Result<RingPlatform<f64>, WorkerError> {
    let (record, source, _) = client.rig()?;
    if let RigSource::Refused(_) | RigSource::Unreadable = source {
        eprintln!("warning: {source}");
    }
    let geometry = record.geometry().map_err(WorkerError::DeviceGeometry)?;
    // The frames and motion compensation show the pose of the counted steps of the rig the device runs now.
    client.followed = crate::link::followed::Followed::of(&record);
    let mut view = RigView::of(&geometry, record.home, source.to_string());
    view.firmware = client
        .device
        .map_or_else(String::new, |d| crate::device::firmware_text(&d.firmware));
    view.jog_the_device_takes(&record.machine.homing.axes);
    // The simulator counts a tick's cost in ns of the host's time, a board in its MCU's cycles.
    if matches!(client.transport(), crate::link::transport::AnyTransport::Sim(_)) {
        view.tick_unit = "ns";
    }
    // The name the user gave the rig (its file's `name`), not the geometry's generic one.
    if !record.name().trim().is_empty() {
        record.name().clone_into(&mut view.name);
    }
    let mut message = serde_json::to_value(view)?;
    message["type"] = json!("rig");
    // A poisoned lock only means a page's thread panicked while holding it: the value is still the rig's.
    *hub.rig.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(message.to_string());
    *hub.record.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(record);
    hub.publish(&message);
    Ok(RingPlatform::new(&geometry))
}

impl Device {
    pub(super) fn load_rig(&mut self, text: &str) -> Result<String, WorkerError> {
        let file = crate::rig::parse(text)?;
        if self.client.status()?.state != State::Off {
            return Err(WorkerError::NotOff);
        }
        crate::device::rig::store(&mut self.client, &file)?;
        let restarted = crate::device::rig::restart(&mut self.client)?;
        self.client.telemetry(true)?;
        let m = announce_rig(&mut self.client, &self.hub)?;
        if let Ok(mut mechanism) = self.mechanism.lock() {
            *mechanism = m;
        }
        if let Ok(axes) = spare::fitted(&mut self.client) {
            self.spare = axes;
        }
        Ok(format!("{} stored; {restarted}", file.name))
    }
}
