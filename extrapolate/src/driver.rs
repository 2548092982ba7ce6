//! The extrapolation of a recording: the memory plan, the pairings (reused from the cache or
//! computed and stored), the tables read or streamed, K periods replayed along the path and
//! written.

use crate::cache;
use crate::path::{self, RecurrencePolicy, Step};
use crate::replay::{
    self, Bodies, CflRow, Exchanges, MemoryNeeds, MemoryPlan, RoleTemperatures, Scheme,
    SyncScratch, Table, TableMode,
};
use crate::sidecar::{PairingSummary, StoredPairing};
use crate::ExtrapolateError;
use std::path::PathBuf;
use std::time::Instant;
use tdex_format::extrapolation::{PathPairing, RecurrencePath, Roles, Symmetry};
use tdex_format::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationWriter, RecordingInfo, RecordingReader,
    Snapshot, FORMAT_VERSION,
};

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
    /// The recorded periods (1-based, within the `recorded_periods` used) a jump may enter;
    /// `None`: every one of them. A user restricts them to the starts whose pairing with
    /// the recording's end is short (`tdex pair` prints each one's distance).
    pub jump_targets: Option<Vec<u32>>,
    /// The drum's symmetry the jumps use: [`Symmetry::AxialMirror`] enters the mirror image
    /// of each start, alternating the recording and its image at every jump.
    pub symmetry: Symmetry,
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
            jump_targets: None,
            symmetry: Symmetry::None,
        }
    }
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
    pub costs: ExtrapolationCosts,
    /// `Σ C T` at `t1` and after the last period (J).
    pub total_heat_t1: f64,
    pub total_heat_end: f64,
}

// the mirror check is stored in the extrapolation's info: its type is the format's
pub use tdex_format::extrapolation::MirrorCheck;

/// A pairing the path needs: of the end snapshot `t_P'` to the start of recorded period
/// `period` (snapshot `t_{period − 1}`).
struct PathStart {
    period: u32,
    stored: StoredPairing,
}

