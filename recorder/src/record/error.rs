//! Why a recording cannot be made: the engine, the output, the settings, a checkpoint or its
//! row journal.

use super::checkpoint::CheckpointError;
use super::journal::JournalError;
use crate::SimulationError;
use tdex_format::FormatError;
use tdex_format::{Classify, Fault};

#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error(transparent)]
    Simulation(#[from] SimulationError),
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error("invalid recording settings: {0}")]
    Settings(String),
    /// A DEM twin that left the run bit for bit unchanged: it measures no spread.
    #[error(
        "invalid recording settings: DEM twin {twin}: the drum's angular velocity changed by \
         {twin} unit(s) in the last place left the run identical to the DEM at t{snapshot}, bit \
         for bit; a twin that does not differ measures no spread (a drum that does not turn \
         cannot be perturbed this way)"
    )]
    TwinIdentical { twin: u32, snapshot: u32 },
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(transparent)]
    Journal(#[from] JournalError),
}

impl Classify for RecordError {
    /// The input is at fault in a file the user gave: a checkpoint or its row journal that
    /// cannot be resumed.
    fn fault(&self) -> Fault {
        match self {
            RecordError::Checkpoint(e) => e.fault(),
            RecordError::Journal(e) => e.fault(),
            RecordError::Format(e) => e.fault(),
            _ => Fault::Run,
        }
    }
}
