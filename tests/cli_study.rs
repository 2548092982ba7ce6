//! `tdex study` end to end on the tiny drum (short periods: τ = 0.05 revolution = 0.1 s):
//! the sampling grid from one DEM run (and its tables equal `tdex record`'s), the period
//! study, the regime study's refusal at a centrifuging speed, and bad flags.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};
use tdex_format::RecordingReader;

fn write_case(dir: &Path) -> PathBuf {
    let case = dir.join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    case
}

fn ok(args: &[&str]) -> String {
    let o = run_tdex(args);
    assert!(
        o.status.success(),
        "tdex {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// All rows of a recording's table, as `(i, j, start, duration, sqrt_area)`.
fn rows(path: &Path) -> Vec<(u32, u32, u64, u32, f64)> {
    let r = RecordingReader::open(path).unwrap();
    r.table()
        .flat_map(|b| b.unwrap().rows)
        .map(|x| (x.i, x.j, x.start_step, x.duration_steps, x.sqrt_area))
        .collect()
}

#[test]
fn sampling_grid_skips_non_multiples_and_matches_tdex_record() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path());
    let out = dir.path().join("sampling");
    let common = [
        "study",
        "sampling",
        case.to_str().unwrap(),
        "--n",
        "5,10,20",
        "--dtc-max",
        "10,20,100",
        "--tau-rev",
        "0.05",
        "--periods",
        "2",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ];
    // the terminal form names the skipped combination
    let text = ok(&common);
    assert!(
        text.contains("n = 20, Δt_c^max = 10: skipped (not a multiple of n)"),
        "{text}"
    );
    for f in [
        "study.md",
        "study.json",
        "error_vs_table_size.svg",
        "error_vs_speedup.svg",
    ] {
        assert!(out.join(f).is_file(), "missing {f}");
    }
    let svg = std::fs::read_to_string(out.join("error_vs_speedup.svg")).unwrap();
    roxmltree::Document::parse(&svg).expect("well-formed SVG");

    let mut args = common.to_vec();
    args.push("--json");
    let v: serde_json::Value = serde_json::from_str(&ok(&args)).expect("one JSON object");
    assert_eq!(v["one_dem_run"], true);
    assert_eq!(v["periods"], 2);
    assert_eq!(v["skipped"].as_array().unwrap().len(), 1);
    assert_eq!(v["skipped"][0]["n"], 20);
    assert_eq!(v["skipped"][0]["dtc_max_steps"], 10);
    let grid = v["grid"].as_array().unwrap();
    assert_eq!(grid.len(), 8, "3 × 3 combinations, one skipped");
    let get = |n: u64, d: u64| {
        grid.iter()
            .find(|e| e["n"] == n && e["dtc_max_steps"] == d)
            .unwrap_or_else(|| panic!("no entry n = {n}, dtc_max = {d}"))
    };
    for e in grid {
        for key in [
            "rows",
            "table_bytes",
            "bytes_per_row",
            "replay_seconds_per_period",
            "eps_rel",
            "eps_rel_max",
            "energy_error",
            "energy_error_mean_abs",
            "speedup_100",
        ] {
            assert!(e.get(key).is_some(), "missing {key} in {e}");
        }
        assert!(e["error"].is_null(), "{e}");
        assert!(e["bytes_per_row"].as_f64().unwrap() > 0.0);
        assert_eq!(e["eps_rel"].as_array().unwrap().len(), 2);
        let max = e["eps_rel"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .fold(0.0, f64::max);
        assert_eq!(e["eps_rel_max"].as_f64().unwrap(), max);
    }
    // rows fall as n grows (same Δt_c^max) and as Δt_c^max grows (same n)
    for d in [20, 100] {
        let r: Vec<u64> = [5, 10, 20]
            .iter()
            .map(|&n| get(n, d)["rows"].as_u64().unwrap())
            .collect();
        assert!(r[0] >= r[1] && r[1] >= r[2], "Δt_c^max = {d}: rows {r:?}");
        assert!(r[0] > r[2], "Δt_c^max = {d}: rows {r:?}");
    }
    for n in [5, 10] {
        let r: Vec<u64> = [10, 20, 100]
            .iter()
            .map(|&d| get(n, d)["rows"].as_u64().unwrap())
            .collect();
        assert!(r[0] > r[1] && r[1] > r[2], "n = {n}: rows {r:?}");
    }

    // one DEM run for all samplers: the same table and snapshots as `tdex record` alone
    let solo = dir.path().join("solo.mcap");
    ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        solo.to_str().unwrap(),
        "--tau-rev",
        "0.05",
        "--n",
        "10",
        "--dtc-max",
        "20",
        "--reference",
        "2",
        "--threads",
        "2",
        "--json",
    ]);
    let shared = out.join("n10_dtc20.mcap");
    assert_eq!(rows(&solo), rows(&shared));
    let (a, b) = (
        RecordingReader::open(&solo).unwrap(),
        RecordingReader::open(&shared).unwrap(),
    );
    assert_eq!(a.snapshots().unwrap(), b.snapshots().unwrap());
    assert_eq!(a.table_bytes(), b.table_bytes());
    assert_eq!(
        get(10, 20)["table_bytes"].as_u64().unwrap(),
        a.table_bytes()
    );
}

