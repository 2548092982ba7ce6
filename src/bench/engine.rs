//! `tdex bench CASE`: particle-steps per second of the rotating, heated phase, the share of
//! each pipeline stage, contacts and peak memory, and optionally LIGGGHTS on the same case.

use super::{liggghts, peak_resident_bytes};
use crate::cli::BenchPlan;
use anyhow::Result;
use recorder::counters::Counters;
use recorder::record;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, Serialize)]
struct StageShare {
    stage: &'static str,
    seconds: f64,
    share: f64,
}

#[derive(Debug, Serialize)]
struct EngineBench {
    case: String,
    particles: usize,
    steps: u64,
    threads: usize,
    /// The vector instructions of the engine's hot loops (`TDEX_SIMD` caps them).
    vector_instructions: recorder::simd::Simd,
    seconds: f64,
    particle_steps_per_s: f64,
    /// Wall time of each stage over the timed steps, and its share of the stages' sum.
    stages: Vec<StageShare>,
    /// Particle–particle contacts per particle (coordination number), mean over the steps.
    contacts_per_particle: f64,
    wall_contacts_per_particle: f64,
    neighbor_rebuilds: u64,
    /// Peak resident memory of the whole process (settling included), bytes.
    peak_resident_bytes: Option<u64>,
    peak_resident_bytes_per_particle: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    liggghts_particle_steps_per_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    liggghts_seconds: Option<f64>,
    /// tdex rate / LIGGGHTS rate.
    #[serde(skip_serializing_if = "Option::is_none")]
    ratio: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    liggghts_dir: Option<String>,
}

/// Runs the case to `t0`, times `steps` steps after it, then (if asked) the LIGGGHTS peer from
/// the same bed at `t0`.
pub fn engine(plan: &BenchPlan) -> Result<()> {
    let (mut result, peer_dir) = crate::with_workers(plan.threads, || time_tdex(plan))?;
    if let Some(dir) = peer_dir {
        let peer = liggghts::run(plan, dir)?;
        result.liggghts_particle_steps_per_s = Some(peer.particle_steps_per_s);
        result.liggghts_seconds = Some(peer.seconds);
        result.ratio = Some(result.particle_steps_per_s / peer.particle_steps_per_s);
        result.liggghts_dir = Some(peer.dir.display().to_string());
    }
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        print_table(&result);
    }
    Ok(())
}

/// The timed steps; and, when the LIGGGHTS peer is asked for, the directory where its deck and
/// tdex's bed at `t0` were written.
fn time_tdex(plan: &BenchPlan) -> Result<(EngineBench, Option<PathBuf>)> {
    let bar = crate::progress::dem_bar(plan.json, "tdex");
    let mut sim = record::run_to_t0(&plan.case, &mut crate::progress::on_phase(&bar))?;
    bar.finish_and_clear();
    let peer_dir = match &plan.liggghts {
        Some(dir) => Some(liggghts::prepare(plan, &sim.particles, dir.as_deref())?),
        None => None,
    };
    sim.counters = Counters::default();
    let rebuilds_before = sim.neighbors.rebuilds;
    let n = sim.particles.len();
    let (mut pair_entries, mut wall_contacts) = (0u64, 0u64);
    let start = Instant::now();
    for _ in 0..plan.steps {
        sim.step();
        pair_entries += sim.last_contacts.pair_entries;
        wall_contacts += sim.last_contacts.wall;
    }
    let seconds = start.elapsed().as_secs_f64();
    sim.check_inside()?;
    let stage_total = sim.counters.total().as_secs_f64().max(f64::MIN_POSITIVE);
    let stages = sim
        .counters
        .stages()
        .into_iter()
        .map(|(stage, d)| StageShare {
            stage,
            seconds: d.as_secs_f64(),
            share: d.as_secs_f64() / stage_total,
        })
        .collect();
    let per_step_particle = (plan.steps * n as u64) as f64;
    let peak = peak_resident_bytes();
    let bench = EngineBench {
        case: plan.case.name.clone(),
        particles: n,
        steps: plan.steps,
        threads: plan.threads,
        vector_instructions: recorder::simd::Simd::in_use(),
        seconds,
        particle_steps_per_s: per_step_particle / seconds,
        stages,
        contacts_per_particle: pair_entries as f64 / per_step_particle,
        wall_contacts_per_particle: wall_contacts as f64 / per_step_particle,
        neighbor_rebuilds: sim.neighbors.rebuilds - rebuilds_before,
        peak_resident_bytes: peak,
        peak_resident_bytes_per_particle: peak.map(|b| b as f64 / n as f64),
        liggghts_particle_steps_per_s: None,
        liggghts_seconds: None,
        ratio: None,
        liggghts_dir: None,
    };
    Ok((bench, peer_dir))
}

fn print_table(r: &EngineBench) {
    println!(
        "{}: {} particles, {} steps after t0, {} threads",
        r.case, r.particles, r.steps, r.threads
    );
    println!("vectors       {}", r.vector_instructions.describe());
    println!(
        "tdex          {:.3e} particle-steps/s ({:.2} s)",
        r.particle_steps_per_s, r.seconds
    );
    let shares: Vec<String> = r
        .stages
        .iter()
        .map(|s| format!("{} {:.0} %", s.stage, 100.0 * s.share))
        .collect();
    println!("stages        {}", shares.join(", "));
    println!(
        "contacts      {:.2} per particle (walls {:.3}); {} list rebuilds",
        r.contacts_per_particle, r.wall_contacts_per_particle, r.neighbor_rebuilds
    );
    match (r.peak_resident_bytes, r.peak_resident_bytes_per_particle) {
        (Some(b), Some(per)) => println!(
            "memory        peak resident {:.1} MB, {:.0} bytes per particle",
            b as f64 / 1e6,
            per
        ),
        _ => println!("memory        peak resident not available on this system"),
    }
    if let (Some(rate), Some(ratio)) = (r.liggghts_particle_steps_per_s, r.ratio) {
        println!(
            "LIGGGHTS 3.8  {:.3e} particle-steps/s (1 process, {:.2} s; deck in {})",
            rate,
            r.liggghts_seconds.unwrap_or(0.0),
            r.liggghts_dir.as_deref().unwrap_or("?")
        );
        println!("ratio         {ratio:.2}x (tdex / LIGGGHTS)");
    }
}
