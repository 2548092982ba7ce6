//! `tdex record --recorded-periods P`: P consecutive periods of one DEM run, their rows cut
//! at the period boundaries, the snapshots `t0 … tP` shared with the reference; the same
//! trajectory as a recording of one period; resumable inside any period; bad values refused.

use crate::cli_checkpoint::{checkpoint_of, kill_at, resume_to_the_end, spawn};
use crate::cli_run::TINY_CASE;
use crate::util::{run_tdex, tdex_ok};
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
