//! One extrapolation's state and a method per stage, in the order
//! [`extrapolate_recording`](super::extrapolate_recording) calls them: the plan, the memory
//! plan, the pairings, the tables, the replay written out, the outcome.

use super::{
    axial_period, has_mirror_image, ExtrapolationOutcome, ExtrapolationRequest, JumpStarts, Leave,
    MirrorCheck, Notice, TableChoice,
};
use crate::boundary::{self, AxialEnds, BoundaryMaps, Pool, PoolDraws, Redraws};
use crate::cache;
use crate::path::{self, RecurrencePolicy, Step};
use crate::replay::{
    self, Bodies, CflRow, Exchanges, MemoryNeeds, MemoryPlan, ReplayError, RoleTemperatures,
    Scheme, SyncScratch, Table, TableMode,
};
use crate::sidecar::{PairingSummary, StoredPairing};
use crate::ExtrapolateError;
use std::borrow::Cow;
use std::time::Instant;
use tdex_format::extrapolation::{Boundary, PathPairing, RecurrencePath, Roles, Symmetry};
use tdex_format::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationWriter, RecordingInfo, RecordingReader,
    Snapshot, FORMAT_VERSION,
};

/// A jump of the path, `(from, period)`: from snapshot `t_from` into recorded period
/// `period`.
type Jump = (u32, u32);

/// A pairing the path needs: of the end snapshot `t_from` (the recording's end `t_P'` unless
/// the path leaves every few periods) to the start of recorded period `period` (snapshot
/// `t_{period − 1}`).
struct PathStart {
    from: u32,
    period: u32,
    stored: StoredPairing,
}

/// One extrapolation of a recording: the path the request asks for, then what each stage
/// adds to it (the pairings of its starts, the tables it replays).
pub(super) struct Extrapolation<'a> {
    request: &'a ExtrapolationRequest,
    reader: RecordingReader,
    info: RecordingInfo,
    /// Recorded periods used, `P'`.
    used: u32,
    /// Seed of the path's jumps.
    seed: u64,
    /// The jump targets the output names (`None`: every recorded period used).
    targets: Option<Vec<u32>>,
    /// The recorded period each of the K periods replays, and whether it jumps there.
    steps: Vec<Step>,
    /// Whether each of the K periods is replayed in the mirror image of the recording.
    mirrored: Vec<bool>,
    /// Whether each recorded period used is replayed at all (only those tables are read).
    replayed: Vec<bool>,
    /// `t0 … t_P'`: the starts of the periods and the ends whose positions the output
    /// carries.
    snaps: Vec<Snapshot>,
    bodies: Bodies,
    /// Each jump the path makes, `(from, period)`, with its pairing if one is stored beside
    /// the recording.
    found: Vec<(Jump, Option<StoredPairing>)>,
    /// Rows of each recorded period used: the summary's counts (they size the memory
    /// estimate) until the tables are read, then the rows as decoded.
    rows_of: Vec<u64>,
    /// The pairing of each jump, reused or computed.
    pairings: Vec<PathStart>,
    /// With the axial mirror: each start's mirrored pairing beside its plain one.
    mirror_check: Vec<MirrorCheck>,
    /// The boundary maps, with the seed they are drawn from.
    boundary: Boundary,
    /// What the fresh maps redraw (`None`: the exact map).
    redraws: Option<Redraws>,
    /// With fresh boundary maps: each jump's pool of pairings, by `(from, period)`.
    pools: Vec<(Jump, Pool)>,
    /// Wall time of the pairings computed (and stored) by this run.
    seconds_pairing: f64,
    /// Whether every pairing of the path was found stored (the mirror check's aside).
    pairing_reused: bool,
    /// Each recorded period's table when held in memory (`None`: streamed from the file
    /// every period, or never replayed).
    tables: Vec<Option<Table>>,
    /// Rows of the tables read, each replayed period's once.
    rows: u64,
    /// The tables' largest CFL number of the explicit scheme (0 for empty tables).
    max_cfl: f64,
    /// Wall time of reading (or scanning) the tables.
    seconds_read_table: f64,
}

