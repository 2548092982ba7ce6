//! The pairing of any two snapshots of a recording, stored as a sidecar beside it: a
//! diagnostic for path studies (`tests/python/path_model.py`), where `tdex pair` pairs only
//! the ends a replay path uses (the recording's last snapshot to each start).
//!
//! usage: cargo run --release -p extrapolate --example pair_snapshots -- RECORDING END START
//!
//! Pairs snapshot `t_END` to `t_START` (each particle at `t_END` to the role it would take at
//! `t_START`, minimum total distance, certified as `tdex pair`'s) and writes
//! `RECORDING.pairing.tEND-tSTART.json` (`RECORDING.pairing.json` for `t1` to `t0`), the
//! sidecar `tdex extrapolate` reads, with the same summary.

use extrapolate::cache;
use std::path::Path;
use std::process::ExitCode;
use tdex_format::RecordingReader;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [recording, end, start] = args.as_slice() else {
        eprintln!(
            "usage: pair_snapshots RECORDING END START (snapshot indices: 0 for t0, k for t_k)"
        );
        return ExitCode::from(2);
    };
    let index = |name: &str, value: &str| {
        value
            .parse::<u32>()
            .map_err(|_| format!("{name}: {value:?} is not a snapshot index (0 for t0, k for t_k)"))
    };
    let result = index("END", end)
        .and_then(|end| Ok((end, index("START", start)?)))
        .and_then(|(end, start)| {
            if end == start {
                return Err(format!("END and START are both t{end}: nothing to pair"));
            }
            pair(Path::new(recording), end, start)
        });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Pairs and stores; the error names the recording (the reader's own errors already do).
fn pair(recording: &Path, end: u32, start: u32) -> Result<(), String> {
    let reader = RecordingReader::open(recording).map_err(|e| e.to_string())?;
    let named = |e: extrapolate::ExtrapolateError| format!("{}: {e}", recording.display());
    let (t_end, t_start) = (
        cache::snapshot(&reader, end).map_err(named)?,
        cache::snapshot(&reader, start).map_err(named)?,
    );
    let period = extrapolate::axial_period(reader.info());
    let stored = cache::compute(&t_start, &t_end, period).map_err(named)?;
    let path = cache::store(&reader, end, start, &stored).map_err(named)?;
    let s = &stored.summary;
    println!(
        "t{end} to t{start}: {} particles, mean distance {:.4} diameters, certified: {}, {:.2} s; stored in {}",
        s.particles,
        s.mean_distance_diameters,
        if s.certified { "yes" } else { "no" },
        s.seconds.unwrap_or(0.0),
        path.display()
    );
    Ok(())
}
