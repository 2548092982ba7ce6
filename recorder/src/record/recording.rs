//! `tdex record` as a library call: run the case to `t0`, assign the temperatures, record one
//! period `τ` (sampled table + snapshots at `t0` and `t1`) and, optionally, K reference periods.

use super::ContactSampler;
use crate::case::Case;
use crate::format::{
    AreaEncoding, FormatError, RecordingCosts, RecordingInfo, RecordingSummary, RecordingWriter,
    WallInfo, FORMAT_VERSION, SQRT_AREA_CODES,
};
use crate::heat::ConductionLaw;
use crate::wall::WallSet;
use crate::{Simulation, SimulationError};
use std::path::Path;
use std::sync::mpsc;
use std::time::Instant;

/// What to record, validated by the caller (the CLI plan).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordOptions {
    /// Sampling factor `n` (steps).
    pub sample_every: u32,
    /// `Δt_c^max` in steps, a positive multiple of `n`.
    pub dtc_max_steps: u32,
    /// `τ` in steps, a positive multiple of `n`.
    pub period_steps: u64,
    /// Reference periods after `t1`.
    pub reference_periods: u32,
    pub area_encoding: AreaEncoding,
}

/// The stage a progress report belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    Settle,
    SpinUp,
    Period,
    Reference,
}

#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error(transparent)]
    Simulation(#[from] SimulationError),
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error("invalid recording settings: {0}")]
    Settings(String),
}

/// Steps between progress reports and stability checks outside the recorded period.
const REPORT_EVERY: u64 = 500;

/// Runs the case and writes the recording to `dest`. `case_toml` is the case file as given.
pub fn record(
    case: &Case,
    case_path: &Path,
    case_toml: &str,
    opts: &RecordOptions,
    dest: &Path,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    check(opts)?;
    let started = Instant::now();
    let mut sim = run_to_t0(case, progress)?;
    let seconds_to_t0 = started.elapsed().as_secs_f64();
    record_from_t0(
        &mut sim,
        case_path,
        case_toml,
        opts,
        dest,
        seconds_to_t0,
        progress,
    )
}

fn check(opts: &RecordOptions) -> Result<ContactSampler, RecordError> {
    let every = opts.sample_every as u64;
    if every == 0 || opts.period_steps == 0 || opts.period_steps % every != 0 {
        return Err(RecordError::Settings(format!(
            "τ = {} steps must be a positive multiple of n = {every}",
            opts.period_steps
        )));
    }
    ContactSampler::new(opts.sample_every, opts.dtc_max_steps).ok_or_else(|| {
        RecordError::Settings(format!(
            "Δt_c^max = {} steps must be a positive multiple of n = {}",
            opts.dtc_max_steps, opts.sample_every
        ))
    })
}

/// Inserts, settles and spins the drum up to `t0`, then assigns the initial temperatures.
pub fn run_to_t0(
    case: &Case,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<Simulation, SimulationError> {
    let mut sim = Simulation::new(case)?;
    let (n_settle, n_spin) = (
        case.steps_in(case.time.settle),
        case.steps_in(case.time.spin_up),
    );
    sim.run(n_settle, REPORT_EVERY, &mut |s| {
        progress(Phase::Settle, s, n_settle)
    })?;
    sim.start_rotation();
    sim.run(n_spin, REPORT_EVERY, &mut |s| {
        progress(Phase::SpinUp, s, n_spin)
    })?;
    sim.assign_temperatures();
    Ok(sim)
}

/// Records the period `[t0, t1]` of a simulation standing at `t0` (and the reference
/// periods) into `dest`.
pub fn record_from_t0(
    sim: &mut Simulation,
    case_path: &Path,
    case_toml: &str,
    opts: &RecordOptions,
    dest: &Path,
    seconds_to_t0: f64,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let job = RecordJob {
        options: opts.clone(),
        dest,
    };
    let mut summaries =
        record_many_from_t0(sim, case_path, case_toml, &[job], seconds_to_t0, progress)?;
    Ok(summaries.pop().expect("one summary per job"))
}

/// One recording of [`record_many_from_t0`]: its settings and its file.
#[derive(Debug, Clone)]
pub struct RecordJob<'a> {
    pub options: RecordOptions,
    pub dest: &'a Path,
}

