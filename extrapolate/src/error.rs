//! Why a recording cannot be paired or extrapolated: the errors of the layers below, and
//! whether the fault is in the input the user gave.

use crate::pairing::PairingError;
use crate::replay::ReplayError;
use std::path::PathBuf;
use tdex_format::output::OutputError;
use tdex_format::FormatError;

/// Why [`extrapolate_recording`](crate::extrapolate_recording) or the pairing cache failed.
/// The wrapped errors read as they do on their own.
#[derive(Debug, thiserror::Error)]
pub enum ExtrapolateError {
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error(transparent)]
    Pairing(#[from] PairingError),
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The replay of this recording is refused (memory, the explicit scheme's CFL guard).
    #[error("{}", recording.display())]
    Refused {
        recording: PathBuf,
        #[source]
        error: ReplayError,
    },
    #[error("the recording has no t{index} snapshot")]
    MissingSnapshot { index: u32 },
    /// The pairing sidecar could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Encode(#[from] serde_json::Error),
}

impl ExtrapolateError {
    /// Whether the error is in the input the user gave (exit code 2), not in the run.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ExtrapolateError::Format(e) => e.is_bad_input(),
            ExtrapolateError::Pairing(_)
            | ExtrapolateError::Replay(_)
            | ExtrapolateError::Refused { .. } => true,
            // a missing snapshot has always exited with 1 (kept so: behaviour unchanged)
            ExtrapolateError::MissingSnapshot { .. }
            | ExtrapolateError::Output(_)
            | ExtrapolateError::Encode(_) => false,
        }
    }
}
