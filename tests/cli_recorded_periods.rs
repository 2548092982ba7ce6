//! `tdex record --recorded-periods P`: P consecutive periods of one DEM run, their rows cut
//! at the period boundaries, the snapshots `t0 … tP` shared with the reference; the same
//! trajectory as a recording of one period; resumable inside any period; bad values refused.

use crate::cli_checkpoint::{checkpoint_of, kill_at, resume_to_the_end, spawn};
use crate::cli_run::TINY_CASE;
use crate::util::{extrapolated, run_tdex, tdex_ok};
use std::path::{Path, PathBuf};
use tdex_format::{CollisionRow, RecordingReader};

/// τ = 0.2 s: 2 000 steps of the tiny drum (a fifth of a revolution).
const TAU: [&str; 2] = ["--tau", "0.2"];

fn setup(dir: &Path) -> PathBuf {
    let case = dir.join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    case
}

/// Records `case` to `out` with τ = 0.2 s, reproducibly, and returns the `--json` summary.
fn record(case: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "record",
        case.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--reproducible",
        "--threads",
        "2",
        "--json",
    ];
    args.extend(TAU);
    args.extend(extra);
    serde_json::from_str(&tdex_ok(&args)).unwrap()
}

fn rows(
    batches: impl Iterator<Item = Result<tdex_format::TableBatch, tdex_format::FormatError>>,
) -> Vec<CollisionRow> {
    batches.flat_map(|b| b.unwrap().rows).collect()
}

#[test]
fn three_recorded_periods_hold_three_tables_cut_at_the_boundaries() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let out = dir.path().join("p3.mcap");
    let report = record(&case, &out, &["--recorded-periods", "3"]);

    let rec = RecordingReader::open(&out).unwrap();
    let info = rec.info();
    assert_eq!(info.recorded_periods, 3);
    let tau = info.period_steps;
    assert_eq!(tau, 2000);
    let snapshots = rec.snapshots().unwrap();
    assert_eq!(
        snapshots.iter().map(|s| s.index).collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
    for s in &snapshots {
        // the engine's time (t0 plus steps × dt, summed) is t0 + kτ to round-off
        let expected = info.snapshot_time(s.index);
        assert!(
            (s.time - expected).abs() < 1e-9,
            "snapshot {} at {} s, t0 + kτ = {expected} s",
            s.index,
            s.time
        );
    }
    assert!(snapshots[3].time > snapshots[0].time + 0.59);

    let summary = rec.summary().unwrap();
    assert_eq!(summary.period_rows.len(), 3);
    assert_eq!(summary.period_rows.iter().sum::<u64>(), summary.rows);
    assert_eq!(summary.snapshots, 4);
    let mut together = Vec::new();
    for p in 0..3u32 {
        let period = rows(rec.period_table(p));
        assert!(!period.is_empty(), "period {p} has no rows");
        assert_eq!(period.len() as u64, summary.period_rows[p as usize]);
        let (from, to) = (p as u64 * tau, (p as u64 + 1) * tau);
        for r in &period {
            assert!(
                (from..to).contains(&r.start_step),
                "period {p}: row {r:?} starts outside [{from}, {to})"
            );
            assert!(
                r.start_step + r.duration_steps as u64 <= to,
                "period {p}: row {r:?} crosses the boundary at step {to}"
            );
        }
        // contacts open at the boundary are cut there and open new rows at its first sample
        if p > 0 {
            assert!(period.iter().any(|r| r.start_step == from));
        }
        together.extend(period);
    }
    assert_eq!(
        together,
        rows(rec.table()),
        "the periods together are the table"
    );

    // what tdex record --json and tdex inspect --json say
    assert_eq!(report["recorded_periods"], 3);
    assert_eq!(
        report["period_rows"],
        serde_json::json!(summary.period_rows)
    );
    assert_eq!(report["rows"], summary.rows);
    let inspect: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["inspect", out.to_str().unwrap(), "--json"])).unwrap();
    assert_eq!(inspect["recorded_periods"], 3);
    assert_eq!(
        inspect["period_rows"],
        serde_json::json!(summary.period_rows)
    );
    let human = tdex_ok(&["inspect", out.to_str().unwrap()]);
    let [a, b, c] = summary.period_rows[..] else {
        unreachable!()
    };
    assert!(
        human.contains(&format!(
            "3 periods, t0 to t3, one after the other; rows in each: {a}, {b}, {c}"
        )),
        "{human}"
    );
}

