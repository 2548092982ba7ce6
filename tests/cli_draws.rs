//! The pooled verdict over several draws end to end on the tiny drum: recordings of one case
//! with other seeds (τ = a quarter revolution, 3 reference periods, 2 DEM twins), each
//! extrapolated; `tdex compare --draw` and `tdex study horizon` with several recordings pool
//! what the single comparisons say, and refuse draws that cannot be pooled.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The tiny case with its `seed` (and, if given, its name) replaced.
fn case_text(seed: u64, name: Option<&str>) -> String {
    let text = TINY_CASE.replace("seed = 5", &format!("seed = {seed}"));
    assert!(
        text.contains(&format!("seed = {seed}")),
        "the tiny case has a seed line"
    );
    match name {
        Some(n) => text.replace("name = \"tiny\"", &format!("name = \"{n}\"")),
        None => text,
    }
}

/// One draw: the case with `seed` (named `name`, or the tiny case's own name) recorded as
/// `stem.mcap` with `twins` DEM twins and `recorded` recorded periods, and extrapolated over
/// its 3 reference periods as `stem.extra.mcap`.
fn record_draw(
    dir: &Path,
    stem: &str,
    seed: u64,
    name: Option<&str>,
    twins: u32,
    recorded: u32,
) -> (PathBuf, PathBuf) {
    let case = dir.join(format!("{stem}.toml"));
    std::fs::write(&case, case_text(seed, name)).unwrap();
    let (rec, extra) = (
        dir.join(format!("{stem}.mcap")),
        dir.join(format!("{stem}.extra.mcap")),
    );
    let (twins, recorded) = (twins.to_string(), recorded.to_string());
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        rec.to_str().unwrap(),
        "--tau-rev",
        "0.25",
        "--reference",
        "3",
        "--twins",
        &twins,
        "--recorded-periods",
        &recorded,
        "--threads",
        "2",
    ]);
    tdex_ok(&[
        "extrapolate",
        rec.to_str().unwrap(),
        "--periods",
        "3",
        "-o",
        extra.to_str().unwrap(),
    ]);
    (rec, extra)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Mean and standard error (sample standard deviation over √n), computed here.
fn mean_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
}

/// `{"mean": …, "standard_error": …}` of the JSON against `(mean, se)`.
fn assert_mean_se(json: &Value, (mean, se): (f64, f64), what: &str) {
    let (m, e) = (
        json["mean"].as_f64().unwrap(),
        json["standard_error"].as_f64().unwrap(),
    );
    assert!(
        close(m, mean) && close(e, se),
        "{what}: {json} but expected {mean} ± {se}"
    );
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn ks(v: &Value) -> Vec<u64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect()
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// What one single comparison (`tdex compare REC EXTRA --json`) says, as the pooled verdict
/// takes it: the extrapolation's median and outside share, the DEM runs' in the seat
/// (means over the runs), the means' largest error and spread.
struct Single {
    median: f64,
    outside: f64,
    dem_median: f64,
    dem_outside: f64,
    means_error: f64,
    means_spread: f64,
    /// Per seat (each DEM run left out for the extrapolation, each run judged against the
    /// others): whether beyond the others' spread, and the largest error over it.
    seats: Vec<Seat>,
    dem_seats: Vec<Seat>,
}

/// A seat: whether beyond its runs' spread, and its largest error over that spread.
type Seat = (bool, f64);

/// One group's means at one `t_k`: the extrapolation's, and the DEM runs' (reference first).
type Means = (f64, Vec<f64>);

/// The group means in the seats, recomputed from the per-`t_k` means of the comparison:
/// for the extrapolation with DEM run `j` left out, and for each DEM run against the others,
/// the largest error to the first remaining run over the largest spread of the remaining.
fn seats_from_periods(v: &Value) -> (Vec<Seat>, Vec<Seat>) {
    let mut groups: Vec<Means> = Vec::new();
    for p in v["periods"].as_array().unwrap() {
        if p["within_recording"].as_bool() == Some(true) {
            continue;
        }
        for g in ["hot", "cold"] {
            let mut runs = vec![p[format!("{g}_mean_dem")].as_f64().unwrap()];
            runs.extend(numbers(&p[format!("dem_runs_{g}_mean")]));
            groups.push((p[format!("{g}_mean_extra")].as_f64().unwrap(), runs));
        }
    }
    let seat = |judged: &dyn Fn(&Means) -> f64, left_out: usize| {
        let (mut error, mut spread) = (0.0f64, 0.0f64);
        for g in &groups {
            let others: Vec<f64> = (0..3).filter(|&i| i != left_out).map(|i| g.1[i]).collect();
            error = error.max((judged(g) - others[0]).abs());
            spread = spread.max((others[0] - others[1]).abs());
        }
        (error > spread + 1e-9, error / spread)
    };
    (
        (0..3).map(|j| seat(&|g| g.0, j)).collect(),
        (0..3).map(|i| seat(&|g| g.1[i], i)).collect(),
    )
}

/// A seat's figures as the JSON gives them: `[(beyond, error / spread)]`.
fn seats_from_json(seats: &Value) -> Vec<Seat> {
    seats
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let (e, sp) = (
                s["error_max"].as_f64().unwrap(),
                s["spread_max"].as_f64().unwrap(),
            );
            (e > sp + 1e-9, e / sp)
        })
        .collect()
}

