//! The checkpoints of one recording run: written every so many seconds of wall time, with a
//! first line that says where the run stands, and removed once the recording is in place.

use super::checkpoint::{Checkpoint, CheckpointError, EngineState, OutputState, Stage};
use super::error::RecordError;
use super::journal::journal_path;
use super::metadata::Elapsed;
use super::options::{RecordOptions, RecordRun};
use crate::case::Case;
use crate::Simulation;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Writes the checkpoints of one run.
pub(super) struct Saver<'a> {
    run: &'a RecordRun<'a>,
    path: PathBuf,
    /// The row journal beside the checkpoint.
    pub(super) journal: PathBuf,
    every: Duration,
    every_seconds: f64,
    last: Instant,
    /// The recording, absolute: a resume may start in another directory.
    dest: PathBuf,
}

impl<'a> Saver<'a> {
    /// Checkpoints of `run` to `path`, every `every_seconds` of wall time.
    pub(super) fn new(
        run: &'a RecordRun<'a>,
        path: &Path,
        every_seconds: f64,
    ) -> Result<Self, RecordError> {
        let every = Duration::try_from_secs_f64(every_seconds)
            .ok()
            .filter(|_| every_seconds > 0.0)
            .ok_or_else(|| {
                RecordError::Settings(format!(
                    "checkpoint interval {every_seconds} s is not a number of seconds > 0"
                ))
            })?;
        let absolute = |p: &Path| {
            std::path::absolute(p).map_err(|error| {
                CheckpointError::from(tdex_format::output::OutputError::writing(p, error))
            })
        };
        Ok(Self {
            run,
            path: absolute(path)?,
            journal: absolute(&journal_path(path))?,
            every,
            every_seconds,
            last: Instant::now(),
            dest: absolute(run.dest)?,
        })
    }

    /// The checkpoint file.
    pub(super) fn path(&self) -> PathBuf {
        self.path.clone()
    }

    pub(super) fn due(&self) -> bool {
        self.last.elapsed() >= self.every
    }

    pub(super) fn save(
        &mut self,
        sim: &Simulation,
        stage: Stage,
        elapsed: Elapsed,
        output: Option<OutputState>,
    ) -> Result<(), RecordError> {
        let run = self.run;
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
        // the header is part of the file (`head -1` shows it, docs/file-format.md), so it
        // keeps saying how to continue
        let header = format!(
            "case {}, {}, t = {:.6} s; continue with: tdex record --resume {}",
            run.case.name,
            describe(stage, run.case, run.options),
            sim.time,
            self.path.display()
        );
        checkpoint.write(&self.path, &header)?;
        self.last = Instant::now();
        Ok(())
    }

    /// The run is complete: its checkpoint and journal are no longer needed.
    pub(super) fn remove(self) {
        let _ = std::fs::remove_file(&self.path);
        let _ = std::fs::remove_file(&self.journal);
    }
}

/// Where a run stands, in words (the checkpoint's first line, and `tdex inspect`'s).
pub(super) fn describe(stage: Stage, c: &Case, o: &RecordOptions) -> String {
    match stage {
        Stage::Settle { done } => format!("settle step {done} of {}", c.steps_in(c.time.settle)),
        Stage::SpinUp { done } => format!("spin-up step {done} of {}", c.steps_in(c.time.spin_up)),
        Stage::Period { period: _, done } if o.recorded_periods == 1 => {
            format!("period step {done} of {}", o.period_steps)
        }
        Stage::Period { period, done } => format!(
            "recorded period {} of {} step {done} of {}",
            period + 1,
            o.recorded_periods,
            o.period_steps
        ),
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
