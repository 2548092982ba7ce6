//! Every fuzz target's entry point in one place, for the fuzz targets (`fuzz/`) and the corpus test (`tests/fuzz_corpus.rs`): the pairing sidecar here, the others in [`recorder::fuzzing`].

use crate::sidecar::{self, SidecarError};
use std::path::Path;

/// The fuzz targets, each with a folder of the regression corpus `tests/corpus/<target>/`.
pub const TARGETS: [&str; 5] = ["recording", "extrapolation", "dump", "case", "pairing"];

/// The file name the errors of [`pairing`] name.
pub const SIDECAR_NAME: &str = "fuzz-input.mcap.pairing.json";
/// The particles of the recording [`pairing`] assumes (the micro drum of the seed corpus, `tests/corpus/README.md`).
pub const SIDECAR_PARTICLES: usize = 30;

/// Parses and checks `bytes` as the pairing sidecar of a recording of
/// [`SIDECAR_PARTICLES`] particles.
pub fn pairing(bytes: &[u8]) -> Result<(), SidecarError> {
    sidecar::parse(bytes, Path::new(SIDECAR_NAME), SIDECAR_PARTICLES).map(drop)
}

/// The file name the errors of the target `target` name (the input is not read from disk).
pub fn file_name(target: &str) -> Option<&'static str> {
    use recorder::fuzzing::{CASE_NAME, DUMP_NAME, MCAP_NAME};
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
    match target {
        "pairing" => Some(vec![pairing(bytes).map_err(|e| e.to_string())]),
        _ => recorder::fuzzing::run(target, bytes),
    }
}
