//! The pairing cache: the pairing of two of a recording's snapshots (`t1` to `t0`, or for
//! several recorded periods `tP` to the start of each period), computed once and stored
//! beside the recording ([`sidecar`], one file per pair of snapshots), reused while the
//! snapshots' positions are the ones it was computed for.

use crate::pairing::{self, PairingOptions};
use crate::sidecar::{self, PairingSummary, StoredPairing};
use crate::ExtrapolateError;
use std::borrow::Cow;
use std::hash::Hasher;
use std::path::PathBuf;
use tdex_format::extrapolation::Symmetry;
use tdex_format::{RecordingReader, Snapshot};

/// The recording's snapshot `t_index`.
pub fn snapshot(reader: &RecordingReader, index: u32) -> Result<Snapshot, ExtrapolateError> {
    reader
        .snapshot(index)?
        .ok_or(ExtrapolateError::MissingSnapshot { index })
}

/// A hash of the positions at the start (`t0`) and the end (`t1`) the pairing joins, its only input: a stored pairing
/// is reused for these snapshots and no others (a recording made again with another case
/// or seed into the same file name has other positions).
///
/// The key is on disk, so its algorithm must not change with the compiler: SipHash-1-3 with
/// zero keys from the `siphasher` crate, fed per point the length 3 as a little-endian u64
/// and the three coordinates' bits, little-endian — the byte stream that std's
/// `DefaultHasher` (SipHash-1-3 with zero keys today, without a promise) was fed by
/// `[u64; 3]::hash` on the 64-bit little-endian machines tdex runs on, so the sidecars
/// written before keep their key.
pub fn fingerprint(t0: &Snapshot, t1: &Snapshot) -> u64 {
    let mut h = siphasher::sip::SipHasher13::new_with_keys(0, 0);
    for p in t0.pos.iter().chain(&t1.pos) {
        h.write(&(p.len() as u64).to_le_bytes());
        for x in p {
            h.write(&x.to_bits().to_le_bytes());
        }
    }
    h.finish()
}

/// Computes the pairing of the snapshot `t1` (the end of a period) to `t0` (the start of
/// one) on the current worker pool: `g[p]` is the role at `t0` nearest particle `p` at
/// `t1` among those of its own radius ([`pairing::pair_by_size`], one cost unit for the
/// whole bed), the distances taken across the seam of a section periodic along its axis
/// with period `axial_period` ([`crate::axial_period`] of the recording). Its summary
/// carries the solve's time and thread count, the number of size classes when there are
/// several, and the period when there is one.
pub fn compute(
    t0: &Snapshot,
    t1: &Snapshot,
    axial_period: Option<f64>,
) -> Result<StoredPairing, ExtrapolateError> {
    let d = t0.mean_diameter();
    let opts = PairingOptions {
        axial_period,
        ..PairingOptions::for_bed(d, &t0.pos, &t1.pos)
    };
    let p = pairing::pair_by_size(&t0.pos, &t0.radius, &t1.pos, &t1.radius, &opts)?;
    let classes = t0.size_classes().len();
    Ok(StoredPairing {
        snapshots_fingerprint: fingerprint(t0, t1),
        summary: PairingSummary {
            particles: p.g.len(),
            diameter: d,
            total_distance_diameters: p.total_distance / d,
            mean_distance_diameters: p.mean_distance_in_diameters(d),
            k_used: p.k_used,
            certified: p.certified,
            rounds: p.rounds,
            size_classes: (classes > 1).then_some(classes),
            axial_period,
            seconds: Some(p.seconds),
            threads: Some(rayon::current_num_threads()),
        },
        g: p.g,
    })
}

/// The stored pairing of this recording's snapshot `t1` (end) to `t0` (start), if one
/// matches them (a missing, unreadable or malformed sidecar is computed again). The
/// snapshots' indices name the sidecar ([`sidecar::path_between`]).
pub fn load(reader: &RecordingReader, t0: &Snapshot, t1: &Snapshot) -> Option<StoredPairing> {
    load_image(reader, t0, t1, Symmetry::None)
}

