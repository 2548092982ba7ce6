//! The recorder's driver: runs a case to `t0`, records the periods `[t0, t1]` … `[t(P-1),
//! tP]`, the reference periods and the DEM twins into one recording (checkpointed when asked)
//! or into several samplings of one run; the entry points of `tdex record` and of the studies.

use super::checkpoint::{
    checkpoint_path, Checkpoint, CheckpointError, EngineState, OutputState, Restored, Stage,
};
use super::error::RecordError;
use super::journal::{JournalMark, RowJournal};
use super::metadata::{recording_info, stage_seconds, Elapsed, RunAtT0};
use super::options::{Phase, RecordJob, RecordOptions, RecordRun, REPORT_EVERY};
use super::period::{record_period, PeriodCheckpoint, RecordedPeriod, RecorderState, RowSink};
use super::saver::Saver;
use super::ContactSampler;
use crate::case::Case;
use crate::Simulation;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;
use tdex_format::{RecordingSummary, RecordingWriter, Snapshot};

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
    drive_one(run, Start::Case(run.case), saver, progress)
}

/// Resumes the run in which `checkpoint` (read from `path` by [`Checkpoint::read`], its
/// case from [`Checkpoint::case`]) was taken, writing further checkpoints to `path` every
/// `every` seconds (default: as before). The recording is the one the run would have
/// written uninterrupted, to the byte, up to the costs record (which adds the wall times of
/// both runs).
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
    tdex_format::output::remove_stale_temps(&dest);
    tdex_format::output::remove_stale_temps(path);
    let saver = Saver::new(&run, path, run.checkpoint_every.expect("set above"))?;
    let start = Start::Restored(Box::new(restored));
    drive_one(&run, start, Some(saver), progress)
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

/// Records the periods from `t0` of a simulation standing there (and the reference periods)
/// into `dest`.
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

/// Records several samplings of one DEM run: the simulation standing at `t0` is stepped
/// once through the recorded and the reference periods, and every job's sampler is fed the
/// contact list at its own steps (`k` a multiple of its `n`). Sampling only reads the state,
/// so each file holds the table and snapshots that a run with its options alone would write;
/// only the costs differ: `seconds_period` is the recorded periods' wall time (shared) and
/// `seconds_recorder` the job's own sampler, splitter and writer time. Jobs must share
/// `period_steps`, `recorded_periods` and `reference_periods`; DEM twins are recorded by
/// [`record_run`] alone.
pub fn record_many_from_t0(
    sim: &mut Simulation,
    case_path: &Path,
    case_toml: &str,
    jobs: &[RecordJob],
    seconds_to_t0: f64,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<Vec<RecordingSummary>, RecordError> {
    let shared = |j: &RecordJob| {
        let o = &j.options;
        (o.period_steps, o.recorded_periods, o.reference_periods)
    };
    if jobs.windows(2).any(|w| shared(&w[0]) != shared(&w[1])) {
        return Err(RecordError::Settings(
            "the recordings of one run must share τ, the recorded periods and the reference              periods"
                .into(),
        ));
    }
    if jobs.iter().any(|j| j.options.twins > 0) {
        return Err(RecordError::Settings(
            "DEM twins are recorded by a single recording run from the case's start, not by \
             recordings from a state at t0"
                .into(),
        ));
    }
    let dem = DemRun {
        case_path,
        case_toml,
        jobs,
        write_costs: true,
    };
    let start = Start::AtT0 { sim, seconds_to_t0 };
    drive(&dem, start, None, progress)
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

/// The recordings one DEM run feeds: one when the run is checkpointed or has DEM twins,
/// several samplings of the same run otherwise. The case is the simulation's.
struct DemRun<'a> {
    case_path: &'a Path,
    case_toml: &'a str,
    jobs: &'a [RecordJob<'a>],
    write_costs: bool,
}

/// Where the driver takes a run up.
enum Start<'s> {
    /// The first step of the case.
    Case(&'s Case),
    /// A simulation standing at `t0` (temperatures assigned), `seconds_to_t0` of wall time
    /// after the case's first step.
    AtT0 {
        sim: &'s mut Simulation,
        seconds_to_t0: f64,
    },
    /// A checkpoint's state.
    Restored(Box<Restored>),
}

