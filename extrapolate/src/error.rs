//! Why a recording cannot be paired or extrapolated: the errors of the layers below, and
//! whether the fault is in the input the user gave.

use crate::pairing::PairingError;
use crate::replay::ReplayError;
use std::path::PathBuf;
use tdex_format::output::OutputError;
use tdex_format::{fault_as, Classify, Fault, FormatError};

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
    /// More recorded periods asked for than the recording holds (or none).
    #[error(
        "{}: {asked} recorded periods asked for, but the recording holds {recorded} \
         (recorded_periods must be between 1 and {recorded})",
        recording.display()
    )]
    RecordedPeriods {
        recording: PathBuf,
        asked: u32,
        recorded: u32,
    },
    #[error(
        "{}: jump target {target} is not one of the {used} recorded period(s) replayed \
         (jump targets must be between 1 and {used})",
        recording.display()
    )]
    JumpTarget {
        recording: PathBuf,
        target: u32,
        used: u32,
    },
    /// Near starts asked of a path that leaves from every end: they are ranked by their
    /// pairing with the recording's end `t_P'` alone.
    #[error(
        "{}: the starts nearest the recording's end are ranked by their pairing with t{used}, \
         and a path leaving every {every} period(s) jumps from every recorded end",
        recording.display()
    )]
    NearestLeavingEvery {
        recording: PathBuf,
        used: u32,
        every: u32,
    },
    /// The axial mirror asked of a recording whose geometry is not known to be symmetric.
    #[error(
        "{}: its case has no [drum], so its mid-plane y = 0 is not known to be a mirror \
         plane (the axial mirror needs a tdex drum: axis y, end caps at y = ±L/2)",
        recording.display()
    )]
    NoMirrorImage { recording: PathBuf },
    /// Fresh boundary maps asked of a recording whose drum axis is not known.
    #[error(
        "{}: its case has no [drum], so the drum's axis is not known (fresh boundary maps \
         redraw the particles' steps along a tdex drum's axis y; use --boundary exact)",
        recording.display()
    )]
    NoDrumAxis { recording: PathBuf },
    /// A cap zone asked of a section periodic along its axis, which has no end caps.
    #[error(
        "{}: its section is periodic along the axis and has no end caps, so a cap zone of \
         {cap_zone_diameters} diameters keeps nothing (the cap zone must be 0 there)",
        recording.display()
    )]
    CapZoneWithoutCaps {
        recording: PathBuf,
        cap_zone_diameters: f64,
    },
    #[error("the recording has no t{index} snapshot")]
    MissingSnapshot { index: u32 },
    /// The pairing sidecar could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Encode(#[from] serde_json::Error),
}

impl Classify for ExtrapolateError {
    fn fault(&self) -> Fault {
        match self {
            ExtrapolateError::Format(e) => e.fault(),
            ExtrapolateError::Pairing(_)
            | ExtrapolateError::Replay(_)
            | ExtrapolateError::Refused { .. }
            | ExtrapolateError::RecordedPeriods { .. }
            | ExtrapolateError::JumpTarget { .. }
            | ExtrapolateError::NearestLeavingEvery { .. }
            | ExtrapolateError::NoMirrorImage { .. }
            | ExtrapolateError::CapZoneWithoutCaps { .. }
            | ExtrapolateError::NoDrumAxis { .. } => Fault::Input,
            // a missing snapshot has always exited with 1 (kept so: behaviour unchanged)
            ExtrapolateError::MissingSnapshot { .. }
            | ExtrapolateError::Output(_)
            | ExtrapolateError::Encode(_) => Fault::Run,
        }
    }
}

impl Classify for PairingError {
    /// Snapshots that cannot be paired are the recording's fault.
    fn fault(&self) -> Fault {
        Fault::Input
    }
}

impl Classify for ReplayError {
    /// A table the replay refuses, or a pairing that does not fit it, is the input's fault.
    fn fault(&self) -> Fault {
        Fault::Input
    }
}

/// The fault of `error` if it is one of this crate's errors or of the file format's.
pub fn fault_of(error: &(dyn std::error::Error + 'static)) -> Option<Fault> {
    fault_as::<ExtrapolateError>(error)
        .or_else(|| fault_as::<PairingError>(error))
        .or_else(|| fault_as::<ReplayError>(error))
        .or_else(|| tdex_format::fault_of(error))
}
