//! `tdex run`: a whole case (settle, spin up, heat) with a progress bar and a summary.

use crate::cli::RunPlan;
use anyhow::{Context, Result};
use recorder::Simulation;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// The run summary; also the `--json` object (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct RunSummary {
    case: String,
    case_file: String,
    particles: usize,
    threads: usize,
    dt: f64,
    steps_settle: u64,
    steps_spin_up: u64,
    steps_heating: u64,
    wall_seconds: f64,
    particle_steps_per_second: f64,
    heating_particle_steps_per_second: f64,
    stage_seconds: BTreeMap<&'static str, f64>,
    neighbor_rebuilds: u64,
    contacts_per_particle: f64,
    wall_contacts_per_particle: f64,
    split_at: Option<f64>,
    hot_mean_start: Option<f64>,
    hot_mean_end: Option<f64>,
    cold_mean_start: Option<f64>,
    cold_mean_end: Option<f64>,
    mean_temperature_start: f64,
    mean_temperature_end: f64,
    total_heat_start: f64,
    total_heat_end: f64,
    heat_relative_change: f64,
}

pub fn run(plan: &RunPlan) -> Result<()> {
    let summary = crate::with_workers(plan.threads, || simulate(plan))?;
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_human(&summary);
    }
    Ok(())
}

fn simulate(plan: &RunPlan) -> Result<RunSummary> {
    let case = &plan.case;
    let (n_settle, n_spin, n_heat) = (
        case.steps_in(case.time.settle),
        case.steps_in(case.time.spin_up),
        case.steps_in(case.heating_time()),
    );
    let mut sim =
        Simulation::new(case).with_context(|| format!("case {}", plan.case_path.display()))?;
    let bar = crate::progress::dem_bar(plan.json, "");
    bar.set_length(n_settle + n_spin + n_heat);
    let every = 200;
    let wall_start = Instant::now();

    // a log for a run in the background, where the bar is not drawn; each phase is reported
    // once before its first step (PhaseLog::report), then every `every` steps
    let mut log = crate::progress::PhaseLog::on_stderr();
    let mut phase = |sim: &mut Simulation, name: &str, steps: u64, before: u64| {
        bar.set_message(name.to_string());
        let mut logged = |done: u64| {
            if let Some(log) = &mut log {
                log.report(name, done, steps);
            }
        };
        logged(0);
        sim.run(steps, every, &mut |s| {
            bar.set_position(before + s);
            logged(s);
        })
    };

    phase(&mut sim, "settle", n_settle, 0)?;
    sim.start_rotation();
    phase(&mut sim, "spin-up", n_spin, n_settle)?;

    sim.assign_temperatures();
    let start = sim.heat_summary();
    let before_heating = sim.counters.clone();
    phase(&mut sim, "heating", n_heat, n_settle + n_spin)?;
    let end = sim.heat_summary();
    bar.finish_and_clear();

    let heating_seconds = (sim.counters.total() - before_heating.total()).as_secs_f64();
    let heating_rate = (sim.counters.particle_steps - before_heating.particle_steps) as f64
        / heating_seconds.max(1e-12);
    Ok(RunSummary {
        case: case.name.clone(),
        case_file: plan.case_path.display().to_string(),
        particles: sim.particles.len(),
        threads: plan.threads,
        dt: case.time.dt,
        steps_settle: n_settle,
        steps_spin_up: n_spin,
        steps_heating: n_heat,
        wall_seconds: wall_start.elapsed().as_secs_f64(),
        particle_steps_per_second: sim.counters.particle_steps_per_second(),
        heating_particle_steps_per_second: heating_rate,
        stage_seconds: sim
            .counters
            .stages()
            .iter()
            .map(|(k, d)| (*k, d.as_secs_f64()))
            .collect(),
        neighbor_rebuilds: sim.neighbors.rebuilds,
        contacts_per_particle: sim.contacts_per_particle(),
        wall_contacts_per_particle: sim.last_contacts.wall as f64 / sim.particles.len() as f64,
        split_at: sim.groups.split_at,
        hot_mean_start: start.hot_mean,
        hot_mean_end: end.hot_mean,
        cold_mean_start: start.cold_mean,
        cold_mean_end: end.cold_mean,
        mean_temperature_start: start.mean_temperature,
        mean_temperature_end: end.mean_temperature,
        total_heat_start: start.total_heat,
        total_heat_end: end.total_heat,
        heat_relative_change: (end.total_heat - start.total_heat) / start.total_heat,
    })
}

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), crate::fmt::num)
}

fn print_human(s: &RunSummary) {
    let total: f64 = s.stage_seconds.values().sum();
    println!(
        "case          {} ({}), {} particles, {} threads",
        s.case, s.case_file, s.particles, s.threads
    );
    println!(
        "steps         settle {} + spin-up {} + heating {} (dt {})",
        s.steps_settle,
        s.steps_spin_up,
        s.steps_heating,
        crate::fmt::seconds(s.dt)
    );
    println!(
        "speed         {:.1} s wall, {:.3e} particle-steps/s ({:.3e} while heating), {} neighbour rebuilds",
        s.wall_seconds, s.particle_steps_per_second, s.heating_particle_steps_per_second, s.neighbor_rebuilds
    );
    let stages: Vec<String> = s
        .stage_seconds
        .iter()
        .map(|(k, v)| format!("{k} {v:.2} s ({:.0} %)", 100.0 * v / total.max(1e-12)))
        .collect();
    println!("stages        {}", stages.join(", "));
    println!(
        "contacts      {:.2} particle-particle and {:.3} wall contacts per particle",
        s.contacts_per_particle, s.wall_contacts_per_particle
    );
    println!(
        "hot group     {} K -> {} K",
        opt(s.hot_mean_start),
        opt(s.hot_mean_end)
    );
    println!(
        "cold group    {} K -> {} K",
        opt(s.cold_mean_start),
        opt(s.cold_mean_end)
    );
    println!(
        "heat          sum m c T: {:.10e} J at t0, {:.10e} J at the end (relative change {:.2e})",
        s.total_heat_start, s.total_heat_end, s.heat_relative_change
    );
}