/// The single comparison's figures; and the DEM runs' shares outside the others' range
/// checked against the per-`t_k` flags they come from (with three runs each run's others
/// are one pair, so it is outside their range exactly where its ratio is above 1).
fn single(v: &Value) -> Single {
    assert_eq!(v["dem_runs"], 3, "reference and 2 twins");
    let verdict = &v["verdict"];
    let compared = ks(&verdict["compared"]);
    assert!(!compared.is_empty(), "{verdict}");
    let n = compared.len() as f64;
    let mut outside_per_run = [0usize; 3];
    for p in v["periods"].as_array().unwrap() {
        if !compared.contains(&p["k"].as_u64().unwrap()) {
            continue;
        }
        let ratios = numbers(&p["dem_runs_ratio_to_others"]);
        let flags: Vec<bool> = p["dem_runs_outside_others_range"]
            .as_array()
            .unwrap_or_else(|| panic!("three runs: the runs' outside flags at {p}"))
            .iter()
            .map(|b| b.as_bool().unwrap())
            .collect();
        assert_eq!(flags.len(), 3, "{p}");
        for (run, (ratio, flag)) in ratios.iter().zip(&flags).enumerate() {
            assert_eq!(*flag, *ratio > 1.0, "run {run} at {p}");
            outside_per_run[run] += usize::from(*flag);
        }
    }
    let shares = numbers(&verdict["dem_runs_outside_share"]);
    assert_eq!(shares.len(), 3, "{verdict}");
    for (share, count) in shares.iter().zip(outside_per_run) {
        assert!(
            close(*share, count as f64 / n),
            "{shares:?} {outside_per_run:?}"
        );
    }
    let (seats, dem_seats) = seats_from_periods(v);
    for (json, computed) in [
        (&verdict["means_in_seat"], &seats),
        (&verdict["dem_runs_means"], &dem_seats),
    ] {
        let given = seats_from_json(json);
        assert_eq!(given.len(), 3, "{verdict}");
        for (g, c) in given.iter().zip(computed) {
            assert!(
                g.0 == c.0 && close(g.1, c.1),
                "{given:?} against {computed:?}"
            );
        }
    }
    Single {
        median: verdict["median_ratio"].as_f64().unwrap(),
        outside: verdict["outside_range"].as_array().unwrap().len() as f64 / n,
        dem_median: mean(&numbers(&verdict["dem_runs_median_ratio"])),
        dem_outside: mean(&shares),
        means_error: verdict["means_error_max"].as_f64().unwrap(),
        means_spread: verdict["means_spread_max"].as_f64().unwrap(),
        seats,
        dem_seats,
    }
}

/// The share of `seats` beyond their runs' spread, and the mean of their error over it.
fn seat_figures(seats: &[Seat]) -> (f64, f64) {
    let beyond = seats.iter().filter(|s| s.0).count() as f64 / seats.len() as f64;
    (
        beyond,
        mean(&seats.iter().map(|s| s.1).collect::<Vec<f64>>()),
    )
}