#[test]
fn period_study_covers_the_same_time_per_tau() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path());
    let out = dir.path().join("period");
    let v: serde_json::Value = serde_json::from_str(&ok(&[
        "study",
        "period",
        case.to_str().unwrap(),
        "--tau-rev",
        "0.025,0.05",
        "--revolutions",
        "0.1",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]))
    .unwrap();
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[0]["periods"], 4);
    assert_eq!(runs[1]["periods"], 2);
    for r in runs {
        assert!(r["error"].is_null(), "{r}");
        assert!(r["eps_rel_max"].as_f64().is_some());
        // both reach the same simulated time: t1 + 0.1 rev (the drum turns in 2 s)
        let last = r["k"].as_array().unwrap().last().unwrap().as_u64().unwrap();
        assert_eq!(last, r["periods"].as_u64().unwrap() + 1);
    }
    assert!(out.join("means.svg").is_file() && out.join("study.md").is_file());
}

#[test]
fn regimes_refuse_to_extrapolate_a_centrifuging_drum() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path());
    let out = dir.path().join("regimes");
    let args = [
        "study",
        "regimes",
        case.to_str().unwrap(),
        "--rev-period",
        "2,0.2",
        "--tau-rev",
        "0.05",
        "--periods",
        "1",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ];
    let text = ok(&args);
    assert!(
        text.contains("0.2 s per revolution (ω = 31.416 rad/s, Froude 5.030): extrapolation refused: the drum centrifuges"),
        "{text}"
    );
    assert!(
        text.contains("the method has nothing to extrapolate"),
        "{text}"
    );
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let v: serde_json::Value = serde_json::from_str(&ok(&json_args)).unwrap();
    let runs = v["runs"].as_array().unwrap();
    // R = 0.05 m: 2 s/rev → Fr = 0.0503 (cascading), 0.2 s/rev → Fr = 5.03 (centrifuging)
    assert_eq!(runs[0]["regime"], "cascading");
    assert!((runs[0]["froude"].as_f64().unwrap() - 0.05030).abs() < 1e-4);
    assert_eq!(runs[0]["extrapolated"], true);
    assert!(runs[0]["refusal"].is_null());
    assert!(runs[0]["outcome"]["eps_rel_max"].as_f64().is_some());
    let a = runs[0]["angle_degrees"].as_f64().unwrap();
    assert!(a > 0.0 && a < 90.0, "angle {a}");
    assert_eq!(runs[1]["regime"], "centrifuging");
    assert_eq!(runs[1]["extrapolated"], false);
    assert!(runs[1]["outcome"].is_null());
    assert!(runs[1]["refusal"]
        .as_str()
        .unwrap()
        .contains("Fr = ω²R/g ≥ 1"));
    // still measured at that speed
    assert!(runs[1]["relative_speed"].as_f64().is_some());
}

