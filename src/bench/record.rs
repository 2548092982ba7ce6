//! `tdex bench record`: the recording overhead and bytes per row against a plain period.

use crate::cli::BenchRecordPlan;
use anyhow::Result;
use recorder::record::{self, Phase};
use serde::Serialize;
use std::time::Instant;
use tdex_format::RecordingReader;

/// Design targets: recording at most 1.15× a plain run, at most 6 bytes per row.
const MAX_OVERHEAD: f64 = 1.15;
const MAX_BYTES_PER_ROW: f64 = 6.0;

#[derive(Debug, Serialize)]
struct RecordBench {
    case: String,
    particles: usize,
    threads: usize,
    period_steps: u64,
    n: u32,
    dtc_max_steps: u32,
    repeats: u32,
    plain_seconds: Vec<f64>,
    record_seconds: Vec<f64>,
    /// Fastest recorded period / fastest plain period.
    overhead: f64,
    recorder_seconds: f64,
    rows: u64,
    table_bytes: u64,
    file_bytes: u64,
    bytes_per_row: f64,
    overhead_target: f64,
    bytes_per_row_target: f64,
    meets_targets: bool,
}

/// Runs the case to `t0` once; then, from copies of that state, the period plain and recorded
/// (alternating, `repeats` times each).
pub fn record(plan: &BenchRecordPlan) -> Result<()> {
    crate::with_workers(plan.threads, || bench_record(plan))
}

fn bench_record(plan: &BenchRecordPlan) -> Result<()> {
    let quiet = &mut |_: Phase, _: u64, _: u64| {};
    let say = |msg: String| {
        if !plan.json {
            eprintln!("{msg}");
        }
    };
    say(format!("bench record: running {} to t0", plan.case.name));
    let t = Instant::now();
    let at_t0 = record::run_to_t0(&plan.case, quiet)?;
    let seconds_to_t0 = t.elapsed().as_secs_f64();
    let out = std::env::temp_dir().join(format!("tdex-bench-{}.mcap", std::process::id()));
    let steps = plan.options.period_steps;
    let (mut plain, mut recorded, mut recorder_seconds) = (Vec::new(), Vec::new(), f64::MAX);
    for round in 0..plan.repeats {
        let mut sim = at_t0.clone();
        let t = Instant::now();
        sim.run(steps, 10_000, &mut |_| {})?;
        plain.push(t.elapsed().as_secs_f64());
        say(format!(
            "  round {round}: plain period {:.2} s",
            plain.last().unwrap()
        ));
        let mut sim = at_t0.clone();
        let t = Instant::now();
        record::record_from_t0(
            &mut sim,
            &plan.case_path,
            &plan.case_toml,
            &plan.options,
            &out,
            seconds_to_t0,
            quiet,
        )?;
        recorded.push(t.elapsed().as_secs_f64());
        let reader = RecordingReader::open(&out)?;
        recorder_seconds = recorder_seconds.min(reader.costs().map_or(0.0, |c| c.seconds_recorder));
        say(format!(
            "  round {round}: recorded period {:.2} s",
            recorded.last().unwrap()
        ));
    }
    let reader = RecordingReader::open(&out)?;
    let rows = reader.summary().map_or(0, |s| s.rows);
    let (table_bytes, file_bytes) = (reader.table_bytes(), reader.file_bytes());
    drop(reader);
    let _ = std::fs::remove_file(&out);
    let min = |v: &[f64]| v.iter().cloned().fold(f64::MAX, f64::min);
    let overhead = min(&recorded) / min(&plain);
    let bytes_per_row = table_bytes as f64 / rows.max(1) as f64;
    let result = RecordBench {
        case: plan.case.name.clone(),
        particles: plan.case.particles.count,
        threads: plan.threads,
        period_steps: steps,
        n: plan.options.sample_every,
        dtc_max_steps: plan.options.dtc_max_steps,
        repeats: plan.repeats,
        plain_seconds: plain,
        record_seconds: recorded,
        overhead,
        recorder_seconds,
        rows,
        table_bytes,
        file_bytes,
        bytes_per_row,
        overhead_target: MAX_OVERHEAD,
        bytes_per_row_target: MAX_BYTES_PER_ROW,
        meets_targets: overhead <= MAX_OVERHEAD && bytes_per_row <= MAX_BYTES_PER_ROW,
    };
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        println!(
            "{}: {} particles, {} steps, {} threads",
            result.case, result.particles, steps, result.threads
        );
        println!(
            "period        plain {:.2} s, recorded {:.2} s: overhead {:.3}x (target ≤ {MAX_OVERHEAD}x); recorder {:.2} s",
            min(&result.plain_seconds),
            min(&result.record_seconds),
            overhead,
            recorder_seconds
        );
        println!(
            "table         {rows} rows, {table_bytes} bytes: {bytes_per_row:.2} bytes per row (target ≤ {MAX_BYTES_PER_ROW}); file {file_bytes} bytes"
        );
    }
    Ok(())
}
