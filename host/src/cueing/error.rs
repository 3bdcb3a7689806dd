//! Why a drive could not be cued (`cue`, the bench).

use crate::error::CliError;
use ringpod_core::cueing;

/// Why a drive could not be cued.
#[derive(Debug, thiserror::Error)]
pub enum CueError {
    /// The washout refused its configuration.
    #[error("{0}")]
    Washout(cueing::ConfigError),
    /// The input could not be read, or is not telemetry (a CSV or a packet capture).
    #[error("{}: {reason}", path.display())]
    Input {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
    /// The poses could not be written.
    #[error("{}: {reason}", path.display())]
    Output {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: std::io::Error,
    },
    /// The bench's floor could not be found.
    #[error("the floor: {0}")]
    Floor(super::optimal::floor::FloorError),
    /// The command's other errors: the mechanism, the cueing file, the picture, the JSON.
    #[error(transparent)]
    Cli(#[from] CliError),
}
