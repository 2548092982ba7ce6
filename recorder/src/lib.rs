//! tdex recorder: case files, the thermal DEM engine of a rotating drum, the collision
//! recorder, LIGGGHTS import and VTK export. The files it writes are defined in the
//! `tdex-format` crate (`recorder/format/`).
//!
//! Stages follow a DEM step: [`neighbor`] (cell grid, Verlet list), [`contact`] (one file per
//! force law or pair kind), [`wall`], [`heat`] (conduction), [`integrate`], tied together by
//! [`pipeline`]; [`counters`] times each stage. [`simulation`] drives a whole drum case.
//! [`record`] samples the contacts into the table that `tdex_format::RecordingWriter` writes;
//! [`import`] builds the same recording from LIGGGHTS dumps and [`export`] writes files for
//! ParaView; every file goes through `tdex_format::output` (temporary file, fsync, rename).

pub mod case;
pub mod contact;
pub mod counters;
pub mod export;
pub mod fuzzing;
pub mod heat;
pub mod import;
pub mod insertion;
pub mod integrate;
pub mod math;
pub mod neighbor;
pub mod particles;
pub mod periodic;
pub mod pipeline;
pub mod prefetch;
pub mod record;
pub mod simd;
pub mod simulation;
pub mod slices;
pub mod wall;

pub use case::{Case, CaseError};

/// The fault of `error` if it is one of the recorder's errors or of the file format's.
pub fn fault_of(error: &(dyn std::error::Error + 'static)) -> Option<tdex_format::Fault> {
    use tdex_format::fault_as;
    fault_as::<CaseError>(error)
        .or_else(|| fault_as::<SimulationError>(error))
        .or_else(|| fault_as::<record::RecordError>(error))
        .or_else(|| fault_as::<record::CheckpointError>(error))
        .or_else(|| fault_as::<record::JournalError>(error))
        .or_else(|| fault_as::<import::ImportError>(error))
        .or_else(|| tdex_format::fault_of(error))
}
pub use simulation::{Simulation, SimulationError};
