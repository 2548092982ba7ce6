//! `tdex extrapolate`: K periods of the recorded table replayed through the pairing.

use crate::cli::ExtrapolatePlan;
use crate::pair;
use anyhow::{Context, Result};
use extrapolate::replay::{self, Bodies, Exchange, Scheme, SyncScratch, Table};
use recorder::format::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationWriter, RecordingReader, FORMAT_VERSION,
};
use serde::Serialize;
use std::time::Instant;

/// `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
pub struct ExtrapolationReport {
    output: String,
    scheme: String,
    periods: u32,
    particles: u32,
    rows: u64,
    max_cfl: f64,
    table_in_memory: bool,
    pairing: pair::PairingSummary,
    costs: ExtrapolationCosts,
    total_heat_t1: f64,
    total_heat_end: f64,
}

pub fn run(plan: &ExtrapolatePlan) -> Result<()> {
    let report = crate::with_workers(plan.threads, || extrapolate(plan))?;
    print(&report, plan.json)
}

/// Pairs (or reuses the stored pairing), replays and writes the extrapolation; prints
/// nothing. Runs on the current worker pool.
pub fn extrapolate(plan: &ExtrapolatePlan) -> Result<ExtrapolationReport> {
    let reader = RecordingReader::open(&plan.file)?;
    let info = reader.info().clone();
    let (t0, t1) = pair::period_snapshots(&reader)?;
    let bodies = Bodies::of(&info, &t0);

    let started = Instant::now();
    let (stored, reused) = match pair::load(&reader, &t0, &t1) {
        Some(stored) => (stored, true),
        None => {
            let stored = pair::compute(&t0, &t1)?;
            // the stored pairing only saves time next run: a recording on a full or read-only
            // disk is still extrapolated
            if let Err(e) = pair::store(&reader, &stored) {
                eprintln!("warning: {e:#}; the pairing will be computed again next time");
            }
            (stored, false)
        }
    };
    let seconds_pairing = if reused {
        0.0
    } else {
        started.elapsed().as_secs_f64()
    };

    // the table: decoded once into memory, or streamed from the file each period
    let t = Instant::now();
    let (table, rows, worst) = if plan.stream {
        let found = replay::scan(&reader, &bodies, |_, _| {})?;
        (None, found.rows, found.worst)
    } else {
        let (table, worst) = Table::read(&reader, &bodies)?;
        let rows = table.exchanges.len() as u64;
        (Some(table), rows, worst)
    };
    let seconds_read_table = t.elapsed().as_secs_f64();
    let max_cfl = worst.map_or(0.0, |w| w.cfl);
    if let Some(w) = worst.filter(|w| plan.scheme == Scheme::Explicit && w.cfl >= 1.0) {
        return Err(w.refusal()).with_context(|| format!("{}", plan.file.display()));
    }

    let out_info = ExtrapolationInfo {
        format_version: FORMAT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        recording: plan.file.display().to_string(),
        recording_info: info.clone(),
        scheme: plan.scheme.name().into(),
        periods: plan.periods,
        pairing: serde_json::to_value(&stored.summary)?,
    };
    let mut writer = ExtrapolationWriter::create(&plan.output, &out_info)?;
    writer.write_snapshot(&t1)?;

    // role a ends each period at x_a(t1): the snapshot's positions, radii and velocities
    let mut temps = t1.temp.clone();
    let heat_t1 = replay::total_heat(&temps, &bodies);
    let mut next = Vec::with_capacity(temps.len());
    let mut scratch = SyncScratch::default();
    let mut exchanges: Vec<Exchange> = Vec::new();
    // the output snapshot: t1's positions, radii and velocities, the extrapolated
    // temperatures, and as `id` the particle that plays each role (it moves with its heat)
    let mut out = t1;
    let mut next_id = Vec::with_capacity(out.id.len());
    let t = Instant::now();
    for k in 1..=plan.periods {
        replay::move_to_roles(&temps, &stored.g, &mut next)?;
        std::mem::swap(&mut temps, &mut next);
        replay::move_to_roles(&out.id, &stored.g, &mut next_id)?;
        std::mem::swap(&mut out.id, &mut next_id);
        match &table {
            Some(table) => replay::apply_rows_with(
                &mut temps,
                &table.exchanges,
                &bodies,
                plan.scheme,
                &mut scratch,
            ),
            None => {
                for batch in reader.table() {
                    exchanges.clear();
                    exchanges.extend(batch?.rows.iter().map(|r| Exchange::of(r, &info)));
                    replay::apply_rows_with(
                        &mut temps,
                        &exchanges,
                        &bodies,
                        plan.scheme,
                        &mut scratch,
                    );
                }
            }
        }
        scratch.flush(&mut temps);
        out.index = k + 1;
        out.time = info.snapshot_time(k + 1);
        out.temp.copy_from_slice(&temps);
        writer.write_snapshot(&out)?;
    }
    let seconds_replay = t.elapsed().as_secs_f64();
    let costs = ExtrapolationCosts {
        seconds_pairing,
        pairing_reused: reused,
        seconds_read_table,
        seconds_replay,
        seconds_per_period: seconds_replay / plan.periods as f64,
        rows_per_second: rows as f64 * plan.periods as f64 / seconds_replay.max(1e-12),
        rows,
    };
    writer.finish(&costs)?;
    let report = ExtrapolationReport {
        output: plan.output.display().to_string(),
        scheme: plan.scheme.name().into(),
        periods: plan.periods,
        particles: info.particles,
        rows,
        max_cfl,
        table_in_memory: table.is_some(),
        pairing: stored.summary.clone(),
        costs,
        total_heat_t1: heat_t1,
        total_heat_end: replay::total_heat(&temps, &bodies),
    };
    Ok(report)
}

fn print(report: &ExtrapolationReport, json: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        let c = &report.costs;
        println!(
            "extrapolation {} ({} periods, {} scheme, {} particles, {} rows, max CFL {:.4})",
            report.output,
            report.periods,
            report.scheme,
            report.particles,
            report.rows,
            report.max_cfl
        );
        println!(
            "pairing       mean distance {:.4} diameters, {} ({:.2} s{})",
            report.pairing.mean_distance_diameters,
            if report.pairing.certified {
                "certified"
            } else {
                "not certified"
            },
            c.seconds_pairing,
            if c.pairing_reused { ", reused" } else { "" }
        );
        println!(
            "replay        {:.3} s per period, {:.3e} rows/s (table read {:.2} s, {})",
            c.seconds_per_period,
            c.rows_per_second,
            c.seconds_read_table,
            if report.table_in_memory {
                "in memory"
            } else {
                "streamed"
            }
        );
        println!(
            "heat          sum C T {:.10e} J at t1, {:.10e} J at the end",
            report.total_heat_t1, report.total_heat_end
        );
    }
    Ok(())
}