#[test]
fn bad_study_flags_exit_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path());
    let c = case.to_str().unwrap();
    let o = dir.path().join("out");
    let o = o.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["sampling", c, "--n", "0", "-o", o], "--n = 0"),
        (&["sampling", c, "--n", "", "-o", o], "--n is empty"),
        (&["sampling", c, "--n", "5,,10", "-o", o], "--n"),
        (
            &["sampling", c, "--dtc-max", "-5", "-o", o],
            "--dtc-max = -5",
        ),
        (&["sampling", c, "--n", "x", "-o", o], "\"x\" is not"),
        (&["sampling", c, "--periods", "0", "-o", o], "--periods = 0"),
        (
            &["sampling", c, "--n", "20", "--dtc-max", "10,30", "-o", o],
            "nothing to run",
        ),
        (&["sampling", c, "--tau-rev", "0", "-o", o], "--tau-rev = 0"),
        (
            &["sampling", c, "--tau-rev", "-1", "-o", o],
            "--tau-rev = -1",
        ),
        (
            &["regimes", c, "--min-relative", "-1", "-o", o],
            "--min-relative = -1",
        ),
        (
            &["period", c, "--tau-rev", "0.5,-1", "-o", o],
            "--tau-rev = -1",
        ),
        (
            &[
                "period",
                c,
                "--tau-rev",
                "0.4",
                "--revolutions",
                "1",
                "-o",
                o,
            ],
            "whole number",
        ),
        (
            &["period", c, "--revolutions", "0", "-o", o],
            "--revolutions = 0",
        ),
        (
            &["regimes", c, "--rev-period", "abc", "-o", o],
            "--rev-period",
        ),
        (
            &["regimes", c, "--rev-period", "0", "-o", o],
            "--rev-period = 0",
        ),
        (&["regimes", c, "--cells", "0", "-o", o], "--cells = 0"),
        (&["regimes", c, "--threads", "0", "-o", o], "--threads = 0"),
    ];
    for (args, expected) in cases {
        let mut all = vec!["study"];
        all.extend_from_slice(args);
        let out = run_tdex(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {stderr}");
        assert!(stderr.contains(expected), "{all:?}: {stderr}");
    }
    assert!(
        !Path::new(o).exists(),
        "no work before the flags are checked"
    );
}

/// Every snapshot's temperatures of the extrapolation at `path`, in order.
fn temperatures(path: &Path) -> Vec<Vec<f64>> {
    extrapolated(path).into_iter().map(|s| s.temp).collect()
}

/// `tdex study horizon REC --recorded-periods 1,2 FLAGS --json -o OUT`, its JSON.
fn horizon_from_recording(rec: &Path, flags: &[&str], out: &Path) -> serde_json::Value {
    let mut args = vec![
        "study",
        "horizon",
        rec.to_str().unwrap(),
        "--recorded-periods",
        "1,2",
    ];
    args.extend(flags);
    args.extend(["--json", "-o", out.to_str().unwrap()]);
    serde_json::from_str(&ok(&args)).unwrap()
}

