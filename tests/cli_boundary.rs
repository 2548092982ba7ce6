//! `tdex extrapolate --boundary`: the fresh boundary maps conserve the heat over 500 periods,
//! are the same bytes on any thread count and a function of the seed, say what they did, and
//! work along a recurrence path (also one leaving every few periods, `--jump-every`);
//! `--boundary exact` is the paper's method to the byte; the
//! fresh maps' options are refused without them, and a cap zone in a section without caps.

use crate::cli_run::TINY_CASE;
use crate::util::{run_tdex, tdex_ok};
use std::path::{Path, PathBuf};

/// The tiny drum heated by its mantle, recorded with τ = 0.2 s (a tenth of a revolution) and
/// `periods` recorded periods, reproducibly.
fn heated_recording(dir: &Path, periods: &str) -> PathBuf {
    let heated = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    );
    recording(dir, &heated, periods)
}

/// The case `case_text` recorded in `dir` with τ = 0.2 s and `periods` recorded periods,
/// reproducibly.
fn recording(dir: &Path, case_text: &str, periods: &str) -> PathBuf {
    let case = dir.join("tiny.toml");
    std::fs::write(&case, case_text).unwrap();
    let run = dir.join("run.mcap");
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        run.to_str().unwrap(),
        "--tau",
        "0.2",
        "--recorded-periods",
        periods,
        "--reproducible",
    ]);
    run
}

/// The arguments of `tdex extrapolate RUN -o OUT` with `flags`.
fn extrapolate_args<'a>(run: &'a Path, out: &'a Path, flags: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "extrapolate",
        run.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(flags);
    args
}

/// Σ C T at t1 and at the end of an extrapolation's summary, in J.
fn heat_t1_and_end(report: &serde_json::Value) -> (f64, f64) {
    (
        report["total_heat_t1"].as_f64().unwrap(),
        report["total_heat_end"].as_f64().unwrap(),
    )
}

/// The summary's Σ C T at the end is the one at t1, to 1e-12 relative.
fn assert_heat_conserved(report: &serde_json::Value, what: &str) {
    let (t1, end) = heat_t1_and_end(report);
    assert!(
        ((end - t1) / t1).abs() < 1e-12,
        "{what}: heat {t1} J at t1, {end} J at the end"
    );
}

/// `tdex extrapolate RUN -o OUT --reproducible --json` with `flags`: the summary.
fn extrapolate(run: &Path, out: &Path, flags: &[&str]) -> serde_json::Value {
    let args = extrapolate_args(run, out, &[&["--reproducible", "--json"], flags].concat());
    serde_json::from_str(&tdex_ok(&args)).unwrap()
}

