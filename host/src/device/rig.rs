//! `ringpod device rig load RIG.toml | show` and `ringpod device restart`: a rig file on the device, checked there
//! by the same core code that restores it at the next start, stored in its flash, shown back as a rig file.

use std::path::Path;
use std::time::Duration;

use ringpod_core::protocol::RigSource;

use ringpod_core::kinematics::GeometryError;

use crate::link::client::{Client, ClientError, Transport};
use crate::rig::{RigError, RigFile};

/// Why a rig could not be put on, read from or restarted on a device.
#[derive(Debug, thiserror::Error)]
pub enum DeviceRigError {
    /// The rig file is not valid (the error names its key).
    #[error(transparent)]
    File(#[from] RigError),
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// The rig the device runs is not a valid geometry (a device of another version, or damaged).
    #[error("the device's rig: {0}")]
    DeviceGeometry(GeometryError),
    /// The rig could not be written as TOML.
    #[error("the device's rig as TOML: {0}")]
    Toml(#[from] toml::ser::Error),
    /// The device did not come back.
    #[error("the device did not restart within {0:?}")]
    NoRestart(Duration),
}

/// `device rig load FILE`: checks the file here (every error names its key), then the device checks and stores
/// it for the next start. Returns what to print.
pub fn load<T: Transport>(client: &mut Client<T>, path: &Path) -> Result<String, DeviceRigError> {
    store(client, &crate::rig::read(path)?)
}

/// Checks a rig file here, then stores it on the device for its next start. Returns what to print.
pub fn store<T: Transport>(client: &mut Client<T>, file: &RigFile) -> Result<String, DeviceRigError> {
    let record = file.check()?.record;
    let spare = file.spare_section(&record)?;
    if record.name() != file.name {
        eprintln!(
            "note: the device keeps the name's first {} bytes: {}",
            record.name.len(),
            record.name()
        );
    }
    client.set_rig(record)?;
    // Beside the rig, not in it: a file without `[[spare]]` fits none, whatever the device had.
    client.set_settings(spare)?;
    Ok(format!(
        "{}: stored on the device for its next start; `ringpod device restart` runs it",
        record.name()
    ))
}

/// The running rig as a rig file (with where it came from in its header), so that `device rig show > rig.toml`
/// gives a file `device rig load` takes back.
pub fn show<T: Transport>(client: &mut Client<T>) -> Result<String, DeviceRigError> {
    let (record, source, pending) = client.rig()?;
    let text = as_file(&record)?;
    let mut header = format!("# running on the device: {} ({source})\n", record.name());
    if pending {
        header += "# another rig is stored for the next start (`ringpod device restart`)\n";
    }
    if let RigSource::Refused(_) | RigSource::Unreadable = source {
        eprintln!("warning: {source}");
    }
    Ok(header + &text)
}

/// A rig the device runs, as a rig file.
pub fn as_file(record: &ringpod_core::protocol::RigRecord) -> Result<String, DeviceRigError> {
    let geometry = record.geometry().map_err(DeviceRigError::DeviceGeometry)?;
    let mut file = RigFile::of(&geometry, record.home, None, Vec::new()).with_sections(record);
    file.name = record.name().to_owned();
    Ok(file.to_toml()?)
}

/// `device restart`: the device stores everything, then resets; waits until it answers as a new start (a
/// request before `hello` is refused as not connected) and shows the rig it came up with.
pub fn restart<T: Transport>(client: &mut Client<T>) -> Result<String, DeviceRigError> {
    client.restart()?;
    let limit = Duration::from_secs(10);
    match client.await_new_start(limit) {
        Ok(true) => {}
        Ok(false) => return Ok("restarting: the port closed; the board enumerates again".into()),
        Err(ClientError::Timeout(waited)) => return Err(DeviceRigError::NoRestart(waited)),
        Err(e) => return Err(e.into()),
    }
    client.hello()?;
    let (record, source, _) = client.rig()?;
    Ok(format!("restarted: running {} ({source})", record.name()))
}