/// [`drive`] for the single recording of `run`.
fn drive_one(
    run: &RecordRun,
    start: Start,
    saver: Option<Saver>,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<RecordingSummary, RecordError> {
    let job = RecordJob {
        options: run.options.clone(),
        dest: run.dest,
    };
    let dem = DemRun {
        case_path: run.case_path,
        case_toml: run.case_toml,
        jobs: std::slice::from_ref(&job),
        write_costs: run.write_costs,
    };
    let mut summaries = drive(&dem, start, saver, progress)?;
    Ok(summaries.pop().expect("one summary per job"))
}

/// The sampler of a recording with `opts`, once the options are checked.
fn check(opts: &RecordOptions) -> Result<ContactSampler, RecordError> {
    let every = opts.sample_every as u64;
    if every == 0 || opts.period_steps == 0 || !opts.period_steps.is_multiple_of(every) {
        return Err(RecordError::Settings(format!(
            "τ = {} steps must be a positive multiple of n = {every}",
            opts.period_steps
        )));
    }
    let most = tdex_format::MAX_RECORDED_PERIODS;
    if !(1..=most).contains(&opts.recorded_periods) {
        return Err(RecordError::Settings(format!(
            "{} recorded periods: between 1 and {most} are recorded",
            opts.recorded_periods
        )));
    }
    if opts.twins > tdex_format::MAX_TWINS || (opts.twins > 0 && opts.reference_periods == 0) {
        return Err(RecordError::Settings(format!(
            "{} DEM twins with {} reference periods: twins run over the reference periods, so \
             they need at least one, and at most {} twins are recorded",
            opts.twins,
            opts.reference_periods,
            tdex_format::MAX_TWINS
        )));
    }
    let latest = tdex_format::latest_twins_parting(
        opts.recorded_periods,
        opts.reference_periods,
        opts.twins,
    );
    if !(1..=latest).contains(&opts.twins_from) {
        return Err(RecordError::Settings(format!(
            "twins parting at t{}: DEM twins part from the run at a recorded snapshot, t1 to \
             t{latest} here ({} recorded, {} reference periods), and at t1 without twins",
            opts.twins_from, opts.recorded_periods, opts.reference_periods
        )));
    }
    ContactSampler::new(opts.sample_every, opts.dtc_max_steps).ok_or_else(|| {
        RecordError::Settings(format!(
            "Δt_c^max = {} steps must be a positive multiple of n = {}",
            opts.dtc_max_steps, opts.sample_every
        ))
    })
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
        stage = Stage::Period { period: 0, done: 0 };
    }
    Ok(stage)
}

/// Runs `total - done` more steps of a phase in blocks of [`REPORT_EVERY`] (counted from
/// the phase's start), checking stability and reporting after each block and offering a
/// checkpoint between blocks. It reports once before its first step too, where it starts
/// (0, or mid-way after a resume), so that a progress log knows a phase's start exactly.
fn run_phase(
    sim: &mut Simulation,
    mut done: u64,
    total: u64,
    progress: &mut dyn FnMut(u64),
    checkpoint: &mut dyn FnMut(&Simulation, u64) -> Result<(), RecordError>,
) -> Result<(), RecordError> {
    if done < total {
        progress(done);
    }
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
        return Err(RecordError::TwinIdentical {
            twin,
            snapshot: snapshot.index,
        });
    }
    Ok(())
}

