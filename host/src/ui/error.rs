//! Why the workbench could not start or did not end well.

/// Why `ringpod ui` stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum UiError {
    /// The operating system gave no random bytes for the per-run token.
    #[error("no random source for the token: {0}")]
    Random(getrandom::Error),
    /// The address could not be listened on (in use, not ours).
    #[error("--listen {addr}: {reason}")]
    Listen {
        /// The address asked.
        addr: std::net::SocketAddr,
        /// Why.
        reason: std::io::Error,
    },
    /// The platform to simulate, or the page's cueing file.
    #[error(transparent)]
    Cli(#[from] crate::error::CliError),
    /// The runtime, the signal handlers or the server.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The default cueing configuration as TOML.
    #[error(transparent)]
    Toml(#[from] toml::ser::Error),
    /// The server ended and no stop reached it.
    #[error("the server ended without a stop")]
    NoStop,
    /// The device thread ended with an error.
    #[error("the device")]
    Device(#[source] worker::WorkerError),
    /// `--motion-compensation`: the tracker's mapping.
    #[error(transparent)]
    Vr(#[from] crate::vr::VrError),
    /// The device thread panicked.
    #[error("the device thread failed")]
    DeviceThread,
}

use super::worker;