#[test]
fn one_recorded_period_is_the_first_of_three_and_the_reference_is_the_same_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (one, three) = (dir.path().join("p1.mcap"), dir.path().join("p3.mcap"));
    let report = record(&case, &one, &["--reference", "2"]);
    // one period: the summary and the file say nothing of recorded periods
    assert!(report.get("recorded_periods").is_none() && report.get("period_rows").is_none());
    record(&case, &three, &["--recorded-periods", "3"]);
    let (one, three) = (
        RecordingReader::open(&one).unwrap(),
        RecordingReader::open(&three).unwrap(),
    );
    assert_eq!(one.info().recorded_periods, 1);
    assert!(one.summary().unwrap().period_rows.is_empty());

    let first = rows(three.period_table(0));
    assert_eq!(
        rows(one.table()),
        first,
        "period 0 of P = 3 is the P = 1 table"
    );
    // the recorder only observes the DEM: the reference t2, t3 of one recorded period are
    // the recorded t2, t3 of three
    let (s1, s3) = (one.snapshots().unwrap(), three.snapshots().unwrap());
    assert_eq!(s1.len(), 4);
    for k in 0..4 {
        assert_eq!(s1[k], s3[k], "snapshot t{k}");
    }
}

#[test]
fn a_run_of_three_recorded_periods_killed_inside_them_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    // 0.4 s periods: long enough to be caught by the checkpoints
    let table = [
        "--tau",
        "0.4",
        "--recorded-periods",
        "3",
        "--reference",
        "4",
        "--twins",
        "1",
        "--reproducible",
    ];
    let mut args = vec!["record", case.to_str().unwrap(), "-o", a.to_str().unwrap()];
    args.extend(table);
    tdex_ok(&args);

    let ck = checkpoint_of(&b);
    let ck_arg = ck.to_str().unwrap().to_string();
    let mut args = vec!["record", case.to_str().unwrap(), "-o", b.to_str().unwrap()];
    args.extend(table);
    args.extend(["--checkpoint-every", "0.005", "--threads", "2"]);
    // inside the second recorded period (the state at t1 kept for the twin), the third, the
    // reference periods after t3 and the twin
    let mut stops = vec![kill_at(spawn(&args), &ck, "recorded period 2 of 3 step")];
    for stage in [
        "recorded period 3 of 3 step",
        ", reference period 4 of 4 step",
        ", twin 1 of 1 reference period 2 of 4",
    ] {
        assert!(!b.exists(), "a killed run left {}", b.display());
        let resumed = spawn(&["record", "--resume", &ck_arg, "--threads", "1"]);
        stops.push(kill_at(resumed, &ck, stage));
    }
    resume_to_the_end(&ck_arg, &a, &b, &stops);
    let rec = RecordingReader::open(&b).unwrap();
    assert_eq!(rec.info().recorded_periods, 3);
    let own: Vec<u32> = rec.snapshots().unwrap().iter().map(|s| s.index).collect();
    assert_eq!(own, [0, 1, 2, 3, 4, 5]);
    let twin: Vec<u32> = rec.twin_snapshots().unwrap()[0]
        .iter()
        .map(|s| s.index)
        .collect();
    assert_eq!(twin, [2, 3, 4, 5]);
}

