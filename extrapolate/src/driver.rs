//! The extrapolation of a recording: the memory plan, the pairing (reused from the cache or
//! computed and stored), the table read or streamed, K periods replayed and written.

use crate::cache;
use crate::replay::{
    self, Bodies, Exchange, MemoryNeeds, MemoryPlan, Scheme, SyncScratch, Table, TableMode,
};
use crate::sidecar::PairingSummary;
use crate::ExtrapolateError;
use std::path::PathBuf;
use std::time::Instant;
use tdex_format::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationWriter, RecordingReader, FORMAT_VERSION,
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
    /// Rows of the recorded table replayed each period.
    pub rows: u64,
    /// The table's largest CFL number of the explicit scheme (0 for an empty table).
    pub max_cfl: f64,
    pub memory: MemoryPlan,
    pub limit: MemoryLimit,
    /// The pairing used, as computed or as stored.
    pub pairing: PairingSummary,
    pub costs: ExtrapolationCosts,
    /// `Σ C T` at `t1` and after the last period (J).
    pub total_heat_t1: f64,
    pub total_heat_end: f64,
}

/// Pairs (or reuses the stored pairing), replays and writes the extrapolation on the
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
    let (t0, t1) = cache::period_snapshots(&reader)?;
    let bodies = Bodies::of(&info, &t0);
    let stored_pairing = cache::load(&reader, &t0, &t1);

    // the memory it will need, stated and held against the limit before the pairing and
    // the replay start: a table that does not fit is streamed, never left to the OOM killer
    let limit = request.memory_limit.clone();
    let needs = MemoryNeeds::estimate(
        info.particles as u64,
        reader.table_rows(),
        reader.largest_table_chunk(),
        stored_pairing.is_some(),
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

    let started = Instant::now();
    let (stored, reused) = match stored_pairing {
        Some(stored) => (stored, true),
        None => {
            let mut stored = cache::compute(&t0, &t1)?;
            if request.reproducible {
                stored.summary = stored.summary.reproducible();
            }
            // the stored pairing only saves time next run: a recording on a full or read-only
            // disk is still extrapolated
            if let Err(e) = cache::store(&reader, &stored) {
                notice(Notice::PairingNotStored(&e));
            }
            (stored, false)
        }
    };
    let seconds_pairing = if reused {
        0.0
    } else {
        started.elapsed().as_secs_f64()
    };

    // the table: decoded once into memory, or streamed from the file each period
    let t = Instant::now();
    let (table, rows, worst) = if memory.mode == TableMode::Streamed {
        let found = replay::scan(&reader, &bodies, |_, _| {})?;
        (None, found.rows, found.worst)
    } else {
        let (table, worst) = Table::read(&reader, &bodies)?;
        let rows = table.exchanges.len() as u64;
        (Some(table), rows, worst)
    };
    let seconds_read_table = t.elapsed().as_secs_f64();
    let max_cfl = worst.map_or(0.0, |w| w.cfl);
    if let Some(w) = worst.filter(|w| request.scheme == Scheme::Explicit && w.cfl >= 1.0) {
        return Err(refused(w.refusal()));
    }

    let out_info = ExtrapolationInfo {
        format_version: FORMAT_VERSION,
        // one version for the whole workspace: the binary's and this library's
        tool_version: env!("CARGO_PKG_VERSION").into(),
        recording: request.recording.display().to_string(),
        recording_info: info.clone(),
        scheme: request.scheme,
        periods: request.periods,
        pairing: if request.reproducible {
            // a stored pairing made without --reproducible carries its time
            stored.summary.clone().reproducible()
        } else {
            stored.summary.clone()
        },
    };
    let mut writer = ExtrapolationWriter::create(&request.output, &out_info)?;
    writer.write_snapshot(&t1)?;

    // role a ends each period at x_a(t1): the snapshot's positions, radii and velocities
    let mut temps = t1.temp.clone();
    let heat_t1 = replay::total_heat(&temps, &bodies);
    let mut next = Vec::with_capacity(temps.len());
    let mut scratch = SyncScratch::default();
    let mut exchanges: Vec<Exchange> = Vec::new();
    // the output snapshot: t1's positions, radii and velocities, the extrapolated
    // temperatures, and as `id` the particle that plays each role (it moves with its heat)
    let mut out = t1;
    let mut next_id = Vec::with_capacity(out.id.len());
    let t = Instant::now();
    for k in 1..=request.periods {
        replay::move_to_roles(&temps, &stored.g, &mut next)?;
        std::mem::swap(&mut temps, &mut next);
        replay::move_to_roles(&out.id, &stored.g, &mut next_id)?;
        std::mem::swap(&mut out.id, &mut next_id);
        match &table {
            Some(table) => replay::apply_rows_with(
                &mut temps,
                &table.exchanges,
                &bodies,
                request.scheme,
                &mut scratch,
            ),
            None => {
                for batch in reader.table() {
                    exchanges.clear();
                    exchanges.extend(batch?.rows.iter().map(|r| Exchange::of(r, &info)));
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
        out.index = k + 1;
        out.time = info.snapshot_time(k + 1);
        out.temp.copy_from_slice(&temps);
        writer.write_snapshot(&out)?;
    }
    let seconds_replay = t.elapsed().as_secs_f64();
    let costs = ExtrapolationCosts {
        seconds_pairing,
        pairing_reused: reused,
        seconds_read_table,
        seconds_replay,
        seconds_per_period: seconds_replay / request.periods as f64,
        rows_per_second: rows as f64 * request.periods as f64 / seconds_replay.max(1e-12),
        rows,
    };
    writer.finish((!request.reproducible).then_some(&costs))?;
    Ok(ExtrapolationOutcome {
        particles: info.particles,
        rows,
        max_cfl,
        memory,
        limit,
        pairing: stored.summary,
        costs,
        total_heat_t1: heat_t1,
        total_heat_end: replay::total_heat(&temps, &bodies),
    })
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