/// The whole run from wherever it stands: settle, spin-up, the recorded periods, the
/// reference periods after them, the DEM twins, with checkpoints when `saver` is given (a run with one
/// recording). Returns each recording's summary, in the order of the jobs. A resumed run
/// takes the fresh run's path: each stage starts where the checkpoint left it.
fn drive(
    dem: &DemRun,
    start: Start,
    saver: Option<Saver>,
    progress: &mut dyn FnMut(Phase, u64, u64),
) -> Result<Vec<RecordingSummary>, RecordError> {
    let fresh_samplers = dem
        .jobs
        .iter()
        .map(|j| check(&j.options))
        .collect::<Result<Vec<_>, _>>()?;
    // what the recordings share: τ, the recorded and reference periods and the twins
    let Some(opts) = dem.jobs.first().map(|j| &j.options) else {
        return Ok(Vec::new());
    };
    let mut own_sim;
    let (sim, mut run, output) = match start {
        Start::Case(case) => {
            own_sim = Simulation::new(case)?;
            let run = RunState::new(Stage::Settle { done: 0 }, Elapsed::default(), None, saver);
            (&mut own_sim, run, None)
        }
        Start::AtT0 { sim, seconds_to_t0 } => {
            let elapsed = Elapsed {
                to_t0: seconds_to_t0,
                ..Elapsed::default()
            };
            let stage = Stage::Period { period: 0, done: 0 };
            (sim, RunState::new(stage, elapsed, None, saver), None)
        }
        Start::Restored(r) => {
            let r = *r;
            own_sim = r.sim;
            let run = RunState::new(r.stage, r.elapsed, r.t1, saver);
            (&mut own_sim, run, r.output)
        }
    };
    run.settle_and_spin_up(sim, progress)?;
    let mut outputs = match output {
        None => Outputs::open(dem, sim, fresh_samplers, &run)?,
        Some(out) => Outputs::reopen(dem, opts, sim, out, &run)?,
    };
    let mut parting = Parting::of(opts, &outputs.snapshots);
    run.recorded_periods(sim, dem, opts, &mut outputs, &mut parting, progress)?;
    let main_stage_seconds = run.past_t1(sim, opts, &mut outputs, &mut parting, progress)?;
    run.finish(dem, sim, outputs, main_stage_seconds)
}

/// Where a run stands between its stages: the stage it has reached, its wall times so far,
/// the engine at the twins' start (kept from `t_s` while DEM twins are to come) and the
/// writer of its checkpoints.
struct RunState<'s> {
    stage: Stage,
    elapsed: Elapsed,
    at_t1: Option<Simulation>,
    saver: Option<Saver<'s>>,
}

/// What a run has written so far: each recording's sink and sampler, and what its
/// checkpoints carry.
struct Outputs {
    sinks: Vec<RowSink>,
    samplers: Vec<ContactSampler>,
    /// `t0` and every snapshot since, kept only while the run is checkpointed (a snapshot is
    /// 68 B a particle); `t0` alone otherwise.
    snapshots: Vec<Snapshot>,
    run_at_t0: RunAtT0,
    /// Each recording's own recorder seconds; a checkpointed run has one recording, whose
    /// seconds [`Elapsed::recorder`] carries.
    recorder_seconds: Vec<f64>,
}

/// The run's snapshots the DEM twins need. Twins part from the run at `t_s` (`s` =
/// `twins_from`, a recorded snapshot): until there a twin is the run, so its snapshots
/// `t2 … t_s` are the run's (kept here), and its first own one, `t_(s+1)`, is checked
/// against the run's.
struct Parting {
    at: u32,
    with_twins: bool,
    before: Vec<Snapshot>,
    dem_next: Option<Snapshot>,
}

impl Parting {
    /// What the snapshots a run has written (`t0` on, the run's own first) tell.
    fn of(opts: &RecordOptions, snapshots: &[Snapshot]) -> Parting {
        let own = opts.last_snapshot() as usize + 1;
        let mut parting = Parting {
            at: opts.twins_from,
            with_twins: opts.twins > 0,
            before: Vec::new(),
            dem_next: None,
        };
        for snapshot in snapshots.iter().take(own) {
            parting.note(snapshot);
        }
        parting
    }

    /// The run's snapshot `t_k`, just written (recorded or reference): kept if the twins need
    /// it.
    fn note(&mut self, snapshot: &Snapshot) {
        if !self.with_twins {
            return;
        }
        if (2..=self.at).contains(&snapshot.index) {
            self.before.push(snapshot.clone());
        }
        if snapshot.index == self.at + 1 {
            self.dem_next = Some(snapshot.clone());
        }
    }
}