/// The pooled JSON object against the single comparisons it pools: every mean and
/// standard error recomputed from them, the bars and the pass rule.
fn assert_pooled(draws: &Value, singles: &[Single]) {
    let col = |f: fn(&Single) -> f64| singles.iter().map(f).collect::<Vec<f64>>();
    assert_eq!(draws["draws"].as_u64(), Some(singles.len() as u64));
    let x = mean_se(&col(|s| s.median));
    let d = mean_se(&col(|s| s.dem_median));
    let xo = mean_se(&col(|s| s.outside));
    let dout = mean_se(&col(|s| s.dem_outside));
    assert_mean_se(&draws["median_ratio"], x, "median ratio");
    assert_mean_se(
        &draws["dem_runs_median_ratio"],
        d,
        "the DEM runs' median ratio",
    );
    assert_mean_se(&draws["outside_share"], xo, "outside share");
    assert_mean_se(
        &draws["dem_runs_outside_share"],
        dout,
        "the DEM runs' outside share",
    );
    let bar = d.0 + 2.0 * (x.1 * x.1 + d.1 * d.1).sqrt();
    assert!(
        close(draws["median_ratio_bar"].as_f64().unwrap(), bar),
        "{draws}"
    );
    let outside_bar = dout.0 + 0.1;
    assert!(
        close(draws["outside_share_bar"].as_f64().unwrap(), outside_bar),
        "{draws}"
    );
    let failing = singles
        .iter()
        .filter(|s| s.means_error > s.means_spread)
        .count();
    assert_eq!(
        draws["means_outside_spread_draws"].as_u64(),
        Some(failing as u64)
    );
    let worst = singles
        .iter()
        .max_by(|a, b| a.means_error.total_cmp(&b.means_error))
        .unwrap();
    assert_eq!(draws["means_error_max"].as_f64(), Some(worst.means_error));
    assert_eq!(
        draws["means_spread_beside"].as_f64(),
        Some(worst.means_spread)
    );
    // the means in a DEM run's seat, the extrapolation's beside a DEM run's
    for (key, figure) in [
        (
            "means_outside_share_in_seat",
            (|s: &Single| seat_figures(&s.seats).0) as fn(&Single) -> f64,
        ),
        ("dem_runs_means_outside_share", |s| {
            seat_figures(&s.dem_seats).0
        }),
        ("means_error_to_spread", |s| seat_figures(&s.seats).1),
        ("dem_runs_means_error_to_spread", |s| {
            seat_figures(&s.dem_seats).1
        }),
    ] {
        assert_mean_se(&draws[key], mean_se(&col(figure)), key);
    }
    let passes = x.0 <= bar && xo.0 <= outside_bar + 1e-12 && failing == 0;
    assert_eq!(draws["passes"].as_bool(), Some(passes), "{draws}");
    let text = draws["text"].as_str().unwrap();
    assert!(
        text.starts_with(if passes {
            "passes as one more DEM run over the "
        } else {
            "does not pass as one more DEM run over the "
        }),
        "{text}"
    );
}

