//! `tdex inspect`: what a recording holds, read back from the file itself (the whole table is
//! streamed, so a damaged file is reported here rather than during an extrapolation).

use crate::cli::InspectPlan;
use anyhow::Result;
use extrapolate::replay::{self, Bodies, CflRow};
use recorder::format::{RecordingCosts, RecordingReader};
use serde::Serialize;

/// Share of collisions that must last at least the suggested `n` steps (the paper's 97 %).
const KEEP_FRACTION: f64 = 0.97;

#[derive(Debug, Serialize)]
struct HistogramBin {
    /// Consecutive samples the collision was seen at.
    samples: u32,
    /// Duration bounds implied (steps).
    min_steps: u64,
    max_steps: u64,
    count: u64,
}

#[derive(Debug, Serialize)]
struct SnapshotSummary {
    index: u32,
    time: f64,
    mean_temperature: f64,
    mean_position: [f64; 3],
}

/// How a recording was sampled; shared by the `record` and `inspect` reports.
#[derive(Debug, Serialize)]
pub struct Sampling {
    pub particles: u32,
    pub dt: f64,
    pub n: u32,
    pub dtc_max_steps: u32,
    pub tau: f64,
    pub period_steps: u64,
    pub t0: f64,
    pub reference_periods: u32,
}

impl Sampling {
    pub fn of(info: &recorder::format::RecordingInfo) -> Self {
        Self {
            particles: info.particles,
            dt: info.dt,
            n: info.sample_every,
            dtc_max_steps: info.dtc_max_steps,
            tau: info.tau,
            period_steps: info.period_steps,
            t0: info.t0,
            reference_periods: info.reference_periods,
        }
    }
}

/// `tdex inspect --json` (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct Inspection {
    file: String,
    file_bytes: u64,
    format_version: u32,
    tool_version: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    walls: usize,
    conducting_walls: usize,
    area_encoding: String,
    rows: u64,
    wall_rows: u64,
    batches: u64,
    contact_steps: u64,
    table_bytes: u64,
    bytes_per_row: f64,
    collisions: u64,
    duration_histogram: Vec<HistogramBin>,
    suggested_n: Option<u64>,
    max_cfl: Option<CflRow>,
    snapshots: Vec<SnapshotSummary>,
    costs: Option<RecordingCosts>,
}

pub fn run(plan: &InspectPlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    let info = reader.info().clone();
    let snapshots = reader.snapshots()?;
    let t0 = snapshots.iter().find(|s| s.index == 0).ok_or_else(|| {
        recorder::format::FormatError::Corrupt {
            path: plan.file.clone(),
            detail: "no snapshot at t0 (index 0)".into(),
        }
    })?;
    let (mut wall_rows, mut contact_steps) = (0u64, 0u64);
    let found = replay::scan(&reader, &Bodies::of(&info, t0), |r, _| {
        wall_rows += (r.j >= info.particles) as u64;
        contact_steps += r.duration_steps as u64;
    })?;
    let summary = reader.summary().cloned();
    let n = info.sample_every as u64;
    let histogram: Vec<HistogramBin> = summary.as_ref().map_or_else(Vec::new, |s| {
        s.duration_histogram
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .map(|(samples, &count)| HistogramBin {
                samples: samples as u32,
                min_steps: (samples as u64 - 1) * n + 1,
                max_steps: (samples as u64 + 1) * n - 1,
                count,
            })
            .collect()
    });
    let collisions: u64 = histogram.iter().map(|b| b.count).sum();
    // the largest n that KEEP_FRACTION of the collisions certainly outlast
    let suggested_n = {
        let mut shorter = 0u64;
        histogram.iter().find_map(|b| {
            shorter += b.count;
            (shorter as f64 > (1.0 - KEEP_FRACTION) * collisions as f64).then_some(b.min_steps)
        })
    };
    let inspection = Inspection {
        file: plan.file.display().to_string(),
        file_bytes: reader.file_bytes(),
        format_version: info.format_version,
        tool_version: info.tool_version.clone(),
        case: info
            .case_resolved
            .get("name")
            .and_then(|v| v.as_str())
            .unwrap_or("")
            .into(),
        sampling: Sampling::of(&info),
        walls: info.walls.len(),
        conducting_walls: info
            .walls
            .iter()
            .filter(|w| w.temperature.is_some())
            .count(),
        area_encoding: format!("{:?}", info.area_encoding).to_lowercase(),
        rows: found.rows,
        wall_rows,
        batches: found.batches,
        contact_steps,
        table_bytes: reader.table_bytes(),
        bytes_per_row: reader.table_bytes() as f64 / found.rows.max(1) as f64,
        collisions,
        duration_histogram: histogram,
        suggested_n,
        max_cfl: found.worst,
        snapshots: snapshots
            .iter()
            .map(|s| {
                let n = s.len().max(1) as f64;
                let mut mean = [0.0; 3];
                for p in &s.pos {
                    for a in 0..3 {
                        mean[a] += p[a] / n;
                    }
                }
                SnapshotSummary {
                    index: s.index,
                    time: s.time,
                    mean_temperature: s.temp.iter().sum::<f64>() / n,
                    mean_position: mean,
                }
            })
            .collect(),
        costs: reader.costs().cloned(),
    };
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&inspection)?);
    } else {
        print_human(&inspection);
    }
    Ok(())
}