impl Outputs {
    /// The outputs of a run at `t0`: each recording created with its first snapshot.
    fn open(
        dem: &DemRun,
        sim: &Simulation,
        samplers: Vec<ContactSampler>,
        run: &RunState,
    ) -> Result<Outputs, RecordError> {
        let journal = run.saver.as_ref().map(|s| &s.journal);
        let run_at_t0 = RunAtT0::of(sim);
        let t0 = sim.snapshot(0);
        let mut sinks = Vec::with_capacity(dem.jobs.len());
        for job in dem.jobs {
            let info = recording_info(
                &sim.case,
                dem.case_path,
                dem.case_toml,
                &job.options,
                run_at_t0.clone(),
            );
            let mut writer = RecordingWriter::create(job.dest, info)?;
            writer.write_snapshot(&t0)?;
            let journal = match journal {
                Some(path) => Some(RowJournal::create(path)?),
                None => None,
            };
            sinks.push(RowSink { writer, journal });
        }
        Ok(Outputs {
            recorder_seconds: vec![run.elapsed.recorder; sinks.len()],
            sinks,
            samplers,
            snapshots: vec![t0],
            run_at_t0,
        })
    }

    /// The output of a checkpointed run rebuilt to where the checkpoint left it: the rows
    /// of its journal and its snapshots written again in the order the run wrote them.
    fn reopen(
        dem: &DemRun,
        opts: &RecordOptions,
        sim: &Simulation,
        out: OutputState<'static>,
        run: &RunState,
    ) -> Result<Outputs, RecordError> {
        let saver = run
            .saver
            .as_ref()
            .expect("a resumed run keeps checkpointing");
        let info = recording_info(
            &sim.case,
            dem.case_path,
            dem.case_toml,
            opts,
            out.run.clone(),
        );
        let mut writer = RecordingWriter::create(dem.jobs[0].dest, info)?;
        writer.write_snapshot(&out.snapshots[0])?;
        // a snapshot closes the chunk before it: t_k after the rows of period k - 1, before
        // the first row of a later period
        let mut next = 1;
        let journal = RowJournal::resume(&saver.journal, out.journal, &mut |mut rows| {
            while let Some(first) = rows.first() {
                let period = first.start_step / opts.period_steps;
                while next as u64 <= period {
                    let snapshot =
                        out.snapshots
                            .get(next)
                            .ok_or_else(|| CheckpointError::Inconsistent {
                                path: saver.path(),
                                detail: format!(
                                    "its row journal holds rows of recorded period {period}, its \
                                     snapshots end at t{}",
                                    next - 1
                                ),
                            })?;
                    writer.write_snapshot(snapshot)?;
                    next += 1;
                }
                let same = rows
                    .iter()
                    .position(|r| r.start_step / opts.period_steps != period)
                    .unwrap_or(rows.len());
                writer.push_rows(rows[..same].iter().copied())?;
                rows = &rows[same..];
            }
            Ok::<_, RecordError>(())
        })?;
        // the run's own snapshots left, then each twin's, in the order they were written
        let own = opts.last_snapshot() as usize + 1;
        for (k, snapshot) in out.snapshots.iter().enumerate().skip(next) {
            match k.checked_sub(own) {
                None => writer.write_snapshot(snapshot)?,
                Some(past) => writer.write_twin_snapshot(
                    1 + (past / opts.reference_periods as usize) as u32,
                    snapshot,
                )?,
            }
        }
        Ok(Outputs {
            sinks: vec![RowSink {
                writer,
                journal: Some(journal),
            }],
            samplers: vec![out.sampler.into_owned()],
            snapshots: out.snapshots.into_owned(),
            run_at_t0: out.run,
            recorder_seconds: vec![run.elapsed.recorder],
        })
    }
}