/// The image of snapshot `start` a jump under `symmetry` enters: the snapshot itself
/// (borrowed: the paper's method copies nothing), or its mirror image (`y → −y` on
/// positions and velocities), with its index.
pub fn start_image(start: &Snapshot, symmetry: Symmetry) -> Cow<'_, Snapshot> {
    match symmetry {
        Symmetry::None => Cow::Borrowed(start),
        Symmetry::AxialMirror => {
            let mut image = start.clone();
            symmetry.copy_image(true, &start.pos, &mut image.pos);
            symmetry.copy_image(true, &start.vel, &mut image.vel);
            Cow::Owned(image)
        }
    }
}

/// Where the pairing of snapshot `end` to (the image under `symmetry` of) snapshot `start`
/// is stored beside the recording.
fn sidecar_path(reader: &RecordingReader, end: u32, start: u32, symmetry: Symmetry) -> PathBuf {
    match symmetry {
        Symmetry::None => sidecar::path_between(reader.path(), end, start),
        Symmetry::AxialMirror => sidecar::path_to_mirror_image(reader.path(), end, start),
    }
}

/// [`load`] of the pairing of `t1` (end) to `start`, the image under `symmetry` of a
/// recorded start ([`start_image`]): its sidecar is named by the symmetry as well.
///
/// On a bed of several particle sizes a stored pairing is reused only if it was computed
/// with its size classes: its summary counts as many as the snapshots hold, and it maps
/// every particle onto a role of its own radius. One written before sizes were kept apart
/// is stale and computed again. Likewise a stored pairing is reused only if it was
/// computed with the recording's axial period ([`crate::axial_period`]): for a periodic
/// section, one computed without the seam is stale.
pub fn load_image(
    reader: &RecordingReader,
    start: &Snapshot,
    t1: &Snapshot,
    symmetry: Symmetry,
) -> Option<StoredPairing> {
    let n = reader.info().particles as usize;
    let path = sidecar_path(reader, t1.index, start.index, symmetry);
    let stored = sidecar::read(&path, n).ok()??;
    let classes = t1.size_classes().len();
    let fresh = stored.snapshots_fingerprint == fingerprint(start, t1)
        && stored.summary.size_classes.unwrap_or(1) == classes
        && pairing::respects_classes(&stored.g, &start.radius, &t1.radius)
        && stored.summary.axial_period.map(f64::to_bits)
            == crate::axial_period(reader.info()).map(f64::to_bits);
    fresh.then_some(stored)
}

/// Writes the pairing of snapshot `end` to snapshot `start` beside the recording
/// (temporary file, fsync, rename); returns the sidecar's path.
pub fn store(
    reader: &RecordingReader,
    end: u32,
    start: u32,
    stored: &StoredPairing,
) -> Result<PathBuf, ExtrapolateError> {
    store_image(reader, end, start, Symmetry::None, stored)
}

/// [`store`] of the pairing of snapshot `end` to the image under `symmetry` of `start`.
pub fn store_image(
    reader: &RecordingReader,
    end: u32,
    start: u32,
    symmetry: Symmetry,
    stored: &StoredPairing,
) -> Result<PathBuf, ExtrapolateError> {
    let path = sidecar_path(reader, end, start, symmetry);
    Ok(tdex_format::output::write_atomically(
        &path,
        &serde_json::to_vec(stored)?,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn snapshot(pos: Vec<[f64; 3]>) -> Snapshot {
        let n = pos.len();
        Snapshot {
            index: 0,
            time: 0.0,
            id: (0..n as u32).collect(),
            pos,
            radius: vec![0.005; n],
            vel: vec![[0.0; 3]; n],
            temp: vec![300.0; n],
        }
    }

    /// The cache key is on disk: a change of algorithm (or of the bytes fed to it) would
    /// silently make every stored pairing stale, so its value is pinned. The literal is also
    /// what std's `DefaultHasher` gave for these positions (Rust 1.95), the key of the
    /// sidecars written before the cache moved to `siphasher`.
    #[test]
    fn the_fingerprint_of_fixed_positions_is_pinned() {
        let t0 = snapshot(vec![[0.0, 0.5, -1.0], [1.0e-3, 2.0, 3.25]]);
        let t1 = snapshot(vec![[1.0e-3, 2.0, 3.25], [f64::MAX, -0.0, 7.0]]);
        assert_eq!(fingerprint(&t0, &t1), 15_178_127_322_323_436_536);
    }
}
