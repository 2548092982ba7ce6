//! Checkpoints of `tdex record`: the whole state of a run in one file, written atomically,
//! from which `tdex record --resume` goes on to the same bytes as an uninterrupted run.
//!
//! A checkpoint holds what the next step depends on — the particles in their memory order,
//! the Verlet list with every contact history, the drum's motion, the step count — and what
//! the output has received: the snapshots, the sampler with its open contacts and the
//! [`JournalMark`] of the rows. Everything else (step parameters, cell grid, walls) is rebuilt
//! from the case text stored inside. The engine draws no random numbers after insertion (the
//! seeded lattice of [`crate::insertion`]), so there is no generator state to keep.
//!
//! Layout: one line of text saying what the file is and where the run stands (`head -1`
//! shows it), then the body's length (u64) and CRC-32 (u32), little-endian, then the body in
//! postcard's serde encoding (floats as their 8 bytes: a state read back is the state saved,
//! bit for bit).

use super::journal::JournalMark;
use super::metadata::{Elapsed, RunAtT0};
use super::options::RecordOptions;
use super::ContactSampler;
use crate::case::Case;
use crate::counters::Counters;
use crate::neighbor::NeighborList;
use crate::particles::ParticleSet;
use crate::pipeline::ContactCount;
use crate::simulation::Groups;
use crate::Simulation;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};
use tdex_format::Snapshot;

/// Format of the body; a reader refuses others. v2: the Verlet list's pair histories are
/// packed layer by layer (v1 had one per entry). v3: one stage timer for pair and wall
/// contacts (`contact`) instead of `pair` and `wall`. v4: DEM twins (the state at `t1` kept
/// while the runs that continue from it go on, the twin stage, the twins' wall time). v5:
/// several recorded periods (the recorded period's index in the stage, the recording option
/// `recorded_periods`, each period's wall time; the state at `t1` also kept inside recorded
/// periods after the first while twins are to come).
pub const CHECKPOINT_VERSION: u32 = 5;
const HEADER_PREFIX: &str = "tdex checkpoint v";
/// The header line is at most this long (a reader does not scan a large file for it).
const MAX_HEADER: usize = 512;

/// Whether `path` starts like a checkpoint (its header's prefix): how `tdex inspect` tells a
/// checkpoint from a recording before reading either.
pub fn is_checkpoint(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; HEADER_PREFIX.len()];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == HEADER_PREFIX.as_bytes())
}

/// How far a run stands: steps run and steps of the whole job (settling, spin-up, the run's
/// periods to its last snapshot, each twin's periods from its parting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct StepsDone {
    pub done: u64,
    pub total: u64,
    /// The part of the run it stands in, and the steps run in that part so far: with its
    /// wall time ([`Part::seconds`]), the pace of the part running now, which the pace of
    /// the whole run (its settling, a machine shared earlier) need not be.
    pub part: Part,
    pub done_in_part: u64,
}

/// The parts of a run whose wall times a checkpoint's [`Elapsed`] counts apart, in the order
/// the run goes through them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Settling and spin-up.
    ToT0,
    /// The recorded periods (DEM and recorder).
    Recorded,
    /// The run's reference periods after the recorded ones.
    Reference,
    /// The DEM twins.
    Twins,
}

impl Part {
    /// The wall time spent in this part so far.
    pub fn seconds(self, elapsed: &Elapsed) -> f64 {
        match self {
            Part::ToT0 => elapsed.to_t0,
            Part::Recorded => elapsed.period,
            Part::Reference => elapsed.reference,
            Part::Twins => elapsed.twins,
        }
    }
}

/// Where the checkpoints of a recording to `dest` go: `<dest>.checkpoint`.
pub fn checkpoint_path(dest: &Path) -> PathBuf {
    let mut name = dest.as_os_str().to_owned();
    name.push(".checkpoint");
    PathBuf::from(name)
}

