//! `ringpod device rig load RIG.toml | show` and `ringpod device restart`: a rig file on the device, checked there
//! by the same core code that restores it at the next start, stored in its flash, shown back as a rig file.

use std::path::Path;
use std::time::{Duration, Instant};

use ringpod_core::protocol::endpoints::GetStatus;
use ringpod_core::protocol::{NackReason, RigSource};

use super::RigFile;
use crate::link::client::{Client, ClientError, Transport};

/// `device rig load FILE`: checks the file here (every error names its key), then the device checks and stores
/// it for the next start. Returns what to print.
pub fn load<T: Transport>(client: &mut Client<T>, path: &Path) -> anyhow::Result<String> {
    store(client, &super::read(path)?)
}

/// Checks a rig file here, then stores it on the device for its next start. Returns what to print.
pub fn store<T: Transport>(client: &mut Client<T>, file: &RigFile) -> anyhow::Result<String> {
    let record = file.check()?.record;
    if record.name() != file.name {
        eprintln!(
            "note: the device keeps the name's first {} bytes: {}",
            record.name.len(),
            record.name()
        );
    }
    client.set_rig(record)?;
    Ok(format!(
        "{}: stored on the device for its next start; `ringpod device restart` runs it",
        record.name()
    ))
}

/// The running rig as a rig file (with where it came from in its header), so that `device rig show > rig.toml`
/// gives a file `device rig load` takes back.
pub fn show<T: Transport>(client: &mut Client<T>) -> anyhow::Result<String> {
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
pub fn as_file(record: &ringpod_core::protocol::RigRecord) -> anyhow::Result<String> {
    let geometry = record
        .geometry()
        .map_err(|e| anyhow::anyhow!("the device's rig: {e}"))?;
    let mut file = RigFile::of(&geometry, record.home, None, Vec::new()).with_sections(record);
    file.name = record.name().to_owned();
    Ok(file.to_toml()?)
}

/// `device restart`: the device stores everything, then resets; waits until it answers as a new start (a
/// request before `hello` is refused as not connected) and shows the rig it came up with.
pub fn restart<T: Transport>(client: &mut Client<T>) -> anyhow::Result<String> {
    client.restart()?;
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        match client.call(GetStatus) {
            Err(ClientError::Device(NackReason::NotConnected)) => break,
            // A board on USB leaves: its port closes, and it comes back under the same name in a moment.
            Err(ClientError::Io(_)) => return Ok("restarting: the port closed; the board enumerates again".into()),
            _ if Instant::now() > deadline => anyhow::bail!("the device did not restart within 10 s"),
            _ => client.transport().elapse(Duration::from_millis(50)),
        }
    }
    client.hello()?;
    let (record, source, _) = client.rig()?;
    Ok(format!("restarted: running {} ({source})", record.name()))
}
