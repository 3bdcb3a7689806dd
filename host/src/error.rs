//! Errors of the command line: the ones the analysis commands, and the stream, device and ui commands' platform,
//! share. It sits low (it wraps only rig's, input's and out's errors, and the core's): a command module returns it,
//! and a command's own error that carries more (`CueError`, `PlotCommandError`, `DeviceError`, `UiError`) wraps it
//! from above.

use ringpod_core::kinematics::KinematicsError;

/// Why a command could not produce its answer.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// `--mechanism` names no preset.
    #[error(transparent)]
    UnknownMechanism(#[from] crate::rig::UnknownMechanism),
    /// The kinematics have no answer.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// The pose is out of reach; `margin` says how far (in the geometry's length unit: m for metric presets).
    #[error("{reason}; the pose is {:.4} outside the reach limits", -margin)]
    OutOfReach {
        /// Which chain and why.
        reason: KinematicsError,
        /// Reach margin of the pose (negative).
        margin: f64,
    },
    /// A rig file is invalid (the error names the file and the key).
    #[error(transparent)]
    Rig(#[from] crate::rig::error::RigError),
    /// A number on the command line cannot be used.
    #[error(transparent)]
    Number(#[from] crate::input::numbers::BadNumber),
    /// A mechanism's chains could not be analysed.
    #[error("structure: {0}")]
    Structure(String),
    /// The matrix-method dynamics have no answer at a point of the motion.
    #[error("dynamics: {0}")]
    Dynamics(String),
    /// A tip-over analysis has no answer.
    #[error("tip-over: {0}")]
    TipOver(ringpod_core::kinematics::TipOverError),
    /// A vehicle that cannot be analysed.
    #[error("vehicle: {0}")]
    Vehicle(#[from] ringpod_core::vehicle::VehicleError),
    /// An experiment on the simulated platform could not run.
    #[error("experiment: {0}")]
    Experiment(String),
    /// JSON output failed.
    #[error("JSON output: {0}")]
    Json(#[from] serde_json::Error),
    /// `workspace --z` with a section that is not at one height.
    #[error("--z is the height of the xy section; the other sections span every height or none")]
    SectionHeight,
    /// A picture was not written.
    #[error(transparent)]
    Plot(#[from] crate::out::plot::PlotError),
    /// The cueing file.
    #[error(transparent)]
    Cueing(#[from] crate::input::cueing::CueingFileError),
    /// A command for ring platforms was given another mechanism.
    #[error("cueing moves a ring platform; {0} is not one")]
    NotARing(String),
    /// Cueing about a neutral pose outside the platform's own workspace.
    #[error(
        "cueing moves the platform about its home, and {name}'s home fails the {check} check (`ringpod check`): no \
         pose about it is inside the envelope; give the rig a home inside its workspace"
    )]
    NeutralOutside {
        /// The mechanism.
        name: String,
        /// The check its home fails.
        check: ringpod_core::kinematics::workspace::Check,
    },
    /// A file could not be written.
    #[error("{}: {reason}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
}

impl CliError {
    /// `--what: reason`: an option's value the command cannot use.
    pub fn bad(what: &'static str, reason: String) -> Self {
        Self::Number(crate::input::numbers::BadNumber::new(what, reason))
    }

    /// `path: reason`: a file that could not be written.
    pub fn file(path: &std::path::Path, reason: impl std::fmt::Display) -> Self {
        Self::File {
            path: path.to_owned(),
            reason: reason.to_string(),
        }
    }
}

/// A rig command's error is said as the command line's own of the same kind.
impl From<crate::rig::CommandError> for CliError {
    fn from(e: crate::rig::CommandError) -> Self {
        use crate::rig::CommandError as E;
        match e {
            E::UnknownMechanism(e) => Self::UnknownMechanism(e),
            E::Number(e) => Self::Number(e),
            E::Rig(e) => Self::Rig(e),
            E::Json(e) => Self::Json(e),
        }
    }
}

impl From<ringpod_core::kinematics::TipOverError> for CliError {
    fn from(e: ringpod_core::kinematics::TipOverError) -> Self {
        Self::TipOver(e)
    }
}

/// An error and its causes in one line, each said once: a message that already holds its cause's words (`transport:
/// {0}` over the I/O error it wraps, which is also its `source()`) is not followed by them again, as anyhow's `{:#}`
/// would ("transport: the peer closed the connection: the peer closed the connection").
pub fn in_one_line(error: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in error.chain() {
        let words = cause.to_string();
        if words.is_empty() || line.contains(&words) {
            continue;
        }
        if !line.is_empty() {
            line += ": ";
        }
        line += &words;
    }
    line
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_cause_is_said_once() {
        let peer = std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "the peer closed the connection");
        let twice = anyhow::Error::from(crate::link::client::ClientError::Io(peer));
        assert_eq!(super::in_one_line(&twice), "transport: the peer closed the connection");
        let chained = anyhow::Error::from(std::io::Error::other("no space")).context("writing x.csv");
        assert_eq!(super::in_one_line(&chained), "writing x.csv: no space");
    }

    /// The errors that say their cause in their own words give no `source()`: `main` prints an error with its
    /// chain (`{:#}`), and a cause given both ways was printed twice (`/dev/x: No such file: No such file`).
    #[test]
    fn a_cause_in_the_words_is_not_also_a_source() {
        let io = || std::io::Error::new(std::io::ErrorKind::NotFound, "not there");
        let json = serde_json::from_str::<u8>("x").unwrap_err();
        let errors: [Box<dyn std::error::Error>; 4] = [
            Box::new(crate::link::LinkError::Open {
                port: "/dev/x".into(),
                reason: serialport::Error::new(serialport::ErrorKind::NoDevice, "not there"),
            }),
            Box::new(crate::stream::command::SourceError::Bind {
                addr: "127.0.0.1:9".parse().unwrap(),
                reason: io(),
            }),
            Box::new(crate::cueing::offline::CueError::Output {
                path: "/x.csv".into(),
                reason: io(),
            }),
            Box::new(crate::device::settings::ConfigCommandError::Section {
                change: None,
                section: "stream",
                reason: json,
            }),
        ];
        for e in errors {
            assert!(e.source().is_none(), "{e}");
            assert!(e.to_string().contains(": "), "{e}");
        }
    }
}