/// Where a run stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Stage {
    /// `done` steps of the settling.
    Settle { done: u64 },
    /// `done` steps of the spin-up.
    SpinUp { done: u64 },
    /// `done` steps into recorded period `period` (0-based: `[t_period, t_(period+1)]`; the
    /// ones before it are stored).
    Period { period: u32, done: u64 },
    /// `done` steps into reference period `period` (0-based, its snapshot is `t_(period+2)`;
    /// the ones before it are stored). The first to run is the one after the recorded
    /// periods: those up to `tP` are recorded ones.
    Reference { period: u32, done: u64 },
    /// `done` steps into reference period `period` of DEM twin `twin` (1-based; the twins
    /// before it and its periods before `period` are stored).
    Twin { twin: u32, period: u32, done: u64 },
}

/// The engine state a step depends on.
#[derive(Debug, Serialize, Deserialize)]
pub struct EngineState<'a> {
    pub particles: Cow<'a, ParticleSet>,
    pub neighbors: Cow<'a, NeighborList>,
    pub angular_velocity: f64,
    pub mantle_temperature: Option<f64>,
    pub groups: Cow<'a, Groups>,
    pub time: f64,
    pub step: u64,
    pub last_contacts: ContactCount,
    pub counters: Cow<'a, Counters>,
}

impl<'a> EngineState<'a> {
    /// Borrows the state of `sim` (nothing is copied to save it).
    pub fn of(sim: &'a Simulation) -> Self {
        Self {
            particles: Cow::Borrowed(&sim.particles),
            neighbors: Cow::Borrowed(&sim.neighbors),
            angular_velocity: sim.walls.angular_velocity,
            mantle_temperature: sim.walls.mantle_temperature,
            groups: Cow::Borrowed(&sim.groups),
            time: sim.time,
            step: sim.step,
            last_contacts: sim.last_contacts,
            counters: Cow::Borrowed(&sim.counters),
        }
    }
}

/// What the recording has received once the run is past `t0`.
#[derive(Debug, Serialize, Deserialize)]
pub struct OutputState<'a> {
    pub run: RunAtT0,
    /// `t0`, then the recorded and reference snapshots written so far (`t1`, `t2`, ... in
    /// order), then those of the DEM twins (twin 1's `t2..`, twin 2's, ...).
    pub snapshots: Cow<'a, [Snapshot]>,
    /// The engine at `t1`, kept from `t1` on while DEM twins are still to continue from it.
    pub t1_engine: Option<EngineState<'a>>,
    pub sampler: Cow<'a, ContactSampler>,
    pub journal: JournalMark,
}

/// A run of `tdex record`, resumable.
#[derive(Debug, Serialize, Deserialize)]
pub struct Checkpoint<'a> {
    pub tool_version: String,
    pub case_toml: Cow<'a, str>,
    /// The case path as the recording's metadata states it.
    pub case_path: PathBuf,
    pub options: RecordOptions,
    /// The recording (absolute path).
    pub dest: PathBuf,
    /// Wall-clock seconds between checkpoints.
    pub every_seconds: f64,
    /// Whether the recording gets its `tdex.costs` record.
    pub write_costs: bool,
    pub stage: Stage,
    pub elapsed: Elapsed,
    pub engine: EngineState<'a>,
    pub output: Option<OutputState<'a>>,
    /// The first line of the file as read (what the run was at), not part of the body.
    #[serde(skip)]
    pub header: String,
}

/// Why a checkpoint cannot be written, read or resumed.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("{}: cannot read the checkpoint: {error}", path.display())]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("checkpoint {0}")]
    Write(#[from] tdex_format::output::OutputError),
    #[error("{}: not a tdex checkpoint (its first line does not start with '{HEADER_PREFIX}')", path.display())]
    NotCheckpoint { path: PathBuf },
    #[error("{}: checkpoint format v{found}; this tdex reads v{CHECKPOINT_VERSION}", path.display())]
    Version { path: PathBuf, found: String },
    #[error("{}: damaged checkpoint: {detail}", path.display())]
    Damaged { path: PathBuf, detail: String },
    #[error("{}: written by tdex {found}, this is tdex {}: resume with the tdex that wrote it", path.display(), env!("CARGO_PKG_VERSION"))]
    ToolVersion { path: PathBuf, found: String },
    #[error("{}: the checkpoint does not fit its own case: {detail}", path.display())]
    Inconsistent { path: PathBuf, detail: String },
}

