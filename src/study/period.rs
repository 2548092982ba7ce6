//! `tdex study period`: the pairing-period study of Haydar §3.3 (Figures 13–15, Table 8).
//! The DEM runs once to t0; from a copy of that state each τ is recorded (as `tdex record`
//! does) with a DEM reference over R revolutions, extrapolated R/τ periods and compared.

use super::{evaluate, plots, run_paths, Outcome};
use crate::cli::StudyPlan;
use anyhow::{Context, Result};
use indicatif::ProgressBar;
use recorder::record::{self, RecordOptions};
use recorder::Simulation;
use serde::Serialize;
use std::time::Instant;

#[derive(Debug, Serialize)]
struct Entry {
    tau_rev: f64,
    tau: f64,
    n: u32,
    dtc_max_steps: u32,
    #[serde(flatten)]
    outcome: Outcome,
}

#[derive(Debug, Serialize)]
struct PeriodStudy {
    study: &'static str,
    case: String,
    particles: usize,
    revolutions: f64,
    rotation_period: f64,
    seconds_to_t0: f64,
    runs: Vec<Entry>,
}

pub fn run(plan: &StudyPlan, runs: &[(f64, RecordOptions)], revolutions: f64) -> Result<()> {
    let say = |s: String| {
        if !plan.json {
            println!("{s}");
        }
    };
    say(format!(
        "record        {} periods τ, each over {revolutions} revolutions of DEM reference, from one \
         state at t0",
        runs.len()
    ));
    let bar = super::dem_bar(plan.json, "study");
    let started = Instant::now();
    let sim0 = crate::with_workers(plan.threads, || {
        Ok(record::run_to_t0(
            &plan.case,
            &mut super::on_phase_logged(&bar),
        )?)
    })
    .with_context(|| format!("running case {} to t0", plan.case_path.display()))?;
    let seconds_to_t0 = started.elapsed().as_secs_f64();
    let entries = record_and_evaluate(plan, runs, &sim0, seconds_to_t0, &bar)?;
    bar.finish_and_clear();
    let study = PeriodStudy {
        study: "period",
        case: plan.case_path.display().to_string(),
        particles: plan.case.particles.count,
        revolutions,
        rotation_period: plan.case.drum.rotation_period,
        seconds_to_t0,
        runs: entries,
    };
    let svgs = svgs(&study)?;
    let table = table(&study);
    super::finish(plan, &study, &table, &markdown(&study, &table), svgs)
}

/// Records each τ of `runs` from the state at t0 (`sim0`, reached in `seconds_to_t0`),
/// then extrapolates and compares it.
fn record_and_evaluate(
    plan: &StudyPlan,
    runs: &[(f64, RecordOptions)],
    sim0: &Simulation,
    seconds_to_t0: f64,
    bar: &ProgressBar,
) -> Result<Vec<Entry>> {
    let (dir, dt) = (&plan.output, plan.case.time.dt);
    let mut entries = Vec::new();
    for (f, o) in runs {
        let stem = format!("tau{f}rev");
        let (rec, extra) = run_paths(dir, &stem);
        let mut sim = sim0.clone();
        crate::with_workers(plan.threads, || {
            Ok(record::record_from_t0(
                &mut sim,
                &plan.case_path,
                &plan.case_toml,
                o,
                &rec,
                seconds_to_t0,
                &mut super::on_phase_logged(bar),
            )?)
        })
        .with_context(|| format!("recording τ = {f} revolution"))?;
        bar.set_message("");
        let outcome = evaluate(&rec, &extra, o.reference_periods, plan.threads, plan.cells)?;
        entries.push(Entry {
            tau_rev: *f,
            tau: o.period_steps as f64 * dt,
            n: o.sample_every,
            dtc_max_steps: o.dtc_max_steps,
            outcome,
        });
    }
    Ok(entries)
}

/// The study's plots: the largest ε_rel against the speedup per τ, and the group means of
/// each τ's extrapolation beside the DEM's.
fn svgs(study: &PeriodStudy) -> Result<Vec<(&'static str, String)>> {
    let mut svgs: Vec<(&'static str, String)> = Vec::new();
    let points: Vec<(f64, f64, String)> = study
        .runs
        .iter()
        .filter_map(|e| {
            Some((
                e.outcome.speedup_100?,
                100.0 * e.outcome.eps_rel_max?,
                format!("τ = {} rev", e.tau_rev),
            ))
        })
        .collect();
    svgs.push((
        "error_vs_speedup.svg",
        plots::scatter(
            "Maximum ε_rel against the speedup for 100 τ, per pairing period",
            "speedup of reaching t1 + 100 τ",
            "max ε_rel over the t_k (%)",
            &points,
        )?,
    ));
    let mut series = Vec::new();
    if let Some(c) = study
        .runs
        .iter()
        .find_map(|e| e.outcome.comparison.as_ref())
    {
        // the DEM series of the finest τ covers the same time with the most points
        let finest = study
            .runs
            .iter()
            .filter_map(|e| Some((e.tau, e.outcome.comparison.as_ref()?)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(c, |x| x.1);
        series.push(plots::Series {
            label: "DEM".into(),
            points: finest
                .dem_series
                .iter()
                .filter_map(|g| Some((g.t, g.hot?, g.cold?)))
                .collect(),
            dem: true,
        });
    }
    for e in &study.runs {
        if let Some(c) = &e.outcome.comparison {
            series.push(plots::Series {
                label: format!("extrapolated, τ = {} rev", e.tau_rev),
                points: c
                    .periods
                    .iter()
                    .filter_map(|p| Some((p.t, p.hot_mean_extra?, p.cold_mean_extra?)))
                    .collect(),
                dem: false,
            });
        }
    }
    svgs.push((
        "means.svg",
        plots::means("Hot and cold group means per pairing period", &series)?,
    ));
    Ok(svgs)
}

fn table(s: &PeriodStudy) -> String {
    let mut t = format!(
        "{:>8} {:>8} {:>7} {:>9} {:>9} {}\n",
        "τ (rev)",
        "τ (s)",
        "periods",
        "rows",
        "table MB",
        super::outcome_header()
    );
    for e in &s.runs {
        let o = &e.outcome;
        t += &format!(
            "{:>8} {:>8.4} {:>7} {:>9} {:>9.3} {}\n",
            e.tau_rev,
            e.tau,
            o.periods,
            o.rows,
            o.table_bytes as f64 / 1e6,
            o.cells(),
        );
        if let Some(err) = &o.error {
            t += &format!("         τ = {} rev: not extrapolated: {err}\n", e.tau_rev);
        }
    }
    t
}

fn markdown(s: &PeriodStudy, table: &str) -> String {
    format!(
        "# Pairing-period study: {}\n\n{} particles, drum {} s per revolution; every τ covers \
         {} revolutions after t1 (R/τ periods), extrapolated and compared with its DEM \
         reference. All τ start from one DEM state at t0 ({:.1} s to reach it). ε_rel: the \
         largest over the compared t_k; |eq10|: mean absolute Eq. 10 error; speedup: complete \
         DEM over extrapolated DEM seconds to reach t1 + 100 τ.\n\n```\n{table}```\n\n\
         ![means](means.svg)\n\n![error against speedup](error_vs_speedup.svg)\n",
        s.case, s.particles, s.rotation_period, s.revolutions, s.seconds_to_t0
    )
}