/// `tdex compare A XA --draw B XB --draw C XC`: each pair judged as alone, then the pooled
/// means and standard errors over the three, equal to those of the single comparisons.
#[test]
fn compare_pools_the_single_comparisons_of_the_draws() {
    let dir = tempfile::tempdir().unwrap();
    let pairs: Vec<(PathBuf, PathBuf)> = [("a", 5), ("b", 6), ("c", 7)]
        .iter()
        .map(|&(stem, seed)| record_draw(dir.path(), stem, seed, None, 2, 1))
        .collect();
    let alone: Vec<Value> = pairs
        .iter()
        .map(|(r, x)| serde_json::from_str(&tdex_ok(&["compare", s(r), s(x), "--json"])).unwrap())
        .collect();
    let singles: Vec<Single> = alone.iter().map(single).collect();
    // the three seeds are three beds: their medians differ
    assert!(
        singles[0].median != singles[1].median && singles[1].median != singles[2].median,
        "three draws, three medians"
    );

    let mut args = vec!["compare", s(&pairs[0].0), s(&pairs[0].1)];
    for (r, x) in &pairs[1..] {
        args.extend(["--draw", s(r), s(x)]);
    }
    let json: Value =
        serde_json::from_str(&tdex_ok(&[&args[..], &["--json"][..]].concat())).unwrap();
    // every pair's comparison as alone
    let comparisons = json["comparisons"].as_array().unwrap();
    assert_eq!(comparisons.len(), 3);
    for (pooled, alone) in comparisons.iter().zip(&alone) {
        assert_eq!(pooled, alone);
    }
    let draws = &json["draws"];
    assert_pooled(draws, &singles);
    for (each, (r, _)) in draws["each"].as_array().unwrap().iter().zip(&pairs) {
        assert_eq!(each["recording"].as_str(), Some(s(r)));
    }

    // in words: each draw's table, then the pooled figures and the verdict over the draws
    let text = tdex_ok(&args);
    for i in 1..=3 {
        assert!(text.contains(&format!("draw {i} of 3: ")), "{text}");
    }
    assert!(text.contains("DEM run in the seat"), "{text}");
    assert_eq!(
        text.lines().last().unwrap(),
        format!(
            "verdict over the draws: {}",
            draws["text"].as_str().unwrap()
        )
    );
    // one pair alone keeps its own output: no pooled judgement
    let one = tdex_ok(&["compare", s(&pairs[0].0), s(&pairs[0].1)]);
    assert!(!one.contains("over the draws"), "{one}");

    // --draw takes a recording and its extrapolation; it cannot be written as CSV lines
    let o = run_tdex(&[&args[..3], &["--draw", s(&pairs[1].0)][..]].concat());
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--draw <RECORDING> <EXTRAPOLATION>"), "{err}");
    let o = run_tdex(&[&args[..], &["--csv"][..]].concat());
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cannot be used with '--csv'"), "{err}");
}

/// `tdex study horizon A B` with two recordings of the case: every P on each, the files
/// named after each recording, and per P the pooled verdict over both, equal to that of
/// the single runs (and of `tdex compare` on the same files); one recording keeps today's
/// output.
#[test]
fn study_horizon_pools_every_p_over_the_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let (a, _) = record_draw(dir.path(), "seed5", 5, None, 2, 2);
    let (b, _) = record_draw(dir.path(), "seed6", 6, None, 2, 2);
    let out = dir.path().join("horizon");
    let study: Value = serde_json::from_str(&tdex_ok(&[
        "study",
        "horizon",
        s(&a),
        s(&b),
        "--recorded-periods",
        "1,2",
        "--threads",
        "2",
        "--json",
        "-o",
        s(&out),
    ]))
    .unwrap();
    assert_eq!(study["draws"], serde_json::json!([s(&a), s(&b)]));
    let runs = study["runs"].as_array().unwrap();
    let pooled = study["pooled"].as_array().unwrap();
    assert_eq!(runs.len(), 4, "two P on two recordings");
    assert_eq!(pooled.len(), 2, "one pooled verdict per P");
    for (p, pool) in [1u64, 2].iter().zip(pooled) {
        assert_eq!(pool["recorded_periods"].as_u64(), Some(*p));
        let of_p: Vec<&Value> = runs
            .iter()
            .filter(|r| r["recorded_periods"].as_u64() == Some(*p))
            .collect();
        assert_eq!(of_p.len(), 2);
        let mut singles = Vec::new();
        for (run, (rec, stem)) in of_p.iter().zip([(&a, "seed5"), (&b, "seed6")]) {
            assert_eq!(run["recording"].as_str(), Some(s(rec)));
            let extra = out.join(format!("horizon_p{p}_{stem}.extra.mcap"));
            assert_eq!(run["extrapolation"].as_str(), Some(s(&extra)));
            // the same judgement as `tdex compare` on the same files
            let alone: Value =
                serde_json::from_str(&tdex_ok(&["compare", s(rec), s(&extra), "--json"])).unwrap();
            assert_eq!(run["median_ratio"], alone["verdict"]["median_ratio"]);
            singles.push(single(&alone));
        }
        assert_pooled(pool, &singles);
    }
    assert!(!out.join("horizon_p1.extra.mcap").exists());
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    for line in [
        "pooled over the 2 draws",
        "P = 1 (seed5)",
        "P = 2 (seed6)",
        "P = 1 over the draws: ",
        "closest to one more DEM run over the draws: P = ",
    ] {
        assert!(md.contains(line), "{line} not in {md}");
    }
    assert!(
        md.contains(&format!(
            "P = 2 over the draws: {}",
            pooled[1]["text"].as_str().unwrap()
        )),
        "{md}"
    );

    // one recording: the study as without draws (no keys of theirs, today's file names)
    let alone_dir = dir.path().join("alone");
    let alone: Value = serde_json::from_str(&tdex_ok(&[
        "study",
        "horizon",
        s(&a),
        "--recorded-periods",
        "1",
        "--json",
        "-o",
        s(&alone_dir),
    ]))
    .unwrap();
    assert!(alone.get("draws").is_none() && alone.get("pooled").is_none());
    let run = &alone["runs"][0];
    assert!(run.get("recording").is_none(), "{run}");
    assert_eq!(
        run["extrapolation"].as_str(),
        Some(s(&alone_dir.join("horizon_p1.extra.mcap")))
    );
    // the same P = 1 on the same recording as among the draws
    assert_eq!(run["median_ratio"], runs[0]["median_ratio"]);
}

