//! `tdex record` as a library call: run the case to `t0`, assign the temperatures, record one
//! period `τ` (sampled table + snapshots at `t0` and `t1`) and, optionally, K reference periods.

use super::checkpoint::{
    Checkpoint, CheckpointError, Elapsed, EngineState, OutputState, Restored, Stage,
};
use super::journal::{JournalError, JournalMark, RowJournal};
use super::{CollisionRow, ContactSampler};
use crate::case::Case;
use crate::format::Snapshot;
use crate::format::{
    AreaEncoding, FormatError, RecordingCosts, RecordingInfo, RecordingSummary, RecordingWriter,
    WallInfo, WallKind, FORMAT_VERSION, SQRT_AREA_CODES,
};
use crate::heat::ConductionLaw;
use crate::wall::WallSet;
use crate::{Simulation, SimulationError};
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// What to record, validated by the caller (the CLI plan).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordOptions {
    /// Sampling factor `n` (steps).
    pub sample_every: u32,
    /// `Δt_c^max` in steps, a positive multiple of `n`.
    pub dtc_max_steps: u32,
    /// `τ` in steps, a positive multiple of `n`.
    pub period_steps: u64,
    /// Reference periods after `t1`.
    pub reference_periods: u32,
    /// DEM twins: further runs continued from the state at `t1` over the reference periods,
    /// twin `m` with the drum's angular velocity changed by `m` units in the last place.
    pub twins: u32,
    pub area_encoding: AreaEncoding,
}

/// The stage a progress report belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    Settle,
    SpinUp,
    Period,
    Reference,
    /// The reference periods of DEM twin `m` (1-based), continued from `t1`.
    Twin(u32),
}

#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error(transparent)]
    Simulation(#[from] SimulationError),
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error("invalid recording settings: {0}")]
    Settings(String),
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(transparent)]
    Journal(#[from] JournalError),
}

impl RecordError {
    /// Whether the error is in a file the user gave (exit code 2): a checkpoint or its row
    /// journal that cannot be resumed.
    pub fn is_bad_input(&self) -> bool {
        match self {
            RecordError::Checkpoint(e) => e.is_bad_input(),
            RecordError::Journal(e) => {
                matches!(
                    e,
                    JournalError::Short { .. } | JournalError::Mismatch { .. }
                )
            }
            RecordError::Format(e) => e.is_bad_input(),
            _ => false,
        }
    }
}

/// Steps between progress reports, stability checks and checkpoint opportunities outside
/// the recorded period.
const REPORT_EVERY: u64 = 500;

/// A `tdex record` run: what to record, where, and how often to checkpoint it.
#[derive(Debug, Clone, Copy)]
pub struct RecordRun<'a> {
    pub case: &'a Case,
    /// The case path as the recording's metadata states it.
    pub case_path: &'a Path,
    /// The case file as given (the recording stores it).
    pub case_toml: &'a str,
    pub options: &'a RecordOptions,
    pub dest: &'a Path,
    /// Wall-clock seconds between checkpoints to [`checkpoint_path`]; `None`: no checkpoints.
    pub checkpoint_every: Option<f64>,
    /// Write the `tdex.costs` record (wall times, threads); without it the file depends only
    /// on the case, its seed and the options, resumed or not.
    pub write_costs: bool,
}

/// Where the checkpoints of a recording to `dest` go: `<dest>.checkpoint`.
pub fn checkpoint_path(dest: &Path) -> PathBuf {
    let mut name = dest.as_os_str().to_owned();
    name.push(".checkpoint");
    PathBuf::from(name)
}

/// The row journal kept beside a checkpoint: `<checkpoint>.rows`.
pub fn journal_path(checkpoint: &Path) -> PathBuf {
    let mut name = checkpoint.as_os_str().to_owned();
    name.push(".rows");
    PathBuf::from(name)
}

/// Runs the case and writes the recording to `dest`. `case_toml` is the case file as given.
pub fn record(
    case: &Case,
    case_path: &Path,
    case_toml: &str,
    opts: &RecordOptions,
    dest: &Path,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let run = RecordRun {
        case,
        case_path,
        case_toml,
        options: opts,
        dest,
        checkpoint_every: None,
        write_costs: true,
    };
    record_run(&run, progress)
}