impl tdex_format::Classify for CheckpointError {
    /// The input is at fault in the checkpoint the user gave, not in writing one.
    fn fault(&self) -> tdex_format::Fault {
        match self {
            CheckpointError::Write(_) => tdex_format::Fault::Run,
            _ => tdex_format::Fault::Input,
        }
    }
}

impl Checkpoint<'_> {
    /// Writes the checkpoint to `path` atomically: a hidden partial file beside it, synced,
    /// renamed over the previous checkpoint, and the directory synced. `header` is the text
    /// after the version on the first line.
    pub fn write(&self, path: &Path, header: &str) -> Result<(), CheckpointError> {
        let body = postcard::to_stdvec(self).map_err(|e| {
            tdex_format::output::OutputError::writing(path, std::io::Error::other(e))
        })?;
        tdex_format::output::write_with(path, |file| {
            let line = format!(
                "{HEADER_PREFIX}{CHECKPOINT_VERSION}: {}\n",
                header.replace('\n', " ")
            );
            file.write_all(line.as_bytes())?;
            file.write_all(&(body.len() as u64).to_le_bytes())?;
            file.write_all(&crc32fast::hash(&body).to_le_bytes())?;
            file.write_all(&body)
        })?;
        Ok(())
    }
}

impl Checkpoint<'_> {
    /// Where the run stands in `case` (the checkpoint's own, [`Self::case`]), in the words of
    /// its first line: `spin-up step 36500 of 50000, t = 4.650000 s`.
    pub fn stands_at(&self, case: &Case) -> String {
        format!(
            "{}, t = {:.6} s",
            super::saver::describe(self.stage, case, &self.options),
            self.engine.time
        )
    }

    /// How far the run stands in `case` (the checkpoint's own, [`Self::case`]).
    pub fn steps(&self, case: &Case) -> StepsDone {
        steps_done(
            &self.options,
            case.steps_in(case.time.settle),
            case.steps_in(case.time.spin_up),
            self.stage,
        )
    }
}

/// [`Checkpoint::steps`] for `opts`, `settle` and `spin_up` steps, at `stage`. The run's
/// periods reach its last snapshot (`tP` or `t(K+1)`); reference period `p` runs from
/// `t(p+1)`; a twin runs from its parting `tS` to `t(K+1)`.
fn steps_done(opts: &RecordOptions, settle: u64, spin_up: u64, stage: Stage) -> StepsDone {
    let period = opts.period_steps;
    let to_t0 = settle + spin_up;
    let run_periods = u64::from(opts.last_snapshot());
    let twin_periods = u64::from((opts.reference_periods + 1).saturating_sub(opts.twins_from));
    let twins_at = to_t0 + run_periods * period;
    let total = twins_at + u64::from(opts.twins) * twin_periods * period;
    let reference_at = to_t0 + u64::from(opts.recorded_periods) * period;
    let (done, part, part_at) = match stage {
        Stage::Settle { done } => (done, Part::ToT0, 0),
        Stage::SpinUp { done } => (settle + done, Part::ToT0, 0),
        Stage::Period { period: p, done } => {
            (to_t0 + u64::from(p) * period + done, Part::Recorded, to_t0)
        }
        Stage::Reference { period: p, done } => (
            to_t0 + (u64::from(p) + 1) * period + done,
            Part::Reference,
            reference_at,
        ),
        Stage::Twin {
            twin,
            period: p,
            done,
        } => {
            // before its parting a twin is the run (period 0: not started)
            let own = u64::from(p.saturating_sub(opts.twins_from.saturating_sub(1)));
            let done = twins_at + u64::from(twin - 1) * twin_periods * period + own * period + done;
            (done, Part::Twins, twins_at)
        }
    };
    let done = done.min(total);
    StepsDone {
        done,
        total,
        part,
        done_in_part: done.saturating_sub(part_at),
    }
}

