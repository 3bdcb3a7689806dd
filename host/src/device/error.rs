//! Why a device command, the monitor, the simulator or the port list stopped: each part's own error, said as it is.

/// Why `device`, `monitor`, `simulate` or `ports` could not do what it was asked.
#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    /// No link to the controller.
    #[error(transparent)]
    Link(#[from] crate::link::LinkError),
    /// The device's answer.
    #[error(transparent)]
    Client(#[from] crate::link::client::ClientError),
    /// A jog or buzz.
    #[error(transparent)]
    Commission(#[from] super::commission::CommissionError),
    /// `device config`.
    #[error(transparent)]
    Config(#[from] super::settings::ConfigCommandError),
    /// `device rig`, `device restart`.
    #[error(transparent)]
    Rig(#[from] crate::device::rig::DeviceRigError),
    /// The monitor's terminal.
    #[error(transparent)]
    Monitor(#[from] super::monitor::MonitorError),
    /// The platform a simulator was given.
    #[error(transparent)]
    Platform(#[from] crate::error::CliError),
    /// The signal handlers could not be installed.
    #[error(transparent)]
    Signals(#[from] std::io::Error),
    /// The status as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// What this operating system cannot do, named.
    #[cfg(not(unix))]
    #[error("{0}")]
    Unsupported(&'static str),
    /// The serial ports could not be listed.
    #[error(transparent)]
    Ports(#[from] serialport::Error),
}