/// Runs the case and writes the recording, checkpointing every `run.checkpoint_every`
/// seconds of wall time to [`checkpoint_path`]`(dest)`; the checkpoint and its row journal
/// are removed once the recording is in place.
pub fn record_run(
    run: &RecordRun,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let saver = match run.checkpoint_every {
        Some(every) => Some(Saver::new(run, &checkpoint_path(run.dest), every)?),
        None => None,
    };
    drive(run, saver, None, progress)
}

/// Resumes the run in which `checkpoint` (read from `path` by [`Checkpoint::read`], its
/// case from [`Checkpoint::case`]) was taken, writing further checkpoints to `path` every `every` seconds (default: as before).
/// The recording is the one the run would have written uninterrupted, to the byte, up to
/// the costs record (which adds the wall times of both runs).
pub fn resume(
    checkpoint: Checkpoint<'static>,
    case: &Case,
    path: &Path,
    every: Option<f64>,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let (case_toml, case_path) = (
        checkpoint.case_toml.clone().into_owned(),
        checkpoint.case_path.clone(),
    );
    let (options, dest) = (checkpoint.options.clone(), checkpoint.dest.clone());
    let run = RecordRun {
        case,
        case_path: &case_path,
        case_toml: &case_toml,
        options: &options,
        dest: &dest,
        checkpoint_every: Some(every.unwrap_or(checkpoint.every_seconds)),
        write_costs: checkpoint.write_costs,
    };
    let restored = checkpoint.restore(case, path)?;
    // temporary files of the killed run (its output, a checkpoint it was writing)
    crate::output::remove_stale_temps(&dest);
    crate::output::remove_stale_temps(path);
    let saver = Saver::new(&run, path, run.checkpoint_every.expect("set above"))?;
    drive(&run, Some(saver), Some(restored), progress)
}