impl<'s> RunState<'s> {
    fn new(
        stage: Stage,
        elapsed: Elapsed,
        at_t1: Option<Simulation>,
        saver: Option<Saver<'s>>,
    ) -> RunState<'s> {
        RunState {
            stage,
            elapsed,
            at_t1,
            saver,
        }
    }

    /// Settles and spins up to `t0`, if the run stands before it.
    fn settle_and_spin_up(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(Phase, u64, u64),
    ) -> Result<(), RecordError> {
        if !matches!(self.stage, Stage::Settle { .. } | Stage::SpinUp { .. }) {
            return Ok(());
        }
        let (began, base) = (Instant::now(), self.elapsed.to_t0);
        let to_t0 = |elapsed: &Elapsed| Elapsed {
            to_t0: base + began.elapsed().as_secs_f64(),
            ..elapsed.clone()
        };
        let (saver, elapsed) = (&mut self.saver, &self.elapsed);
        let stage = advance_to_t0(sim, self.stage, progress, &mut |sim, stage| match saver {
            Some(s) if s.due() => s.save(sim, stage, to_t0(elapsed), None),
            _ => Ok(()),
        })?;
        self.stage = stage;
        self.elapsed = to_t0(&self.elapsed);
        Ok(())
    }

    /// The recorded periods, one after the other, from where the run stands among them:
    /// the samplers are cut at each boundary, each period's snapshot closes its rows.
    fn recorded_periods(
        &mut self,
        sim: &mut Simulation,
        dem: &DemRun,
        opts: &RecordOptions,
        outputs: &mut Outputs,
        parting: &mut Parting,
        progress: &mut dyn FnMut(Phase, u64, u64),
    ) -> Result<(), RecordError> {
        let Stage::Period {
            period: first,
            done,
        } = self.stage
        else {
            return Ok(());
        };
        let recorded = opts.recorded_periods;
        let every: Vec<u64> = dem
            .jobs
            .iter()
            .map(|j| j.options.sample_every as u64)
            .collect();
        self.elapsed.each_period.resize(recorded as usize, 0.0);
        for index in first..recorded {
            let began = Instant::now();
            let mut hook = PeriodSaver {
                saver: self.saver.as_mut(),
                run_at_t0: &outputs.run_at_t0,
                snapshots: &outputs.snapshots,
                at_t1: self.at_t1.as_ref(),
                period: index,
                elapsed: self.elapsed.clone(),
                began,
            };
            let checkpoints: Option<&mut dyn PeriodCheckpoint> = match hook.saver {
                Some(_) => Some(&mut hook),
                None => None,
            };
            let period = RecordedPeriod {
                index,
                count: recorded,
                steps: opts.period_steps,
            };
            let start = if index == first { done } else { 0 };
            let (samplers, busy) = record_period(
                sim,
                std::mem::take(&mut outputs.samplers),
                &mut outputs.sinks,
                &every,
                period,
                start,
                checkpoints,
                progress,
            )?;
            outputs.samplers = samplers;
            let snapshot = sim.snapshot(index + 1);
            let seconds = outputs.recorder_seconds.iter_mut();
            for ((sink, seconds), busy) in outputs.sinks.iter_mut().zip(seconds).zip(busy) {
                let t = Instant::now();
                sink.writer.write_snapshot(&snapshot)?;
                *seconds += busy + t.elapsed().as_secs_f64();
            }
            if index + 1 == parting.at && parting.with_twins {
                self.at_t1 = Some(sim.clone());
            }
            parting.note(&snapshot);
            if self.saver.is_some() {
                outputs.snapshots.push(snapshot);
            }
            self.elapsed.recorder = outputs.recorder_seconds[0];
            let seconds = began.elapsed().as_secs_f64();
            self.elapsed.period += seconds;
            self.elapsed.each_period[index as usize] += seconds;
        }
        // the reference periods go on after tP (those up to tP are recorded ones)
        self.stage = Stage::Reference {
            period: recorded - 1,
            done: 0,
        };
        Ok(())
    }

    /// The reference periods, then the DEM twins, each from `t_s` over the same periods,
    /// from where the run stands among them. Returns the run's own stage times when the
    /// engine was replaced by a twin's.
    fn past_t1(
        &mut self,
        sim: &mut Simulation,
        opts: &RecordOptions,
        outputs: &mut Outputs,
        parting: &mut Parting,
        progress: &mut dyn FnMut(Phase, u64, u64),
    ) -> Result<Option<BTreeMap<String, f64>>, RecordError> {
        if !matches!(self.stage, Stage::Reference { .. } | Stage::Twin { .. }) {
            return Ok(None);
        }
        let mut main_stage_seconds = None;
        let mark = match outputs.sinks.first_mut().and_then(|s| s.journal.as_mut()) {
            Some(j) => Some(j.sync()?),
            None => None,
        };
        let mut past_t1 = PastT1 {
            opts,
            saver: self.saver.as_mut(),
            mark,
            run_at_t0: &outputs.run_at_t0,
            sampler: &outputs.samplers[0],
            at_t1: self.at_t1.as_ref(),
            elapsed: self.elapsed.clone(),
            began: Instant::now(),
        };
        let mut written = Written {
            sinks: &mut outputs.sinks,
            snapshots: &mut outputs.snapshots,
        };
        if let Stage::Reference { period, done } = self.stage {
            past_t1.reference(sim, (period, done), &mut written, parting, progress)?;
            if let Some(t1) = past_t1.at_t1 {
                main_stage_seconds = Some(stage_seconds(sim));
                *sim = twin_of(t1, 1);
                self.stage = Stage::Twin {
                    twin: 1,
                    period: 0,
                    done: 0,
                };
            }
        }
        if let Stage::Twin { twin, period, done } = self.stage {
            let from = (twin, period, done);
            past_t1.twins(sim, from, &mut written, parting, progress)?;
        }
        self.elapsed = past_t1.elapsed;
        Ok(main_stage_seconds)
    }

    /// Closes every recording with its summary and (when asked) its costs; removes the
    /// checkpoint, no longer needed. The run's own stage times are `main_stage_seconds`
    /// when a twin replaced its engine; a run resumed among its twins has only the last
    /// twin's, which carry the run's up to `t_s`.
    fn finish(
        self,
        dem: &DemRun,
        sim: &Simulation,
        outputs: Outputs,
        main_stage_seconds: Option<BTreeMap<String, f64>>,
    ) -> Result<Vec<RecordingSummary>, RecordError> {
        let stage_seconds = main_stage_seconds.unwrap_or_else(|| stage_seconds(sim));
        let summaries = outputs
            .sinks
            .into_iter()
            .zip(outputs.samplers)
            .zip(outputs.recorder_seconds)
            .map(|((sink, sampler), recorder)| {
                let costs = dem.write_costs.then(|| {
                    Elapsed {
                        recorder,
                        ..self.elapsed.clone()
                    }
                    .costs(stage_seconds.clone())
                });
                let RowSink { writer, journal } = sink;
                drop(journal);
                Ok(writer.finish(sampler.duration_histogram().to_vec(), costs.as_ref())?)
            })
            .collect::<Result<Vec<_>, RecordError>>()?;
        if let Some(s) = self.saver {
            s.remove();
        }
        Ok(summaries)
    }
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
struct PastT1<'a, 's> {
    /// What the recordings share: τ, the recorded and the reference periods.
    opts: &'a RecordOptions,
    saver: Option<&'a mut Saver<'s>>,
    mark: Option<JournalMark>,
    run_at_t0: &'a RunAtT0,
    sampler: &'a ContactSampler,
    at_t1: Option<&'a Simulation>,
    /// Elapsed times when the stage (re)started.
    elapsed: Elapsed,
    began: Instant,
}

