//! `tdex compare` on a tiny drum with a DEM reference: the JSON shape, what the numbers
//! must satisfy, the particle ids of the extrapolation, and refused inputs.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use recorder::format::{ExtrapolationReader, RecordingReader};
use std::path::{Path, PathBuf};

/// A tiny recording (τ = 0.25 rev, reference `reference` periods) and its extrapolation
/// over `periods` periods.
pub(crate) fn record_and_extrapolate(
    dir: &Path,
    reference: u32,
    periods: u32,
) -> (PathBuf, PathBuf) {
    let case = dir.join("case.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let run = dir.join("run.mcap");
    let extra = dir.join("extra.mcap");
    let reference = reference.to_string();
    let periods = periods.to_string();
    for args in [
        vec![
            "record",
            case.to_str().unwrap(),
            "-o",
            run.to_str().unwrap(),
            "--tau-rev",
            "0.25",
            "--reference",
            &reference,
        ],
        vec![
            "extrapolate",
            run.to_str().unwrap(),
            "--periods",
            &periods,
            "-o",
            extra.to_str().unwrap(),
        ],
    ] {
        let o = run_tdex(&args);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    (run, extra)
}

#[test]
fn compare_reports_every_referenced_period() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(dir.path(), 3, 3);
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());

    let o = run_tdex(&["compare", run_s, extra_s, "--cells", "20", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let periods = v["periods"].as_array().expect("periods array");
    assert_eq!(periods.len(), 3);
    let info = RecordingReader::open(&run).unwrap().info().clone();
    for (i, p) in periods.iter().enumerate() {
        let k = i as u64 + 2;
        assert_eq!(p["k"], k);
        let t = p["t"].as_f64().unwrap();
        assert!((t - info.snapshot_time(k as u32)).abs() < 1e-12);
        let num = |key: &str| {
            p[key]
                .as_f64()
                .unwrap_or_else(|| panic!("period {k}: `{key}` is not a number: {}", p[key]))
        };
        let (hot_dem, cold_dem) = (num("hot_mean_dem"), num("cold_mean_dem"));
        let (hot_x, cold_x) = (num("hot_mean_extra"), num("cold_mean_extra"));
        // Both fields start at 30/10 K and relax towards each other without overshoot.
        for (hot, cold) in [(hot_dem, cold_dem), (hot_x, cold_x)] {
            assert!(
                10.0 < cold && cold < hot && hot < 30.0,
                "k {k}: {hot} / {cold}"
            );
        }
        let eps_abs = num("eps_abs");
        assert!(eps_abs >= 0.0);
        assert!((num("eps_rel") - eps_abs / (hot_dem - cold_dem)).abs() < 1e-12);
        assert!(num("energy_error").is_finite());
        assert!(p["cells_used"].as_u64().unwrap() <= 20);
    }
    assert_eq!(v["cells"], 20);
    assert_eq!(
        v["hot_particles"].as_u64().unwrap() + v["cold_particles"].as_u64().unwrap(),
        250
    );

    // The same seed gives the same numbers; another seed other cells.
    let again = run_tdex(&["compare", run_s, extra_s, "--cells", "20", "--json"]);
    assert_eq!(again.stdout, o.stdout);
    let other = run_tdex(&[
        "compare", run_s, extra_s, "--cells", "20", "--seed", "9", "--json",
    ]);
    let w: serde_json::Value = serde_json::from_slice(&other.stdout).unwrap();
    assert_ne!(w["periods"][0]["eps_abs"], v["periods"][0]["eps_abs"]);
    // Group means do not depend on the cells.
    assert_eq!(
        w["periods"][0]["hot_mean_extra"],
        v["periods"][0]["hot_mean_extra"]
    );

    // CSV: a header and one line per period; the terminal table names every k.
    let csv = run_tdex(&["compare", run_s, extra_s, "--cells", "20", "--csv"]);
    let csv = String::from_utf8(csv.stdout).unwrap();
    assert_eq!(csv.lines().count(), 4);
    assert!(csv.starts_with("k,t,eps_abs,eps_rel,energy_error"));
    let table = run_tdex(&["compare", run_s, extra_s, "--cells", "20"]);
    let table = String::from_utf8(table.stdout).unwrap();
    for k in 2..=4 {
        assert!(table
            .lines()
            .any(|l| l.split_whitespace().next() == Some(&k.to_string())));
    }
}

#[test]
fn extrapolated_ids_follow_the_pairing() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(dir.path(), 0, 2);
    let snaps = ExtrapolationReader::open(&extra)
        .unwrap()
        .snapshots()
        .unwrap();
    assert_eq!(
        snaps.iter().map(|s| s.index).collect::<Vec<_>>(),
        vec![1, 2, 3]
    );
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(format!("{}.pairing.json", run.display())).unwrap())
            .unwrap();
    let g: Vec<u32> = serde_json::from_value(sidecar["g"].clone()).unwrap();
    // At t1 particle a plays role a; each period boundary moves the particle at role a
    // to role g(a).
    assert!(snaps[0]
        .id
        .iter()
        .enumerate()
        .all(|(a, &id)| id as usize == a));
    for w in snaps.windows(2) {
        for (a, &id) in w[0].id.iter().enumerate() {
            assert_eq!(w[1].id[g[a] as usize], id);
        }
        // Roles keep the t1 positions.
        assert_eq!(w[1].pos, snaps[0].pos);
    }
    // Comparing needs a DEM reference: refused, naming the flag.
    let o = run_tdex(&["compare", run.to_str().unwrap(), extra.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--reference"));
}

#[test]
fn compare_refuses_files_in_the_wrong_places() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(dir.path(), 1, 1);
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    // Swapped arguments: each file is named with what was expected of it.
    let o = run_tdex(&["compare", extra_s, run_s]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(extra_s) && err.contains("not a tdex recording"),
        "{err}"
    );
    let o = run_tdex(&["compare", run_s, extra_s, "--cells", "0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--cells"));
}

/// Records the tiny case with `seed` into `dir/name.mcap`: one period, given by the flag
/// and value in `period` (`["--tau", "0.5"]`), and `reference` more.
fn record_tiny(dir: &Path, name: &str, seed: u32, period: [&str; 2], reference: u32) -> PathBuf {
    let case = dir.join(format!("{name}.toml"));
    std::fs::write(
        &case,
        TINY_CASE.replace("seed = 5", &format!("seed = {seed}")),
    )
    .unwrap();
    let out = dir.join(format!("{name}.mcap"));
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        period[0],
        period[1],
        "--reference",
        &reference.to_string(),
    ]);
    out
}