#[test]
fn fresh_maps_conserve_the_heat_over_500_periods_and_are_a_function_of_the_seed() {
    let dir = tempfile::tempdir().unwrap();
    let run = heated_recording(dir.path(), "1");
    let mut files = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("fresh{threads}.mcap"));
        let report = extrapolate(
            &run,
            &out,
            &[
                "--periods",
                "500",
                "--boundary",
                "fresh-steps",
                "--threads",
                threads,
            ],
        );
        assert_eq!(report["boundary"]["kind"], "fresh_steps");
        assert_eq!(report["boundary"]["pool"], 32);
        assert_eq!(report["boundary"]["cell_diameters"], 3.0);
        assert_eq!(report["boundary"]["seed"], 5, "the case's seed");
        let pool = &report["fresh_pools"][0];
        assert_eq!(
            (pool["end"].as_u64(), pool["start"].as_u64()),
            (Some(1), Some(0))
        );
        assert!(pool["mean_distance_diameters"].as_f64().unwrap() > 0.0);
        files.push(std::fs::read(&out).unwrap());
    }
    assert!(files[0] == files[1], "the fresh maps depend on the threads");

    // every jump is a permutation of the roles, and the rows exchange heat pairwise: on the
    // same drum without the heated mantle, Σ C T after 500 periods of fresh maps is the one
    // at t1
    let adiabatic_dir = tempfile::tempdir().unwrap();
    let adiabatic = recording(adiabatic_dir.path(), TINY_CASE, "1");
    for kind in ["fresh-steps", "fresh-drift"] {
        let mut files = Vec::new();
        for threads in ["1", "2"] {
            let out = adiabatic_dir.path().join(format!("{kind}{threads}.mcap"));
            let report = extrapolate(
                &adiabatic,
                &out,
                &["--periods", "500", "--boundary", kind, "--threads", threads],
            );
            assert_heat_conserved(&report, kind);
            files.push(std::fs::read(&out).unwrap());
        }
        assert!(files[0] == files[1], "{kind} depends on the threads");
    }
    let drift = extrapolate(
        &adiabatic,
        &adiabatic_dir.path().join("drift.mcap"),
        &[
            "--periods",
            "3",
            "--boundary",
            "fresh-drift",
            "--boundary-bin",
            "1.5",
        ],
    );
    assert_eq!(drift["boundary"]["kind"], "fresh_drift");
    assert_eq!(drift["boundary"]["bin_diameters"], 1.5);
    assert_eq!(drift["boundary"]["cell_diameters"], 3.0);
    // no cap zone is no key, as in the files written before it
    assert!(drift["boundary"].get("cap_zone_diameters").is_none());
    let zoned_output = adiabatic_dir.path().join("zoned.mcap");
    let zoned = extrapolate(
        &adiabatic,
        &zoned_output,
        &[
            "--periods",
            "500",
            "--boundary",
            "fresh-drift",
            "--boundary-cap-zone",
            "1",
        ],
    );
    assert_eq!(zoned["boundary"]["cap_zone_diameters"], 1.0);
    assert_heat_conserved(&zoned, "cap zone");
    // a zone draws other maps than none (the tiny drum is 6 diameters long: a 1-diameter
    // zone keeps the drift of its end bins)
    assert!(
        std::fs::read(&zoned_output).unwrap()
            != std::fs::read(adiabatic_dir.path().join("fresh-drift1.mcap")).unwrap(),
        "the cap zone changed nothing"
    );

    // another seed draws other maps; the same seed the same bytes
    let seeded = |seed: &str, name: &str| {
        let out = dir.path().join(name);
        let report = extrapolate(
            &run,
            &out,
            &[
                "--periods",
                "500",
                "--boundary",
                "fresh-steps",
                "--seed",
                seed,
            ],
        );
        assert_eq!(
            report["boundary"]["seed"].as_u64().unwrap().to_string(),
            seed
        );
        std::fs::read(out).unwrap()
    };
    assert!(
        seeded("5", "s5.mcap") == files[0],
        "--seed 5 is the case's seed"
    );
    assert!(
        seeded("6", "s6.mcap") != files[0],
        "another seed, the same maps"
    );
}

