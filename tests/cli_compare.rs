//! `tdex compare` on a tiny drum with a DEM reference: the JSON shape, what the numbers
//! must satisfy, the particle ids of the extrapolation, and refused inputs.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};
use tdex_format::{ExtrapolationReader, RecordingReader};

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

/// An extrapolation of one recording compared with the reference of another recording of
/// the same run: here two quarter-revolution periods recorded (t0 … t0 + ½ rev), against a
/// half-revolution recording's reference. The snapshots are matched by time: only those at
/// the reference's instants are compared, numbered as the reference's t_k, each over the
/// stretch since the one before; a recording of another run is refused.
#[test]
fn an_extrapolation_of_another_recording_of_the_run_is_compared_at_the_shared_instants() {
    let dir = tempfile::tempdir().unwrap();
    let reference = record_tiny(dir.path(), "ref", 5, ["--tau-rev", "0.5"], 2);
    let quarters = dir.path().join("quarters.mcap");
    let case = dir.path().join("ref.toml");
    let q_s = quarters.to_str().unwrap();
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        q_s,
        "--tau-rev",
        "0.25",
        "--recorded-periods",
        "2",
    ]);
    let extra = dir.path().join("quarters.extra.mcap");
    let extra_s = extra.to_str().unwrap();
    // t1 … t6 of the quarters (the replay starts at t1): t0 + ¼ … 1½ rev
    tdex_ok(&["extrapolate", q_s, "--periods", "5", "-o", extra_s]);
    // the same run: its snapshot at t0 + ½ rev is the reference's t1, bit for bit
    let ref_snaps = RecordingReader::open(&reference)
        .unwrap()
        .snapshots()
        .unwrap();
    let q_snaps = RecordingReader::open(&quarters)
        .unwrap()
        .snapshots()
        .unwrap();
    let at = |snaps: &[tdex_format::Snapshot], k: u32| snaps.iter().find(|s| s.index == k).cloned();
    let (r1, q2) = (at(&ref_snaps, 1).unwrap(), at(&q_snaps, 2).unwrap());
    assert_eq!((r1.time, &r1.pos, &r1.temp), (q2.time, &q2.pos, &q2.temp));

    let ref_s = reference.to_str().unwrap();
    let v: serde_json::Value = serde_json::from_str(&tdex_ok(&[
        "compare", ref_s, extra_s, "--cells", "20", "--json",
    ]))
    .unwrap();
    let periods = v["periods"].as_array().unwrap();
    let ks: Vec<u64> = periods.iter().map(|p| p["k"].as_u64().unwrap()).collect();
    assert_eq!(ks, vec![2, 3], "the reference's t2 and t3: {v}");
    for p in periods {
        let k = p["k"].as_u64().unwrap() as u32;
        let dem = at(&ref_snaps, k).unwrap();
        assert!((p["t"].as_f64().unwrap() - dem.time).abs() < 0.5e-4, "{p}");
        // the DEM side is the reference's own snapshot at t_k
        let hot = v["dem_series"]
            .as_array()
            .unwrap()
            .iter()
            .find(|g| g["k"].as_u64() == Some(k as u64))
            .unwrap()["hot"]
            .clone();
        assert_eq!(p["hot_mean_dem"], hot, "{p}");
        assert!(p["eps_abs"].as_f64().unwrap() > 0.0, "{p}");
    }
    // the quarters in between have no reference instant: not compared, and said so
    let unreferenced: Vec<u64> = v["unreferenced"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_u64().unwrap())
        .collect();
    assert_eq!(unreferenced, vec![1, 3, 5], "{v}");
    let table = tdex_ok(&["compare", ref_s, extra_s, "--cells", "20"]);
    assert!(
        table.contains("not compared, no DEM snapshot at their instant: t_1, t_3, t_5"),
        "{table}"
    );

    // another seed is another run: refused, and the error says what must agree
    let other = record_tiny(dir.path(), "other", 6, ["--tau-rev", "0.25"], 0);
    let other_extra = dir.path().join("other.extra.mcap");
    tdex_ok(&[
        "extrapolate",
        other.to_str().unwrap(),
        "--periods",
        "2",
        "-o",
        other_extra.to_str().unwrap(),
    ]);
    let o = run_tdex(&["compare", ref_s, other_extra.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("same DEM run") && err.contains("t0 must agree"),
        "{err}"
    );
}

