//! `tdex extrapolate`: K periods of the recorded table replayed through the pairing.

use crate::cli::ExtrapolatePlan;
use crate::pair;
use anyhow::{Context, Result};
use extrapolate::replay::{self, Bodies, Exchange, ReplayError, Scheme, SyncScratch, Table};
use recorder::format::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationWriter, RecordingReader, Snapshot,
    FORMAT_VERSION,
};
use serde::Serialize;
use std::time::Instant;

/// `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct ExtrapolationReport {
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.threads)
        .build()
        .context("cannot start the worker threads")?;
    pool.install(|| extrapolate(plan))
}

fn scheme_name(s: Scheme) -> &'static str {
    match s {
        Scheme::Explicit => "explicit",
        Scheme::Exact => "exact",
        Scheme::Synchronous => "synchronous",
    }
}

fn extrapolate(plan: &ExtrapolatePlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    let info = reader.info().clone();
    let t0 = reader
        .snapshot(0)?
        .context("the recording has no t0 snapshot")?;
    let t1 = reader
        .snapshot(1)?
        .context("the recording has no t1 snapshot")?;
    let bodies = Bodies::of(&info, &t0);

    let started = Instant::now();
    let (stored, reused) = match pair::load(&reader) {
        Some(stored) => (stored, true),
        None => {
            let stored = pair::compute(&reader)?;
            pair::store(&reader, &stored)?;
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
    let table = if plan.stream {
        None
    } else {
        Some(Table::read(&reader)?)
    };
    let (rows, worst) = match &table {
        Some(table) => (
            table.exchanges.len() as u64,
            table.max_cfl(&bodies).map(|(k, c)| {
                let (m, a) = table.source[k];
                let e = table.exchanges[k];
                (k as u64, e.i, e.j, m, a, c)
            }),
        ),
        None => stream_max_cfl(&reader, &bodies)?,
    };
    let seconds_read_table = t.elapsed().as_secs_f64();
    let max_cfl = worst.map_or(0.0, |w| w.5);
    if plan.scheme == Scheme::Explicit {
        if let Some((row, i, j, duration_steps, sqrt_area, cfl)) = worst.filter(|w| w.5 >= 1.0) {
            return Err(ReplayError::Cfl {
                row,
                i,
                j,
                duration_steps,
                sqrt_area,
                cfl,
            })
            .with_context(|| format!("{}", plan.file.display()));
        }
    }

    let out_info = ExtrapolationInfo {
        format_version: FORMAT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        recording: plan.file.display().to_string(),
        recording_info: info.clone(),
        scheme: scheme_name(plan.scheme).into(),
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
    let t = Instant::now();
    for k in 1..=plan.periods {
        replay::move_to_roles(&temps, &stored.g, &mut next)?;
        std::mem::swap(&mut temps, &mut next);
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
                    let exchanges: Vec<Exchange> =
                        batch?.rows.iter().map(|r| Exchange::of(r, &info)).collect();
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
        writer.write_snapshot(&Snapshot {
            index: k + 1,
            time: info.snapshot_time(k + 1),
            temp: temps.clone(),
            ..t1.clone()
        })?;
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
        scheme: scheme_name(plan.scheme).into(),
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
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
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

type Worst = Option<(u64, u32, u32, u32, f64, f64)>;

/// Rows and the worst CFL row, reading the table once from the file.
fn stream_max_cfl(reader: &RecordingReader, bodies: &Bodies) -> Result<(u64, Worst)> {
    let (mut rows, mut worst): (u64, Worst) = (0, None);
    for batch in reader.table() {
        let batch = batch?;
        for (k, r) in batch.rows.iter().enumerate() {
            let c = bodies.cfl(&Exchange::of(r, reader.info()));
            if worst.is_none_or(|w| c > w.5) {
                worst = Some((
                    batch.first_row + k as u64,
                    r.i,
                    r.j,
                    r.duration_steps,
                    r.sqrt_area,
                    c,
                ));
            }
        }
        rows += batch.rows.len() as u64;
    }
    Ok((rows, worst))
}