fn check(opts: &RecordOptions) -> Result<ContactSampler, RecordError> {
    let every = opts.sample_every as u64;
    if every == 0 || opts.period_steps == 0 || opts.period_steps % every != 0 {
        return Err(RecordError::Settings(format!(
            "τ = {} steps must be a positive multiple of n = {every}",
            opts.period_steps
        )));
    }
    if opts.twins > crate::format::MAX_TWINS || (opts.twins > 0 && opts.reference_periods == 0) {
        return Err(RecordError::Settings(format!(
            "{} DEM twins with {} reference periods: twins run over the reference periods, so \
             they need at least one, and at most {} twins are recorded",
            opts.twins,
            opts.reference_periods,
            crate::format::MAX_TWINS
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
) -> Result<Simulation, RecordError> {
    let mut sim = Simulation::new(case)?;
    advance_to_t0(
        &mut sim,
        Stage::Settle { done: 0 },
        progress,
        &mut |_, _| Ok(()),
    )?;
    Ok(sim)
}

/// Settles and spins up from where `stage` stands (if it is before `t0`) and assigns the
/// initial temperatures; `checkpoint` is offered the state between blocks of steps.
/// Returns the stage reached: the start of the period.
fn advance_to_t0(
    sim: &mut Simulation,
    mut stage: Stage,
    progress: &mut dyn FnMut(Phase, u64, u64),
    checkpoint: &mut dyn FnMut(&Simulation, Stage) -> Result<(), RecordError>,
) -> Result<Stage, RecordError> {
    let time = &sim.case.time;
    let (n_settle, n_spin) = (
        sim.case.steps_in(time.settle),
        sim.case.steps_in(time.spin_up),
    );
    if let Stage::Settle { done } = stage {
        run_phase(
            sim,
            done,
            n_settle,
            &mut |d| progress(Phase::Settle, d, n_settle),
            &mut |sim, done| checkpoint(sim, Stage::Settle { done }),
        )?;
        sim.start_rotation();
        stage = Stage::SpinUp { done: 0 };
    }
    if let Stage::SpinUp { done } = stage {
        run_phase(
            sim,
            done,
            n_spin,
            &mut |d| progress(Phase::SpinUp, d, n_spin),
            &mut |sim, done| checkpoint(sim, Stage::SpinUp { done }),
        )?;
        sim.assign_temperatures();
        stage = Stage::Period { done: 0 };
    }
    Ok(stage)
}

/// Writes the checkpoints of one run.
struct Saver {
    path: PathBuf,
    journal: PathBuf,
    every: Duration,
    every_seconds: f64,
    last: Instant,
    /// The recording, absolute: a resume may start in another directory.
    dest: PathBuf,
}

impl Saver {
    fn new(run: &RecordRun, path: &Path, every_seconds: f64) -> Result<Self, RecordError> {
        let every = Duration::try_from_secs_f64(every_seconds)
            .ok()
            .filter(|_| every_seconds > 0.0)
            .ok_or_else(|| {
                RecordError::Settings(format!(
                    "checkpoint interval {every_seconds} s: give a number of seconds > 0"
                ))
            })?;
        let absolute = |p: &Path| {
            std::path::absolute(p).map_err(|error| {
                CheckpointError::from(crate::output::OutputError::writing(p, error))
            })
        };
        Ok(Self {
            path: absolute(path)?,
            journal: absolute(&journal_path(path))?,
            every,
            every_seconds,
            last: Instant::now(),
            dest: absolute(run.dest)?,
        })
    }

    fn due(&self) -> bool {
        self.last.elapsed() >= self.every
    }

    fn save(
        &mut self,
        run: &RecordRun,
        sim: &Simulation,
        stage: Stage,
        elapsed: Elapsed,
        output: Option<OutputState>,
    ) -> Result<(), RecordError> {
        let checkpoint = Checkpoint {
            tool_version: env!("CARGO_PKG_VERSION").into(),
            case_toml: Cow::Borrowed(run.case_toml),
            case_path: run.case_path.to_path_buf(),
            options: run.options.clone(),
            dest: self.dest.clone(),
            every_seconds: self.every_seconds,
            write_costs: run.write_costs,
            stage,
            elapsed,
            engine: EngineState::of(sim),
            output,
            header: String::new(),
        };
        let header = format!(
            "case {}, {}, t = {:.6} s; continue with: tdex record --resume {}",
            run.case.name,
            describe(stage, run),
            sim.time,
            self.path.display()
        );
        checkpoint.write(&self.path, &header)?;
        self.last = Instant::now();
        Ok(())
    }

    /// The run is complete: its checkpoint and journal are no longer needed.
    fn remove(self) {
        let _ = std::fs::remove_file(&self.path);
        let _ = std::fs::remove_file(&self.journal);
    }
}

/// Where a run stands, in words (the checkpoint's first line).
fn describe(stage: Stage, run: &RecordRun) -> String {
    let c = run.case;
    let o = run.options;
    match stage {
        Stage::Settle { done } => format!("settle step {done} of {}", c.steps_in(c.time.settle)),
        Stage::SpinUp { done } => format!("spin-up step {done} of {}", c.steps_in(c.time.spin_up)),
        Stage::Period { done } => format!("period step {done} of {}", o.period_steps),
        Stage::Reference { period, done } => format!(
            "reference period {} of {} step {done} of {}",
            period + 1,
            o.reference_periods,
            o.period_steps
        ),
        Stage::Twin { twin, period, done } => format!(
            "twin {twin} of {} reference period {} of {} step {done} of {}",
            o.twins,
            period + 1,
            o.reference_periods,
            o.period_steps
        ),
    }
}

/// Runs `total - done` more steps of a phase in blocks of [`REPORT_EVERY`] (counted from
/// the phase's start), checking stability and reporting after each block and offering a
/// checkpoint between blocks.
fn run_phase(
    sim: &mut Simulation,
    mut done: u64,
    total: u64,
    progress: &mut dyn FnMut(u64),
    checkpoint: &mut dyn FnMut(&Simulation, u64) -> Result<(), RecordError>,
) -> Result<(), RecordError> {
    while done < total {
        let block = (REPORT_EVERY - done % REPORT_EVERY).min(total - done);
        for _ in 0..block {
            sim.step();
        }
        done += block;
        sim.check_inside()?;
        progress(done);
        if done < total {
            checkpoint(sim, done)?;
        }
    }
    Ok(())
}

/// DEM twin `twin` (1-based) of the run standing at `t1`: the same state with the drum's
/// angular velocity changed by `twin` units in the last place. Granular flow is chaotic, so
/// this round-off change parts the twin from the DEM by particle diameters within a period
/// while leaving every law and setting the same: the twin is one more DEM run of the case.
pub fn twin_of(at_t1: &Simulation, twin: u32) -> Simulation {
    let mut sim = at_t1.clone();
    let omega = sim.walls.angular_velocity;
    sim.walls.angular_velocity = f64::from_bits(omega.to_bits() + twin as u64);
    sim
}

/// A twin that left the run bit for bit unchanged measures no spread: refused.
fn check_twin_differs(
    twin: u32,
    snapshot: &Snapshot,
    dem: Option<&Snapshot>,
) -> Result<(), RecordError> {
    let Some(dem) = dem else {
        return Ok(());
    };
    if dem.pos == snapshot.pos && dem.temp == snapshot.temp {
        return Err(RecordError::Settings(format!(
            "DEM twin {twin}: the drum's angular velocity changed by {twin} unit(s) in the last \
             place left the run identical to the DEM at t{}, bit for bit; a twin \
             that does not differ measures no spread (a drum that does not turn cannot be \
             perturbed this way): record without --twins",
            snapshot.index
        )));
    }
    Ok(())
}

/// The whole run from wherever it stands: settle, spin-up, the recorded period, the
/// reference periods, with checkpoints when `saver` is given.
fn drive(
    run: &RecordRun,
    mut saver: Option<Saver>,
    restored: Option<Restored>,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let fresh_sampler = check(run.options)?;
    let (case, opts) = (run.case, run.options);
    let (mut sim, mut stage, mut elapsed, output, mut at_t1) = match restored {
        Some(r) => (r.sim, r.stage, r.elapsed, r.output, r.t1),
        None => (
            Simulation::new(case)?,
            Stage::Settle { done: 0 },
            Elapsed::default(),
            None,
            None,
        ),
    };

    // to t0
    if matches!(stage, Stage::Settle { .. } | Stage::SpinUp { .. }) {
        let (began, base) = (Instant::now(), elapsed.to_t0);
        let to_t0 = |elapsed: &Elapsed| Elapsed {
            to_t0: base + began.elapsed().as_secs_f64(),
            ..*elapsed
        };
        stage = advance_to_t0(
            &mut sim,
            stage,
            progress,
            &mut |sim, stage| match &mut saver {
                Some(s) if s.due() => s.save(run, sim, stage, to_t0(&elapsed), None),
                _ => Ok(()),
            },
        )?;
        elapsed = to_t0(&elapsed);
    }

    // the output: opened at t0, or rebuilt to where the checkpoint left it
    let journal = saver.as_ref().map(|s| s.journal.clone());
    let (mut sink, sampler, mut snapshots, run_at_t0) = match output {
        None => {
            let run_at_t0 = RunAtT0::of(&sim);
            let info = recording_info(case, run.case_path, run.case_toml, opts, run_at_t0.clone());
            let mut writer = RecordingWriter::create(run.dest, info)?;
            let t0 = sim.snapshot(0);
            writer.write_snapshot(&t0)?;
            let journal = match &journal {
                Some(path) => Some(RowJournal::create(path)?),
                None => None,
            };
            (
                RowSink { writer, journal },
                fresh_sampler,
                vec![t0],
                run_at_t0,
            )
        }
        Some(out) => {
            let info = recording_info(case, run.case_path, run.case_toml, opts, out.run.clone());
            let mut writer = RecordingWriter::create(run.dest, info)?;
            writer.write_snapshot(&out.snapshots[0])?;
            let path = journal.as_ref().expect("a resumed run keeps checkpointing");
            let journal = RowJournal::resume(path, out.journal, &mut |rows| {
                Ok(writer.push_rows(rows.iter().copied())?)
            })?;
            // the run's own snapshots, then each twin's, in the order they were written
            let own = 2 + opts.reference_periods as usize;
            for (k, snapshot) in out.snapshots.iter().enumerate().skip(1) {
                match k.checked_sub(own) {
                    None => writer.write_snapshot(snapshot)?,
                    Some(past) => writer.write_twin_snapshot(
                        1 + (past / opts.reference_periods as usize) as u32,
                        snapshot,
                    )?,
                }
            }
            let sink = RowSink {
                writer,
                journal: Some(journal),
            };
            (
                sink,
                out.sampler.into_owned(),
                out.snapshots.into_owned(),
                out.run,
            )
        }
    };

    // the recorded period
    let mut sampler = sampler;
    if let Stage::Period { done } = stage {
        let began = Instant::now();
        let (period_base, recorder_base) = (elapsed.period, elapsed.recorder);
        let mut hook = PeriodSaver {
            run,
            saver: saver.as_mut(),
            run_at_t0: &run_at_t0,
            t0: &snapshots[0],
            elapsed,
            began,
        };
        let checkpoints: Option<&mut dyn PeriodCheckpoint> = match hook.saver {
            Some(_) => Some(&mut hook),
            None => None,
        };
        let (mut samplers, busy) = record_period(
            &mut sim,
            vec![sampler],
            std::slice::from_mut(&mut sink),
            &[opts.sample_every as u64],
            opts.period_steps,
            done,
            checkpoints,
            progress,
        )?;
        sampler = samplers.pop().expect("one sampler");
        let t = Instant::now();
        let t1 = sim.snapshot(1);
        sink.writer.write_snapshot(&t1)?;
        if opts.twins > 0 {
            at_t1 = Some(sim.clone());
        }
        // kept only for the checkpoints: a snapshot is 68 B a particle
        if saver.is_some() {
            snapshots.push(t1);
        }
        elapsed.recorder = recorder_base + busy[0] + t.elapsed().as_secs_f64();
        elapsed.period = period_base + began.elapsed().as_secs_f64();
        stage = Stage::Reference { period: 0, done: 0 };
    }

    // the reference periods, then the DEM twins, each from t1 over the same periods (the
    // run's own t2 is kept to check that the twins differ from it)
    let mut dem_t2: Option<Snapshot> = None;
    let mut main_stage_seconds = None;
    if matches!(stage, Stage::Reference { .. } | Stage::Twin { .. }) {
        let mut past_t1 = PastT1 {
            run,
            saver: saver.as_mut(),
            mark: match &mut sink.journal {
                Some(j) => Some(j.sync()?),
                None => None,
            },
            run_at_t0: &run_at_t0,
            sampler: &sampler,
            at_t1: at_t1.as_ref(),
            elapsed,
            began: Instant::now(),
        };
        if let Stage::Reference {
            period: first,
            done,
        } = stage
        {
            past_t1.periods(
                &mut sim,
                Continuation::Reference,
                (first, done),
                &mut snapshots,
                progress,
                &mut |period, snapshot| {
                    sink.writer.write_snapshot(snapshot)?;
                    if period == 0 && opts.twins > 0 {
                        dem_t2 = Some(snapshot.clone());
                    }
                    Ok(())
                },
            )?;
            past_t1.stage_done(Continuation::Reference);
            if let Some(t1) = &at_t1 {
                main_stage_seconds = Some(stage_seconds(&sim));
                sim = twin_of(t1, 1);
                stage = Stage::Twin {
                    twin: 1,
                    period: 0,
                    done: 0,
                };
            }
        }
        if let Stage::Twin {
            twin: first,
            period: first_period,
            done,
        } = stage
        {
            let t1 = at_t1.as_ref().ok_or_else(|| {
                RecordError::Settings("the twins' start at t1 is not in the checkpoint".into())
            })?;
            if dem_t2.is_none() {
                dem_t2 = snapshots.get(2).cloned();
            }
            for twin in first..=opts.twins {
                if twin != first {
                    sim = twin_of(t1, twin);
                }
                let from = if twin == first {
                    (first_period, done)
                } else {
                    (0, 0)
                };
                past_t1.periods(
                    &mut sim,
                    Continuation::Twin(twin),
                    from,
                    &mut snapshots,
                    progress,
                    &mut |period, snapshot| {
                        if period == 0 {
                            check_twin_differs(twin, snapshot, dem_t2.as_ref())?;
                        }
                        Ok(sink.writer.write_twin_snapshot(twin, snapshot)?)
                    },
                )?;
            }
            past_t1.stage_done(Continuation::Twin(first));
        }
        elapsed = past_t1.elapsed;
    }

    let costs = run.write_costs.then(|| RecordingCosts {
        seconds_to_t0: elapsed.to_t0,
        seconds_period: elapsed.period,
        seconds_reference: elapsed.reference,
        seconds_recorder: elapsed.recorder,
        seconds_twins: elapsed.twins,
        // the run's own stages; a run resumed among its twins has only the last twin's,
        // which carry the run's up to t1
        stage_seconds: main_stage_seconds.unwrap_or_else(|| stage_seconds(&sim)),
        threads: rayon::current_num_threads(),
    });
    let RowSink { writer, journal } = sink;
    drop(journal);
    let summary = writer.finish(sampler.duration_histogram().to_vec(), costs.as_ref())?;
    if let Some(s) = saver {
        s.remove();
    }
    Ok(summary)
}

/// A DEM run continued past `t1` over the reference periods: the run's own, or a twin's.
#[derive(Debug, Clone, Copy)]
enum Continuation {
    Reference,
    Twin(u32),
}

impl Continuation {
    fn stage(self, period: u32, done: u64) -> Stage {
        match self {
            Continuation::Reference => Stage::Reference { period, done },
            Continuation::Twin(twin) => Stage::Twin { twin, period, done },
        }
    }

    fn phase(self) -> Phase {
        match self {
            Continuation::Reference => Phase::Reference,
            Continuation::Twin(twin) => Phase::Twin(twin),
        }
    }
}

/// What the runs past `t1` need to checkpoint themselves: the output's state (fixed since
/// `t1`), the state at `t1` while twins are to come, and the wall time of the stage.
struct PastT1<'a> {
    run: &'a RecordRun<'a>,
    saver: Option<&'a mut Saver>,
    mark: Option<JournalMark>,
    run_at_t0: &'a RunAtT0,
    sampler: &'a ContactSampler,
    at_t1: Option<&'a Simulation>,
    /// Elapsed times when the stage (re)started.
    elapsed: Elapsed,
    began: Instant,
}

impl PastT1<'_> {
    /// The elapsed times with the stage of `which` counted to now.
    fn elapsed_now(&self, which: Continuation) -> Elapsed {
        let now = self.began.elapsed().as_secs_f64();
        match which {
            Continuation::Reference => Elapsed {
                reference: self.elapsed.reference + now,
                ..self.elapsed
            },
            Continuation::Twin(_) => Elapsed {
                twins: self.elapsed.twins + now,
                ..self.elapsed
            },
        }
    }

    /// The stage of `which` is over: its wall time is counted, the next stage's starts now.
    fn stage_done(&mut self, which: Continuation) {
        self.elapsed = self.elapsed_now(which);
        self.began = Instant::now();
    }

    /// Runs the reference periods of `which` from `(period, done)` on, offering checkpoints
    /// between blocks of steps; each period's snapshot goes to `stored` (its index is
    /// `period + 2`) and, when the run is checkpointed, into `snapshots`.
    fn periods(
        &mut self,
        sim: &mut Simulation,
        which: Continuation,
        (first, done): (u32, u64),
        snapshots: &mut Vec<Snapshot>,
        progress: &mut dyn FnMut(Phase, u64, u64),
        stored: &mut dyn FnMut(u32, &Snapshot) -> Result<(), RecordError>,
    ) -> Result<(), RecordError> {
        let opts = self.run.options;
        let total = opts.reference_periods as u64 * opts.period_steps;
        for period in first..opts.reference_periods {
            let start = if period == first { done } else { 0 };
            let offset = period as u64 * opts.period_steps;
            run_phase(
                sim,
                start,
                opts.period_steps,
                &mut |d| progress(which.phase(), offset + d, total),
                &mut |sim, done| {
                    let elapsed = self.elapsed_now(which);
                    let (Some(saver), Some(journal)) = (self.saver.as_deref_mut(), self.mark)
                    else {
                        return Ok(());
                    };
                    if !saver.due() {
                        return Ok(());
                    }
                    let output = OutputState {
                        run: self.run_at_t0.clone(),
                        snapshots: Cow::Borrowed(snapshots),
                        sampler: Cow::Borrowed(self.sampler),
                        journal,
                        t1_engine: self.at_t1.map(EngineState::of),
                    };
                    saver.save(
                        self.run,
                        sim,
                        which.stage(period, done),
                        elapsed,
                        Some(output),
                    )
                },
            )?;
            let snapshot = sim.snapshot(period + 2);
            stored(period, &snapshot)?;
            if self.saver.is_some() {
                snapshots.push(snapshot);
            }
        }
        Ok(())
    }
}

fn stage_seconds(sim: &Simulation) -> std::collections::BTreeMap<String, f64> {
    sim.counters
        .stages()
        .iter()
        .map(|(name, d)| (name.to_string(), d.as_secs_f64()))
        .collect()
}

/// The checkpoints of the recorded period: the engine from the DEM thread, the samplers and
/// journal marks from the recorder thread, the rest from the run.
struct PeriodSaver<'a> {
    run: &'a RecordRun<'a>,
    saver: Option<&'a mut Saver>,
    run_at_t0: &'a RunAtT0,
    t0: &'a Snapshot,
    /// Elapsed times when the period (re)started.
    elapsed: Elapsed,
    began: Instant,
}

impl PeriodCheckpoint for PeriodSaver<'_> {
    fn due(&self) -> bool {
        self.saver.as_ref().is_some_and(|s| s.due())
    }

    fn save(
        &mut self,
        sim: &Simulation,
        done: u64,
        recorder: RecorderState,
    ) -> Result<(), RecordError> {
        let Some(saver) = self.saver.as_deref_mut() else {
            return Ok(());
        };
        let (Some(sampler), Some(Some(journal))) =
            (recorder.samplers.first(), recorder.journals.first())
        else {
            return Ok(()); // only a single journaled recording is checkpointed
        };
        let output = OutputState {
            run: self.run_at_t0.clone(),
            snapshots: Cow::Borrowed(std::slice::from_ref(self.t0)),
            sampler: Cow::Borrowed(sampler),
            journal: *journal,
            t1_engine: None,
        };
        let elapsed = Elapsed {
            period: self.elapsed.period + self.began.elapsed().as_secs_f64(),
            recorder: self.elapsed.recorder + recorder.busy[0],
            ..self.elapsed
        };
        saver.save(self.run, sim, Stage::Period { done }, elapsed, Some(output))
    }
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
    if jobs.iter().any(|j| j.options.twins > 0) {
        return Err(RecordError::Settings(
            "DEM twins are recorded by a single recording (tdex record --twins), not by a \
             sweep of samplings"
                .into(),
        ));
    }
    let samplers = jobs
        .iter()
        .map(|j| check(&j.options))
        .collect::<Result<Vec<_>, _>>()?;
    let t0 = sim.snapshot(0);
    let mut sinks = Vec::with_capacity(jobs.len());
    for j in jobs {
        let info = recording_info(
            &sim.case,
            case_path,
            case_toml,
            &j.options,
            RunAtT0::of(sim),
        );
        let mut writer = RecordingWriter::create(j.dest, info)?;
        writer.write_snapshot(&t0)?;
        sinks.push(RowSink {
            writer,
            journal: None,
        });
    }

    let period_start = Instant::now();
    let every: Vec<u64> = jobs.iter().map(|j| j.options.sample_every as u64).collect();
    let (samplers, mut recorder_seconds) = record_period(
        sim,
        samplers,
        &mut sinks,
        &every,
        period_steps,
        0,
        None,
        progress,
    )?;
    let t1 = sim.snapshot(1);
    for (sink, busy) in sinks.iter_mut().zip(&mut recorder_seconds) {
        let t = Instant::now();
        sink.writer.write_snapshot(&t1)?;
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
        for sink in &mut sinks {
            sink.writer.write_snapshot(&snapshot)?;
        }
    }
    let seconds_reference = reference_start.elapsed().as_secs_f64();
    let stage_seconds = stage_seconds(sim);
    sinks
        .into_iter()
        .zip(samplers)
        .zip(recorder_seconds)
        .map(|((sink, sampler), seconds_recorder)| {
            let costs = RecordingCosts {
                seconds_to_t0,
                seconds_period,
                seconds_reference,
                seconds_recorder,
                seconds_twins: 0.0,
                stage_seconds: stage_seconds.clone(),
                threads: rayon::current_num_threads(),
            };
            Ok(sink
                .writer
                .finish(sampler.duration_histogram().to_vec(), Some(&costs))?)
        })
        .collect()
}

