//! A recording's metadata: the `tdex.recording` record (the case, the options, the run at
//! `t0`) and the `tdex.costs` record (the wall times), for the recorder and the importers.

use super::options::RecordOptions;
use crate::case::Case;
use crate::heat::ConductionLaw;
use crate::wall::WallSet;
use crate::Simulation;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use tdex_format::{
    AreaEncoding, RecordingCosts, RecordingInfo, WallInfo, WallKind, FORMAT_VERSION,
    SQRT_AREA_CODES,
};

/// What a recording's info takes from the run at `t0`, whichever engine made it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunAtT0 {
    pub particles: u32,
    /// Largest particle radius (m): the span of the `sqrt(a)` codes.
    pub r_max: f64,
    pub walls: Vec<WallInfo>,
    /// Simulated time and step count at `t0`.
    pub t0: f64,
    pub step_t0: u64,
}

impl RunAtT0 {
    /// The run of `sim`, standing at `t0`.
    pub(crate) fn of(sim: &Simulation) -> Self {
        let particles = sim.particles.len() as u32;
        Self {
            particles,
            r_max: sim.particles.radius.iter().cloned().fold(0.0, f64::max),
            walls: wall_infos(&sim.walls, particles),
            t0: sim.time,
            step_t0: sim.step,
        }
    }
}

/// The walls of the case's drum as table bodies `particles + w`, with their fixed
/// temperature when they conduct.
pub(crate) fn wall_infos(walls: &WallSet, particles: u32) -> Vec<WallInfo> {
    (0..walls.len())
        .map(|w| WallInfo {
            id: particles + w as u32,
            kind: WallKind::DRUM[w],
            temperature: walls.temperature(w),
        })
        .collect()
}

/// The `tdex.recording` metadata of a period recorded with `opts` from `run`; the material
/// and conduction constants come from the case, as the engine resolves them.
pub(crate) fn recording_info(
    case: &Case,
    case_path: &Path,
    case_toml: &str,
    opts: &RecordOptions,
    run: RunAtT0,
) -> RecordingInfo {
    let m = &case.material;
    let law = ConductionLaw::new(
        &case.conduction,
        m.conductivity,
        case.drum.wall_conductivity.unwrap_or(m.conductivity),
        m.heat_capacity,
        m.youngs_modulus,
    );
    RecordingInfo {
        format_version: FORMAT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        case_toml: case_toml.into(),
        case_path: case_path.display().to_string(),
        case_resolved: serde_json::to_value(case).expect("a case serialises"),
        particles: run.particles,
        walls: run.walls,
        dt: case.time.dt,
        sample_every: opts.sample_every,
        dtc_max_steps: opts.dtc_max_steps,
        period_steps: opts.period_steps,
        tau: opts.period_steps as f64 * case.time.dt,
        t0: run.t0,
        step_t0: run.step_t0,
        reference_periods: opts.reference_periods,
        twins: opts.twins,
        recorded_periods: opts.recorded_periods,
        twins_from: opts.twins_from,
        area_encoding: opts.area_encoding,
        sqrt_area_unit: match opts.area_encoding {
            AreaEncoding::Quantized => std::f64::consts::PI.sqrt() * run.r_max / SQRT_AREA_CODES,
            AreaEncoding::Exact => 0.0,
        },
        pair_conductivity: law.pair_conductivity,
        wall_conductivity: law.wall_conductivity,
        density: m.density,
        heat_capacity: m.heat_capacity,
        conductivity: m.conductivity,
    }
}

/// Wall-clock seconds spent so far, as the costs record reports them.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Elapsed {
    pub to_t0: f64,
    /// All recorded periods.
    pub period: f64,
    /// Each recorded period's share of `period` (one entry per recorded period once the
    /// recording has started).
    pub each_period: Vec<f64>,
    pub recorder: f64,
    pub reference: f64,
    /// The DEM twins' reference periods.
    pub twins: f64,
}

impl Elapsed {
    /// The `tdex.costs` record of a run that took these times, with its engine's per-stage
    /// seconds ([`stage_seconds`]), the worker threads it ran on and the vector instructions.
    pub(crate) fn costs(&self, stage_seconds: BTreeMap<String, f64>) -> RecordingCosts {
        RecordingCosts {
            seconds_to_t0: self.to_t0,
            seconds_period: self.period,
            seconds_reference: self.reference,
            seconds_recorder: self.recorder,
            seconds_twins: self.twins,
            // one period: `seconds_period` says it all
            seconds_each_period: if self.each_period.len() > 1 {
                self.each_period.clone()
            } else {
                Vec::new()
            },
            stage_seconds,
            threads: rayon::current_num_threads(),
            vector_instructions: crate::simd::Simd::in_use().name().to_string(),
        }
    }
}

/// The engine's per-stage seconds so far, by stage name.
pub(crate) fn stage_seconds(sim: &Simulation) -> BTreeMap<String, f64> {
    sim.counters
        .stages()
        .iter()
        .map(|(name, d)| (name.to_string(), d.as_secs_f64()))
        .collect()
}