/// Where the runs past `t1` write: every recording's sink, and the snapshots a checkpoint
/// carries.
struct Written<'o> {
    sinks: &'o mut [RowSink],
    snapshots: &'o mut Vec<Snapshot>,
}

impl PastT1<'_, '_> {
    /// The run's own reference periods from `from` (period, steps done) on; each snapshot
    /// is noted in `parting`, for the twins.
    fn reference(
        &mut self,
        sim: &mut Simulation,
        from: (u32, u64),
        written: &mut Written,
        parting: &mut Parting,
        progress: &mut dyn FnMut(Phase, u64, u64),
    ) -> Result<(), RecordError> {
        let sinks = &mut *written.sinks;
        self.periods(
            sim,
            Continuation::Reference,
            from,
            written.snapshots,
            progress,
            &mut |_, snapshot| {
                for sink in sinks.iter_mut() {
                    sink.writer.write_snapshot(snapshot)?;
                }
                parting.note(snapshot);
                Ok(())
            },
        )?;
        self.stage_done(Continuation::Reference);
        Ok(())
    }

    /// The DEM twins from `from` (twin, period, steps done) on, each from the engine at
    /// `t_s`; a twin's first own snapshot must differ from the run's (`parting`).
    fn twins(
        &mut self,
        sim: &mut Simulation,
        (first, first_period, done): (u32, u32, u64),
        written: &mut Written,
        parting: &Parting,
        progress: &mut dyn FnMut(Phase, u64, u64),
    ) -> Result<(), RecordError> {
        let t1 = self.at_t1.ok_or_else(|| {
            RecordError::Settings("the twins' start at t1 is not in the checkpoint".into())
        })?;
        for twin in first..=self.opts.twins {
            if twin != first {
                *sim = twin_of(t1, twin);
            }
            let mut from = if twin == first {
                (first_period, done)
            } else {
                (0, 0)
            };
            // before it parts the twin is the run: the run's snapshots t2 … t_s, stored
            // as the twin's so that every run holds t2 … t(K+1)
            if from.0 + 1 < parting.at {
                for snapshot in &parting.before[from.0 as usize..] {
                    for sink in written.sinks.iter_mut() {
                        sink.writer.write_twin_snapshot(twin, snapshot)?;
                    }
                    if self.saver.is_some() {
                        written.snapshots.push(snapshot.clone());
                    }
                }
                from = (parting.at - 1, 0);
            }
            let sinks = &mut *written.sinks;
            self.periods(
                sim,
                Continuation::Twin(twin),
                from,
                written.snapshots,
                progress,
                &mut |period, snapshot| {
                    if period + 1 == parting.at {
                        check_twin_differs(twin, snapshot, parting.dem_next.as_ref())?;
                    }
                    for sink in sinks.iter_mut() {
                        sink.writer.write_twin_snapshot(twin, snapshot)?;
                    }
                    Ok(())
                },
            )?;
        }
        self.stage_done(Continuation::Twin(first));
        Ok(())
    }

