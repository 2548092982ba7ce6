//! tdex recorder: case files, the thermal DEM engine of a rotating drum, the collision
//! recorder and its file format, LIGGGHTS import and VTK export.
//!
//! Stages follow a DEM step: [`neighbor`] (cell grid, Verlet list), [`contact`] (one file per
//! force law or pair kind), [`wall`], [`heat`] (conduction), [`integrate`], tied together by
//! [`pipeline`]; [`counters`] times each stage. [`simulation`] drives a whole drum case.
//! [`record`] samples the contacts into the table that [`format`] writes; [`import`] builds
//! the same recording from LIGGGHTS dumps and [`export`] writes files for ParaView; every
//! file goes through [`output`] (temporary file, fsync, rename).

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
pub mod pipeline;
pub mod prefetch;
pub mod record;
pub mod simulation;
pub mod slices;
pub mod wall;

pub use case::{Case, CaseError};
pub use simulation::{Simulation, SimulationError};
/// The file contract lives in its own crate (`recorder/format`); these paths keep reading
/// as before for the engine's own modules.
pub use tdex_format::{self as format, output};