#[test]
fn recorded_periods_outside_1_to_64_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let out = dir.path().join("x.mcap");
    for p in ["0", "65"] {
        let o = run_tdex(&[
            "record",
            case.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--recorded-periods",
            p,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("'{p}' for '--recorded-periods <P>'")) && err.contains("1..=64"),
            "{err}"
        );
        assert!(!out.exists());
    }
    // a resumed run keeps the periods of its checkpoint
    let ck = dir.path().join("x.mcap.checkpoint");
    let o = run_tdex(&[
        "record",
        "--resume",
        ck.to_str().unwrap(),
        "--recorded-periods",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
}

/// `tdex compare rec x --cells 20 --json`.
fn compare_json(rec: &Path, x: &Path) -> serde_json::Value {
    serde_json::from_str(&tdex_ok(&[
        "compare",
        rec.to_str().unwrap(),
        x.to_str().unwrap(),
        "--cells",
        "20",
        "--json",
    ]))
    .unwrap()
}

/// `tdex extrapolate` of `rec` over `periods` into `out`, reproducibly; its `--json`.
fn extrapolate(rec: &Path, out: &Path, periods: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "extrapolate",
        rec.to_str().unwrap(),
        "--periods",
        periods,
        "-o",
        out.to_str().unwrap(),
        "--reproducible",
        "--json",
    ];
    args.extend(extra);
    serde_json::from_str(&tdex_ok(&args)).unwrap()
}

/// The replay of several recorded periods, end to end on a real recording of three: through
/// the recorded stretch the extrapolation is the recording's own continuation (the DEM's positions at t2
/// and t3, and the temperatures of tables 2 and 3 applied in order to the DEM's t1, to the
/// bit); then it jumps. Its first period alone is the paper's method on a recording of one
/// period; the path is a function of the seed; `tdex pair` stores one pairing per start.
#[test]
fn three_recorded_periods_replay_the_recording_then_jump_along_a_seeded_path() {
    use extrapolate::replay::{self, Bodies, Scheme, Table};
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (p3, p1) = (dir.path().join("p3.mcap"), dir.path().join("p1.mcap"));
    record(&case, &p3, &["--recorded-periods", "3", "--reference", "5"]);
    record(&case, &p1, &["--reference", "5"]);

    let x3 = dir.path().join("x3.mcap");
    let json = extrapolate(&p3, &x3, "8", &[]);
    let replayed: Vec<u64> = json["path"]["replayed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(replayed.len(), 8);
    assert_eq!(replayed[..2], [2, 3], "the recording first: {json}");
    assert!(replayed.iter().all(|p| (1..=3).contains(p)), "{json}");

    let rec = RecordingReader::open(&p3).unwrap();
    let dem = rec.snapshots().unwrap();
    let out = extrapolated(&x3);
    let bodies = Bodies::of(rec.info(), &dem[0]);
    let mut temps = dem[1].temp.clone();
    assert_eq!(out[0].index, 1);
    assert_eq!(
        out[0].temp, temps,
        "the extrapolation starts from the DEM at t1"
    );
    for k in [2usize, 3] {
        let rows = rec.summary().unwrap().period_rows[k - 1];
        let (table, _) = Table::read_period(&rec, &bodies, k as u32, rows).unwrap();
        replay::apply_rows(&mut temps, &table.exchanges, &bodies, Scheme::Explicit);
        let at = &out[k - 1];
        assert_eq!(at.index as usize, k);
        assert_eq!(at.pos, dem[k].pos, "t{k}: the DEM's own positions");
        assert_eq!(at.id, dem[k].id, "t{k}: no pairing inside the recording");
        assert_eq!(at.temp, temps, "t{k}: tables 2..{k} in order from t1");
    }

    // the first recorded period alone: the paper's method, as on a recording of one period
    let (x31, x1) = (dir.path().join("x31.mcap"), dir.path().join("x1.mcap"));
    extrapolate(&p3, &x31, "5", &["--recorded-periods", "1"]);
    extrapolate(&p1, &x1, "5", &[]);
    let (a, b) = (extrapolated(&x31), extrapolated(&x1));
    assert_eq!(a.len(), 6);
    for (a, b) in a.iter().zip(&b) {
        assert_eq!((a.index, &a.temp, &a.id), (b.index, &b.temp, &b.id));
    }

    // the path from its seed: the same bytes again (the pairings reused from their
    // sidecars), another path from another seed
    let again = dir.path().join("again.mcap");
    extrapolate(&p3, &again, "8", &[]);
    assert_eq!(std::fs::read(&x3).unwrap(), std::fs::read(&again).unwrap());
    let others: Vec<serde_json::Value> = (1..=4)
        .map(|seed| {
            let out = dir.path().join(format!("seed{seed}.mcap"));
            extrapolate(&p3, &out, "8", &["--seed", &seed.to_string()])["path"]["replayed"].clone()
        })
        .collect();
    assert!(
        others.iter().any(|r| *r != json["path"]["replayed"]),
        "four other seeds all drew the same path: {others:?}"
    );

    // jumps restricted to the last period: after the recording, period 3 again and again;
    // a target outside the periods used is refused, naming the flag
    let near = dir.path().join("near.mcap");
    let json = extrapolate(&p3, &near, "6", &["--jump-to", "3"]);
    assert_eq!(
        json["path"]["replayed"],
        serde_json::json!([2, 3, 3, 3, 3, 3])
    );
    assert_eq!(json["path"]["jump_targets"], serde_json::json!([3]));
    let o = run_tdex(&[
        "extrapolate",
        p3.to_str().unwrap(),
        "--periods",
        "2",
        "-o",
        near.to_str().unwrap(),
        "--jump-to",
        "1,4",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--jump-to") && err.contains("jump target 4"),
        "{err}"
    );

    // one pairing per start, each stored and certified
    let pairs: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["pair", p3.to_str().unwrap(), "--json"])).unwrap();
    let pairs = pairs.as_array().unwrap();
    assert_eq!(pairs.len(), 3);
    for (m, p) in pairs.iter().enumerate() {
        assert_eq!(
            (p["end"].as_u64(), p["start"].as_u64()),
            (Some(3), Some(m as u64))
        );
        assert_eq!(p["certified"], true, "{p}");
        assert!(Path::new(p["pairing_file"].as_str().unwrap()).exists());
    }
}

