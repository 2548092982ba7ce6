//! `tdex extrapolate`: K periods of the recorded table replayed through the pairing.

use crate::cli::ExtrapolatePlan;
use crate::pair;
use anyhow::{Context, Result};
use extrapolate::replay::memory::human_bytes;
use extrapolate::replay::{
    self, Bodies, Exchange, MemoryNeeds, MemoryPlan, ModeReason, Scheme, SyncScratch, Table,
    TableMode,
};
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
    memory: MemoryReport,
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
    let stored_pairing = pair::load(&reader, &t0, &t1);

    // the memory it will need, stated and held against the limit before the pairing and
    // the replay start: a table that does not fit is streamed, never left to the OOM killer
    let limit = match plan.max_memory {
        Some(bytes) => MemoryLimit {
            bytes,
            source: "--max-memory".into(),
        },
        None => MemoryLimit::available(),
    };
    let needs = MemoryNeeds::estimate(
        info.particles as u64,
        reader.table_rows(),
        reader.largest_table_chunk(),
        stored_pairing.is_some(),
    );
    let memory =
        MemoryPlan::choose(needs, limit.bytes, &limit.source, plan.stream).with_context(|| {
            let file = plan.file.display();
            format!("{file}: allow more with --max-memory or free memory")
        })?;
    eprintln!("{}", memory_statement(&memory, &limit));

    let started = Instant::now();
    let (stored, reused) = match stored_pairing {
        Some(stored) => (stored, true),
        None => {
            let mut stored = pair::compute(&t0, &t1)?;
            if plan.reproducible {
                stored.summary = stored.summary.reproducible();
            }
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
    let (table, rows, worst) = if memory.mode == TableMode::Streamed {
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
        return Err(w.refusal()).with_context(|| {
            let file = plan.file.display();
            format!("{file}: record with a smaller --dtc-max or replay with --scheme exact")
        });
    }

    let out_info = ExtrapolationInfo {
        format_version: FORMAT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        recording: plan.file.display().to_string(),
        recording_info: info.clone(),
        scheme: plan.scheme.name().into(),
        periods: plan.periods,
        pairing: serde_json::to_value(if plan.reproducible {
            // a stored pairing made without --reproducible carries its time
            stored.summary.clone().reproducible()
        } else {
            stored.summary.clone()
        })?,
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
    writer.finish((!plan.reproducible).then_some(&costs))?;
    let report = ExtrapolationReport {
        output: plan.output.display().to_string(),
        scheme: plan.scheme.name().into(),
        periods: plan.periods,
        particles: info.particles,
        rows,
        max_cfl,
        table_in_memory: table.is_some(),
        memory: MemoryReport::of(&memory, &limit),
        pairing: stored.summary.clone(),
        costs,
        total_heat_t1: heat_t1,
        total_heat_end: replay::total_heat(&temps, &bodies),
    };
    Ok(report)
}

/// Rows a second that decoding the table costs, each period, when it is streamed: the
/// `bench_drum` recording (23.2 million rows) replays in 1.02 s per period streamed against
/// 0.101 s in memory (docs/benchmarks.md), 0.92 s to decode them.
const STREAM_DECODE_ROWS_PER_SECOND: f64 = 2.5e7;

/// The memory an extrapolation may use, and where that figure came from.
pub struct MemoryLimit {
    pub bytes: u64,
    pub source: String,
}

impl MemoryLimit {
    /// The default: 80 % of what the machine can still give (`MemAvailable` in
    /// /proc/meminfo) and of what the process's cgroup still allows (`memory.max` −
    /// `memory.current`, cgroup v2), whichever is smaller. The 20 % left is for the page
    /// cache holding the recording and for the rest of the machine. Without /proc/meminfo
    /// there is no limit (the table is held in memory, as before `--max-memory`).
    pub fn available() -> Self {
        let mut found: Vec<(u64, &str)> = Vec::new();
        if let Some(kb) = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| meminfo_kb(&text, "MemAvailable:"))
        {
            found.push((kb.saturating_mul(1024), "MemAvailable"));
        }
        if let Some(room) = cgroup_room() {
            found.push((room, "the cgroup's memory.max"));
        }
        match found.into_iter().min() {
            Some((bytes, what)) => Self {
                bytes: bytes / 5 * 4,
                source: format!("80 % of {what}; set it with --max-memory"),
            },
            None => Self {
                bytes: u64::MAX,
                source: "no limit known: no /proc/meminfo; set one with --max-memory".into(),
            },
        }
    }
}

/// A `Key:   123 kB` line of /proc/meminfo, in kB.
fn meminfo_kb(text: &str, key: &str) -> Option<u64> {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

/// What the process's cgroup (v2) still allows, if it sets a limit.
fn cgroup_room() -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = own.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(dir.join(name))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (no limit) does not parse
    let max = read("memory.max")?;
    Some(max.saturating_sub(read("memory.current").unwrap_or(0)))
}

/// The line stated before any work: what the replay needs, the limit, where the table goes.
fn memory_statement(memory: &MemoryPlan, limit: &MemoryLimit) -> String {
    let n = &memory.needs;
    let limit_text = if limit.bytes == u64::MAX {
        format!("no limit ({})", limit.source)
    } else {
        format!("limit {} ({})", human_bytes(limit.bytes), limit.source)
    };
    let parts = format!(
        "table {} ({} rows × {} B), particles {}, pairing {}, buffers {}",
        human_bytes(n.table_bytes),
        n.rows,
        replay::memory::ROW_BYTES,
        human_bytes(n.particle_bytes),
        if n.pairing_bytes == 0 {
            "stored".to_string()
        } else {
            human_bytes(n.pairing_bytes)
        },
        human_bytes(n.buffer_bytes)
    );
    let slower = n.rows as f64 / STREAM_DECODE_ROWS_PER_SECOND;
    match memory.reason {
        ModeReason::Fits => format!(
            "memory        needs {} with the table in memory ({parts}); {limit_text}",
            human_bytes(n.in_memory())
        ),
        ModeReason::TooLarge => format!(
            "memory        table {} (whole replay {}) > {limit_text}: streaming from disk, \
             ~{slower:.2} s per period slower; needs {} ({parts})",
            human_bytes(n.table_bytes),
            human_bytes(n.in_memory()),
            human_bytes(n.streamed())
        ),
        ModeReason::Requested => format!(
            "memory        --stream: the table is read from disk every period, ~{slower:.2} s \
             per period slower; needs {} ({parts}); {limit_text}",
            human_bytes(n.streamed())
        ),
    }
}

/// `memory` in `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct MemoryReport {
    /// `null` when no limit is known.
    limit_bytes: Option<u64>,
    limit_source: String,
    /// `in_memory` or `streamed`, and why: `fits`, `too_large`, `requested`.
    table: &'static str,
    reason: &'static str,
    needed_bytes: u64,
    in_memory_bytes: u64,
    streamed_bytes: u64,
    table_bytes: u64,
    particle_bytes: u64,
    pairing_bytes: u64,
    buffer_bytes: u64,
}

