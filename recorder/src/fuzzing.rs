//! Every fuzz target's entry point in one place, for the fuzz targets (`fuzz/`) and the corpus test (`tests/fuzz_corpus.rs`): bytes in, `Ok` or an error naming the file, never a panic. The case and dump readers are here, the file readers in [`tdex_format::fuzzing`].

use crate::case::CaseError;
use crate::import::{liggghts, ImportError};
use std::path::Path;
use tdex_format::fuzzing::{extrapolation, pairing, recording, SIDECAR_NAME};

pub use tdex_format::fuzzing::MCAP_NAME;

/// The fuzz targets, each with a folder of the regression corpus `tests/corpus/<target>/`.
pub const TARGETS: [&str; 5] = ["recording", "extrapolation", "dump", "case", "pairing"];
/// The file name the errors of [`atom_dump`] and [`contact_dump`] name.
pub const DUMP_NAME: &str = "fuzz-input.dump";
/// The file name the errors of [`case`] name.
pub const CASE_NAME: &str = "fuzz-input.toml";

/// Steps between the atom snapshots [`atom_dump`] takes (the hand-written dumps of
/// `tests/cli_import.rs` have `τ = 30` with a frame at `t0 + 15`).
pub const DUMP_PERIOD: u64 = 15;
/// The particles of t0 [`contact_dump`] assumes: LIGGGHTS ids `1..=250`, as in those dumps.
pub const DUMP_PARTICLES: u64 = 250;

/// Reads `bytes` (plain or gzip) as a LIGGGHTS atom dump (`dump custom`) the way
/// `tdex import liggghts` reads `--atoms`: every frame, and the snapshots every
/// [`DUMP_PERIOD`] steps from the first parsed and checked.
pub fn atom_dump(bytes: &[u8]) -> Result<(), ImportError> {
    liggghts::atom_snapshots_of_bytes(Path::new(DUMP_NAME), bytes.to_vec(), DUMP_PERIOD).map(drop)
}

/// Reads `bytes` (plain or gzip) as a LIGGGHTS contact dump (`dump local`) the way
/// `tdex import liggghts` reads `--contacts`: every frame parsed and sampled into rows.
pub fn contact_dump(bytes: &[u8]) -> Result<(), ImportError> {
    liggghts::contact_rows_of_bytes(
        Path::new(DUMP_NAME),
        bytes.to_vec(),
        DUMP_PARTICLES,
        0.005,
        10,
    )
    .map(drop)
}

/// Parses and validates `bytes` as a case file.
pub fn case(bytes: &[u8]) -> Result<(), CaseError> {
    crate::case::parse_bytes(bytes, Path::new(CASE_NAME)).map(drop)
}

/// The file name the errors of the target `target` name (the input is not read from disk).
pub fn file_name(target: &str) -> Option<&'static str> {
    Some(match target {
        "recording" | "extrapolation" => MCAP_NAME,
        "dump" => DUMP_NAME,
        "case" => CASE_NAME,
        "pairing" => SIDECAR_NAME,
        _ => return None,
    })
}

/// Runs the readers of the fuzz target `target` (one of [`TARGETS`]) on `bytes`: each
/// reader's outcome, the error as its message. `None` for another target.
pub fn run(target: &str, bytes: &[u8]) -> Option<Vec<Result<(), String>>> {
    fn text<E: std::fmt::Display>(r: Result<(), E>) -> Result<(), String> {
        r.map_err(|e| e.to_string())
    }
    Some(match target {
        "recording" => vec![text(recording(bytes))],
        "extrapolation" => vec![text(extrapolation(bytes))],
        "dump" => vec![text(atom_dump(bytes)), text(contact_dump(bytes))],
        "case" => vec![text(case(bytes))],
        "pairing" => vec![text(pairing(bytes))],
        _ => return None,
    })
}
