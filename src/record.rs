//! `tdex record`: the recording stage with a progress bar and a summary of what was written.

use crate::cli::{RecordPlan, RecordStart};
use crate::inspect::Sampling;
use anyhow::{Context, Result};
use recorder::record;
use serde::Serialize;
use std::collections::BTreeMap;
use tdex_format::RecordingReader;

/// `tdex record --json` (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct RecordReport {
    output: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    threads: usize,
    /// false with `--reproducible`: the times below are then 0
    costs_recorded: bool,
    rows: u64,
    wall_rows: u64,
    /// Rows of each recorded period (absent for one period).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    period_rows: Vec<u64>,
    file_bytes: u64,
    table_bytes: u64,
    bytes_per_row: f64,
    seconds_to_t0: f64,
    /// All recorded periods.
    seconds_period: f64,
    /// Each recorded period, DEM and recorder (absent for one period).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    seconds_each_period: Vec<f64>,
    seconds_recorder: f64,
    seconds_reference: f64,
    /// The DEM twins' reference periods, all twins (0 without twins).
    seconds_twins: f64,
    stage_seconds: BTreeMap<String, f64>,
}

pub fn run(plan: RecordPlan) -> Result<()> {
    let bar = crate::progress::dem_bar(plan.json, "");
    let mut progress = crate::progress::on_phase_logged(&bar);
    let (output, case_name) = match plan.start {
        RecordStart::Fresh {
            case_path,
            case_toml,
            case,
            output,
            options,
            checkpoint_every,
            reproducible,
        } => {
            let run = record::RecordRun {
                case: &case,
                case_path: &case_path,
                case_toml: &case_toml,
                options: &options,
                dest: &output,
                checkpoint_every,
                write_costs: !reproducible,
            };
            if checkpoint_every.is_some() {
                let checkpoint = record::checkpoint_path(&output);
                if checkpoint.exists() {
                    eprintln!(
                        "warning: {} is left from an earlier run; this run replaces it (to continue that run instead: tdex record --resume {0})",
                        checkpoint.display()
                    );
                }
                eprintln!(
                    "checkpoints to {} (resume with: tdex record --resume {0})",
                    checkpoint.display()
                );
            }
            crate::with_workers(plan.threads, || {
                record::record_run(&run, &mut progress).map_err(advise)
            })
            .with_context(|| format!("recording case {}", case_path.display()))?;
            (output, case.name)
        }
        RecordStart::Resume {
            path,
            checkpoint,
            case,
            checkpoint_every,
        } => {
            let output = checkpoint.dest.clone();
            eprintln!("resuming from {}", checkpoint.header);
            crate::with_workers(plan.threads, || {
                record::resume(*checkpoint, &case, &path, checkpoint_every, &mut progress)
                    .map_err(advise)
            })
            .with_context(|| format!("resuming {}", path.display()))?;
            (output, case.name)
        }
    };
    bar.finish_and_clear();

    let reader = RecordingReader::open(&output)?;
    let info = reader.info();
    let summary = reader.summary().expect("written by finish");
    let costs = reader.costs().cloned().unwrap_or_default();
    let report = RecordReport {
        output: output.display().to_string(),
        case: case_name,
        sampling: Sampling::of(info),
        threads: costs.threads,
        costs_recorded: reader.costs().is_some(),
        rows: summary.rows,
        wall_rows: summary.wall_rows,
        period_rows: summary.period_rows.clone(),
        file_bytes: reader.file_bytes(),
        table_bytes: reader.table_bytes(),
        bytes_per_row: reader.table_bytes() as f64 / summary.rows.max(1) as f64,
        seconds_to_t0: costs.seconds_to_t0,
        seconds_period: costs.seconds_period,
        seconds_each_period: costs.seconds_each_period.clone(),
        seconds_recorder: costs.seconds_recorder,
        seconds_reference: costs.seconds_reference,
        seconds_twins: costs.seconds_twins,
        stage_seconds: costs.stage_seconds.clone(),
    };
    crate::inspect::emit(plan.json, &report, print_human)
}

/// The recorder states what went wrong; the advice about the flags is the CLI's.
fn advise(error: record::RecordError) -> anyhow::Error {
    match error {
        record::RecordError::TwinIdentical { .. } => {
            anyhow::Error::new(error).context("record without --twins")
        }
        error => error.into(),
    }
}

fn print_human(report: &RecordReport) {
    println!(
        "recording     {} ({} particles, case {})",
        report.output, report.sampling.particles, report.case
    );
    report
        .sampling
        .print_period(true, &report.sampling.n_and_dtc_max());
    println!(
        "table         {} rows ({} wall rows), {:.2} bytes per row, file {:.1} MB",
        report.rows,
        report.wall_rows,
        report.bytes_per_row,
        report.file_bytes as f64 / 1e6
    );
    report.sampling.print_recorded_periods(&report.period_rows);
    let twins = report.sampling.twins;
    if twins > 0 {
        println!(
            "twins         {twins} DEM run{} continued from t{} {}, the drum's angular velocity \
             changed by 1{} unit{} in the last place",
            if twins == 1 { "" } else { "s" },
            report.sampling.twins_from,
            match report.sampling.twins_from {
                1 => format!(
                    "over the {} reference periods",
                    report.sampling.reference_periods
                ),
                _ => format!(
                    "to t{} (the run until then)",
                    report.sampling.reference_periods + 1
                ),
            },
            if twins == 1 {
                String::new()
            } else {
                format!("…{twins}")
            },
            if twins == 1 { "" } else { "s" },
        );
    }
    if report.costs_recorded {
        // the reference snapshots up to tP are recorded ones: the DEM ran on for the rest
        let (recorded, reference) = match report.sampling.recorded_periods {
            1 => (
                "the period".to_string(),
                format!("{} reference periods", report.sampling.reference_periods),
            ),
            p => (
                format!("the {p} recorded periods"),
                format!(
                    "{} reference periods after t{p}",
                    tdex_format::periods_after_recorded(p, report.sampling.reference_periods)
                ),
            ),
        };
        println!(
            "time          {:.1} s to t0, {:.1} s for {recorded} ({:.1} s of it recording), {:.1} s for {reference}",
            report.seconds_to_t0, report.seconds_period, report.seconds_recorder, report.seconds_reference
        );
        if !report.seconds_each_period.is_empty() {
            let each: Vec<String> = report
                .seconds_each_period
                .iter()
                .map(|s| format!("{s:.1}"))
                .collect();
            println!(
                "              {} s for each recorded period",
                each.join(", ")
            );
        }
        if twins > 0 {
            println!(
                "              {:.1} s for the twins' reference periods",
                report.seconds_twins
            );
        }
    } else {
        println!("time          not recorded (--reproducible)");
    }
}
