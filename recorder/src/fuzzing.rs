//! The input readers as the fuzz targets (`fuzz/`) and the corpus test (`tests/fuzz_corpus.rs`) run them: bytes in, `Ok` or an error naming the file, never a panic.

use crate::case::CaseError;
use crate::format::{ExtrapolationReader, FormatError, RecordingReader};
use crate::import::{liggghts, ImportError};
use std::path::Path;

/// The file name the errors of [`recording`] and [`extrapolation`] name.
pub const MCAP_NAME: &str = "fuzz-input.mcap";
/// The file name the errors of [`atom_dump`] and [`contact_dump`] name.
pub const DUMP_NAME: &str = "fuzz-input.dump";
/// The file name the errors of [`case`] name.
pub const CASE_NAME: &str = "fuzz-input.toml";

/// Steps between the atom snapshots [`atom_dump`] takes (the hand-written dumps of
/// `tests/cli_import.rs` have `τ = 30` with a frame at `t0 + 15`).
pub const DUMP_PERIOD: u64 = 15;
/// The particles of t0 [`contact_dump`] assumes: LIGGGHTS ids `1..=250`, as in those dumps.
pub const DUMP_PARTICLES: u64 = 250;

/// Opens `bytes` as a recording and reads everything a tdex command reads of one: its info,
/// summary, costs and sizes, every snapshot (all, and `t0` and `t1` alone, and the DEM
/// twins') and the whole table.
pub fn recording(bytes: &[u8]) -> Result<(), FormatError> {
    let reader = RecordingReader::from_bytes(Path::new(MCAP_NAME), bytes.to_vec())?;
    let _ = (reader.info(), reader.summary(), reader.costs());
    let _ = (reader.file_bytes(), reader.table_bytes());
    reader.snapshots()?;
    reader.twin_snapshots()?;
    reader.snapshot(0)?;
    reader.snapshot(1)?;
    for batch in reader.table() {
        batch?;
    }
    Ok(())
}

/// Opens `bytes` as an extrapolation and reads its info, costs and every snapshot (at once
/// and streamed).
pub fn extrapolation(bytes: &[u8]) -> Result<(), FormatError> {
    let reader = ExtrapolationReader::from_bytes(Path::new(MCAP_NAME), bytes.to_vec())?;
    let _ = (reader.info(), reader.costs(), reader.snapshot_count());
    reader.snapshots()?;
    for snapshot in reader.snapshots_in_order() {
        snapshot?;
    }
    Ok(())
}

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

/// Runs the readers of the fuzz target `target` (`recording`, `extrapolation`, `dump` or
/// `case`) on `bytes`: each reader's outcome, the error as its message. `None` for another
/// target.
pub fn run(target: &str, bytes: &[u8]) -> Option<Vec<Result<(), String>>> {
    fn text<E: std::fmt::Display>(r: Result<(), E>) -> Result<(), String> {
        r.map_err(|e| e.to_string())
    }
    Some(match target {
        "recording" => vec![text(recording(bytes))],
        "extrapolation" => vec![text(extrapolation(bytes))],
        "dump" => vec![text(atom_dump(bytes)), text(contact_dump(bytes))],
        "case" => vec![text(case(bytes))],
        _ => return None,
    })
}