impl Checkpoint<'static> {
    /// Reads and checks a checkpoint file: header, version, length, CRC and decoding. The
    /// state is checked against its case by [`Self::restore`].
    pub fn read(path: &Path) -> Result<Self, CheckpointError> {
        let bytes = std::fs::read(path).map_err(|error| CheckpointError::Read {
            path: path.to_path_buf(),
            error,
        })?;
        let damaged = |detail: String| CheckpointError::Damaged {
            path: path.to_path_buf(),
            detail,
        };
        let head = &bytes[..bytes.len().min(MAX_HEADER)];
        let Some(newline) = head.iter().position(|&b| b == b'\n') else {
            return Err(CheckpointError::NotCheckpoint {
                path: path.to_path_buf(),
            });
        };
        let line = String::from_utf8_lossy(&bytes[..newline]);
        let Some(rest) = line.strip_prefix(HEADER_PREFIX) else {
            return Err(CheckpointError::NotCheckpoint {
                path: path.to_path_buf(),
            });
        };
        let version = rest.split(':').next().unwrap_or("").trim();
        if version != CHECKPOINT_VERSION.to_string() {
            return Err(CheckpointError::Version {
                path: path.to_path_buf(),
                found: version.chars().take(20).collect(),
            });
        }
        let after = &bytes[newline + 1..];
        if after.len() < 12 {
            return Err(damaged(format!(
                "{} bytes after the header line, at least 12 needed (length and CRC)",
                after.len()
            )));
        }
        let length = u64::from_le_bytes(after[..8].try_into().expect("8 bytes"));
        let crc = u32::from_le_bytes(after[8..12].try_into().expect("4 bytes"));
        let body = &after[12..];
        if length != body.len() as u64 {
            return Err(damaged(format!(
                "the header announces a body of {length} bytes, the file holds {} (cut short or extended)",
                body.len()
            )));
        }
        let found = crc32fast::hash(body);
        if found != crc {
            return Err(damaged(format!(
                "CRC-32 of the body is {found:08x}, the header says {crc:08x}"
            )));
        }
        // `Cow` fields decode owned (no borrow from `bytes`)
        let mut checkpoint: Checkpoint<'static> = postcard::from_bytes(body)
            .map_err(|e| damaged(format!("the body does not decode: {e}")))?;
        if checkpoint.tool_version != env!("CARGO_PKG_VERSION") {
            return Err(CheckpointError::ToolVersion {
                path: path.to_path_buf(),
                found: checkpoint.tool_version.chars().take(40).collect(),
            });
        }
        checkpoint.header = line.into_owned();
        Ok(checkpoint)
    }

    /// The case the checkpoint was taken in, parsed and validated again from its text.
    pub fn case(&self, path: &Path) -> Result<Case, CheckpointError> {
        crate::case::parse(&self.case_toml, &self.case_path).map_err(|e| {
            CheckpointError::Inconsistent {
                path: path.to_path_buf(),
                detail: format!("its case text is refused: {e}"),
            }
        })
    }

    /// Rebuilds the simulation of `case` with the saved state, after checking that every
    /// index the engine and the recorder will follow is in range (a checkpoint that passed
    /// its CRC can still have been written by hand). `path` is for messages.
    pub fn restore(self, case: &Case, path: &Path) -> Result<Restored, CheckpointError> {
        let bad = |detail: String| CheckpointError::Inconsistent {
            path: path.to_path_buf(),
            detail,
        };
        let sim = Simulation::new(case).map_err(|e| bad(e.to_string()))?;
        let snapshots = self.stage_snapshots(case).map_err(&bad)?;
        match (&self.output, snapshots) {
            (None, None) => {}
            (Some(out), Some(count)) => self.check_output(out, count, case, &sim).map_err(&bad)?,
            (out, _) => {
                return Err(bad(format!(
                    "stage {:?} {} recording state",
                    self.stage,
                    if out.is_some() { "has a" } else { "lacks the" }
                )))
            }
        }
        let mut output = self.output;
        let t1 = match output.as_mut().and_then(|o| o.t1_engine.take()) {
            Some(e) => Some(apply(e, sim.clone(), case, &bad)?),
            None => None,
        };
        let sim = apply(self.engine, sim, case, &bad)?;
        Ok(Restored {
            sim,
            stage: self.stage,
            elapsed: self.elapsed,
            output,
            t1,
        })
    }

    /// How many snapshots the recording state holds at the saved stage (`None` before t0,
    /// where there is none), once the stage is checked to lie within the run the options
    /// and `case` describe; `Err` says how it does not.
    fn stage_snapshots(&self, case: &Case) -> Result<Option<usize>, String> {
        let o = &self.options;
        let (settle, spin) = (
            case.steps_in(case.time.settle),
            case.steps_in(case.time.spin_up),
        );
        let recorded = o.recorded_periods;
        // the run's own snapshots: t0 up to tP or to the last reference t_(K+1)
        let own = o.last_snapshot() as usize + 1;
        let (stage_ok, snapshots) = match self.stage {
            Stage::Settle { done } => (done <= settle, None),
            Stage::SpinUp { done } => (done <= spin, None),
            Stage::Period { period, done } => (
                period < recorded
                    && done <= o.period_steps
                    && done % o.sample_every.max(1) as u64 == 0,
                Some(1 + period as usize),
            ),
            Stage::Reference { period, done } => (
                period < o.reference_periods && period + 1 >= recorded && done <= o.period_steps,
                Some(2 + period as usize),
            ),
            Stage::Twin { twin, period, done } => (
                (1..=o.twins).contains(&twin)
                    && period < o.reference_periods
                    && done <= o.period_steps,
                Some(own + (o.reference_periods as usize) * (twin as usize - 1) + period as usize),
            ),
        };
        if !(1..=tdex_format::MAX_RECORDED_PERIODS).contains(&recorded) || !stage_ok {
            return Err(format!(
                "stage {:?} is outside the run ({settle} settling, {spin} spin-up steps, {recorded} recorded periods of {} steps sampled every {}, {} reference periods)",
                self.stage, o.period_steps, o.sample_every, o.reference_periods
            ));
        }
        Ok(snapshots)
    }

    /// Checks the recording state `out` against the stage (`count` snapshots), the options,
    /// `case` and its simulation `sim`; `Err` says what differs.
    fn check_output(
        &self,
        out: &OutputState,
        count: usize,
        case: &Case,
        sim: &Simulation,
    ) -> Result<(), String> {
        let (o, n) = (&self.options, sim.particles.len());
        if out.snapshots.len() != count {
            return Err(format!(
                "{} snapshots stored at stage {:?}, {count} expected",
                out.snapshots.len(),
                self.stage
            ));
        }
        if let Some(s) = out.snapshots.iter().find(|s| {
            [
                s.id.len(),
                s.pos.len(),
                s.radius.len(),
                s.temp.len(),
                s.vel.len(),
            ]
            .iter()
            .any(|&len| len != n)
        }) {
            return Err(format!("snapshot {} does not hold {n} particles", s.index));
        }
        if out.run.particles as usize != n || out.run.walls.len() != sim.walls.len() {
            return Err(format!(
                "the recording's {} particles and {} walls differ from the case's {n} and {}",
                out.run.particles,
                out.run.walls.len(),
                sim.walls.len()
            ));
        }
        let s = &out.sampler;
        if s.every != o.sample_every || s.max_duration != o.dtc_max_steps {
            return Err(format!(
                "the sampler has n = {}, Δt_c^max = {}; the options say {} and {}",
                s.every, s.max_duration, o.sample_every, o.dtc_max_steps
            ));
        }
        s.check(o.period_steps / o.sample_every.max(1) as u64)?;
        // the main run's snapshots are numbered by position, each twin's from 2
        let own = o.last_snapshot() as usize + 1;
        let references = o.reference_periods.max(1) as usize;
        let expected = |k: usize| match k.checked_sub(own) {
            None => k,
            Some(past) => 2 + past % references,
        };
        if let Some((k, s)) = out
            .snapshots
            .iter()
            .enumerate()
            .find(|(k, s)| s.index as usize != expected(*k))
        {
            return Err(format!("snapshot {k} is numbered {}", s.index));
        }
        // the state at t1 is kept from t1 on while twins are still to run from it
        let keeps_t1 = match self.stage {
            Stage::Period { period, .. } => period >= o.twins_from && o.twins > 0,
            Stage::Reference { .. } => o.twins > 0,
            Stage::Twin { .. } => true,
            _ => false,
        };
        if out.t1_engine.is_some() != keeps_t1 {
            return Err(format!(
                "stage {:?} with {} twins {} the engine state at t1",
                self.stage,
                o.twins,
                if out.t1_engine.is_some() {
                    "has"
                } else {
                    "lacks"
                }
            ));
        }
        let t0_step = case.steps_in(case.time.settle) + case.steps_in(case.time.spin_up);
        let r = case.particles.largest_radius();
        if out.run.step_t0 != t0_step
            || out.run.t0 != t0_step as f64 * case.time.dt
            || out.run.r_max != r
        {
            return Err(format!(
                "t0 at step {} ({} s) with largest radius {} m; the case gives step {t0_step} and {r} m",
                out.run.step_t0, out.run.t0, out.run.r_max
            ));
        }
        Ok(())
    }
}