/// A recording's writer and, when the run is checkpointed, its row journal.
struct RowSink {
    writer: RecordingWriter,
    journal: Option<RowJournal>,
}

impl RowSink {
    fn push(&mut self, rows: Vec<CollisionRow>) -> Result<(), RecordError> {
        if let Some(journal) = &mut self.journal {
            journal.append(&rows)?;
        }
        Ok(self.writer.push_rows(rows)?)
    }
}

/// What the recorder thread hands over for a checkpoint: its samplers, the journal marks
/// (`None` for a recording without journal) and each job's busy seconds so far.
pub(crate) struct RecorderState {
    samplers: Vec<ContactSampler>,
    journals: Vec<Option<JournalMark>>,
    busy: Vec<f64>,
}

/// How the period loop offers checkpoints: asked between steps whether one is due, then
/// given the engine and the recorder's state, consistent at step `done`.
pub(crate) trait PeriodCheckpoint {
    fn due(&self) -> bool;
    fn save(
        &mut self,
        sim: &Simulation,
        done: u64,
        recorder: RecorderState,
    ) -> Result<(), RecordError>;
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

type Sample = Vec<(u32, u32, f64)>;

/// What the DEM thread sends the recorder thread.
enum ToRecorder {
    /// The contact list at step `k` of the period.
    Sample(u64, Sample),
    /// Everything sent before has been recorded: reply with the state for a checkpoint.
    Checkpoint(mpsc::Sender<RecorderState>),
}

/// The period `[t0, t1]` from step `start` on: the DEM steps on the calling thread (and its
/// pool) while a recorder thread samples, splits, encodes and writes for every job (sampler
/// `i` takes the steps that are multiples of `every[i]`). Each sample is the contact list
/// copied at its step, so the tables are the same as a serial recorder's, whatever the
/// timing; the recorder fills the cores the DEM leaves idle instead of stalling it. Between
/// steps, `checkpoints` is offered the state when one is due. Returns the finished samplers
/// (for their histograms) and each job's busy seconds on the recorder thread.
#[allow(clippy::too_many_arguments)]
fn record_period(
    sim: &mut Simulation,
    mut samplers: Vec<ContactSampler>,
    sinks: &mut [RowSink],
    every: &[u64],
    period_steps: u64,
    start: u64,
    mut checkpoints: Option<&mut dyn PeriodCheckpoint>,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<(Vec<ContactSampler>, Vec<f64>), RecordError> {
    // every sampled step is a multiple of the stride; the DEM steps that far between checks
    let stride = every.iter().copied().fold(0, gcd);
    let (to_recorder, messages) = mpsc::sync_channel::<ToRecorder>(SAMPLES_IN_FLIGHT);
    let (to_dem, spare) = mpsc::channel::<Sample>();
    std::thread::scope(|scope| {
        let recorder = scope.spawn(
            move || -> Result<(Vec<ContactSampler>, Vec<f64>), RecordError> {
                let mut busy = vec![0.0; samplers.len()];
                for message in messages {
                    let (step, contacts) = match message {
                        ToRecorder::Sample(step, contacts) => (step, contacts),
                        ToRecorder::Checkpoint(reply) => {
                            let journals = sinks
                                .iter_mut()
                                .map(|s| s.journal.as_mut().map(|j| j.sync()).transpose())
                                .collect::<Result<Vec<_>, _>>()?;
                            let _ = reply.send(RecorderState {
                                samplers: samplers.clone(),
                                journals,
                                busy: busy.clone(),
                            });
                            continue;
                        }
                    };
                    for (i, sampler) in samplers.iter_mut().enumerate() {
                        if step % every[i] == 0 {
                            let t = Instant::now();
                            sampler.sample(step, contacts.iter().copied());
                            sinks[i].push(sampler.drain_ready())?;
                            busy[i] += t.elapsed().as_secs_f64();
                        }
                    }
                    let _ = to_dem.send(contacts);
                }
                for (i, sampler) in samplers.iter_mut().enumerate() {
                    let t = Instant::now();
                    sinks[i].push(sampler.finish())?;
                    busy[i] += t.elapsed().as_secs_f64();
                }
                Ok((samplers, busy))
            },
        );
        let mut dem = || -> Result<(), RecordError> {
            let mut k = start;
            while k < period_steps {
                // sample k is the contact list that conducted during DEM step k, from
                // t0 + k dt to t0 + (k+1) dt: the list the step has just computed
                sim.step();
                if every.iter().any(|e| k % e == 0) {
                    let mut contacts = spare.try_recv().unwrap_or_default();
                    contacts.clear();
                    contacts.extend(sim.touching_pairs().chain(sim.touching_walls()));
                    if to_recorder.send(ToRecorder::Sample(k, contacts)).is_err() {
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
                if let Some(c) = checkpoints.as_deref_mut() {
                    if k < period_steps && c.due() {
                        let (reply, state) = mpsc::channel();
                        if to_recorder.send(ToRecorder::Checkpoint(reply)).is_err() {
                            return Ok(());
                        }
                        let Ok(state) = state.recv() else {
                            return Ok(()); // the recorder stopped: its error is reported below
                        };
                        c.save(sim, k, state)?;
                    }
                }
            }
            Ok(())
        };
        let dem_result = dem();
        drop(to_recorder);
        let recorded = recorder.join().expect("the recorder thread does not panic");
        dem_result?;
        recorded
    })
}

/// What a recording's info takes from the run at `t0`, whichever engine made it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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
    fn of(sim: &Simulation) -> Self {
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
