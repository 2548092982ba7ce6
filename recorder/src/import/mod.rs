//! Recordings made from another DEM engine's output: LIGGGHTS text dumps (`tdex import liggghts`).

pub mod dump;
pub mod liggghts;

use std::path::PathBuf;
use tdex_format::FormatError;

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
    /// The atom dumps have `t0` but no frame `τ` steps later: they were dumped with
    /// another period than the one asked for.
    #[error(
        "{pattern}: no atom dump at t1 = timestep {step_t1} (t0 = timestep {step_t0}, the \
         first atom dump, + τ = {period} steps); other atom timesteps found: {others}. Dump \
         the atoms at t0 and every τ steps after it, or import with τ set to the period that \
         was dumped"
    )]
    NoAtomDumpAtT1 {
        pattern: String,
        step_t0: u64,
        step_t1: u64,
        period: u64,
        /// The other atom timesteps seen, with their files (`none` without any).
        others: String,
    },
    /// The case heats its mantle, but no wall contacts were given: the mantle's heat would
    /// be lost from the replay.
    #[error(
        "{}: drum.wall_temperature = {temperature} K (a heated mantle), but no wall contact \
         dumps were given: the replay heats the bed through the wall rows they make",
        case.display()
    )]
    HeatedMantleWithoutWallDumps { case: PathBuf, temperature: f64 },
    /// Wall contacts were given for a case whose walls are adiabatic.
    #[error(
        "{pattern}: wall contact dumps for {}, whose walls are adiabatic (no \
         drum.wall_temperature): its wall rows would conduct from a mantle without a temperature",
        case.display()
    )]
    WallDumpsWithoutHeatedMantle { case: PathBuf, pattern: String },
    /// The case cannot describe an imported run.
    #[error("{0}")]
    Case(String),
    #[error(transparent)]
    Format(#[from] FormatError),
}

impl tdex_format::Classify for ImportError {
    /// The input is at fault, unless writing the recording failed.
    fn fault(&self) -> tdex_format::Fault {
        match self {
            ImportError::Format(f) => tdex_format::Classify::fault(f),
            _ => tdex_format::Fault::Input,
        }
    }
}