/// Draws that cannot be pooled are refused before any comparison, naming the file and what
/// is wrong: another case, fewer than 3 DEM runs, a case file among recordings.
#[test]
fn draws_of_another_case_or_with_one_twin_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (a, xa) = record_draw(dir.path(), "a", 5, None, 2, 1);
    let (other, x_other) = record_draw(dir.path(), "other", 6, Some("wider"), 2, 1);
    let (one, x_one) = record_draw(dir.path(), "one_twin", 7, None, 1, 1);
    let refused = |args: &[&str], expect: &[&str]| {
        let o = run_tdex(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        for e in expect {
            assert!(err.contains(e), "{args:?}: {e:?} not in {err}");
        }
        assert!(o.stdout.is_empty(), "nothing judged: {args:?}");
    };
    let other_case = format!("{} is not a draw of the case of {}", s(&other), s(&a));
    refused(
        &["compare", s(&a), s(&xa), "--draw", s(&other), s(&x_other)],
        &[&other_case, "named \"wider\" and the other's \"tiny\""],
    );
    // one twin: 2 DEM runs, whichever place the recording has
    let one_twin = format!("{} has 2 DEM run(s)", s(&one));
    refused(
        &["compare", s(&a), s(&xa), "--draw", s(&one), s(&x_one)],
        &[&one_twin, "at least 3", "--twins 2"],
    );
    refused(
        &["compare", s(&one), s(&x_one), "--draw", s(&a), s(&xa)],
        &[&one_twin],
    );
    // a draw whose extrapolation is another recording's
    refused(
        &["compare", s(&a), s(&xa), "--draw", s(&a), s(&x_one)],
        &[&format!(
            "{} was not extrapolated from {}",
            s(&x_one),
            s(&a)
        )],
    );

    // the horizon study: the same refusals, and a case file among the inputs
    let out = dir.path().join("horizon");
    let study = |inputs: &[&str]| {
        let mut args = vec!["study", "horizon"];
        args.extend(inputs);
        args.extend(["--recorded-periods", "1", "-o", s(&out)]);
        args.iter().map(|a| a.to_string()).collect::<Vec<String>>()
    };
    let run = |inputs: &[&str], expect: &[&str]| {
        let args = study(inputs);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, expect);
    };
    run(&[s(&a), s(&other)], &[&other_case]);
    run(
        &[s(&a), s(&one)],
        &[&format!("{}: has 1 DEM twin(s)", s(&one)), "--twins 2"],
    );
    let case = dir.path().join("a.toml");
    run(
        &[s(&case), s(&a)],
        &[s(&case), "allowed only if all are recordings"],
    );
    run(
        &[s(&a), s(&case)],
        &[&format!("{}: not a recording", s(&case))],
    );
    assert!(
        !out.exists(),
        "nothing written before the inputs are checked"
    );
}