/// `--jump-nearest K`: the path jumps only into the K starts whose pairing with the end is
/// shortest (`tdex pair` ranks them), and is then the path `--jump-to` those starts gives, to
/// the byte; K = every start is the default path; it cannot be given with `--jump-to`.
#[test]
fn jump_nearest_enters_the_starts_nearest_the_recordings_end() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let p4 = dir.path().join("p4.mcap");
    record(&case, &p4, &["--recorded-periods", "4", "--reference", "5"]);
    let pairs: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["pair", p4.to_str().unwrap(), "--json"])).unwrap();
    let mut by_distance: Vec<(f64, u64)> = pairs
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let distance = p["mean_distance_diameters"].as_f64().unwrap();
            (distance, p["start"].as_u64().unwrap() + 1)
        })
        .collect();
    by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(
        by_distance[1].0 < by_distance[2].0,
        "no two starts nearest: {by_distance:?}"
    );
    let mut nearest: Vec<u64> = by_distance[..2].iter().map(|&(_, p)| p).collect();
    nearest.sort_unstable();
    let listed: Vec<String> = nearest.iter().map(u64::to_string).collect();

    let (by_rank, by_hand) = (dir.path().join("rank.mcap"), dir.path().join("hand.mcap"));
    let json = extrapolate(&p4, &by_rank, "12", &["--jump-nearest", "2"]);
    assert_eq!(json["path"]["jump_targets"], serde_json::json!(nearest));
    extrapolate(&p4, &by_hand, "12", &["--jump-to", &listed.join(",")]);
    assert_eq!(
        std::fs::read(&by_rank).unwrap(),
        std::fs::read(&by_hand).unwrap()
    );

    let (every, default) = (
        dir.path().join("every.mcap"),
        dir.path().join("default.mcap"),
    );
    let json = extrapolate(&p4, &every, "12", &["--jump-nearest", "4"]);
    assert!(json["path"]["jump_targets"].is_null(), "{json}");
    extrapolate(&p4, &default, "12", &[]);
    assert_eq!(
        std::fs::read(&every).unwrap(),
        std::fs::read(&default).unwrap()
    );

    let o = run_tdex(&[
        "extrapolate",
        p4.to_str().unwrap(),
        "--periods",
        "2",
        "-o",
        every.to_str().unwrap(),
        "--jump-nearest",
        "2",
        "--jump-to",
        "1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
}

/// An extrapolation of several recorded periods is the recorded run itself until its first
/// jump (t2 … tP'): `tdex compare` shows those t_k, in parentheses, but leaves them out of
/// the verdict, whose median they would only flatter; the paper's method (one period)
/// leaves nothing out.
#[test]
fn the_verdict_leaves_out_the_recorded_stretch() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let rec = dir.path().join("p2.mcap");
    record(
        &case,
        &rec,
        &[
            "--recorded-periods",
            "2",
            "--reference",
            "4",
            "--twins",
            "1",
        ],
    );
    let (x2, x1) = (dir.path().join("x2.mcap"), dir.path().join("x1.mcap"));
    // t2 (the recording's own second period), then t3, t4 after jumps
    let path = extrapolate(&rec, &x2, "3", &["--jump-to", "2"]);
    assert_eq!(path["path"]["replayed"], serde_json::json!([2, 2, 2]));
    extrapolate(&rec, &x1, "3", &["--recorded-periods", "1"]);
    let compare = |x: &Path| compare_json(&rec, x);
    let ks = |v: &serde_json::Value, key: &str| -> Vec<u64> {
        v["verdict"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k.as_u64().unwrap())
            .collect()
    };

    let v = compare(&x2);
    let periods = v["periods"].as_array().unwrap();
    let within: Vec<(u64, bool)> = periods
        .iter()
        .map(|p| {
            let k = p["k"].as_u64().unwrap();
            (k, p["within_recording"].as_bool().unwrap())
        })
        .collect();
    assert_eq!(within, [(2, true), (3, false), (4, false)], "{v}");
    // at t2 the extrapolation is the DEM's own snapshot: a tiny distance to it; and it is
    // measured to the twin alone (the reference is its own past), so there it is as far
    // from the twin as the reference is: a ratio of 1, where the mean over both runs would
    // give 0.5
    assert!(periods[0]["eps_abs"].as_f64().unwrap() < 1e-3, "{v}");
    let ratio_t2 = periods[0]["ratio_to_floor"].as_f64().unwrap();
    assert!((ratio_t2 - 1.0).abs() < 0.05, "{v}");
    assert_eq!(ks(&v, "within_recording"), [2]);
    assert_eq!(ks(&v, "compared"), [3, 4]);
    let judged: Vec<f64> = periods[1..]
        .iter()
        .map(|p| p["ratio_to_floor"].as_f64().unwrap())
        .collect();
    let median = 0.5 * (judged[0] + judged[1]);
    assert!(
        (v["verdict"]["median_ratio"].as_f64().unwrap() - median).abs() < 1e-12,
        "{v}"
    );
    let text = v["verdict"]["text"].as_str().unwrap();
    assert!(text.contains("over t3, t4"), "{text}");
    assert!(
        text.contains("t2 left out, where the extrapolation is still the recorded run"),
        "{text}"
    );
    // the reader is told the reference was left out, in the verdict, the JSON and the table
    let measured_to = "the DEM runs other than the reference (it is the reference until t2; the \
                       twins parted at t1)";
    assert!(
        text.ends_with(&format!("; its distance measured to {measured_to}")),
        "{text}"
    );
    assert_eq!(
        v["departure"],
        serde_json::json!({"kind": "after_the_twins", "left": 2, "parted": 1}),
        "{v}"
    );
    let table = tdex_ok(&[
        "compare",
        rec.to_str().unwrap(),
        x2.to_str().unwrap(),
        "--cells",
        "20",
    ]);
    let t2 = table
        .lines()
        .find(|l| l.trim_start().starts_with("2 "))
        .unwrap();
    assert!(t2.contains(" ("), "t2's ratio in parentheses: {table}");
    assert!(
        table.contains(&format!(
            "ratio = the second field's mean eps_abs to {measured_to} / mean floor"
        )),
        "{table}"
    );

    // one recorded period: every t_k is the extrapolation's own, measured to both runs
    let v = compare(&x1);
    assert!(v.get("departure").is_none(), "{v}");
    assert!(
        !v["verdict"]["text"]
            .as_str()
            .unwrap()
            .contains("measured to"),
        "{v}"
    );
    assert!(ks(&v, "within_recording").is_empty(), "{v}");
    assert_eq!(ks(&v, "compared"), [2, 3, 4]);
    for p in v["periods"].as_array().unwrap() {
        let (e, to_runs) = (
            p["eps_abs"].as_f64().unwrap(),
            p["eps_abs_to_dem_runs"].as_f64().unwrap(),
        );
        // the mean of its distances to the reference and to the twin
        assert!(to_runs >= 0.5 * e - 1e-12, "{p}");
    }
}

