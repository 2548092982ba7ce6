//! The replay against the DEM (docs/method.md §6): self-consistency with `n = 1`,
//! `Δt_c^max = 1` step and the synchronous scheme; heat conservation of every scheme over
//! 100 periods; the explicit scheme's CFL refusal through the CLI.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use extrapolate::pairing::{pair, PairingOptions};
use extrapolate::replay::{self, Bodies, Scheme, Table};
use std::path::Path;
use tdex_format::{RecordingReader, Snapshot};

fn record(dir: &Path, case_text: &str, flags: &[&str]) -> std::path::PathBuf {
    let case = dir.join("case.toml");
    std::fs::write(&case, case_text).unwrap();
    let out = dir.join("run.mcap");
    let mut args = vec![
        "record",
        case.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(flags);
    let o = run_tdex(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// The snapshots at `t0` and `t1`, the bodies and the in-memory table of a recording.
fn open(recording: &Path) -> (Snapshot, Snapshot, Bodies, Table) {
    let reader = RecordingReader::open(recording).unwrap();
    let (t0, t1) = (
        reader.snapshot(0).unwrap().unwrap(),
        reader.snapshot(1).unwrap().unwrap(),
    );
    let bodies = Bodies::of(reader.info(), &t0);
    let (table, _) = Table::read(&reader, &bodies).unwrap();
    (t0, t1, bodies, table)
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn replaying_the_recorded_period_reproduces_the_dem_temperatures_at_t1() {
    let dir = tempfile::tempdir().unwrap();
    let out = record(
        dir.path(),
        TINY_CASE,
        &[
            "--tau",
            "0.05",
            "--n",
            "1",
            "--dtc-max",
            "1",
            "--exact-area",
        ],
    );
    let (t0, t1, bodies, table) = open(&out);
    let mut temps = t0.temp.clone();
    replay::apply_rows(&mut temps, &table.exchanges, &bodies, Scheme::Synchronous);
    let worst = max_difference(&temps, &t1.temp);
    let moved = max_difference(&t0.temp, &t1.temp);
    eprintln!(
        "{} rows; largest DEM change over the period {moved:.3e} K, replay error {worst:.3e} K",
        table.exchanges.len()
    );
    assert!(moved > 1e-3, "the period must move heat ({moved} K)");
    assert!(worst < 1e-9, "replay differs from the DEM by {worst} K");
}

#[test]
fn every_scheme_conserves_heat_over_100_periods() {
    let dir = tempfile::tempdir().unwrap();
    let out = record(dir.path(), TINY_CASE, &["--tau", "0.1"]);
    let (t0, t1, bodies, table) = open(&out);
    let g = pair(&t0.pos, &t1.pos, &PairingOptions::for_diameter(0.01))
        .unwrap()
        .g;
    for scheme in [Scheme::Explicit, Scheme::Exact, Scheme::Synchronous] {
        let mut temps = t1.temp.clone();
        let start = replay::total_heat(&temps, &bodies);
        let mut next = Vec::new();
        for _ in 0..100 {
            replay::move_to_roles(&temps, &g, &mut next).unwrap();
            std::mem::swap(&mut temps, &mut next);
            replay::apply_rows(&mut temps, &table.exchanges, &bodies, scheme);
        }
        let end = replay::total_heat(&temps, &bodies);
        let spread = temps.iter().cloned().fold(f64::MIN, f64::max)
            - temps.iter().cloned().fold(f64::MAX, f64::min);
        eprintln!(
            "{scheme:?}: relative heat change {:.2e}, spread {spread:.3} K",
            (end - start) / start
        );
        assert!(
            ((end - start) / start).abs() < 1e-12,
            "{scheme:?}: {start} -> {end}"
        );
        assert!(
            spread < 19.0,
            "{scheme:?}: 100 periods must mix the 20 K split ({spread} K)"
        );
    }
}

#[test]
fn the_explicit_scheme_refuses_an_unstable_table_and_names_the_row() {
    let dir = tempfile::tempdir().unwrap();
    // a thousandfold conductivity and Δt_c^max of 1000 steps: c ≫ 1 on long contacts
    let hot = TINY_CASE.replace("conductivity = 100.0", "conductivity = 1.0e5");
    let out = record(dir.path(), &hot, &["--tau", "0.2", "--dtc-max", "1000"]);
    let extra = dir.path().join("extra.mcap");
    let args = |scheme: &str| {
        run_tdex(&[
            "extrapolate",
            out.to_str().unwrap(),
            "--periods",
            "2",
            "-o",
            extra.to_str().unwrap(),
            "--scheme",
            scheme,
        ])
    };
    let o = args("explicit");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for needed in ["CFL number", "row ", "--dtc-max", "--scheme exact"] {
        assert!(err.contains(needed), "missing '{needed}': {err}");
    }
    assert!(!extra.exists(), "no output after a refusal");
    let o = args("exact");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(extra.exists());
}

#[test]
fn a_stored_pairing_is_reused_only_for_the_same_snapshots() {
    let dir = tempfile::tempdir().unwrap();
    let extra = dir.path().join("extra.mcap");
    let extrapolate = |run: &Path| -> serde_json::Value {
        let o = run_tdex(&[
            "extrapolate",
            run.to_str().unwrap(),
            "--periods",
            "1",
            "-o",
            extra.to_str().unwrap(),
            "--json",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let flags = ["--tau-rev", "0.25"];
    let run = record(dir.path(), TINY_CASE, &flags);
    assert_eq!(extrapolate(&run)["costs"]["pairing_reused"], false);
    assert_eq!(extrapolate(&run)["costs"]["pairing_reused"], true);
    // Another packing recorded into the same file: its pairing is computed afresh.
    let other = TINY_CASE.replace("seed = 5", "seed = 6");
    assert_ne!(other, TINY_CASE);
    let run = record(dir.path(), &other, &flags);
    assert_eq!(extrapolate(&run)["costs"]["pairing_reused"], false);
}
