//! `tdex study sampling`: the sampling study of Haydar §3.2 (Figure 10). One DEM run (to t0,
//! the period, the K-period reference) feeds one sampler per (n, Δt_c^max); each recording
//! is extrapolated K periods and compared with the shared reference.

use super::{evaluate, pct, plots, run_paths, Outcome};
use crate::cli::StudyPlan;
use anyhow::{Context, Result};
use recorder::record::{self, RecordJob, RecordOptions};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, Serialize)]
struct Skipped {
    n: u32,
    dtc_max_steps: u32,
    reason: &'static str,
}

#[derive(Debug, Serialize)]
struct Entry {
    n: u32,
    dtc_max_steps: u32,
    #[serde(flatten)]
    outcome: Outcome,
}

/// `study.json` and `--json`.
#[derive(Debug, Serialize)]
struct SamplingStudy {
    study: &'static str,
    case: String,
    particles: usize,
    tau: f64,
    tau_rev: f64,
    period_steps: u64,
    periods: u32,
    /// All recordings were sampled from one DEM run.
    one_dem_run: bool,
    seconds_to_t0: f64,
    seconds_recording_run: f64,
    skipped: Vec<Skipped>,
    grid: Vec<Entry>,
}

const NOT_A_MULTIPLE: &str = "not a multiple of n";

pub fn run(
    plan: &StudyPlan,
    runs: &[RecordOptions],
    skipped: &[(u32, u32)],
    tau_rev: f64,
) -> Result<()> {
    let dir = &plan.output;
    let say = |s: String| {
        if !plan.json {
            println!("{s}");
        }
    };
    for (n, d) in skipped {
        say(format!(
            "n = {n}, Δt_c^max = {d}: skipped ({NOT_A_MULTIPLE})"
        ));
    }
    let periods = runs[0].reference_periods;
    let stems: Vec<String> = runs
        .iter()
        .map(|o| format!("n{}_dtc{}", o.sample_every, o.dtc_max_steps))
        .collect();
    let paths: Vec<_> = stems.iter().map(|s| run_paths(dir, s)).collect();
    say(format!(
        "record        {} combinations of (n, Δt_c^max) from one DEM run: τ = {} s ({} steps), \
         then {periods} reference periods",
        runs.len(),
        runs[0].period_steps as f64 * plan.case.time.dt,
        runs[0].period_steps
    ));

    let (seconds_to_t0, seconds_recording_run) = record_grid(plan, runs, &paths)?;
    let grid = evaluate_grid(plan, runs, &stems, &paths, periods)?;
    let study = SamplingStudy {
        study: "sampling",
        case: plan.case_path.display().to_string(),
        particles: plan.case.particles.count,
        tau: runs[0].period_steps as f64 * plan.case.time.dt,
        tau_rev,
        period_steps: runs[0].period_steps,
        periods,
        one_dem_run: true,
        seconds_to_t0,
        seconds_recording_run,
        skipped: skipped
            .iter()
            .map(|&(n, d)| Skipped {
                n,
                dtc_max_steps: d,
                reason: NOT_A_MULTIPLE,
            })
            .collect(),
        grid,
    };
    let svgs = svgs(&study)?;
    let table = table(&study);
    super::finish(plan, &study, &table, &markdown(&study, &table), svgs)
}

/// Records every combination of `runs` from one DEM run into `paths` (each's recording);
/// returns the seconds to t0 and of the whole recording run.
fn record_grid(
    plan: &StudyPlan,
    runs: &[RecordOptions],
    paths: &[(PathBuf, PathBuf)],
) -> Result<(f64, f64)> {
    let bar = super::dem_bar(plan.json, "study");
    let started = Instant::now();
    let seconds_to_t0 = crate::with_workers(plan.threads, || {
        let mut progress = super::on_phase_logged(&bar);
        let mut sim = record::run_to_t0(&plan.case, &mut progress)?;
        let seconds_to_t0 = started.elapsed().as_secs_f64();
        let jobs: Vec<RecordJob> = runs
            .iter()
            .zip(paths)
            .map(|(o, (rec, _))| RecordJob {
                options: o.clone(),
                dest: rec,
            })
            .collect();
        record::record_many_from_t0(
            &mut sim,
            &plan.case_path,
            &plan.case_toml,
            &jobs,
            seconds_to_t0,
            &mut progress,
        )?;
        Ok(seconds_to_t0)
    })
    .with_context(|| format!("recording case {}", plan.case_path.display()))?;
    let seconds_recording_run = started.elapsed().as_secs_f64();
    bar.finish_and_clear();

    Ok((seconds_to_t0, seconds_recording_run))
}

