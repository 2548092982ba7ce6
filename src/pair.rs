//! `tdex pair`: the pairing of a recording's `t0` and `t1` snapshots, stored beside it for
//! reuse by `tdex extrapolate` (`RECORDING.pairing.json`).

use crate::cli::PairPlan;
use anyhow::{Context, Result};
use extrapolate::pairing::{self, PairingOptions};
use recorder::format::{RecordingReader, Snapshot};
use std::path::{Path, PathBuf};

pub use extrapolate::sidecar::{PairingSummary, StoredPairing};

pub fn sidecar(recording: &Path) -> PathBuf {
    extrapolate::sidecar::path_of(recording)
}

/// The snapshots at `t0` and `t1` that bound the recorded period.
pub fn period_snapshots(reader: &RecordingReader) -> Result<(Snapshot, Snapshot)> {
    let t0 = reader
        .snapshot(0)?
        .context("the recording has no t0 snapshot")?;
    let t1 = reader
        .snapshot(1)?
        .context("the recording has no t1 snapshot")?;
    Ok((t0, t1))
}

/// A hash of the positions at `t0` and `t1`, the pairing's only input: a stored pairing
/// is reused for these snapshots and no others (a recording made again with another case
/// or seed into the same file name has other positions).
pub fn fingerprint(t0: &Snapshot, t1: &Snapshot) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in t0.pos.iter().chain(&t1.pos) {
        p.map(f64::to_bits).hash(&mut h);
    }
    h.finish()
}

/// Computes the pairing of the recording's snapshots at `t0` and `t1`.
pub fn compute(t0: &Snapshot, t1: &Snapshot) -> Result<StoredPairing> {
    let d = t0.mean_diameter();
    let p = pairing::pair(&t0.pos, &t1.pos, &PairingOptions::for_diameter(d))?;
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
            seconds: Some(p.seconds),
            threads: Some(rayon::current_num_threads()),
        },
        g: p.g,
    })
}

/// The stored pairing of this recording's snapshots `t0` and `t1`, if one matches them (a
/// missing, unreadable or malformed sidecar is computed again).
pub fn load(reader: &RecordingReader, t0: &Snapshot, t1: &Snapshot) -> Option<StoredPairing> {
    let n = reader.info().particles as usize;
    let stored = extrapolate::sidecar::read(&sidecar(reader.path()), n).ok()??;
    (stored.snapshots_fingerprint == fingerprint(t0, t1)).then_some(stored)
}

/// Writes the pairing beside the recording (temporary file, fsync, rename).
pub fn store(reader: &RecordingReader, stored: &StoredPairing) -> Result<PathBuf> {
    let path = sidecar(reader.path());
    Ok(recorder::output::write_atomically(
        &path,
        &serde_json::to_vec(stored)?,
    )?)
}

pub fn run(plan: &PairPlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    let (t0, t1) = period_snapshots(&reader)?;
    let mut stored = crate::with_workers(plan.threads, || compute(&t0, &t1))?;
    let measured = stored.summary.clone();
    if plan.reproducible {
        stored.summary = stored.summary.reproducible();
    }
    let path = store(&reader, &stored)?;
    let s = &measured;
    // replaying one period applies g again and again: each particle only ever plays the
    // roles of its own cycle
    let cycles = pairing::cycle_structure(&stored.g);
    let short_share = cycles.short_share(stored.g.len());
    if plan.json {
        let mut json = serde_json::to_value(s)?;
        json["pairing_file"] = path.display().to_string().into();
        json["cycles"] = serde_json::to_value(&cycles)?;
        json["cycles"]["short_cycle_periods"] = pairing::SHORT_CYCLE.into();
        json["cycles"]["short_share"] = short_share.into();
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        println!(
            "pairing       {} particles, total distance {} diameters (mean {}), k = {}, {} solve round(s), {}",
            s.particles,
            crate::fmt::sig(s.total_distance_diameters, 4),
            crate::fmt::sig(s.mean_distance_diameters, 4),
            s.k_used,
            s.rounds,
            if s.certified { "certified optimal" } else { "NOT certified" }
        );
        println!(
            "cycles of g   {} cycles, {} fixed points (particles that keep their role), {} % of \
             the particles on cycles of at most {} periods, longest {} periods",
            cycles.cycles,
            cycles.fixed_points,
            crate::fmt::sig(100.0 * short_share, 3),
            pairing::SHORT_CYCLE,
            cycles.longest
        );
        println!(
            "time          {:.3} s on {} threads; stored in {}",
            s.seconds.unwrap_or_default(),
            s.threads.unwrap_or_default(),
            path.display()
        );
    }
    Ok(())
}