/// What the replay leaves for the outcome: its costs and the bed's heat before and after.
pub(super) struct Replayed {
    costs: ExtrapolationCosts,
    total_heat_t1: f64,
    total_heat_end: f64,
}

impl<'a> Extrapolation<'a> {
    /// Holds the request against the recording and lays the path out: the recorded periods
    /// used, the jumps, the snapshots and the pairings already stored for its starts (with
    /// [`JumpStarts::Nearest`], every start's pairing, which ranks them).
    pub(super) fn plan(
        request: &'a ExtrapolationRequest,
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<Self, ExtrapolateError> {
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
        if request.boundary != BoundaryMaps::Exact && !has_mirror_image(&info) {
            return Err(ExtrapolateError::NoDrumAxis {
                recording: request.recording.clone(),
            });
        }
        let redraws = Redraws::of(request.boundary, AxialEnds::of(axial_period(&info))).map_err(
            |refused| ExtrapolateError::CapZoneWithoutCaps {
                recording: request.recording.clone(),
                cap_zone_diameters: refused.cap_zone_diameters,
            },
        )?;
        if let (JumpStarts::Nearest(_), Leave::Every(every)) = (&request.jumps, request.leave) {
            return Err(ExtrapolateError::NearestLeavingEvery {
                recording: request.recording.clone(),
                used,
                every: every.get(),
            });
        }
        let seed = request.path_seed.unwrap_or_else(|| case_seed(&info));
        let snaps = (0..=used)
            .map(|index| cache::snapshot(&reader, index))
            .collect::<Result<Vec<Snapshot>, _>>()?;
        let mut ranking = StartRanking::unranked();
        let targets = match &request.jumps {
            JumpStarts::Every => None,
            JumpStarts::Listed(listed) => listed_targets(request, listed, used)?,
            JumpStarts::Nearest(k) => {
                ranking = StartRanking::of(request, &reader, &info, &snaps, notice)?;
                ranking.nearest(k.get(), used)
            }
        };
        let steps: Vec<Step> =
            RecurrencePolicy::with_targets(used, seed, targets.as_deref().unwrap_or(&[]))
                .leaving(request.leave)
                .take(request.periods as usize)
                .collect();
        // the paper's method pairs t1 to t0 even for no period (as it always has); a path
        // pairs only the jumps it makes
        let jumps = if used == 1 {
            vec![(1, 1)]
        } else {
            path::jumps(&steps)
        };
        let mirrored = path::mirrored(&steps, request.symmetry);
        let mut replayed = vec![used == 1; used as usize];
        for s in &steps {
            replayed[s.period() as usize - 1] = true;
        }
        let bodies = Bodies::of(&info, &snaps[0]);
        let found = jumps
            .iter()
            .map(|&(from, m)| {
                let image = start_image(&snaps, m, request.symmetry);
                let end = &snaps[from as usize];
                let stored = cache::load_image(&reader, &image, end, request.symmetry);
                ((from, m), stored)
            })
            .collect();
        let rows_of = (1..=used).map(|p| period_rows(&reader, p)).collect();
        Ok(Self {
            request,
            reader,
            info,
            used,
            seed,
            targets,
            steps,
            mirrored,
            replayed,
            snaps,
            bodies,
            found,
            rows_of,
            pairings: Vec::new(),
            mirror_check: Vec::new(),
            boundary: request.boundary.with_seed(seed),
            redraws,
            pools: Vec::new(),
            seconds_pairing: ranking.seconds,
            pairing_reused: ranking.reused,
            tables: Vec::new(),
            rows: 0,
            max_cfl: 0.0,
            seconds_read_table: 0.0,
        })
    }

    /// The memory the replay will need, stated and held against the limit before the
    /// pairing and the replay start: a table that does not fit is streamed, never left to
    /// the OOM killer.
    pub(super) fn memory_plan(
        &self,
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<MemoryPlan, ExtrapolateError> {
        let limit = &self.request.memory_limit;
        let needs = MemoryNeeds::estimate(
            self.info.particles as u64,
            self.rows_of
                .iter()
                .zip(&self.replayed)
                .filter(|(_, &r)| r)
                .map(|(rows, _)| rows)
                .sum(),
            self.reader.largest_table_chunk(),
            self.found.iter().all(|(_, s)| s.is_some()),
            self.used,
            self.found.len(),
        );
        let memory = MemoryPlan::choose(
            needs,
            limit.bytes,
            &limit.source,
            self.request.table == TableChoice::Streamed,
        )
        .map_err(|e| self.refused(e))?;
        notice(Notice::Memory {
            plan: &memory,
            limit,
        });
        Ok(memory)
    }

    /// Each pairing the path needs, reused or computed once (and stored for the next run),
    /// and with the axial mirror the check that the mirror holds.
    pub(super) fn pair(
        &mut self,
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<(), ExtrapolateError> {
        let found = std::mem::take(&mut self.found);
        let mut pairings = Vec::with_capacity(found.len());
        for ((from, period), found) in found {
            let stored = match found {
                Some(stored) => stored,
                None => {
                    self.pairing_reused = false;
                    self.compute_and_store((from, period), self.request.symmetry, notice)?
                }
            };
            pairings.push(PathStart {
                from,
                period,
                stored,
            });
        }
        self.pairings = pairings;
        if self.request.symmetry == Symmetry::AxialMirror {
            self.mirror_check = self.check_mirror(notice)?;
        }
        self.pools = self.fresh_pools()?;
        Ok(())
    }

    /// Each jump's pool of fresh pairings (none for the exact boundary), from the period the
    /// jump leaves (`t_{from−1}` to `t_from`; `t_P'` ends it unless the path leaves every
    /// few periods), each jump's maps drawn from a seed of its own. Computed every run: a
    /// pool costs `pool` pairings, which is small beside a DEM period, and storing it would
    /// write `pool` sidecars per jump.
    fn fresh_pools(&mut self) -> Result<Vec<(Jump, Pool)>, ExtrapolateError> {
        let started = Instant::now();
        let mut pools = Vec::new();
        let Some(redraws) = self.redraws else {
            return Ok(pools);
        };
        for p in &self.pairings {
            let start = start_image(&self.snaps, p.period, self.request.symmetry);
            let (before, end) = (
                &self.snaps[p.from as usize - 1],
                &self.snaps[p.from as usize],
            );
            // from the recording's end the seed is the start's alone, as it has always been
            let seed = self
                .seed
                .wrapping_add(u64::from(p.period))
                .wrapping_add(u64::from(self.used - p.from) << 32);
            let pool = boundary::fresh_pool(redraws, before, end, &start, seed)?;
            pools.push(((p.from, p.period), pool));
        }
        self.seconds_pairing += started.elapsed().as_secs_f64();
        Ok(pools)
    }

    /// The mirror holds only if the bed is its own mirror image at the recorded instants:
    /// each start's mirrored pairing is then as short as the plain one, which is reused or
    /// computed to say so.
    fn check_mirror(
        &mut self,
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<Vec<MirrorCheck>, ExtrapolateError> {
        let mut mirror_check = Vec::with_capacity(self.pairings.len());
        for at in 0..self.pairings.len() {
            let (from, period) = (self.pairings[at].from, self.pairings[at].period);
            let start = &self.snaps[period as usize - 1];
            let plain = match cache::load(&self.reader, start, &self.snaps[from as usize]) {
                Some(stored) => stored,
                None => self.compute_and_store((from, period), Symmetry::None, notice)?,
            };
            mirror_check.push(MirrorCheck::of(
                from,
                period - 1,
                &plain.summary,
                &self.pairings[at].stored.summary,
            ));
        }
        Ok(mirror_check)
    }

    /// Computes and stores the pairing of snapshot `t_from` to the start of recorded period
    /// `period` (its image under `symmetry`), timed with the run's pairings.
    fn compute_and_store(
        &mut self,
        (from, period): Jump,
        symmetry: Symmetry,
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<StoredPairing, ExtrapolateError> {
        let started = Instant::now();
        let start = start_image(&self.snaps, period, symmetry);
        let stored = pair_and_store(
            &self.reader,
            &self.info,
            self.request.reproducible,
            (&start, &self.snaps[from as usize]),
            symmetry,
            notice,
        )?;
        self.seconds_pairing += started.elapsed().as_secs_f64();
        Ok(stored)
    }

    /// The tables of the periods replayed: decoded once into memory, or scanned from the
    /// file for their rows and CFL numbers when `mode` streams them; the explicit scheme
    /// refuses a table whose CFL number reaches 1.
    pub(super) fn read_tables(&mut self, mode: TableMode) -> Result<(), ExtrapolateError> {
        let t = Instant::now();
        self.tables = vec![None; self.used as usize];
        let mut worst: Option<CflRow> = None;
        for p in (1..=self.used).filter(|&p| self.replayed[p as usize - 1]) {
            let at = p as usize - 1;
            // the rows as decoded (the summary's counts only sized the estimate)
            let found = if mode == TableMode::Streamed {
                let found = replay::scan_period(&self.reader, &self.bodies, p, |_, _| {})?;
                self.rows_of[at] = found.rows;
                found.worst
            } else {
                let (table, found) =
                    Table::read_period(&self.reader, &self.bodies, p, self.rows_of[at])?;
                self.rows_of[at] = table.exchanges.len() as u64;
                self.tables[at] = Some(table);
                found
            };
            if found.is_some_and(|f| worst.is_none_or(|w| f.cfl > w.cfl)) {
                worst = found;
            }
        }
        self.rows = self
            .replayed_periods()
            .map(|p| self.rows_of[p as usize - 1])
            .sum();
        self.seconds_read_table = t.elapsed().as_secs_f64();
        self.max_cfl = worst.map_or(0.0, |w| w.cfl);
        if let Some(w) = worst.filter(|w| self.request.scheme == Scheme::Explicit && w.cfl >= 1.0) {
            return Err(self.refused(w.refusal()));
        }
        Ok(())
    }

    /// Replays the K periods along the path and writes the extrapolation: `t1`, then the
    /// roles' temperatures at the end of every period, with the positions of the recorded
    /// period (or its image) the period replayed.
    pub(super) fn replay_and_write(&mut self) -> Result<Replayed, ExtrapolateError> {
        let request = self.request;
        let mut writer = ExtrapolationWriter::create(&request.output, &self.output_info())?;
        writer.write_snapshot(&self.snaps[1])?;

        // role a ends recorded period p at x_a(t_p): the snapshot's positions, radii and
        // velocities
        let total_heat_t1 = replay::total_heat(&self.snaps[1].temp, &self.bodies);
        let mut temps = RoleTemperatures::new(&self.snaps[1].temp, &self.bodies);
        let mut next = Vec::with_capacity(temps.len());
        let mut scratch = SyncScratch::default();
        let mut exchanges = Exchanges::default();
        // the output snapshot: t_p's positions and velocities (radii are per particle, the
        // same at every t_p), the extrapolated temperatures, and as `id` the particle that
        // plays each role (it moves with its heat, at the jumps only); the paper's method
        // never reads t1 again, so it takes t1 rather than copying it
        let mut out = if self.used == 1 && request.symmetry.is_none() {
            self.snaps.pop().expect("t0 and t1")
        } else {
            self.snaps[1].clone()
        };
        // the recorded period whose end the output's positions are, and in which image
        let mut positions_of = (1, false);
        let mut next_id = Vec::with_capacity(out.id.len());
        let mut pool_draws = PoolDraws::new(self.seed);
        let t = Instant::now();
        for ((k, step), &mirrored) in (1..=request.periods).zip(&self.steps).zip(&self.mirrored) {
            let p = step.period();
            if let Step::Jump { from, period } = *step {
                let drawn = draw_from_pool(self.boundary, &mut pool_draws);
                let g = self.pairing_at_jump((from, period), drawn);
                temps.move_to_roles(g, &mut next)?;
                replay::move_to_roles(&out.id, g, &mut next_id)?;
                std::mem::swap(&mut out.id, &mut next_id);
            }
            self.apply_period(p, &mut temps, &mut scratch, &mut exchanges)?;
            scratch.flush(&mut temps);
            if (p, mirrored) != positions_of {
                let end = &self.snaps[p as usize];
                let symmetry = request.symmetry;
                symmetry.copy_image(mirrored, &end.pos, &mut out.pos);
                symmetry.copy_image(mirrored, &end.vel, &mut out.vel);
                positions_of = (p, mirrored);
            }
            out.index = k + 1;
            out.time = self.info.snapshot_time(k + 1);
            temps.write_to(&mut out.temp);
            writer.write_snapshot(&out)?;
        }
        let seconds_replay = t.elapsed().as_secs_f64();
        let rows_replayed: u64 = self
            .steps
            .iter()
            .map(|s| self.rows_of[s.period() as usize - 1])
            .sum();
        let costs = ExtrapolationCosts {
            seconds_pairing: self.seconds_pairing,
            pairing_reused: self.pairing_reused,
            seconds_read_table: self.seconds_read_table,
            seconds_replay,
            seconds_per_period: seconds_replay / request.periods as f64,
            rows_per_second: rows_replayed as f64 / seconds_replay.max(1e-12),
            rows: self.rows,
        };
        writer.finish((!request.reproducible).then_some(&costs))?;
        Ok(Replayed {
            costs,
            total_heat_t1,
            total_heat_end: temps.total_heat(&self.bodies),
        })
    }

    /// The pairing a jump from the end of recorded period `from` into recorded period
    /// `period` moves the roles along: of `t_from` to that period's start (or its image),
    /// the exact one or the pool's `drawn`.
    fn pairing_at_jump(&self, jump: Jump, drawn: Option<usize>) -> &[u32] {
        match drawn {
            None => self
                .pairings
                .iter()
                .find(|p| (p.from, p.period) == jump)
                .map(|p| &p.stored.g[..])
                .expect("a pairing for every jump of the path"),
            Some(m) => self
                .pools
                .iter()
                .find(|(at, _)| *at == jump)
                .map(|(_, pool)| &pool.maps[m][..])
                .expect("a pool for every jump of the path"),
        }
    }

    /// Applies the rows of recorded period `p` to the roles' temperatures, from its table in
    /// memory or batch by batch from the file.
    fn apply_period(
        &self,
        p: u32,
        temps: &mut RoleTemperatures,
        scratch: &mut SyncScratch,
        exchanges: &mut Exchanges,
    ) -> Result<(), ExtrapolateError> {
        let scheme = self.request.scheme;
        match &self.tables[p as usize - 1] {
            Some(table) => {
                replay::apply_rows_with(temps, &table.exchanges, &self.bodies, scheme, scratch)
            }
            None => {
                let (batches, offset) = replay::period_batches(&self.reader, p);
                for batch in batches {
                    exchanges.clear();
                    for r in &batch?.rows {
                        exchanges.push_row(r, &self.info, offset);
                    }
                    replay::apply_rows_with(temps, exchanges, &self.bodies, scheme, scratch);
                }
            }
        }
        Ok(())
    }

    /// The extrapolation's info record: the recording it extends, the scheme, the periods
    /// and the roles, with the pairings' summaries as `--reproducible` asks.
    fn output_info(&self) -> ExtrapolationInfo {
        let request = self.request;
        ExtrapolationInfo {
            format_version: FORMAT_VERSION,
            // one version for the whole workspace: the binary's and this library's
            tool_version: env!("CARGO_PKG_VERSION").into(),
            recording: request.recording.display().to_string(),
            recording_info: self.info.clone(),
            scheme: request.scheme,
            periods: request.periods,
            roles: self.roles(|s| {
                if request.reproducible {
                    // a stored pairing made without --reproducible carries its time
                    s.summary.clone().reproducible()
                } else {
                    s.summary.clone()
                }
            }),
            symmetry: request.symmetry,
            mirror_check: self.mirror_check.clone(),
            boundary: self.boundary,
            fresh_pools: self.fresh_pool_summaries(),
        }
    }

    /// The pairing used (one recorded period) or the path followed, each pairing told by
    /// `summary`.
    fn roles(&self, summary: impl Fn(&StoredPairing) -> PairingSummary) -> Roles {
        if self.used == 1 {
            Roles::Pairing(summary(&self.pairings[0].stored))
        } else {
            Roles::Path(RecurrencePath {
                recorded_periods: self.used,
                seed: self.seed,
                jump_targets: self.targets.clone(),
                leave_every: match self.request.leave {
                    Leave::AtEnd => None,
                    Leave::Every(n) => Some(n.get()),
                },
                replayed: self.steps.iter().map(|s| s.period()).collect(),
                pairings: self
                    .pairings
                    .iter()
                    .map(|p| PathPairing {
                        end: p.from,
                        start: p.period - 1,
                        summary: summary(&p.stored),
                    })
                    .collect(),
            })
        }
    }

    /// What the extrapolation found and cost, the pairings with their summaries as
    /// computed (with their times) or as stored.
    pub(super) fn outcome(self, memory: MemoryPlan, replayed: Replayed) -> ExtrapolationOutcome {
        ExtrapolationOutcome {
            particles: self.info.particles,
            rows: self.rows,
            max_cfl: self.max_cfl,
            memory,
            limit: self.request.memory_limit.clone(),
            roles: self.roles(|s| s.summary.clone()),
            symmetry: self.request.symmetry,
            boundary: self.boundary,
            fresh_pools: self.fresh_pool_summaries(),
            mirror_check: self.mirror_check,
            costs: replayed.costs,
            total_heat_t1: replayed.total_heat_t1,
            total_heat_end: replayed.total_heat_end,
        }
    }

    /// Each start's pool of fresh pairings, told in the output and the outcome.
    fn fresh_pool_summaries(&self) -> Vec<tdex_format::extrapolation::FreshPool> {
        self.pools.iter().map(|(_, pool)| pool.summary).collect()
    }

    /// The recorded periods replayed at least once, in order.
    fn replayed_periods(&self) -> impl Iterator<Item = u32> + '_ {
        (1..=self.used).filter(|&p| self.replayed[p as usize - 1])
    }

    /// The replay of this recording refused for `error` (memory, the CFL guard).
    fn refused(&self, error: ReplayError) -> ExtrapolateError {
        ExtrapolateError::Refused {
            recording: self.request.recording.clone(),
            error,
        }
    }
}

/// The jump targets a request names, checked against the `used` recorded periods; `None`
/// when they are every period used, the default path.
fn listed_targets(
    request: &ExtrapolationRequest,
    listed: &[u32],
    used: u32,
) -> Result<Option<Vec<u32>>, ExtrapolateError> {
    if let Some(&bad) = listed.iter().find(|t| !(1..=used).contains(*t)) {
        return Err(ExtrapolateError::JumpTarget {
            recording: request.recording.clone(),
            target: bad,
            used,
        });
    }
    Ok(unless_every(path::distinct_ascending(listed), used))
}

/// `targets`, or `None` when they are every period used: the default path, nothing to record.
fn unless_every(targets: Vec<u32>, used: u32) -> Option<Vec<u32>> {
    (!targets.is_empty() && targets.len() < used as usize).then_some(targets)
}

/// Every start of the recording ranked by the mean distance (diameters) of its pairing with
/// the end `t_P'`, the recurrence norm [`JumpStarts::Nearest`] chooses by: each pairing
/// reused or computed and stored, as the path's own are.
struct StartRanking {
    /// (mean distance, period), nearest first; ties to the earlier period.
    by_distance: Vec<(f64, u32)>,
    /// Wall time of the pairings computed here.
    seconds: f64,
    /// Whether every pairing was found stored.
    reused: bool,
}

/// Computes the pairing of `end` to `start` (a start, or its image under `symmetry`) and
/// stores it beside the recording; the stored pairing only saves time next run, so a
/// recording on a full or read-only disk is still extrapolated.
fn pair_and_store(
    reader: &RecordingReader,
    info: &RecordingInfo,
    reproducible: bool,
    (start, end): (&Snapshot, &Snapshot),
    symmetry: Symmetry,
    notice: &mut impl FnMut(Notice<'_>),
) -> Result<StoredPairing, ExtrapolateError> {
    let mut stored = cache::compute(start, end, axial_period(info))?;
    if reproducible {
        stored.summary = stored.summary.reproducible();
    }
    if let Err(e) = cache::store_image(reader, end.index, start.index, symmetry, &stored) {
        notice(Notice::PairingNotStored(&e));
    }
    Ok(stored)
}

impl StartRanking {
    /// No start ranked: no pairing computed, so none but stored ones.
    fn unranked() -> Self {
        Self {
            by_distance: Vec::new(),
            seconds: 0.0,
            reused: true,
        }
    }

    fn of(
        request: &ExtrapolationRequest,
        reader: &RecordingReader,
        info: &RecordingInfo,
        snaps: &[Snapshot],
        notice: &mut impl FnMut(Notice<'_>),
    ) -> Result<Self, ExtrapolateError> {
        let end = &snaps[snaps.len() - 1];
        let mut ranking = Self::unranked();
        for period in 1..snaps.len() as u32 {
            let start = &snaps[period as usize - 1];
            let stored = match cache::load(reader, start, end) {
                Some(stored) => stored,
                None => {
                    let started = Instant::now();
                    let stored = pair_and_store(
                        reader,
                        info,
                        request.reproducible,
                        (start, end),
                        Symmetry::None,
                        notice,
                    )?;
                    ranking.seconds += started.elapsed().as_secs_f64();
                    ranking.reused = false;
                    stored
                }
            };
            ranking
                .by_distance
                .push((stored.summary.mean_distance_diameters, period));
        }
        ranking
            .by_distance
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Ok(ranking)
    }

    /// The `k` nearest starts, in ascending order (`None`: all of the `used`).
    fn nearest(&self, k: u32, used: u32) -> Option<Vec<u32>> {
        let chosen: Vec<u32> = self
            .by_distance
            .iter()
            .take(k as usize)
            .map(|&(_, p)| p)
            .collect();
        unless_every(path::distinct_ascending(&chosen), used)
    }
}

/// Which pairing of its pool the next jump takes (`None` with the exact boundary, which
/// draws nothing).
fn draw_from_pool(boundary: Boundary, draws: &mut PoolDraws) -> Option<usize> {
    match boundary {
        Boundary::Exact => None,
        Boundary::FreshSteps { pool, .. } | Boundary::FreshDrift { pool, .. } => {
            Some(draws.next(pool as usize))
        }
    }
}

/// What a jump into recorded period `period` enters: its start itself, or its mirror image.
fn start_image(snaps: &[Snapshot], period: u32, symmetry: Symmetry) -> Cow<'_, Snapshot> {
    cache::start_image(&snaps[period as usize - 1], symmetry)
}

/// The case's `seed` (the default seed of the path's jumps), 0 if the recording has none
/// (an imported run).
fn case_seed(info: &RecordingInfo) -> u64 {
    info.case_resolved
        .get("seed")
        .and_then(serde_json::Value::as_u64)
        .unwrap_or(0)
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