/// Extrapolates and compares each combination's recording over `periods` reference periods.
fn evaluate_grid(
    plan: &StudyPlan,
    runs: &[RecordOptions],
    stems: &[String],
    paths: &[(PathBuf, PathBuf)],
    periods: u32,
) -> Result<Vec<Entry>> {
    let bar = super::runs_bar(plan.json, runs.len(), "extrapolate+compare");
    let mut grid = Vec::new();
    for ((o, stem), (rec, extra)) in runs.iter().zip(stems).zip(paths) {
        bar.set_message(stem.clone());
        let outcome = evaluate(rec, extra, periods, plan.threads, plan.cells)?;
        grid.push(Entry {
            n: o.sample_every,
            dtc_max_steps: o.dtc_max_steps,
            outcome,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();

    Ok(grid)
}

/// The study's plots: the largest ε_rel against the table's size and against the speedup.
fn svgs(study: &SamplingStudy) -> Result<Vec<(&'static str, String)>> {
    let mut svgs: Vec<(&'static str, String)> = Vec::new();
    let label = |e: &Entry| format!("n{}/{}", e.n, e.dtc_max_steps);
    let size: Vec<(f64, f64, String)> = study
        .grid
        .iter()
        .filter_map(|e| {
            Some((
                e.outcome.table_bytes as f64 / 1e6,
                100.0 * e.outcome.eps_rel_max?,
                label(e),
            ))
        })
        .collect();
    let speed: Vec<(f64, f64, String)> = study
        .grid
        .iter()
        .filter_map(|e| {
            Some((
                e.outcome.speedup_100?,
                100.0 * e.outcome.eps_rel_max?,
                label(e),
            ))
        })
        .collect();
    svgs.push((
        "error_vs_table_size.svg",
        plots::scatter(
            "Maximum ε_rel against the collision table's size",
            "table size (MB)",
            "max ε_rel over the t_k (%)",
            &size,
        )?,
    ));
    svgs.push((
        "error_vs_speedup.svg",
        plots::scatter(
            &format!(
                "Maximum ε_rel against the speedup for {} τ",
                super::TABLE_PERIODS
            ),
            &format!("speedup of reaching t1 + {} τ", super::TABLE_PERIODS),
            "max ε_rel over the t_k (%)",
            &speed,
        )?,
    ));
    Ok(svgs)
}

fn table(s: &SamplingStudy) -> String {
    let mut t = format!(
        "{:>4} {:>9} {:>9} {:>9} {:>7} {}\n",
        "n",
        "dtc_max",
        "rows",
        "table MB",
        "B/row",
        super::outcome_header()
    );
    for e in &s.grid {
        let o = &e.outcome;
        t += &format!(
            "{:>4} {:>9} {:>9} {:>9.3} {:>7.2} {}\n",
            e.n,
            e.dtc_max_steps,
            o.rows,
            o.table_bytes as f64 / 1e6,
            o.bytes_per_row,
            o.cells(),
        );
        if let Some(err) = &o.error {
            t += &format!(
                "     n = {}, Δt_c^max = {}: not extrapolated: {err}\n",
                e.n, e.dtc_max_steps
            );
        }
    }
    t
}

fn markdown(s: &SamplingStudy, table: &str) -> String {
    let mut m = format!(
        "# Sampling study: {}\n\n{} particles, τ = {} s ({} of a revolution, {} steps), {} periods \
         extrapolated and compared with the DEM reference. All recordings were sampled from one \
         DEM run ({:.1} s to t0, {:.1} s for the period and the reference with every sampler).\n\n",
        s.case, s.particles, s.tau, s.tau_rev, s.period_steps, s.periods, s.seconds_to_t0,
        s.seconds_recording_run - s.seconds_to_t0
    );
    for k in &s.skipped {
        m += &format!(
            "- n = {}, Δt_c^max = {}: skipped ({})\n",
            k.n, k.dtc_max_steps, k.reason
        );
    }
    if !s.skipped.is_empty() {
        m += "\n";
    }
    m += "Δt_c^max in DEM steps; ε_rel is the largest over the compared t_k; |eq10| the mean \
          absolute Eq. 10 energy-transfer error over the periods; speedup: complete DEM seconds \
          over extrapolated DEM seconds to reach t1 + 100 τ (the report's Table 6 form).\n\n";
    m += "```\n";
    m += table;
    m += "```\n\n";
    m += "## ε_rel at every t_k (%)\n\n| n | Δt_c^max |";
    let ks: Vec<u32> =
        s.grid
            .iter()
            .flat_map(|e| e.outcome.k.clone())
            .fold(Vec::new(), |mut v, k| {
                if !v.contains(&k) {
                    v.push(k);
                }
                v
            });
    for k in &ks {
        m += &format!(" t{k} |");
    }
    m += "\n|---|---|";
    for _ in &ks {
        m += "---|";
    }
    m += "\n";
    for e in &s.grid {
        m += &format!("| {} | {} |", e.n, e.dtc_max_steps);
        for k in &ks {
            let v = e
                .outcome
                .k
                .iter()
                .position(|x| x == k)
                .and_then(|i| e.outcome.eps_rel[i]);
            m += &format!(" {} |", pct(v));
        }
        m += "\n";
    }
    m += "\n![error against table size](error_vs_table_size.svg)\n\n\
          ![error against speedup](error_vs_speedup.svg)\n";
    m
}
