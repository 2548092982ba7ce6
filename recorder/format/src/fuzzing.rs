//! The file readers as the fuzz targets (`fuzz/`) and the corpus test (`tests/fuzz_corpus.rs`) run them: bytes in, `Ok` or an error naming the file, never a panic. The case and dump targets are in `recorder::fuzzing`, which runs every target.

use crate::sidecar::{self, SidecarError};
use crate::{ExtrapolationReader, FormatError, RecordingReader};
use std::path::Path;

/// The file name the errors of [`recording`] and [`extrapolation`] name.
pub const MCAP_NAME: &str = "fuzz-input.mcap";
/// The file name the errors of [`pairing`] name.
pub const SIDECAR_NAME: &str = "fuzz-input.mcap.pairing.json";
/// The particles of the recording [`pairing`] assumes (the micro drum of the seed corpus, `tests/corpus/README.md`).
pub const SIDECAR_PARTICLES: usize = 30;

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

/// Parses and checks `bytes` as the pairing sidecar of a recording of
/// [`SIDECAR_PARTICLES`] particles.
pub fn pairing(bytes: &[u8]) -> Result<(), SidecarError> {
    sidecar::parse(bytes, Path::new(SIDECAR_NAME), SIDECAR_PARTICLES).map(drop)
}