    /// The elapsed times with the stage of `which` counted to now.
    fn elapsed_now(&self, which: Continuation) -> Elapsed {
        let now = self.began.elapsed().as_secs_f64();
        match which {
            Continuation::Reference => Elapsed {
                reference: self.elapsed.reference + now,
                ..self.elapsed.clone()
            },
            Continuation::Twin(_) => Elapsed {
                twins: self.elapsed.twins + now,
                ..self.elapsed.clone()
            },
        }
    }

    /// The stage of `which` is over: its wall time is counted, the next stage's starts now.
    fn stage_done(&mut self, which: Continuation) {
        self.elapsed = self.elapsed_now(which);
        self.began = Instant::now();
    }

    /// Runs the reference periods of `which` from `(period, done)` on (none when the recorded
    /// periods reach past them), offering checkpoints
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
        let opts = self.opts;
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
                    saver.save(sim, which.stage(period, done), elapsed, Some(output))
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

/// The checkpoints of a recorded period: the engine from the DEM thread, the samplers and
/// journal marks from the recorder thread, the rest from the driver.
struct PeriodSaver<'a, 's> {
    saver: Option<&'a mut Saver<'s>>,
    run_at_t0: &'a RunAtT0,
    /// `t0 … t_period`, the snapshots stored before this period.
    snapshots: &'a [Snapshot],
    /// The engine at `t1`, in the periods after the first while DEM twins are to come.
    at_t1: Option<&'a Simulation>,
    period: u32,
    /// Elapsed times when the period (re)started.
    elapsed: Elapsed,
    began: Instant,
}

impl PeriodCheckpoint for PeriodSaver<'_, '_> {
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
            snapshots: Cow::Borrowed(self.snapshots),
            sampler: Cow::Borrowed(sampler),
            journal: *journal,
            t1_engine: self.at_t1.map(EngineState::of),
        };
        let seconds = self.began.elapsed().as_secs_f64();
        let mut elapsed = Elapsed {
            period: self.elapsed.period + seconds,
            recorder: self.elapsed.recorder + recorder.busy[0],
            ..self.elapsed.clone()
        };
        elapsed.each_period[self.period as usize] += seconds;
        let stage = Stage::Period {
            period: self.period,
            done,
        };
        saver.save(sim, stage, elapsed, Some(output))
    }
}
