//! Recordings made from another DEM engine's output: LIGGGHTS text dumps (`tdex import liggghts`).

pub mod dump;
pub mod liggghts;

use crate::format::FormatError;
use std::path::PathBuf;

/// Why dumps cannot be imported; every message names the file (and line) at fault.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("{path}: cannot read: {error}")]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}:{line}: {detail}")]
    At {
        path: PathBuf,
        line: u64,
        detail: String,
    },
    #[error("{pattern}: no file matches (wildcards `*`, `%` and `?` in the file name only)")]
    NoFiles { pattern: String },
    /// Dumps that are each well formed but do not make one recording together.
    #[error("{0}")]
    Inconsistent(String),
    /// The case cannot describe an imported run.
    #[error("{0}")]
    Case(String),
    #[error(transparent)]
    Format(#[from] FormatError),
}

impl ImportError {
    /// Whether the error is in the input (exit code 2), not in writing the recording.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ImportError::Format(f) => f.is_bad_input(),
            _ => true,
        }
    }
}
