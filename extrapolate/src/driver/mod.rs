//! The extrapolation of a recording: the memory plan, the pairings (reused from the cache or
//! computed and stored), the tables read or streamed, K periods replayed along the path and
//! written.
//!
//! `run` holds one extrapolation's state with a method per stage, which
//! [`extrapolate_recording`] calls in order; `memory_limit` finds the memory it may use.

mod memory_limit;
mod run;

pub use memory_limit::MemoryLimit;

use crate::boundary::BoundaryMaps;
pub use crate::path::Leave;
use crate::replay::{MemoryPlan, Scheme};
use crate::ExtrapolateError;
use run::Extrapolation;
use std::path::PathBuf;
use tdex_format::extrapolation::{Boundary, FreshPool, Roles, Symmetry};
use tdex_format::{ExtrapolationCosts, RecordingInfo};

/// What to extrapolate, how far, and into which file.
#[derive(Debug, Clone)]
pub struct ExtrapolationRequest {
    pub recording: PathBuf,
    /// Periods K replayed after `t1`.
    pub periods: u32,
    pub output: PathBuf,
    pub scheme: Scheme,
    pub table: TableChoice,
    /// The memory the extrapolation may use (e.g. [`MemoryLimit::available`]): a table
    /// that does not fit is streamed, and a replay that cannot fit even so is refused.
    pub memory_limit: MemoryLimit,
    /// No times or thread counts in the sidecar or the extrapolation: the same inputs give
    /// the same bytes on any thread count.
    pub reproducible: bool,
    /// Recorded periods used, `P'`: the first `P'` of the recording's `P` (`None`: all).
    /// `P' = 1` is the paper's method on the first recorded period.
    pub recorded_periods: Option<u32>,
    /// Seed of the recurrence path's jumps (`None`: the case's `seed`, else 0). Plays no
    /// part with one recorded period.
    pub path_seed: Option<u64>,
    /// The recorded starts a jump may enter.
    pub jumps: JumpStarts,
    /// Where the path leaves the recording for a jump: at its end only, or every few
    /// periods from where it stands.
    pub leave: Leave,
    /// The drum's symmetry the jumps use: [`Symmetry::AxialMirror`] enters the mirror image
    /// of each start, alternating the recording and its image at every jump.
    pub symmetry: Symmetry,
    /// How the roles are handed over at each jump: one exact pairing per start (the
    /// paper's method) or a pool of fresh ones, drawn from the path's seed.
    pub boundary: BoundaryMaps,
}

impl ExtrapolationRequest {
    /// The paper's method on every recorded period: the explicit scheme, the table in memory
    /// when it fits the limit, the case's path seed, every start a jump target, no
    /// symmetry, times kept. Callers change what they need with struct update syntax.
    pub fn new(
        recording: PathBuf,
        periods: u32,
        output: PathBuf,
        memory_limit: MemoryLimit,
    ) -> Self {
        Self {
            recording,
            periods,
            output,
            scheme: Scheme::Explicit,
            table: TableChoice::InMemoryIfItFits,
            memory_limit,
            reproducible: false,
            recorded_periods: None,
            path_seed: None,
            jumps: JumpStarts::Every,
            leave: Leave::AtEnd,
            symmetry: Symmetry::None,
            boundary: BoundaryMaps::Exact,
        }
    }
}

/// Which recorded starts the path's jumps may enter (each jump draws one uniformly among them).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JumpStarts {
    /// Every recorded period used.
    Every,
    /// The recorded periods named (1-based, within the recorded periods used).
    Listed(Vec<u32>),
    /// The `k` starts nearest the recording's end in the mean distance of their pairing
    /// with it, as recurrence CFD jumps to the recorded states most like the current one: a
    /// bed that drifts slowly over the recording is then entered where it stands.
    Nearest(std::num::NonZeroU32),
}

/// Where the replay keeps the collision table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableChoice {
    /// Decoded once into memory when the whole replay fits the limit, else streamed.
    InMemoryIfItFits,
    /// Decoded from the file every period, whatever the memory.
    Streamed,
}

/// What the caller is told while the extrapolation runs (it prints nothing itself).
#[derive(Debug)]
pub enum Notice<'a> {
    /// The memory the replay needs and where the table goes, decided before any work.
    Memory {
        plan: &'a MemoryPlan,
        limit: &'a MemoryLimit,
    },
    /// The computed pairing could not be stored beside the recording: the extrapolation
    /// goes on, and the next one computes the pairing again.
    PairingNotStored(&'a ExtrapolateError),
}

/// What an extrapolation found and cost; the extrapolation itself is in the output file.
#[derive(Debug, Clone)]
pub struct ExtrapolationOutcome {
    pub particles: u32,
    /// Rows of the recorded tables used (one period's table for the paper's method).
    pub rows: u64,
    /// The tables' largest CFL number of the explicit scheme (0 for empty tables).
    pub max_cfl: f64,
    pub memory: MemoryPlan,
    pub limit: MemoryLimit,
    /// The pairing used (one recorded period) or the path followed, with the pairings as
    /// computed (with their times) or as stored.
    pub roles: Roles,
    pub symmetry: Symmetry,
    /// With the axial mirror: each start's mirrored pairing beside its plain one.
    pub mirror_check: Vec<MirrorCheck>,
    /// How the roles were handed over at the jumps, and with fresh maps each start's pool.
    pub boundary: Boundary,
    pub fresh_pools: Vec<FreshPool>,
    pub costs: ExtrapolationCosts,
    /// `Σ C T` at `t1` and after the last period (J).
    pub total_heat_t1: f64,
    pub total_heat_end: f64,
}

// the mirror check is stored in the extrapolation's info: its type is the format's
pub use tdex_format::extrapolation::MirrorCheck;

/// Pairs (or reuses the stored pairings), replays and writes the extrapolation on the
/// current worker pool; `notice` hears what a caller may want to tell the user.
pub fn extrapolate_recording(
    request: &ExtrapolationRequest,
    mut notice: impl FnMut(Notice<'_>),
) -> Result<ExtrapolationOutcome, ExtrapolateError> {
    let mut run = Extrapolation::plan(request, &mut notice)?;
    let memory = run.memory_plan(&mut notice)?;
    run.pair(&mut notice)?;
    run.read_tables(memory.mode)?;
    let replayed = run.replay_and_write()?;
    Ok(run.outcome(memory, replayed))
}

/// Whether the recording is of a tdex drum, whose mid-plane `y = 0` is a mirror plane
/// ([`Symmetry`]): its case (recorded, or the case an import was made with) has a `[drum]`.
/// The mirror swaps the two end caps, which is harmless because they move alike and conduct
/// no heat (a wall row of a cap moves none). A future drum feature that breaks the mirror
/// (an inclined axis, a feed at one end, a heated cap, a mantle heated along part of its
/// length) must be refused here.
pub fn has_mirror_image(info: &RecordingInfo) -> bool {
    info.case_resolved
        .get("drum")
        .is_some_and(serde_json::Value::is_object)
}

/// The period along the axis (the drum's `length`) when the recording's drum is a section
/// periodic along it (`[drum] end_caps = "periodic"`), else `None`: the pairings of such a
/// recording take their distances across the seam.
pub fn axial_period(info: &RecordingInfo) -> Option<f64> {
    let drum = info.case_resolved.get("drum")?;
    (drum.get("end_caps")?.as_str()? == "periodic")
        .then(|| drum.get("length")?.as_f64())
        .flatten()
}
