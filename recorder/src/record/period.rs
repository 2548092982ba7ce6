//! A recorded period's two threads: the DEM steps on the caller's thread while a recorder
//! thread samples, splits, encodes and writes each recording's rows.

use super::error::RecordError;
use super::journal::{JournalMark, RowJournal};
use super::options::{Phase, REPORT_EVERY};
use super::{CollisionRow, ContactSampler};
use crate::Simulation;
use std::sync::mpsc;
use std::time::Instant;
use tdex_format::RecordingWriter;

/// A recording's writer and, when the run is checkpointed, its row journal.
pub(super) struct RowSink {
    pub(super) writer: RecordingWriter,
    pub(super) journal: Option<RowJournal>,
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
pub(super) struct RecorderState {
    pub(super) samplers: Vec<ContactSampler>,
    pub(super) journals: Vec<Option<JournalMark>>,
    pub(super) busy: Vec<f64>,
}

/// How the period loop offers checkpoints: asked between steps whether one is due, then
/// given the engine and the recorder's state, consistent at step `done`.
pub(super) trait PeriodCheckpoint {
    fn due(&self) -> bool;
    fn save(
        &mut self,
        sim: &Simulation,
        done: u64,
        recorder: RecorderState,
    ) -> Result<(), RecordError>;
}

/// Recorded period `index` (0-based) of `count`, `steps` DEM steps long: its samples are
/// numbered from `t0`, so its rows start in `[index · steps, (index + 1) · steps)`.
#[derive(Debug, Clone, Copy)]
pub(super) struct RecordedPeriod {
    pub(super) index: u32,
    pub(super) count: u32,
    pub(super) steps: u64,
}

impl RecordedPeriod {
    /// Its first step, counted from `t0`.
    fn first_step(self) -> u64 {
        self.index as u64 * self.steps
    }
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
    /// The contact list at step `k` counted from `t0`.
    Sample(u64, Sample),
    /// Everything sent before has been recorded: reply with the state for a checkpoint.
    Checkpoint(mpsc::Sender<RecorderState>),
}

/// Recorded period `period` from its step `start` on: the DEM steps on the calling thread
/// (and its pool) while a recorder thread samples, splits, encodes and writes for every job
/// (sampler `i` takes the steps that are multiples of `every[i]`). At its end the samplers
/// cut the contacts still open ([`ContactSampler::finish`]): no row crosses the boundary, and
/// the next period's first sample opens new rows. Each sample is the contact list
/// copied at its step, so the tables are the same as a serial recorder's, whatever the
/// timing; the recorder fills the cores the DEM leaves idle instead of stalling it. Between
/// steps, `checkpoints` is offered the state when one is due. Returns the finished samplers
/// (for their histograms) and each job's busy seconds on the recorder thread.
#[allow(clippy::too_many_arguments)]
pub(super) fn record_period(
    sim: &mut Simulation,
    mut samplers: Vec<ContactSampler>,
    sinks: &mut [RowSink],
    every: &[u64],
    period: RecordedPeriod,
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
        let (first, period_steps) = (period.first_step(), period.steps);
        let stretch = period.count as u64 * period_steps;
        let mut dem = || -> Result<(), RecordError> {
            let mut k = start;
            // where the stretch starts (mid-way after a resume), before its first step
            if k < period_steps {
                progress(Phase::Period, first + k, stretch);
            }
            while k < period_steps {
                // sample k is the contact list that conducted during DEM step k, from
                // t0 + k dt to t0 + (k+1) dt: the list the step has just computed
                sim.step();
                // τ is a multiple of every n: the period's first step is too
                if every.iter().any(|e| k.is_multiple_of(*e)) {
                    let mut contacts = spare.try_recv().unwrap_or_default();
                    contacts.clear();
                    contacts.extend(sim.touching_pairs().chain(sim.touching_walls()));
                    let sample = ToRecorder::Sample(first + k, contacts);
                    if to_recorder.send(sample).is_err() {
                        return Ok(()); // the recorder stopped: its error is reported below
                    }
                }
                for _ in 1..stride {
                    sim.step();
                }
                sim.check_inside()?;
                k += stride;
                if k % REPORT_EVERY < stride || k == period_steps {
                    progress(Phase::Period, first + k, stretch);
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
