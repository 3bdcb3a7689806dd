//! What a command gives back: the text it prints and its exit code, and the pictures it draws.

pub mod plot;

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