#[test]
fn a_second_dem_run_is_compared_on_its_own_particles() {
    let dir = tempfile::tempdir().unwrap();
    let a = record_tiny(dir.path(), "a", 5, ["--tau", "0.5"], 2);
    let b = record_tiny(dir.path(), "b", 6, ["--tau", "0.5"], 2);
    let (a_s, b_s) = (a.to_str().unwrap(), b.to_str().unwrap());
    let json = |x: &str, y: &str| -> serde_json::Value {
        serde_json::from_str(&tdex_ok(&["compare", x, y, "--cells", "20", "--json"])).unwrap()
    };
    let (ab, aa, bb) = (json(a_s, b_s), json(a_s, a_s), json(b_s, b_s));
    assert_eq!(ab["second"], "dem");
    let ks = |v: &serde_json::Value| -> Vec<u64> {
        v["periods"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["k"].as_u64().unwrap())
            .collect()
    };
    // A second run is compared from t1 on: it is not the recording's DEM there.
    assert_eq!(ks(&ab), vec![1, 2, 3]);
    for k in 0..3 {
        let (pab, paa, pbb) = (&ab["periods"][k], &aa["periods"][k], &bb["periods"][k]);
        // A run against itself: nothing apart.
        assert_eq!(paa["eps_abs"].as_f64(), Some(0.0), "{paa}");
        assert_eq!(paa["energy_error"].as_f64(), Some(0.0), "{paa}");
        assert_eq!(paa["hot_mean_extra"], paa["hot_mean_dem"]);
        // Another packing: apart in the cells, and its group means are those of its own
        // hot and cold particles, not of the particles with the recording's ids.
        assert!(pab["eps_abs"].as_f64().unwrap() > 0.0, "{pab}");
        assert_eq!(pab["hot_mean_extra"], pbb["hot_mean_dem"]);
        assert_eq!(pab["cold_mean_extra"], pbb["cold_mean_dem"]);
        assert_eq!(pab["hot_mean_dem"], paa["hot_mean_dem"]);
    }
    let table = tdex_ok(&["compare", a_s, b_s, "--cells", "20"]);
    assert!(table.starts_with("second DEM run"), "{table}");

    // Other instants (τ half a revolution of 2 s: t1 at 1 s after t0, not 0.5 s) are refused.
    let c = record_tiny(dir.path(), "c", 5, ["--tau-rev", "0.5"], 1);
    let o = run_tdex(&["compare", a_s, c.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("same instants") && err.contains(c.to_str().unwrap()),
        "{err}"
    );
}
