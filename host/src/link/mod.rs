//! How the host reaches a controller: a transport (a board's serial port, a TCP connection to a served simulator or
//! a serial-to-network bridge, or the simulated controller in this process), the typed client over it, and the
//! simulated controller served on a pseudo-terminal (Unix) or over TCP.

pub mod client;
pub mod followed;
#[cfg(unix)]
pub mod pty;
pub mod sim;
pub mod tcp;
pub mod transport;

use std::sync::OnceLock;
use std::time::Duration;

use ringpod_core::controller::ConfigError;

/// The USB vendor and product a ringpod board enumerates with (pid.codes' open-source test pair).
pub const BOARD_USB_ID: (u16, u16) = (0x1209, 0x0001);

/// The environment variable whose factor (1 to 1000, default 1) lengthens every wait of the host for a board: a
/// board run in an emulator many times slower than real time (the rehost harness) answers in the same device time
/// as a real one but later in wall time.
pub const PATIENCE_VAR: &str = "RINGPOD_PATIENCE";

/// `wait` lengthened by [`PATIENCE_VAR`]'s factor.
pub fn patience(wait: Duration) -> Duration {
    static FACTOR: OnceLock<f64> = OnceLock::new();
    let factor = FACTOR.get_or_init(|| {
        let value = std::env::var(PATIENCE_VAR).ok();
        patience_factor(value.as_deref()).unwrap_or_else(|given| {
            eprintln!("ringpod: {PATIENCE_VAR}={given:?} ignored: a factor from 1 to 1000");
            1.0
        })
    });
    wait.mul_f64(*factor)
}

/// The factor a [`PATIENCE_VAR`] value gives: 1 when it is not set; the value itself when it is not a number
/// from 1 to 1000.
pub fn patience_factor(value: Option<&str>) -> Result<f64, String> {
    let Some(value) = value else { return Ok(1.0) };
    match value.trim().parse::<f64>() {
        Ok(f) if (1.0..=1000.0).contains(&f) => Ok(f),
        _ => Err(value.to_owned()),
    }
}

/// Why a link to a controller could not be made or kept.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// Neither `--port` nor `--sim` was given.
    #[error("say where the controller is: --port PATH or --sim")]
    NoTarget,
    /// The serial port could not be opened.
    #[error("{port}: {reason}")]
    Open {
        /// The port's path.
        port: String,
        /// Why.
        reason: serialport::Error,
    },
    /// The network address of a `tcp://` port could not be reached.
    #[error("{port}: {reason}")]
    Connect {
        /// The port as given (`tcp://HOST:PORT`).
        port: String,
        /// Why.
        reason: std::io::Error,
    },
    /// A simulated controller cannot drive the rig it was given.
    #[error("{rig}: the controller cannot drive it: {reason}")]
    Undrivable {
        /// The rig's name.
        rig: String,
        /// The controller's check that refused it.
        reason: ConfigError,
    },
    /// The pseudo-terminal could not be set up.
    #[cfg(unix)]
    #[error("pseudo-terminal: {0}")]
    Pty(#[from] nix::Error),
    /// Reading or writing the link failed.
    #[error("link: {0}")]
    Io(#[from] std::io::Error),
}

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
    pub fn named(port: Option<&str>, sim: bool) -> Result<Self, LinkError> {
        match (port, sim) {
            (Some(port), _) => Ok(Target::Port(port.to_owned())),
            (None, true) => Ok(Target::Sim),
            (None, false) => Err(LinkError::NoTarget),
        }
    }
}

/// Opens the transport to `target`; a simulated controller runs in real time or as fast as it can.
pub fn connect(target: &Target, realtime: bool) -> Result<transport::AnyTransport, LinkError> {
    Ok(match target {
        Target::Port(port) if tcp::address(port).is_some() => {
            let address = tcp::address(port).unwrap_or_default();
            let tcp = tcp::Tcp::connect(address).map_err(|reason| LinkError::Connect {
                port: port.clone(),
                reason,
            })?;
            transport::AnyTransport::Tcp(tcp)
        }
        Target::Port(port) => {
            let serial = transport::Serial::open(port).map_err(|reason| LinkError::Open {
                port: port.clone(),
                reason,
            })?;
            transport::AnyTransport::Serial(serial)
        }
        Target::Sim => transport::AnyTransport::Sim(Box::new(sim::SimDevice::new(realtime))),
    })
}

#[cfg(test)]
mod tests {
    use super::patience_factor;

    #[test]
    fn patience_factor_takes_1_to_1000_and_refuses_the_rest() {
        assert_eq!(patience_factor(None), Ok(1.0));
        assert_eq!(patience_factor(Some("40")), Ok(40.0));
        assert_eq!(patience_factor(Some(" 2.5 ")), Ok(2.5));
        assert_eq!(patience_factor(Some("1")), Ok(1.0));
        assert_eq!(patience_factor(Some("1000")), Ok(1000.0));
        for garbage in ["", "0.5", "0", "-3", "1001", "NaN", "inf", "forty"] {
            assert_eq!(patience_factor(Some(garbage)), Err(garbage.to_owned()), "{garbage:?}");
        }
    }
}