/// `--twins-from 2`: the twin is the run until t2 (its stored t2 is the run's, so the floor
/// there is nil and no ratio is taken) and parts after it; an extrapolation of both periods
/// leaves the run at t2 too and is judged over t3, t4; one of the first period alone left
/// the run at t1, before the twin did, and its verdict says the floor is then too narrow.
/// A parting the run cannot give is refused before any work.
#[test]
fn twins_that_part_where_the_extrapolation_starts() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let rec = dir.path().join("p2.mcap");
    let json = record(
        &case,
        &rec,
        &[
            "--recorded-periods",
            "2",
            "--reference",
            "4",
            "--twins",
            "1",
            "--twins-from",
            "2",
        ],
    );
    assert_eq!(json["twins"], 1, "{json}");
    let (x2, x1) = (dir.path().join("x2.mcap"), dir.path().join("x1.mcap"));
    extrapolate(&rec, &x2, "3", &["--jump-to", "2"]);
    extrapolate(&rec, &x1, "3", &["--recorded-periods", "1"]);
    let compare = |x: &Path| compare_json(&rec, x);
    let v = compare(&x2);
    let periods = v["periods"].as_array().unwrap();
    assert_eq!(periods[0]["k"], 2);
    assert_eq!(periods[0]["floor_eps_abs"].as_f64(), Some(0.0), "{v}");
    assert!(periods[0]["ratio_to_floor"].is_null(), "{v}");
    for p in &periods[1..] {
        assert!(p["floor_eps_abs"].as_f64().unwrap() > 0.0, "{p}");
    }
    assert_eq!(v["verdict"]["compared"], serde_json::json!([3, 4]), "{v}");
    assert!(v.get("departure").is_none(), "{v}");
    let text = v["verdict"]["text"].as_str().unwrap();
    assert!(!text.contains("parted from the DEM at"), "{text}");
    assert!(!text.contains("measured to"), "{text}");

    let v = compare(&x1);
    // t2, where the runs are still one, has no floor: neither a ratio nor a range to leave
    assert_eq!(v["verdict"]["compared"], serde_json::json!([3, 4]), "{v}");
    assert!(
        !v["verdict"]["outside_range"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!(2)),
        "{v}"
    );
    let text = v["verdict"]["text"].as_str().unwrap();
    assert!(
        text.contains(
            "the twins parted from the DEM at t2, after the extrapolation left it (t1): their \
             spread from t3 on is narrower than a fair floor for it"
        ),
        "{text}"
    );
    assert_eq!(
        v["departure"],
        serde_json::json!({"kind": "before_the_twins", "left": 1, "parted": 2}),
        "{v}"
    );

    for (flags, says) in [
        (
            [
                "--recorded-periods",
                "2",
                "--reference",
                "4",
                "--twins",
                "1",
                "--twins-from",
                "3",
            ],
            "--twins-from 3",
        ),
        (
            [
                "--recorded-periods",
                "3",
                "--reference",
                "2",
                "--twins",
                "1",
                "--twins-from",
                "3",
            ],
            "--twins-from 3",
        ),
    ] {
        let mut args = vec!["record", case.to_str().unwrap(), "-o", "never.mcap"];
        args.extend(flags);
        let o = run_tdex(&args);
        assert_eq!(o.status.code(), Some(2), "{flags:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(says) && err.contains("at most"), "{err}");
    }
    let o = run_tdex(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        "never.mcap",
        "--twins-from",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = run_tdex(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        "never.mcap",
        "--reference",
        "4",
        "--twins",
        "0",
        "--twins-from",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--twins-from 2 with --twins 0") && err.contains("give --twins M"),
        "{err}"
    );
}
