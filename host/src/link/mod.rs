//! How the host reaches a controller: a transport (a board's serial port or the simulated controller in this
//! process), the typed client over it, and the simulated controller served on a pseudo-terminal.

pub mod client;
pub mod pty;
pub mod transport;

/// Where the controller is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A board on this serial port.
    Port(String),
    /// A fresh simulated controller in this process.
    Sim,
}

impl Target {
    /// The target named by `--port` or `--sim`.
    pub fn named(port: Option<&str>, sim: bool) -> anyhow::Result<Self> {
        match (port, sim) {
            (Some(port), _) => Ok(Target::Port(port.to_owned())),
            (None, true) => Ok(Target::Sim),
            (None, false) => anyhow::bail!("say where the controller is: --port PATH or --sim"),
        }
    }
}

/// Opens the transport to `target`; a simulated controller runs in real time or as fast as it can.
pub fn connect(target: &Target, realtime: bool) -> anyhow::Result<transport::AnyTransport> {
    Ok(match target {
        Target::Port(port) => transport::AnyTransport::Serial(transport::Serial::open(port)?),
        Target::Sim => transport::AnyTransport::Sim(Box::new(transport::SimDevice::new(realtime))),
    })
}