impl MemoryReport {
    fn of(memory: &MemoryPlan, limit: &MemoryLimit) -> Self {
        let n = &memory.needs;
        Self {
            limit_bytes: (limit.bytes != u64::MAX).then_some(limit.bytes),
            limit_source: limit.source.clone(),
            table: match memory.mode {
                TableMode::InMemory => "in_memory",
                TableMode::Streamed => "streamed",
            },
            reason: match memory.reason {
                ModeReason::Fits => "fits",
                ModeReason::TooLarge => "too_large",
                ModeReason::Requested => "requested",
            },
            needed_bytes: memory.needed(),
            in_memory_bytes: n.in_memory(),
            streamed_bytes: n.streamed(),
            table_bytes: n.table_bytes,
            particle_bytes: n.particle_bytes,
            pairing_bytes: n.pairing_bytes,
            buffer_bytes: n.buffer_bytes,
        }
    }
}

fn print(report: &ExtrapolationReport, json: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        let c = &report.costs;
        println!(
            "extrapolation {} ({} periods, {} scheme, {} particles, {} rows, max CFL {})",
            report.output,
            report.periods,
            report.scheme,
            report.particles,
            report.rows,
            crate::fmt::sig(report.max_cfl, 4)
        );
        println!(
            "pairing       mean distance {} diameters, {} ({:.2} s{})",
            crate::fmt::sig(report.pairing.mean_distance_diameters, 4),
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