/// The state a run resumes from: the engine where it stood, and at `t1` when DEM twins
/// are still to continue from there.
pub struct Restored {
    pub sim: Simulation,
    pub stage: Stage,
    pub elapsed: Elapsed,
    pub output: Option<OutputState<'static>>,
    pub t1: Option<Simulation>,
}

/// `sim` (freshly built from `case`) with the saved engine state `e`, after checking that
/// every index the engine will follow is in range.
fn apply(
    e: EngineState,
    mut sim: Simulation,
    case: &Case,
    bad: &dyn Fn(String) -> CheckpointError,
) -> Result<Simulation, CheckpointError> {
    let n = sim.particles.len();
    e.particles.check(n).map_err(&bad)?;
    // sizes and masses are the case's (the inserted set has them by id); the state is
    // finite and inside the drum, as the engine keeps it
    let inserted = &sim.particles;
    let p = &e.particles;
    for i in 0..n {
        let id = p.id[i] as usize;
        let finite = [p.pos[i], p.vel[i], p.omega[i], p.force[i], p.torque[i]]
            .iter()
            .flatten()
            .chain([&p.temp[i], &p.heat_flow[i]])
            .all(|x| x.is_finite());
        if p.radius[i] != inserted.radius[id] || p.mass[i] != inserted.mass[id] || !finite {
            return Err(bad(format!(
                    "particle {id} (slot {i}): radius {} m, mass {} kg, or a non-finite state value; the case gives {} m, {} kg",
                    p.radius[i], p.mass[i], inserted.radius[id], inserted.mass[id]
                )));
        }
    }
    e.neighbors
        .check(n, sim.pipeline.grid.layers(), sim.walls.len())
        .map_err(&bad)?;
    if e.neighbors.skin != sim.neighbors.skin {
        return Err(bad(format!(
            "Verlet skin {} m, the case gives {} m",
            e.neighbors.skin, sim.neighbors.skin
        )));
    }
    if !e.groups.hot.is_empty() && e.groups.hot.len() != n {
        return Err(bad(format!(
            "{} group flags for {n} particles",
            e.groups.hot.len()
        )));
    }
    if e.time != e.step as f64 * case.time.dt {
        return Err(bad(format!(
            "t = {} s is not step {} × dt = {} s",
            e.time, e.step, case.time.dt
        )));
    }
    sim.particles = e.particles.into_owned();
    sim.neighbors = e.neighbors.into_owned();
    sim.walls.angular_velocity = e.angular_velocity;
    sim.walls.mantle_temperature = e.mantle_temperature;
    sim.groups = e.groups.into_owned();
    sim.time = e.time;
    sim.step = e.step;
    sim.last_contacts = e.last_contacts;
    sim.counters = e.counters.into_owned();
    sim.check_inside().map_err(|e| bad(e.to_string()))?;
    Ok(sim)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(recorded: u32, reference: u32, twins: u32, twins_from: u32) -> RecordOptions {
        RecordOptions {
            sample_every: 10,
            dtc_max_steps: 100,
            period_steps: 1000,
            reference_periods: reference,
            twins,
            recorded_periods: recorded,
            twins_from,
            area_encoding: tdex_format::AreaEncoding::Quantized,
        }
    }

    /// The steps count every phase once: settle 100 + spin-up 400, two recorded periods,
    /// the run to t7 (K = 6), and a twin from t2 to t7 (five periods of 1000 steps).
    #[test]
    fn a_run_stands_at_the_steps_of_every_phase_before_its_stage() {
        let opts = options(2, 6, 1, 2);
        let at = |stage| steps_done(&opts, 100, 400, stage);
        let total = 500 + 7 * 1000 + 5 * 1000;
        assert_eq!(
            at(Stage::Settle { done: 40 }),
            StepsDone {
                done: 40,
                total,
                part: Part::ToT0,
                done_in_part: 40
            }
        );
        assert_eq!(at(Stage::SpinUp { done: 40 }).done, 140);
        assert_eq!(at(Stage::SpinUp { done: 40 }).done_in_part, 140);
        assert_eq!(
            at(Stage::Period {
                period: 1,
                done: 40
            })
            .done,
            500 + 1040
        );
        let recorded = at(Stage::Period {
            period: 1,
            done: 40,
        });
        assert_eq!(
            (recorded.part, recorded.done_in_part),
            (Part::Recorded, 1040)
        );
        // the first reference period after two recorded ones runs from t2 (index 1)
        let reference = at(Stage::Reference {
            period: 1,
            done: 40,
        });
        assert_eq!(reference.done, 500 + 2040);
        assert_eq!(
            (reference.part, reference.done_in_part),
            (Part::Reference, 40)
        );
        assert_eq!(
            at(Stage::Reference {
                period: 5,
                done: 999
            })
            .done,
            500 + 6999
        );
        // the twin parts at t2: its period 1 (t2 → t3) is its first own
        let twin = |period, done| {
            at(Stage::Twin {
                twin: 1,
                period,
                done,
            })
            .done
        };
        assert_eq!(twin(0, 0), 7500);
        assert_eq!(twin(1, 40), 7540);
        assert_eq!(twin(5, 1000), total);
        // twins from t1, two of them: each runs six periods
        let opts = options(1, 6, 2, 1);
        let second = steps_done(
            &opts,
            100,
            400,
            Stage::Twin {
                twin: 2,
                period: 3,
                done: 0,
            },
        );
        assert_eq!(second.total, 500 + 7000 + 2 * 6000);
        assert_eq!(second.done, 500 + 7000 + 6000 + 3000);
        // the twins' part counts both twins' steps
        assert_eq!((second.part, second.done_in_part), (Part::Twins, 9000));
        // no reference: the run ends at tP
        assert_eq!(
            steps_done(&options(3, 0, 0, 1), 0, 0, Stage::Settle { done: 0 }).total,
            3000
        );
    }
}