/// Pairs (or reuses the stored pairings), replays and writes the extrapolation on the
/// current worker pool; `notice` hears what a caller may want to tell the user.
pub fn extrapolate_recording(
    request: &ExtrapolationRequest,
    mut notice: impl FnMut(Notice<'_>),
) -> Result<ExtrapolationOutcome, ExtrapolateError> {
    let refused = |error| ExtrapolateError::Refused {
        recording: request.recording.clone(),
        error,
    };
    let reader = RecordingReader::open(&request.recording)?;
    let info = reader.info().clone();
    let used = request.recorded_periods.unwrap_or(info.recorded_periods);
    if !(1..=info.recorded_periods).contains(&used) {
        return Err(ExtrapolateError::RecordedPeriods {
            recording: request.recording.clone(),
            asked: used,
            recorded: info.recorded_periods,
        });
    }
    if request.symmetry == Symmetry::AxialMirror && !has_mirror_image(&info) {
        return Err(ExtrapolateError::NoMirrorImage {
            recording: request.recording.clone(),
        });
    }
    let seed = request.path_seed.unwrap_or_else(|| case_seed(&info));
    let targets = match &request.jump_targets {
        Some(targets) => {
            if let Some(&bad) = targets.iter().find(|t| !(1..=used).contains(*t)) {
                return Err(ExtrapolateError::JumpTarget {
                    recording: request.recording.clone(),
                    target: bad,
                    used,
                });
            }
            let targets = path::distinct_ascending(targets);
            // every period as a target is the default path: nothing to record
            (!targets.is_empty() && targets.len() < used as usize).then_some(targets)
        }
        None => None,
    };
    let steps: Vec<Step> =
        RecurrencePolicy::with_targets(used, seed, targets.as_deref().unwrap_or(&[]))
            .take(request.periods as usize)
            .collect();
    // the paper's method pairs t1 to t0 even for no period (as it always has); a path
    // pairs only the starts it jumps to
    let starts = if used == 1 {
        vec![1]
    } else {
        path::starts(&steps)
    };
    let mirrored = path::mirrored(&steps, request.symmetry);
    let mut replayed = vec![used == 1; used as usize];
    for s in &steps {
        replayed[s.period() as usize - 1] = true;
    }
    // t0 … t_P': the starts of the periods and the ends whose positions the output carries
    let mut snaps = (0..=used)
        .map(|index| cache::snapshot(&reader, index))
        .collect::<Result<Vec<Snapshot>, _>>()?;
    let bodies = Bodies::of(&info, &snaps[0]);
    let end = &snaps[used as usize];
    // what each jump enters: the start itself, or its mirror image
    let start_image = |m: u32| cache::start_image(&snaps[m as usize - 1], request.symmetry);
    let mut stored: Vec<(u32, Option<StoredPairing>)> = starts
        .iter()
        .map(|&m| {
            let image = start_image(m);
            (m, cache::load_image(&reader, &image, end, request.symmetry))
        })
        .collect();

    // the memory it will need, stated and held against the limit before the pairing and
    // the replay start: a table that does not fit is streamed, never left to the OOM killer
    let limit = request.memory_limit.clone();
    let mut rows_of: Vec<u64> = (1..=used).map(|p| period_rows(&reader, p)).collect();
    let needs = MemoryNeeds::estimate(
        info.particles as u64,
        rows_of
            .iter()
            .zip(&replayed)
            .filter(|(_, &r)| r)
            .map(|(rows, _)| rows)
            .sum(),
        reader.largest_table_chunk(),
        stored.iter().all(|(_, s)| s.is_some()),
        used,
        starts.len(),
    );
    let memory = MemoryPlan::choose(
        needs,
        limit.bytes,
        &limit.source,
        request.table == TableChoice::Streamed,
    )
    .map_err(refused)?;
    notice(Notice::Memory {
        plan: &memory,
        limit: &limit,
    });

    // each pairing the path needs, reused or computed once (and stored for the next run)
    let mut seconds_pairing = 0.0;
    let mut reused = true;
    let mut pairings = Vec::with_capacity(stored.len());
    // computes the pairing of `end` to `start` (an image under `symmetry`) and stores it
    // beside the recording; the stored pairing only saves time next run, so a recording on
    // a full or read-only disk is still extrapolated
    let mut compute_and_store = |start: &Snapshot,
                                 end: &Snapshot,
                                 symmetry: Symmetry|
     -> Result<StoredPairing, ExtrapolateError> {
        let started = Instant::now();
        let mut stored = cache::compute(start, end)?;
        if request.reproducible {
            stored.summary = stored.summary.reproducible();
        }
        if let Err(e) = cache::store_image(&reader, end.index, start.index, symmetry, &stored) {
            notice(Notice::PairingNotStored(&e));
        }
        seconds_pairing += started.elapsed().as_secs_f64();
        Ok(stored)
    };
    for (period, found) in stored.drain(..) {
        let stored = match found {
            Some(stored) => stored,
            None => {
                reused = false;
                let start = start_image(period);
                compute_and_store(&start, &snaps[used as usize], request.symmetry)?
            }
        };
        pairings.push(PathStart { period, stored });
    }
    // the mirror holds only if the bed is its own mirror image at the recorded instants: its
    // mirrored pairing is then as short as the plain one, which is reused or computed to
    // say so
    let mut mirror_check = Vec::new();
    if request.symmetry == Symmetry::AxialMirror {
        let end = &snaps[used as usize];
        for p in &pairings {
            let start = &snaps[p.period as usize - 1];
            let plain = match cache::load(&reader, start, end) {
                Some(stored) => stored,
                None => compute_and_store(start, end, Symmetry::None)?,
            };
            mirror_check.push(MirrorCheck::of(
                used,
                p.period - 1,
                &plain.summary,
                &p.stored.summary,
            ));
        }
    }
    let pairing_of = |period: u32| {
        pairings
            .iter()
            .find(|p| p.period == period)
            .map(|p| &p.stored.g[..])
            .expect("a pairing for every start of the path")
    };

    // the tables: decoded once into memory, or streamed from the file each period
    let t = Instant::now();
    let mut tables: Vec<Option<Table>> = vec![None; used as usize];
    let mut worst: Option<CflRow> = None;
    for p in (1..=used).filter(|&p| replayed[p as usize - 1]) {
        let at = p as usize - 1;
        // the rows as decoded (the summary's counts only sized the estimate)
        let found = if memory.mode == TableMode::Streamed {
            let found = replay::scan_period(&reader, &bodies, p, |_, _| {})?;
            rows_of[at] = found.rows;
            found.worst
        } else {
            let (table, found) = Table::read_period(&reader, &bodies, p, rows_of[at])?;
            rows_of[at] = table.exchanges.len() as u64;
            tables[at] = Some(table);
            found
        };
        if found.is_some_and(|f| worst.is_none_or(|w| f.cfl > w.cfl)) {
            worst = found;
        }
    }
    let rows: u64 = (1..=used)
        .filter(|&p| replayed[p as usize - 1])
        .map(|p| rows_of[p as usize - 1])
        .sum();
    let seconds_read_table = t.elapsed().as_secs_f64();
    let max_cfl = worst.map_or(0.0, |w| w.cfl);
    if let Some(w) = worst.filter(|w| request.scheme == Scheme::Explicit && w.cfl >= 1.0) {
        return Err(refused(w.refusal()));
    }

    let summary_of = |s: &StoredPairing| {
        if request.reproducible {
            // a stored pairing made without --reproducible carries its time
            s.summary.clone().reproducible()
        } else {
            s.summary.clone()
        }
    };
    let path_of = |summary: &dyn Fn(&StoredPairing) -> PairingSummary| {
        if used == 1 {
            Roles::Pairing(summary(&pairings[0].stored))
        } else {
            Roles::Path(RecurrencePath {
                recorded_periods: used,
                seed,
                jump_targets: targets.clone(),
                replayed: steps.iter().map(|s| s.period()).collect(),
                pairings: pairings
                    .iter()
                    .map(|p| PathPairing {
                        end: used,
                        start: p.period - 1,
                        summary: summary(&p.stored),
                    })
                    .collect(),
            })
        }
    };
    let out_info = ExtrapolationInfo {
        format_version: FORMAT_VERSION,
        // one version for the whole workspace: the binary's and this library's
        tool_version: env!("CARGO_PKG_VERSION").into(),
        recording: request.recording.display().to_string(),
        recording_info: info.clone(),
        scheme: request.scheme,
        periods: request.periods,
        roles: path_of(&summary_of),
        symmetry: request.symmetry,
        mirror_check: mirror_check.clone(),
    };
    let mut writer = ExtrapolationWriter::create(&request.output, &out_info)?;
    writer.write_snapshot(&snaps[1])?;

    // role a ends recorded period p at x_a(t_p): the snapshot's positions, radii and
    // velocities
    let heat_t1 = replay::total_heat(&snaps[1].temp, &bodies);
    let mut temps = RoleTemperatures::new(&snaps[1].temp, &bodies);
    let mut next = Vec::with_capacity(temps.len());
    let mut scratch = SyncScratch::default();
    let mut exchanges = Exchanges::default();
    // the output snapshot: t_p's positions and velocities (radii are per particle, the same
    // at every t_p), the extrapolated temperatures, and as `id` the particle that plays each
    // role (it moves with its heat, at the jumps only)
    let mut out = if used == 1 && request.symmetry.is_none() {
        snaps.pop().expect("t0 and t1")
    } else {
        snaps[1].clone()
    };
    // the recorded period whose end the output's positions are, and in which image
    let mut positions_of = (1, false);
    let mut next_id = Vec::with_capacity(out.id.len());
    let t = Instant::now();
    for ((k, step), &mirrored) in (1..=request.periods).zip(&steps).zip(&mirrored) {
        let p = step.period();
        if let Step::Jump { period } = *step {
            let g = pairing_of(period);
            temps.move_to_roles(g, &mut next)?;
            replay::move_to_roles(&out.id, g, &mut next_id)?;
            std::mem::swap(&mut out.id, &mut next_id);
        }
        match &tables[p as usize - 1] {
            Some(table) => replay::apply_rows_with(
                &mut temps,
                &table.exchanges,
                &bodies,
                request.scheme,
                &mut scratch,
            ),
            None => {
                let (batches, offset) = replay::period_batches(&reader, p);
                for batch in batches {
                    exchanges.clear();
                    for r in &batch?.rows {
                        exchanges.push_row(r, &info, offset);
                    }
                    replay::apply_rows_with(
                        &mut temps,
                        &exchanges,
                        &bodies,
                        request.scheme,
                        &mut scratch,
                    );
                }
            }
        }
        scratch.flush(&mut temps);
        if (p, mirrored) != positions_of {
            let end = &snaps[p as usize];
            let symmetry = request.symmetry;
            symmetry.copy_image(mirrored, &end.pos, &mut out.pos);
            symmetry.copy_image(mirrored, &end.vel, &mut out.vel);
            positions_of = (p, mirrored);
        }
        out.index = k + 1;
        out.time = info.snapshot_time(k + 1);
        temps.write_to(&mut out.temp);
        writer.write_snapshot(&out)?;
    }
    let seconds_replay = t.elapsed().as_secs_f64();
    let rows_replayed: u64 = steps.iter().map(|s| rows_of[s.period() as usize - 1]).sum();
    let costs = ExtrapolationCosts {
        seconds_pairing,
        pairing_reused: reused,
        seconds_read_table,
        seconds_replay,
        seconds_per_period: seconds_replay / request.periods as f64,
        rows_per_second: rows_replayed as f64 / seconds_replay.max(1e-12),
        rows,
    };
    writer.finish((!request.reproducible).then_some(&costs))?;
    Ok(ExtrapolationOutcome {
        particles: info.particles,
        rows,
        max_cfl,
        memory,
        limit,
        roles: path_of(&|s: &StoredPairing| s.summary.clone()),
        symmetry: request.symmetry,
        mirror_check,
        costs,
        total_heat_t1: heat_t1,
        total_heat_end: temps.total_heat(&bodies),
    })
}

/// The case's `seed` (the default seed of the path's jumps), 0 if the recording has none
/// (an imported run).
fn case_seed(info: &RecordingInfo) -> u64 {
    info.case_resolved
        .get("seed")
        .and_then(serde_json::Value::as_u64)
        .unwrap_or(0)
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

/// Rows of recorded period `period` (1-based): the whole table for a recording of one
/// period, else the summary's count (the whole table, an upper bound, if the summary is
/// missing).
fn period_rows(reader: &RecordingReader, period: u32) -> u64 {
    if reader.info().recorded_periods == 1 {
        return reader.table_rows();
    }
    reader
        .summary()
        .and_then(|s| s.period_rows.get(period as usize - 1).copied())
        .unwrap_or_else(|| reader.table_rows())
}

/// The memory an extrapolation may use, and where that figure came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryLimit {
    /// `u64::MAX` when no limit is known.
    pub bytes: u64,
    pub source: String,
}

impl MemoryLimit {
    /// The default: 80 % of what the machine can still give (`MemAvailable` in
    /// /proc/meminfo) and of what the process's cgroup still allows (`memory.max` −
    /// `memory.current`, cgroup v2), whichever is smaller. The 20 % left is for the page
    /// cache holding the recording and for the rest of the machine. Without /proc/meminfo
    /// there is no limit (the table is held in memory, as before `--max-memory`).
    pub fn available() -> Self {
        let mut found: Vec<(u64, &str)> = Vec::new();
        if let Some(kb) = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| meminfo_kb(&text, "MemAvailable:"))
        {
            found.push((kb.saturating_mul(1024), "MemAvailable"));
        }
        if let Some(room) = cgroup_room() {
            found.push((room, "the cgroup's memory.max"));
        }
        match found.into_iter().min() {
            Some((bytes, what)) => Self {
                bytes: bytes / 5 * 4,
                source: format!("80 % of {what}"),
            },
            None => Self {
                bytes: u64::MAX,
                source: "no limit known: no /proc/meminfo".into(),
            },
        }
    }

    /// Whether a limit is known.
    pub fn is_known(&self) -> bool {
        self.bytes != u64::MAX
    }
}

/// A `Key:   123 kB` line of /proc/meminfo, in kB.
fn meminfo_kb(text: &str, key: &str) -> Option<u64> {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

/// What the process's cgroup (v2) still allows, if it sets a limit.
fn cgroup_room() -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = own.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(dir.join(name))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (no limit) does not parse
    let max = read("memory.max")?;
    Some(max.saturating_sub(read("memory.current").unwrap_or(0)))
}