fn print_human(s: &Inspection) {
    println!(
        "recording     {} ({:.1} MB, format {}, tdex {})",
        s.file,
        s.file_bytes as f64 / 1e6,
        s.format_version,
        s.tool_version
    );
    println!(
        "case          {}: {} particles, {} walls ({} conducting)",
        s.case, s.sampling.particles, s.walls, s.conducting_walls
    );
    println!(
        "period        τ = {} s = {} steps of {:e} s from t0 = {} s; {} reference periods",
        s.sampling.tau,
        s.sampling.period_steps,
        s.sampling.dt,
        s.sampling.t0,
        s.sampling.reference_periods
    );
    println!(
        "sampling      n = {} steps, Δt_c^max = {} steps, sqrt(a) {}",
        s.sampling.n, s.sampling.dtc_max_steps, s.area_encoding
    );
    println!(
        "table         {} rows ({} wall rows) in {} batches, {} contact-steps; {:.2} bytes per row ({:.1} MB)",
        s.rows, s.wall_rows, s.batches, s.contact_steps, s.bytes_per_row, s.table_bytes as f64 / 1e6
    );
    println!(
        "collisions    {} (durations: samples seen → steps)",
        s.collisions
    );
    let total = s.collisions.max(1) as f64;
    let mut cumulative = 0u64;
    for b in &s.duration_histogram {
        cumulative += b.count;
        if b.samples <= 12 || b.count as f64 > 0.01 * total {
            println!(
                "  {:>4} samples ({:>5}–{:<5} steps) {:>10}  {:5.1} % ≤",
                b.samples,
                b.min_steps,
                b.max_steps,
                b.count,
                100.0 * cumulative as f64 / total
            );
        }
    }
    match s.suggested_n {
        Some(n) => println!("suggested n   {n} steps (97 % of the collisions last at least that)"),
        None => println!("suggested n   - (no collisions)"),
    }
    if let Some(w) = &s.max_cfl {
        println!(
            "max CFL c     {:.4} (row {}: bodies {} and {}, m = {} steps, sqrt(a) = {:.4e} m){}",
            w.cfl,
            w.row,
            w.i,
            w.j,
            w.duration_steps,
            w.sqrt_area,
            if w.cfl >= 1.0 {
                " — the explicit replay will refuse this table"
            } else {
                ""
            }
        );
    }
    for snap in &s.snapshots {
        println!(
            "snapshot {:>3}  t = {:.4} s, mean T {:.6} K, mean position [{:.5}, {:.5}, {:.5}] m",
            snap.index,
            snap.time,
            snap.mean_temperature,
            snap.mean_position[0],
            snap.mean_position[1],
            snap.mean_position[2]
        );
    }
    if let Some(c) = &s.costs {
        let stages: Vec<String> = c
            .stage_seconds
            .iter()
            .map(|(k, v)| format!("{k} {v:.2} s"))
            .collect();
        println!(
            "costs         {:.1} s to t0, {:.1} s period ({:.1} s recorder), {:.1} s reference; {} threads; stages {}",
            c.seconds_to_t0, c.seconds_period, c.seconds_recorder, c.seconds_reference, c.threads, stages.join(", ")
        );
    }
}