/// The tiny drum recorded for τ = a quarter revolution with 3 reference periods and `twins`
/// DEM twins, extrapolated 3 periods: (recording, extrapolation) in `dir`.
fn record_twins_and_extrapolate(dir: &Path, twins: u32) -> (PathBuf, PathBuf) {
    record_case_twins_and_extrapolate(dir, TINY_CASE, twins)
}

/// [`record_twins_and_extrapolate`] of the case `case_text`.
fn record_case_twins_and_extrapolate(
    dir: &Path,
    case_text: &str,
    twins: u32,
) -> (PathBuf, PathBuf) {
    let case = dir.join("case.toml");
    std::fs::write(&case, case_text).unwrap();
    let (run, extra) = (dir.join("run.mcap"), dir.join("extra.mcap"));
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    let twins = twins.to_string();
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        run_s,
        "--tau-rev",
        "0.25",
        "--reference",
        "3",
        "--twins",
        &twins,
    ]);
    tdex_ok(&["extrapolate", run_s, "--periods", "3", "-o", extra_s]);
    (run, extra)
}

/// A recording with one real DEM twin: `compare` measures the floor between the DEM and
/// the twin at every t_k, the extrapolation's distance to both runs and the ratio, and says
/// its verdict; the twin is stored in the recording, found without extra arguments.
#[test]
fn a_twin_gives_the_floor_and_the_ratio_at_every_period() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_twins_and_extrapolate(dir.path(), 1);
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    let twins = RecordingReader::open(&run)
        .unwrap()
        .twin_snapshots()
        .unwrap();
    assert_eq!(twins.len(), 1);

    let o = run_tdex(&["compare", run_s, extra_s, "--cells", "20", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["dem_runs"], 2);
    let periods = v["periods"].as_array().unwrap();
    assert_eq!(periods.len(), 3, "t2, t3 and t4");
    let mut ratios = Vec::new();
    for p in periods {
        let num = |key: &str| {
            p[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{key} missing at k = {}: {p}", p["k"]))
        };
        let (floor, max, min) = (
            num("floor_eps_abs"),
            num("floor_eps_abs_max"),
            num("floor_eps_abs_min"),
        );
        // one pair of runs: mean, smallest and largest floor are that pair's distance
        assert!(floor > 0.0, "the twin differs from the DEM: {p}");
        assert_eq!((floor, floor), (max, min));
        assert!((num("floor_eps_rel") - floor / num("contrast")).abs() < 1e-12);
        // the distance to the runs is the mean of the distance to the DEM (eps_abs) and to
        // the twin: it cannot be below half the DEM distance
        let to_runs = num("eps_abs_to_dem_runs");
        assert!(to_runs >= 0.5 * num("eps_abs") - 1e-12, "{p}");
        assert!((num("ratio_to_floor") - to_runs / floor).abs() < 1e-9 * to_runs / floor);
        assert_eq!(p["dem_runs_hot_mean"].as_array().unwrap().len(), 1);
        ratios.push(num("ratio_to_floor"));
    }
    let verdict = &v["verdict"];
    ratios.sort_by(f64::total_cmp);
    let median = ratios[1];
    assert!((verdict["median_ratio"].as_f64().unwrap() - median).abs() < 1e-12);
    // one pair of runs: the median decides (staying within the pair's distance at every
    // t_k would be a ratio <= 1 at every t_k), and the t_k above 1 are listed
    assert_eq!(verdict["passes"].as_bool().unwrap(), median <= 1.0);
    let above: Vec<u64> = periods
        .iter()
        .filter(|p| p["ratio_to_floor"].as_f64().unwrap() > 1.0)
        .map(|p| p["k"].as_u64().unwrap())
        .collect();
    let outside: Vec<u64> = verdict["outside_range"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_u64().unwrap())
        .collect();
    assert_eq!(outside, above);
    // two runs: no run can be judged against "the others", and the keys are left out
    assert!(periods
        .iter()
        .all(|p| p.get("dem_runs_ratio_to_others").is_none()));
    assert!(verdict.get("dem_runs_median_ratio").is_none());
    let text = tdex_ok(&["compare", run_s, extra_s, "--cells", "20"]);
    assert!(
        text.lines()
            .last()
            .unwrap()
            .starts_with(&format!("verdict: {}", verdict["text"].as_str().unwrap())),
        "{text}"
    );
    assert!(text.contains("floor max"), "{text}");

    // export vtk writes the twin's own series beside the DEM's
    let vtk = dir.path().join("vtk");
    tdex_ok(&["export", "vtk", run_s, "-o", vtk.to_str().unwrap()]);
    let names = file_names(&vtk);
    for name in [
        "run.pvd",
        "run_twin1.pvd",
        "run_twin1_0002.vtp",
        "run_twin1_0004.vtp",
    ] {
        assert!(names.iter().any(|n| n == name), "{name} not in {names:?}");
    }
    assert!(
        !names.iter().any(|n| n == "run_twin1_0001.vtp"),
        "{names:?}"
    );

    // the arguments the wrong way round are named as such
    let o = run_tdex(&["compare", extra_s, run_s]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("the recording comes first"), "{err}");
}

/// Three DEM runs: each is judged against the other two as the extrapolation is against all
/// three. With three runs the floor's mean, smallest and largest distance give all three
/// pair distances, so the runs' ratios are known from them whatever the order of the runs:
/// the run opposite pair (b, c) scores (d_ab + d_ac) / 2 / d_bc.
/// `tdex compare RUN EXTRA --cells 20 --json`: the output and the compared `t_k` (some).
fn compare_on_20_cells(run: &Path, extra: &Path) -> (serde_json::Value, Vec<u64>) {
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    let o = run_tdex(&["compare", run_s, extra_s, "--cells", "20", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let compared: Vec<u64> = v["verdict"]["compared"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_u64().unwrap())
        .collect();
    assert!(!compared.is_empty(), "{}", v["verdict"]);
    (v, compared)
}

#[test]
fn with_three_dem_runs_each_run_is_judged_against_the_others() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_twins_and_extrapolate(dir.path(), 2);
    let (v, compared) = compare_on_20_cells(&run, &extra);
    assert_eq!(v["dem_runs"], 3);
    let verdict = &v["verdict"];
    let mut per_run: Vec<Vec<f64>> = vec![Vec::new(); 3];
    for p in v["periods"].as_array().unwrap() {
        let num = |key: &str| p[key].as_f64().unwrap();
        let (mean, lo, hi) = (
            num("floor_eps_abs"),
            num("floor_eps_abs_min"),
            num("floor_eps_abs_max"),
        );
        let mid = 3.0 * mean - lo - hi;
        let sum = lo + mid + hi;
        let mut expected: Vec<f64> = [lo, mid, hi]
            .iter()
            .map(|opposite| (sum - opposite) / 2.0 / opposite)
            .collect();
        let mut got: Vec<f64> = p["dem_runs_ratio_to_others"]
            .as_array()
            .unwrap_or_else(|| panic!("three runs give each run's ratio at k = {}: {p}", p["k"]))
            .iter()
            .map(|r| r.as_f64().unwrap())
            .collect();
        assert_eq!(got.len(), 3, "{p}");
        if compared.contains(&p["k"].as_u64().unwrap()) {
            for (run, ratio) in got.iter().enumerate() {
                per_run[run].push(*ratio);
            }
        }
        expected.sort_by(f64::total_cmp);
        got.sort_by(f64::total_cmp);
        for (e, g) in expected.iter().zip(&got) {
            assert!(
                (e - g).abs() <= 1e-9 * e,
                "expected {expected:?}, got {got:?} at {p}"
            );
        }
    }
    let medians: Vec<f64> = verdict["dem_runs_median_ratio"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_f64().unwrap())
        .collect();
    assert_eq!(medians.len(), 3);
    for (run, ratios) in per_run.iter().enumerate() {
        // compare's own median, unit-tested in compare::floor
        let median = tdex::compare::floor::median(ratios).unwrap();
        assert!(
            (medians[run] - median).abs() <= 1e-12 * median,
            "run {run}: {medians:?}"
        );
    }
    let above = medians
        .iter()
        .filter(|&&m| m > verdict["median_ratio"].as_f64().unwrap())
        .count();
    let text = verdict["text"].as_str().unwrap();
    assert!(
        text.contains("each DEM run judged the same way against the others: medians")
            && text.contains(&format!("{above} of the 3 above the extrapolation's")),
        "{text}"
    );
    // an adiabatic bed keeps its bed mean: nothing to set apart
    assert!(verdict.get("pattern").is_none(), "{verdict}");
    assert!(v["periods"][0].get("pattern").is_none());
    assert!(!text.contains("less its own bed mean"), "{text}");
}

/// A bed heated by its mantle is also measured on each field less its own bed mean, at every
/// compared t_k for the extrapolation and for each DEM run in its seat, and the verdict says
/// its median beside the runs'.
#[test]
fn a_heated_bed_is_also_measured_less_its_bed_mean() {
    let dir = tempfile::tempdir().unwrap();
    let heated = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    );
    assert_ne!(heated, TINY_CASE);
    let (run, extra) = record_case_twins_and_extrapolate(dir.path(), &heated, 2);
    let (v, compared) = compare_on_20_cells(&run, &extra);
    let verdict = &v["verdict"];
    let (mut pattern, mut differs) = (Vec::new(), false);
    for p in v["periods"].as_array().unwrap() {
        if !compared.contains(&p["k"].as_u64().unwrap()) {
            continue;
        }
        let ratio = p["pattern"]["ratio_to_floor"]
            .as_f64()
            .unwrap_or_else(|| panic!("a heated bed's pattern at k = {}: {p}", p["k"]));
        assert_eq!(
            p["pattern"]["dem_runs_ratio_to_others"]
                .as_array()
                .map(Vec::len),
            Some(3),
            "{p}"
        );
        // the runs' bed means differ, so the pattern is not the field
        differs |= (ratio - p["ratio_to_floor"].as_f64().unwrap()).abs() > 1e-9;
        pattern.push(ratio);
    }
    assert!(differs, "{v}");
    let median = tdex::compare::floor::median(&pattern).unwrap();
    let judged = verdict["pattern"]["median_ratio"].as_f64().unwrap();
    assert!((judged - median).abs() <= 1e-12 * median, "{verdict}");
    assert_eq!(
        verdict["pattern"]["dem_runs_median_ratio"]
            .as_array()
            .map(Vec::len),
        Some(3)
    );
    let text = verdict["text"].as_str().unwrap();
    assert!(
        text.contains("each field less its own bed mean")
            && text.contains("each DEM run's judged the same way"),
        "{text}"
    );
}

/// `tdex pair --json` states the cycle structure of `g`, which the test counts again from the
/// stored pairing.
#[test]
fn pair_reports_the_cycle_structure_of_the_pairing() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = record_and_extrapolate(dir.path(), 0, 1);
    let run_s = run.to_str().unwrap();
    let v: serde_json::Value = serde_json::from_str(&tdex_ok(&["pair", run_s, "--json"])).unwrap();
    let stored: serde_json::Value =
        serde_json::from_slice(&std::fs::read(v["pairing_file"].as_str().unwrap()).unwrap())
            .unwrap();
    let g: Vec<usize> = stored["g"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as usize)
        .collect();
    let mut lengths = Vec::new();
    let mut seen = vec![false; g.len()];
    for start in 0..g.len() {
        let (mut p, mut len) = (start, 0);
        while !seen[p] {
            seen[p] = true;
            p = g[p];
            len += 1;
        }
        if len > 0 {
            lengths.push(len);
        }
    }
    let c = &v["cycles"];
    assert_eq!(c["cycles"], lengths.len());
    assert_eq!(
        c["fixed_points"],
        lengths.iter().filter(|&&l| l == 1).count()
    );
    let short: usize = lengths.iter().filter(|&&l| l <= 10).sum();
    assert_eq!(c["on_short_cycles"], short);
    assert_eq!(c["longest"], *lengths.iter().max().unwrap());
    assert_eq!(
        c["short_share"].as_f64().unwrap(),
        short as f64 / g.len() as f64
    );
    let text = tdex_ok(&["pair", run_s]);
    assert!(
        text.contains(&format!("{} fixed points", c["fixed_points"])),
        "{text}"
    );
}