/// The horizon study on the tiny drum: one DEM run recording two periods with a twin, both
/// P replayed over the same reference periods and judged against the same DEM runs; the
/// recording cost grows with P; the same study from the recording itself gives the same
/// verdicts; flags that shape a recording are refused with a recording.
/// `tdex study horizon` on the tiny drum in `dir`: two recorded periods and a twin, three
/// reference periods of a twentieth of a revolution; its JSON and its directory (the
/// recording is `horizon.mcap` in it).
fn tiny_horizon_study(dir: &Path) -> (String, PathBuf) {
    let case = write_case(dir);
    let out = dir.join("horizon");
    let json = ok(&[
        "study",
        "horizon",
        case.to_str().unwrap(),
        "--recorded-periods",
        "2,1",
        "--reference",
        "3",
        "--twins",
        "1",
        "--tau-rev",
        "0.05",
        "--threads",
        "2",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    (json, out)
}

#[test]
fn horizon_study_compares_recorded_periods_on_one_dem_run() {
    let dir = tempfile::tempdir().unwrap();
    let (json, out) = tiny_horizon_study(dir.path());
    let study: serde_json::Value = serde_json::from_str(&json).unwrap();
    let runs = study["runs"].as_array().unwrap();
    let p: Vec<u64> = runs
        .iter()
        .map(|r| r["recorded_periods"].as_u64().unwrap())
        .collect();
    assert_eq!(p, [1, 2], "distinct and ascending");
    assert_eq!(study["periods_in_recording"], 2);
    for r in runs {
        // t2..t4 judged against the DEM and its twin, less the recorded stretch: with two
        // recorded periods t2 is the DEM's own snapshot, left out of the verdict
        let p = r["recorded_periods"].as_u64().unwrap();
        assert_eq!(r["compared"].as_u64(), Some(3 - (p - 1)), "{r}");
        assert!(r["median_ratio"].as_f64().unwrap() > 0.0, "{r}");
        assert!(r["verdict"].as_str().unwrap().len() > 20, "{r}");
    }
    let cost = |r: &serde_json::Value| r["recording_seconds"].as_f64().unwrap();
    assert!(cost(&runs[1]) > cost(&runs[0]), "{json}");
    for f in [
        "study.json",
        "study.md",
        "ratio.svg",
        "means.svg",
        "horizon.mcap",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }

    // from the recording: the same DEM runs, the same paths, the same judgement
    let rec = out.join("horizon.mcap");
    let again = dir.path().join("again");
    let study2 = horizon_from_recording(&rec, &[], &again);
    for (a, b) in runs.iter().zip(study2["runs"].as_array().unwrap()) {
        assert_eq!(a["median_ratio"], b["median_ratio"]);
        assert_eq!(a["outside_range"], b["outside_range"]);
    }
    // a study replays one recording many times: replays whose table fits in memory say
    // nothing of it (`tdex extrapolate` states it before any work)
    let quiet = dir.path().join("quiet");
    let o = run_tdex(&[
        "study",
        "horizon",
        rec.to_str().unwrap(),
        "--recorded-periods",
        "1,2",
        "-o",
        quiet.to_str().unwrap(),
    ]);
    let told = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{told}");
    assert!(!told.contains("with the table in memory"), "{told}");

    // with --mirror every P runs twice, the paper's method first (the same figures as
    // without the flag) and then the mirror image, with its check; each has its own file
    let mirrored = dir.path().join("mirrored");
    let study3 = horizon_from_recording(&rec, &["--mirror"], &mirrored);
    let runs3 = study3["runs"].as_array().unwrap();
    let shape: Vec<(u64, &str)> = runs3
        .iter()
        .map(|r| {
            (
                r["recorded_periods"].as_u64().unwrap(),
                r["symmetry"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        shape,
        [
            (1, "none"),
            (1, "axial_mirror"),
            (2, "none"),
            (2, "axial_mirror")
        ]
    );
    for (plain, again) in runs.iter().zip([&runs3[0], &runs3[2]]) {
        assert_eq!(plain["median_ratio"], again["median_ratio"]);
        assert!(again.get("mirror_check").is_none(), "{again}");
    }
    for (mirror, starts) in [(&runs3[1], 1), (&runs3[3], 2)] {
        assert_ne!(mirror["extrapolation"], runs3[0]["extrapolation"]);
        let checks = mirror["mirror_check"].as_array().unwrap();
        // one check per start the path jumps to
        assert!((1..=starts).contains(&checks.len()), "{mirror}");
        for c in checks {
            assert!(c["mirrored_mean_diameters"].as_f64().unwrap() > 0.0, "{c}");
        }
        assert!(Path::new(mirror["extrapolation"].as_str().unwrap()).exists());
    }
    let md = std::fs::read_to_string(mirrored.join("study.md")).unwrap();
    assert!(md.contains("P = 2, mirror: mirror check t"), "{md}");

    // a recording has its own reference periods; it cannot replay more periods than it holds
    for (flags, expect) in [
        (vec!["--reference", "5"], "--reference: "),
        (
            vec!["--recorded-periods", "3"],
            "holds 2 recorded period(s)",
        ),
        (
            vec!["--recorded-periods", "1", "--boundary-pool", "4"],
            "with --boundary exact there is one pairing per start",
        ),
        (
            vec![
                "--recorded-periods",
                "1",
                "--boundary",
                "exact,fresh-steps",
                "--boundary-bin",
                "2",
            ],
            "--boundary-bin and --boundary-cap-zone set the drift of --boundary fresh-drift",
        ),
    ] {
        let mut args = vec!["study", "horizon", rec.to_str().unwrap()];
        args.extend(flags);
        args.extend(["-o", again.to_str().unwrap()]);
        let o = run_tdex(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(expect), "{err}");
    }
}

/// The horizon study with `--boundary`: every P runs with each boundary map, the exact one as
/// without the flag, each fresh one with its own file, the same as `tdex extrapolate
/// --boundary` makes, and with the fresh maps' settings where given.
#[test]
fn horizon_study_runs_every_p_with_each_boundary_and_its_settings() {
    let dir = tempfile::tempdir().unwrap();
    let (_, out) = tiny_horizon_study(dir.path());
    let rec = out.join("horizon.mcap");
    let plain = horizon_from_recording(&rec, &[], &dir.path().join("plain"));
    let runs = plain["runs"].as_array().unwrap();
    let fresh = dir.path().join("fresh");
    let by_boundary = horizon_from_recording(
        &rec,
        &["--boundary", "exact,fresh-steps,fresh-drift"],
        &fresh,
    );
    let boundary_runs = by_boundary["runs"].as_array().unwrap();
    let shape: Vec<(u64, Option<&str>)> = boundary_runs
        .iter()
        .map(|r| {
            (
                r["recorded_periods"].as_u64().unwrap(),
                r.get("boundary").map(|b| b.as_str().unwrap()),
            )
        })
        .collect();
    assert_eq!(
        shape,
        [
            (1, None),
            (1, Some("fresh_steps")),
            (1, Some("fresh_drift")),
            (2, None),
            (2, Some("fresh_steps")),
            (2, Some("fresh_drift"))
        ]
    );
    for (plain, again) in runs.iter().zip([&boundary_runs[0], &boundary_runs[3]]) {
        assert_eq!(plain["median_ratio"], again["median_ratio"]);
    }
    let steps = fresh.join("by_hand.mcap");
    ok(&[
        "extrapolate",
        rec.to_str().unwrap(),
        "--recorded-periods",
        "2",
        "--periods",
        &by_boundary["reference_periods"].to_string(),
        "--boundary",
        "fresh-steps",
        "-o",
        steps.to_str().unwrap(),
    ]);
    let studied = boundary_runs[4]["extrapolation"].as_str().unwrap();
    assert!(
        studied.ends_with("horizon_p2_fresh-steps.extra.mcap"),
        "{studied}"
    );
    assert_eq!(temperatures(&steps), temperatures(Path::new(studied)));
    let md = std::fs::read_to_string(fresh.join("study.md")).unwrap();
    assert!(md.contains("P = 2, fresh steps"), "{md}");

    // the fresh maps' settings reach every fresh map of the study, and the exact one ignores
    // them: its figures are the study's without them
    let set = dir.path().join("set");
    let with_settings = horizon_from_recording(
        &rec,
        &[
            "--boundary",
            "exact,fresh-drift",
            "--boundary-pool",
            "4",
            "--boundary-cap-zone",
            "1",
        ],
        &set,
    );
    let settings_runs = with_settings["runs"].as_array().unwrap();
    assert_eq!(settings_runs[0]["median_ratio"], runs[0]["median_ratio"]);
    let drift = tdex_format::ExtrapolationReader::open(Path::new(
        settings_runs[1]["extrapolation"].as_str().unwrap(),
    ))
    .unwrap()
    .info()
    .boundary;
    match drift {
        tdex_format::extrapolation::Boundary::FreshDrift {
            pool,
            cap_zone_diameters,
            ..
        } => assert_eq!((pool, cap_zone_diameters), (4, 1.0)),
        other => panic!("{other:?}"),
    }
    // and the study names them once, in its JSON and beside its table
    let named = with_settings["boundary_maps"].as_array().unwrap();
    assert_eq!(named.len(), 1, "{named:?}");
    let words = named[0].as_str().unwrap();
    assert!(
        words.starts_with("fresh drift: each jump draws one of 4 pairings")
            && words.ends_with("but within 1 diameters of an end cap, where it is kept"),
        "{words}"
    );
    let md = std::fs::read_to_string(set.join("study.md")).unwrap();
    assert!(md.contains(words), "{md}");
    // with the exact pairing alone there is nothing to name
    assert!(plain.get("boundary_maps").is_none(), "{plain}");
}

/// The study's P = 2 run (the second of `--recorded-periods 1,2`): its extrapolation and
/// the recurrence path it followed.
fn studied_path(
    study: &serde_json::Value,
) -> (PathBuf, tdex_format::extrapolation::RecurrencePath) {
    let p2 = &study["runs"].as_array().unwrap()[1];
    assert_eq!(p2["recorded_periods"], 2);
    let studied = PathBuf::from(p2["extrapolation"].as_str().unwrap());
    let info = tdex_format::ExtrapolationReader::open(&studied)
        .unwrap()
        .info()
        .clone();
    match info.roles {
        tdex_format::extrapolation::Roles::Path(path) => (studied, path),
        other => panic!("{other:?}"),
    }
}

/// `tdex extrapolate REC --recorded-periods 2` over the study's reference periods with
/// `flags`, beside the recording: the output's path.
fn extrapolated_by_hand(rec: &Path, study: &serde_json::Value, flags: &[&str]) -> PathBuf {
    let by_hand = rec.with_file_name("by_hand.mcap");
    let periods = study["reference_periods"].to_string();
    let mut args = vec![
        "extrapolate",
        rec.to_str().unwrap(),
        "--recorded-periods",
        "2",
        "--periods",
        &periods,
        "-o",
        by_hand.to_str().unwrap(),
    ];
    args.extend(flags);
    ok(&args);
    by_hand
}

/// `tdex study horizon --jump-nearest K`: every path of the study jumps only into the K
/// starts nearest its end, as `tdex extrapolate --jump-nearest K` does, and the study says so.
#[test]
fn horizon_study_jumps_to_the_nearest_starts_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let (_, out) = tiny_horizon_study(dir.path());
    let rec = out.join("horizon.mcap");
    let pairs: serde_json::Value =
        serde_json::from_str(&ok(&["pair", rec.to_str().unwrap(), "--json"])).unwrap();
    let distance = |start: u64| {
        pairs
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["start"] == start)
            .unwrap()["mean_distance_diameters"]
            .as_f64()
            .unwrap()
    };
    assert_ne!(distance(0), distance(1), "the two starts tie");
    let nearest: u32 = if distance(0) < distance(1) { 1 } else { 2 };

    let near = dir.path().join("near");
    let study = horizon_from_recording(&rec, &["--jump-nearest", "1"], &near);
    assert_eq!(study["jump_nearest"], 1);
    let (studied, path) = studied_path(&study);
    assert_eq!(path.jump_targets, Some(vec![nearest]));
    let by_hand = extrapolated_by_hand(&rec, &study, &["--jump-to", &nearest.to_string()]);
    assert_eq!(temperatures(&by_hand), temperatures(&studied));
    let md = std::fs::read_to_string(near.join("study.md")).unwrap();
    assert!(
        md.contains("jumps only into the recorded period whose start is nearest"),
        "{md}"
    );
}

/// `tdex study horizon --jump-every N`: every path of the study leaves the recording after
/// every N periods in a row from where it stands, as `tdex extrapolate --jump-every N` does,
/// to the temperature, and the study says so.
#[test]
fn horizon_study_leaves_from_every_end_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let (_, out) = tiny_horizon_study(dir.path());
    let rec = out.join("horizon.mcap");
    let every = dir.path().join("every");
    let study = horizon_from_recording(&rec, &["--jump-every", "1"], &every);
    assert_eq!(study["jump_every"], 1);
    let (studied, path) = studied_path(&study);
    assert_eq!(path.leave_every, Some(1));
    // from t1 the only jump is into period 1 (period 2 is the continuation)
    assert_eq!(path.replayed[0], 1, "{:?}", path.replayed);
    let by_hand = extrapolated_by_hand(&rec, &study, &["--jump-every", "1"]);
    assert_eq!(temperatures(&by_hand), temperatures(&studied));
    let md = std::fs::read_to_string(every.join("study.md")).unwrap();
    assert!(
        md.contains("leaving the recording after every 1 period in a row"),
        "{md}"
    );
    let plain = horizon_from_recording(&rec, &[], &dir.path().join("plain"));
    assert!(plain.get("jump_every").is_none(), "{plain}");
}
