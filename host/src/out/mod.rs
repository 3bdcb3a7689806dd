//! What a command gives back: the text it prints and its exit code, and the pictures it draws.

pub mod console;
pub mod file;
pub mod plot;

/// Exit code of a run that failed (bad input, no kinematic solution).
pub const EXIT_ERROR: u8 = 1;
/// Exit code of a command whose standard output or error could not be written: a closed pipe (128 + SIGPIPE, the
/// code a shell shows for a program a closed pipe ended) or a full disk. A stream ends as a stop does first.
pub const EXIT_OUTPUT: u8 = 141;
/// Exit code of `check` when the pose has a solution but a workspace check fails.
pub const EXIT_CHECK_FAILED: u8 = 3;

/// What a command prints and its exit code.
pub struct Outcome {
    pub text: String,
    pub code: u8,
}

impl Outcome {
    pub fn ok(text: String) -> Self {
        Self { text, code: 0 }
    }
}