#[test]
fn the_exact_boundary_is_the_paper_method_to_the_byte_and_the_fresh_options_need_fresh() {
    let dir = tempfile::tempdir().unwrap();
    let run = heated_recording(dir.path(), "1");
    let exact = dir.path().join("exact.mcap");
    let paper = dir.path().join("paper.mcap");
    let fresh = dir.path().join("fresh.mcap");
    let e = extrapolate(&run, &exact, &["--periods", "20", "--boundary", "exact"]);
    let p = extrapolate(&run, &paper, &["--periods", "20"]);
    extrapolate(
        &run,
        &fresh,
        &[
            "--periods",
            "20",
            "--boundary",
            "fresh-steps",
            "--boundary-pool",
            "4",
            "--boundary-cell",
            "2",
        ],
    );
    let exact_bytes = std::fs::read(&exact).unwrap();
    assert!(exact_bytes == std::fs::read(&paper).unwrap());
    assert!(exact_bytes != std::fs::read(&fresh).unwrap());
    // the exact boundary writes no boundary key (the files before it had none)
    for report in [&e, &p] {
        assert!(report.get("boundary").is_none() && report.get("fresh_pools").is_none());
    }
    let key = b"fresh_steps";
    assert!(!exact_bytes.windows(key.len()).any(|w| w == key));
    let inspected = tdex_ok(&["inspect", fresh.to_str().unwrap(), "--json"]);
    assert!(inspected.contains("fresh_steps"), "{inspected}");
    // the report's table of the run says what each jump drew from, and only then
    for (extra, says) in [(&fresh, true), (&exact, false)] {
        let report = dir.path().join("report");
        tdex_ok(&[
            "report",
            run.to_str().unwrap(),
            extra.to_str().unwrap(),
            "-o",
            report.to_str().unwrap(),
        ]);
        let md = std::fs::read_to_string(report.join("report.md")).unwrap();
        assert_eq!(
            md.contains("Boundary maps") && md.contains("fresh steps: each jump draws one of 4"),
            says,
            "{md}"
        );
    }

    // the printed summary says what the jumps drew from
    let printed_output = dir.path().join("printed.mcap");
    let printed = tdex_ok(&extrapolate_args(
        &run,
        &printed_output,
        &["--periods", "3", "--boundary", "fresh-steps"],
    ));
    assert!(
        printed.contains("boundary      fresh steps: each jump draws one of 32 pairings")
            && printed.contains("boundary      t1 to t0: 32 pairings, mean distance"),
        "{printed}"
    );

    // the pool, the cell and the bin belong to the fresh maps, the bin to the drift
    let refused_output = dir.path().join("refused.mcap");
    let refused = |flags: &[&str], says: &str| {
        let args = extrapolate_args(
            &run,
            &refused_output,
            &[&["--periods", "3"], flags].concat(),
        );
        let out = run_tdex(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(says), "{err}");
    };
    for flag in [
        ["--boundary-pool", "4"],
        ["--boundary-cell", "2"],
        ["--boundary-bin", "2"],
        ["--boundary-cap-zone", "2"],
    ] {
        refused(
            &flag,
            "with --boundary exact there is one pairing per start",
        );
    }
    for flag in ["--boundary-bin", "--boundary-cap-zone"] {
        refused(
            &["--boundary", "fresh-steps", flag, "2"],
            "--boundary-bin and --boundary-cap-zone set the drift of --boundary fresh-drift",
        );
    }
    refused(
        &["--boundary", "fresh-drift", "--boundary-cap-zone=-1"],
        "give a distance in particle diameters ≥ 0",
    );
    let out = run_tdex(&extrapolate_args(
        &run,
        &refused_output,
        &[
            "--periods",
            "3",
            "--boundary",
            "fresh-steps",
            "--boundary-pool",
            "0",
        ],
    ));
    assert_eq!(out.status.code(), Some(2));
    assert!(!refused_output.exists());
}

#[test]
fn a_path_through_two_recorded_periods_draws_fresh_maps_into_each_start() {
    let dir = tempfile::tempdir().unwrap();
    let run = heated_recording(dir.path(), "2");
    for kind in ["fresh-steps", "fresh-drift"] {
        let mut files = Vec::new();
        for threads in ["1", "2"] {
            let out = dir.path().join(format!("path{threads}.mcap"));
            let report = extrapolate(
                &run,
                &out,
                &["--periods", "40", "--boundary", kind, "--threads", threads],
            );
            let pools = report["fresh_pools"].as_array().unwrap();
            let starts: Vec<u64> = pools.iter().map(|p| p["start"].as_u64().unwrap()).collect();
            assert_eq!(starts, [0, 1], "a pool into each start the path enters");
            assert!(pools.iter().all(|p| p["end"] == 2));
            let (t1, end) = heat_t1_and_end(&report);
            assert!(end > t1, "the mantle heats the bed: {t1} J, then {end} J");
            files.push(std::fs::read(&out).unwrap());
        }
        assert!(
            files[0] == files[1],
            "{kind} along the path depends on the threads"
        );
    }
}

