//! Why a rig file cannot be used: the key (with the file's path once read from one) and what is wrong with it.

use std::fmt;
use std::path::Path;

/// Why a rig file cannot be used: the key, and what is wrong with it.
#[derive(Debug, Clone, PartialEq)]
pub struct RigError {
    /// The key (`chains[2].branch`, `limits.stroke`, `home`), prefixed with the file's path once read from one;
    /// empty for errors of the whole text (its syntax, the core's check of the geometry).
    pub key: String,
    /// Why.
    pub why: String,
}

impl fmt::Display for RigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.key.is_empty() {
            f.write_str(&self.why)
        } else {
            write!(f, "{}: {}", self.key, self.why)
        }
    }
}

impl std::error::Error for RigError {}

impl RigError {
    /// An error of `key`.
    pub fn new(key: impl Into<String>, why: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            why: why.into(),
        }
    }

    /// The same error, said of the file at `path` (once: the path goes in front of the key).
    pub(super) fn in_file(self, path: &Path) -> Self {
        let key = match self.key.is_empty() {
            true => path.display().to_string(),
            false => format!("{}: {}", path.display(), self.key),
        };
        Self { key, why: self.why }
    }
}
