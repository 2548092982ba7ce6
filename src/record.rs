//! `tdex record`: the recording stage with a progress bar and a summary of what was written.

use crate::cli::RecordPlan;
use crate::inspect::Sampling;
use anyhow::{Context, Result};
use recorder::format::RecordingReader;
use recorder::record;
use serde::Serialize;
use std::collections::BTreeMap;

/// `tdex record --json` (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct RecordReport {
    output: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    threads: usize,
    rows: u64,
    wall_rows: u64,
    file_bytes: u64,
    table_bytes: u64,
    bytes_per_row: f64,
    seconds_to_t0: f64,
    seconds_period: f64,
    seconds_recorder: f64,
    seconds_reference: f64,
    stage_seconds: BTreeMap<String, f64>,
}

pub fn run(plan: &RecordPlan) -> Result<()> {
    let bar = crate::progress::dem_bar(plan.json, "");
    let mut progress = crate::progress::on_phase(&bar);
    crate::with_workers(plan.threads, || {
        Ok(record::record(
            &plan.case,
            &plan.case_path,
            &plan.case_toml,
            &plan.options,
            &plan.output,
            &mut progress,
        )?)
    })
    .with_context(|| format!("recording case {}", plan.case_path.display()))?;
    bar.finish_and_clear();

    let reader = RecordingReader::open(&plan.output)?;
    let info = reader.info();
    let summary = reader.summary().expect("written by finish");
    let costs = reader.costs().expect("written by finish");
    let report = RecordReport {
        output: plan.output.display().to_string(),
        case: plan.case.name.clone(),
        sampling: Sampling::of(info),
        threads: costs.threads,
        rows: summary.rows,
        wall_rows: summary.wall_rows,
        file_bytes: reader.file_bytes(),
        table_bytes: reader.table_bytes(),
        bytes_per_row: reader.table_bytes() as f64 / summary.rows.max(1) as f64,
        seconds_to_t0: costs.seconds_to_t0,
        seconds_period: costs.seconds_period,
        seconds_recorder: costs.seconds_recorder,
        seconds_reference: costs.seconds_reference,
        stage_seconds: costs.stage_seconds.clone(),
    };
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "recording     {} ({} particles, case {})",
            report.output, report.sampling.particles, report.case
        );
        println!(
            "period        τ = {} s ({} steps of {:e} s) from t0 = {} s; n = {}, Δt_c^max = {} steps",
            report.sampling.tau, report.sampling.period_steps, report.sampling.dt, report.sampling.t0, report.sampling.n, report.sampling.dtc_max_steps
        );
        println!(
            "table         {} rows ({} wall rows), {:.2} bytes per row, file {:.1} MB",
            report.rows,
            report.wall_rows,
            report.bytes_per_row,
            report.file_bytes as f64 / 1e6
        );
        println!(
            "time          {:.1} s to t0, {:.1} s for the period ({:.1} s of it recording), {:.1} s for {} reference periods",
            report.seconds_to_t0, report.seconds_period, report.seconds_recorder, report.seconds_reference, report.sampling.reference_periods
        );
    }
    Ok(())
}