#[test]
fn a_cap_zone_is_refused_in_a_section_without_caps() {
    let dir = tempfile::tempdir().unwrap();
    let section = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nend_caps = \"periodic\"",
    );
    let run = recording(dir.path(), &section, "1");
    let out_path = dir.path().join("zoned.mcap");
    let flags = ["--periods", "3", "--boundary", "fresh-drift"];
    let out = run_tdex(&extrapolate_args(
        &run,
        &out_path,
        &[&flags[..], &["--boundary-cap-zone", "2"]].concat(),
    ));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("run.mcap: its section is periodic along the axis and has no end caps")
            && err.contains("a cap zone of 2 diameters keeps nothing"),
        "{err}"
    );
    assert!(!out_path.exists());
    // without the zone the drift is moved round the section
    extrapolate(&run, &out_path, &flags);
    assert!(out_path.exists());
}

/// The jumps of an extrapolation's summary, `(end, start)` each once: where the replayed
/// period is not the one after the period before (`t1` ends period 1).
fn jumps_made(report: &serde_json::Value) -> std::collections::BTreeSet<(u64, u64)> {
    let replayed = report["path"]["replayed"].as_array().unwrap();
    let mut previous = 1;
    let mut jumps = std::collections::BTreeSet::new();
    for p in replayed.iter().map(|p| p.as_u64().unwrap()) {
        if p != previous + 1 {
            jumps.insert((previous, p - 1));
        }
        previous = p;
    }
    jumps
}

/// The `(end, start)` of each entry of `list` (the path's pairings, the fresh pools).
fn ends_and_starts(list: &serde_json::Value) -> std::collections::BTreeSet<(u64, u64)> {
    list.as_array()
        .unwrap()
        .iter()
        .map(|p| (p["end"].as_u64().unwrap(), p["start"].as_u64().unwrap()))
        .collect()
}

/// `--jump-every N`: the path leaves the recording after every N periods in a row from the
/// end of the period just replayed, through that end's pairing (or pool) with the start it
/// enters; the heat is conserved over 500 periods and the bytes are the same on any thread
/// count; with N of at least P the path is the default one; with `--jump-nearest` (starts
/// ranked against the recording's end alone) it is refused.
#[test]
fn jumps_every_n_periods_leave_from_where_the_path_stands() {
    let dir = tempfile::tempdir().unwrap();
    let run = recording(dir.path(), TINY_CASE, "4");
    for kind in ["exact", "fresh-drift"] {
        let mut files = Vec::new();
        for threads in ["1", "2"] {
            let out = dir.path().join(format!("every_{kind}{threads}.mcap"));
            let report = extrapolate(
                &run,
                &out,
                &[
                    "--periods",
                    "500",
                    "--jump-every",
                    "2",
                    "--boundary",
                    kind,
                    "--threads",
                    threads,
                ],
            );
            assert_heat_conserved(&report, kind);
            assert_eq!(report["path"]["leave_every"], 2);
            let replayed = &report["path"]["replayed"];
            // t1 ends period 1, period 2 follows, then the path leaves from t2
            assert_eq!(replayed[0], 2);
            assert_ne!(replayed[1], 3, "{replayed}");
            let jumps = jumps_made(&report);
            let ends: std::collections::BTreeSet<u64> = jumps.iter().map(|j| j.0).collect();
            assert_eq!(ends, [2, 3, 4].into(), "stretches of 2 end at t2, t3, t4");
            assert_eq!(ends_and_starts(&report["path"]["pairings"]), jumps);
            if kind == "fresh-drift" {
                assert_eq!(ends_and_starts(&report["fresh_pools"]), jumps);
            }
            files.push(std::fs::read(&out).unwrap());
        }
        assert!(files[0] == files[1], "{kind} depends on the threads");
    }

    let at_end = extrapolate(&run, &dir.path().join("end.mcap"), &["--periods", "40"]);
    let every_4 = extrapolate(
        &run,
        &dir.path().join("every4.mcap"),
        &["--periods", "40", "--jump-every", "4"],
    );
    assert_eq!(at_end["path"]["replayed"], every_4["path"]["replayed"]);
    assert!(at_end["path"].get("leave_every").is_none());
    assert!(jumps_made(&at_end).iter().all(|j| j.0 == 4));

    let out = dir.path().join("refused.mcap");
    let o = run_tdex(&extrapolate_args(
        &run,
        &out,
        &["--periods", "2", "--jump-every", "2", "--jump-nearest", "2"],
    ));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
    assert!(!out.exists());
}