/// Records several samplings of one DEM run: the simulation standing at `t0` is stepped
/// once through the period and the reference periods, and every job's sampler is fed the
/// contact list at its own steps (`k` a multiple of its `n`). Sampling only reads the state,
/// so each file holds the table and snapshots that a run with its options alone would write;
/// only the costs differ: `seconds_period` is the period's wall time (shared) and
/// `seconds_recorder` the job's own sampler, splitter and writer time. Jobs must share
/// `period_steps` and `reference_periods`.
pub fn record_many_from_t0(
    sim: &mut Simulation,
    case_path: &Path,
    case_toml: &str,
    jobs: &[RecordJob],
    seconds_to_t0: f64,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<Vec<RecordingSummary>, RecordError> {
    let Some(first) = jobs.first() else {
        return Ok(Vec::new());
    };
    let (period_steps, reference_periods) =
        (first.options.period_steps, first.options.reference_periods);
    if jobs.iter().any(|j| {
        j.options.period_steps != period_steps || j.options.reference_periods != reference_periods
    }) {
        return Err(RecordError::Settings(
            "the recordings of one run must share τ and the reference periods".into(),
        ));
    }
    let samplers = jobs
        .iter()
        .map(|j| check(&j.options))
        .collect::<Result<Vec<_>, _>>()?;
    let t0 = sim.snapshot(0);
    let mut writers = Vec::with_capacity(jobs.len());
    for j in jobs {
        let particles = sim.particles.len() as u32;
        let run = RunAtT0 {
            particles,
            r_max: sim.particles.radius.iter().cloned().fold(0.0, f64::max),
            walls: wall_infos(&sim.walls, particles),
            t0: sim.time,
            step_t0: sim.step,
        };
        let info = recording_info(&sim.case, case_path, case_toml, &j.options, run);
        let mut writer = RecordingWriter::create(j.dest, info)?;
        writer.write_snapshot(&t0)?;
        writers.push(writer);
    }

    let period_start = Instant::now();
    let every: Vec<u64> = jobs.iter().map(|j| j.options.sample_every as u64).collect();
    let (samplers, mut recorder_seconds) =
        record_period(sim, samplers, &mut writers, &every, period_steps, progress)?;
    let t1 = sim.snapshot(1);
    for (writer, busy) in writers.iter_mut().zip(&mut recorder_seconds) {
        let t = Instant::now();
        writer.write_snapshot(&t1)?;
        *busy += t.elapsed().as_secs_f64();
    }
    let seconds_period = period_start.elapsed().as_secs_f64();

    let reference_start = Instant::now();
    let reference_steps = reference_periods as u64 * period_steps;
    for period in 0..reference_periods {
        let done = period as u64 * period_steps;
        sim.run(period_steps, REPORT_EVERY, &mut |s| {
            progress(Phase::Reference, done + s, reference_steps)
        })?;
        let snapshot = sim.snapshot(period + 2);
        for writer in &mut writers {
            writer.write_snapshot(&snapshot)?;
        }
    }
    let seconds_reference = reference_start.elapsed().as_secs_f64();
    let stage_seconds: std::collections::BTreeMap<String, f64> = sim
        .counters
        .stages()
        .iter()
        .map(|(name, d)| (name.to_string(), d.as_secs_f64()))
        .collect();
    writers
        .into_iter()
        .zip(samplers)
        .zip(recorder_seconds)
        .map(|((writer, sampler), seconds_recorder)| {
            let costs = RecordingCosts {
                seconds_to_t0,
                seconds_period,
                seconds_reference,
                seconds_recorder,
                stage_seconds: stage_seconds.clone(),
                threads: rayon::current_num_threads(),
            };
            Ok(writer.finish(sampler.duration_histogram().to_vec(), &costs)?)
        })
        .collect()
}

/// Contact lists in flight between the DEM and the recorder thread.
const SAMPLES_IN_FLIGHT: usize = 4;

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The period `[t0, t1]`: the DEM steps on the calling thread (and its pool) while a recorder
/// thread samples, splits, encodes and writes for every job (sampler `i` takes the steps
/// that are multiples of `every[i]`). Each sample is the contact list copied at its step, so
/// the tables are the same as a serial recorder's, whatever the timing; the recorder fills
/// the cores the DEM leaves idle instead of stalling it. Returns the finished samplers (for
/// their histograms) and each job's busy seconds on the recorder thread.
fn record_period(
    sim: &mut Simulation,
    mut samplers: Vec<ContactSampler>,
    writers: &mut [RecordingWriter],
    every: &[u64],
    period_steps: u64,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<(Vec<ContactSampler>, Vec<f64>), RecordError> {
    type Sample = Vec<(u32, u32, f64)>;
    // every sampled step is a multiple of the stride; the DEM steps that far between checks
    let stride = every.iter().copied().fold(0, gcd);
    let (to_recorder, samples) = mpsc::sync_channel::<(u64, Sample)>(SAMPLES_IN_FLIGHT);
    let (to_dem, spare) = mpsc::channel::<Sample>();
    std::thread::scope(|scope| {
        let recorder = scope.spawn(
            move || -> Result<(Vec<ContactSampler>, Vec<f64>), FormatError> {
                let mut busy = vec![0.0; samplers.len()];
                for (step, contacts) in samples {
                    for (i, sampler) in samplers.iter_mut().enumerate() {
                        if step % every[i] == 0 {
                            let t = Instant::now();
                            sampler.sample(step, contacts.iter().copied());
                            writers[i].push_rows(sampler.drain_ready())?;
                            busy[i] += t.elapsed().as_secs_f64();
                        }
                    }
                    let _ = to_dem.send(contacts);
                }
                for (i, sampler) in samplers.iter_mut().enumerate() {
                    let t = Instant::now();
                    writers[i].push_rows(sampler.finish())?;
                    busy[i] += t.elapsed().as_secs_f64();
                }
                Ok((samplers, busy))
            },
        );
        let mut dem = || -> Result<(), RecordError> {
            let mut k = 0;
            while k < period_steps {
                // sample k is the contact list that conducted during DEM step k, from
                // t0 + k dt to t0 + (k+1) dt: the list the step has just computed
                sim.step();
                if every.iter().any(|e| k % e == 0) {
                    let mut contacts = spare.try_recv().unwrap_or_default();
                    contacts.clear();
                    contacts.extend(sim.touching_pairs().chain(sim.touching_walls()));
                    if to_recorder.send((k, contacts)).is_err() {
                        return Ok(()); // the recorder stopped: its error is reported below
                    }
                }
                for _ in 1..stride {
                    sim.step();
                }
                sim.check_inside()?;
                k += stride;
                if k % REPORT_EVERY < stride || k == period_steps {
                    progress(Phase::Period, k, period_steps);
                }
            }
            Ok(())
        };
        let dem_result = dem();
        drop(to_recorder);
        let recorded = recorder.join().expect("the recorder thread does not panic");
        dem_result?;
        Ok(recorded?)
    })
}

/// What a recording's info takes from the run at `t0`, whichever engine made it.
pub(crate) struct RunAtT0 {
    pub particles: u32,
    /// Largest particle radius (m): the span of the `sqrt(a)` codes.
    pub r_max: f64,
    pub walls: Vec<WallInfo>,
    /// Simulated time and step count at `t0`.
    pub t0: f64,
    pub step_t0: u64,
}

/// The walls of the case's drum as table bodies `particles + w`, with their fixed
/// temperature when they conduct.
pub(crate) fn wall_infos(walls: &WallSet, particles: u32) -> Vec<WallInfo> {
    let kinds = ["mantle", "cap_low", "cap_high"];
    (0..walls.len())
        .map(|w| WallInfo {
            id: particles + w as u32,
            kind: kinds.get(w).copied().unwrap_or("wall").into(),
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
