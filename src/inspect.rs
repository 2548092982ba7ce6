//! `tdex inspect`: what a recording holds, read back from the file itself (the whole table is
//! streamed, so a damaged file is reported here rather than during an extrapolation), or
//! what an extrapolation holds (its pairing, scheme and heat balance).

use crate::cli::InspectPlan;
use crate::fmt;
use anyhow::Result;
use extrapolate::replay::{
    self, Bodies, CflRow, Exchange, Exchanges, RoleTemperatures, Scheme, SyncScratch,
};
use serde::Serialize;
use tdex_format::extrapolation::Roles;
use tdex_format::{
    ExtrapolationCosts, ExtrapolationReader, FormatError, RecordingCosts, RecordingReader, Snapshot,
};

/// Share of collisions that must last at least the suggested `n` steps (the paper's 97 %).
const KEEP_FRACTION: f64 = 0.97;

/// Histogram bins the human summary shows one by one; the rest are summed in one line.
const SHOWN_BINS: usize = 24;

#[derive(Debug, Serialize)]
struct HistogramBin {
    /// Consecutive samples the collision was seen at.
    samples: u32,
    /// Duration bounds implied (steps).
    min_steps: u64,
    max_steps: u64,
    count: u64,
}

#[derive(Debug, Serialize)]
struct SnapshotSummary {
    index: u32,
    time: f64,
    mean_temperature: f64,
    mean_position: [f64; 3],
}

/// How a recording was sampled; shared by the `record` and `inspect` reports.
#[derive(Debug, Serialize)]
pub struct Sampling {
    pub particles: u32,
    pub dt: f64,
    pub n: u32,
    pub dtc_max_steps: u32,
    pub tau: f64,
    pub period_steps: u64,
    pub t0: f64,
    pub reference_periods: u32,
    /// DEM twins continued from `t_twins_from` over the reference periods.
    pub twins: u32,
    /// The recorded snapshot the twins part from the run at (absent when 1, as in the file).
    #[serde(skip_serializing_if = "is_one")]
    pub twins_from: u32,
    /// Consecutive periods recorded from `t0` (absent when 1, as in the file).
    #[serde(skip_serializing_if = "is_one")]
    pub recorded_periods: u32,
}

fn is_one(x: &u32) -> bool {
    *x == 1
}

impl Sampling {
    pub fn of(info: &tdex_format::RecordingInfo) -> Self {
        Self {
            particles: info.particles,
            dt: info.dt,
            n: info.sample_every,
            dtc_max_steps: info.dtc_max_steps,
            tau: info.tau,
            period_steps: info.period_steps,
            t0: info.t0,
            reference_periods: info.reference_periods,
            twins: info.twins,
            twins_from: info.twins_from,
            recorded_periods: info.recorded_periods,
        }
    }

    /// The line naming the recorded periods and the rows of each, when there are several.
    pub fn print_recorded_periods(&self, period_rows: &[u64]) {
        if self.recorded_periods < 2 {
            return;
        }
        let rows: Vec<String> = period_rows.iter().map(u64::to_string).collect();
        println!(
            "recorded      {} periods, t0 to t{}, one after the other; rows in each: {}",
            self.recorded_periods,
            self.recorded_periods,
            rows.join(", ")
        );
    }

    /// The `period` line of the human summaries: `τ`, its steps (`= N steps of Δt`, or
    /// `(N steps of Δt)` when `bracketed`) and `t0`, then `then`.
    pub fn print_period(&self, bracketed: bool, then: &str) {
        let steps = format!("{} steps of {}", self.period_steps, fmt::seconds(self.dt));
        let steps = if bracketed {
            format!("({steps})")
        } else {
            format!("= {steps}")
        };
        println!(
            "period        τ = {} {steps} from t0 = {}; {then}",
            fmt::seconds(self.tau),
            fmt::seconds(self.t0)
        );
    }

    /// `n = 10, Δt_c^max = 100 steps`.
    pub fn n_and_dtc_max(&self) -> String {
        format!("n = {}, Δt_c^max = {} steps", self.n, self.dtc_max_steps)
    }
}

/// `value` as one pretty JSON object with `--json`, else as `human` writes it.
pub fn emit<T: Serialize>(json: bool, value: &T, human: impl FnOnce(&T)) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(value)?);
    } else {
        human(value);
    }
    Ok(())
}

/// The first line of a human summary: what `file` is, its size and versions.
fn print_file(kind: &str, file: &str, bytes: u64, format_version: u32, tool_version: &str) {
    println!(
        "{kind:<13} {file} ({:.1} MB, format {format_version}, tdex {tool_version})",
        bytes as f64 / 1e6
    );
}

/// The case's name as resolved into the recording ("" without one).
fn case_name(info: &tdex_format::RecordingInfo) -> String {
    info.case_resolved
        .get("name")
        .and_then(|v| v.as_str())
        .unwrap_or("")
        .into()
}

/// The walls held at a temperature.
fn conducting_walls(info: &tdex_format::RecordingInfo) -> usize {
    info.walls
        .iter()
        .filter(|w| w.temperature.is_some())
        .count()
}

/// One size class of a bed: its radius (m) and how many particles have it.
#[derive(Debug, Serialize)]
struct SizeClassCount {
    radius: f64,
    particles: usize,
}

/// The size classes of a snapshot, smallest radius first; empty for a bed of one size.
fn size_classes(s: &Snapshot) -> Vec<SizeClassCount> {
    let classes = crate::compare::classes::SizeClasses::of(&s.radius);
    if classes.len() < 2 {
        return Vec::new();
    }
    classes
        .radii
        .iter()
        .map(|&radius| SizeClassCount {
            radius,
            particles: s.radius.iter().filter(|&&r| r == radius).count(),
        })
        .collect()
}

/// A length in millimetres, to 4 significant digits without float noise.
fn fmt_mm(metres: f64) -> String {
    crate::fmt::sig(metres * 1e3, 4)
}

/// The mean particle temperature of `s` (K).
fn mean_temperature(s: &Snapshot) -> f64 {
    s.temp.iter().sum::<f64>() / s.len().max(1) as f64
}

/// `tdex inspect --json` on a recording (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct Inspection {
    /// `recording`.
    kind: &'static str,
    file: String,
    file_bytes: u64,
    format_version: u32,
    tool_version: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    walls: usize,
    conducting_walls: usize,
    /// A bed of several sizes: each class's radius (m) and particle count, smallest first
    /// (absent for one size, so that its JSON is as before).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    size_classes: Vec<SizeClassCount>,
    /// A periodic section: its length along the axis (m); absent for a drum with end caps.
    #[serde(skip_serializing_if = "Option::is_none")]
    axial_period: Option<f64>,
    area_encoding: String,
    rows: u64,
    wall_rows: u64,
    /// Rows of each recorded period, counted in the table (absent for one period).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    period_rows: Vec<u64>,
    batches: u64,
    contact_steps: u64,
    table_bytes: u64,
    bytes_per_row: f64,
    collisions: u64,
    duration_histogram: Vec<HistogramBin>,
    /// The largest `n` that [`KEEP_FRACTION`] of the collisions outlast and that divides the
    /// recording's `period_steps` and `dtc_max_steps` (so `--n` accepts it as it is).
    suggested_n: Option<u64>,
    /// The largest `n` that [`KEEP_FRACTION`] of the collisions outlast, whatever `τ` and
    /// `Δt_c^max` allow.
    suggested_n_unconstrained: Option<u64>,
    max_cfl: Option<CflRow>,
    /// With a heated mantle: the heat it gave the bed over the first recorded period, in the
    /// DEM and from the period's table replayed on the `t0` temperatures (absent with
    /// adiabatic walls, so that their JSON is as before).
    #[serde(skip_serializing_if = "Option::is_none")]
    recorded_wall_heat: Option<RecordedWallHeat>,
    snapshots: Vec<SnapshotSummary>,
    costs: Option<RecordingCosts>,
}

/// The heat (J) the conducting walls gave the bed over the first recorded period `[t0, t1]`:
/// `dem` is `Σ C T` at `t1` less at `t0` (the other walls are adiabatic, the contacts
/// conserve it), `replayed` the same from the period's rows applied to the `t0` temperatures
/// with the explicit scheme, each particle in its own role. Their difference is what the
/// table's sampling (`n`, `Δt_c^max`, the areas) loses of the wall's heat.
#[derive(Debug, Serialize)]
struct RecordedWallHeat {
    dem: f64,
    replayed: f64,
    /// `(replayed − dem) / dem`.
    relative_difference: f64,
}

/// `tdex inspect --json` on an extrapolation (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct ExtrapolationInspection {
    /// `extrapolation`.
    kind: &'static str,
    file: String,
    file_bytes: u64,
    format_version: u32,
    tool_version: String,
    /// The recording replayed (path as given when extrapolating).
    recording: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    walls: usize,
    conducting_walls: usize,
    scheme: String,
    periods: u32,
    /// How the roles moved between periods, as stored: `pairing` (the pairing's summary, see
    /// `tdex pair --json`) for one recorded period, `path` for several.
    #[serde(flatten)]
    roles: tdex_format::extrapolation::Roles,
    /// `none` or `axial_mirror`: the drum's symmetry the jumps used.
    symmetry: tdex_format::extrapolation::Symmetry,
    /// With the mirror: each start's mirrored pairing beside its plain one, as stored.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    mirror_check: Vec<tdex_format::extrapolation::MirrorCheck>,
    /// With fresh boundary maps: the boundary (pool, cell, seed) and each start's pool, as
    /// stored; absent for the exact pairing.
    #[serde(skip_serializing_if = "tdex_format::extrapolation::Boundary::is_exact")]
    boundary: tdex_format::extrapolation::Boundary,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    fresh_pools: Vec<tdex_format::extrapolation::FreshPool>,
    /// Σ m c T (J) over the particles at the first snapshot (`t1`) and at the last, with
    /// `m c = density · heat_capacity · (4/3)π r³` of the recording's material.
    total_heat_start: f64,
    total_heat_end: f64,
    /// `(end − start) / start`.
    heat_relative_change: f64,
    /// Mean particle temperature (K) at the first and at the last snapshot.
    mean_temperature_start: f64,
    mean_temperature_end: f64,
    /// Heat (J) the conducting walls gave the bed over the extrapolation (`end − start`);
    /// `null` without conducting walls (the total is then conserved).
    wall_heat: Option<f64>,
    snapshots: Vec<ExtrapolatedSnapshot>,
    costs: Option<ExtrapolationCosts>,
}

#[derive(Debug, Serialize)]
struct ExtrapolatedSnapshot {
    index: u32,
    time: f64,
    mean_temperature: f64,
    total_heat: f64,
}

/// Summarises a recording, or an extrapolation (a file without recording metadata is
/// read as one, the way `tdex compare` reads its second file), or where a checkpointed
/// recording stands.
pub fn run(plan: &InspectPlan) -> Result<()> {
    if recorder::record::is_checkpoint(&plan.file) {
        return inspect_checkpoint(plan);
    }
    match RecordingReader::open(&plan.file) {
        Ok(reader) => inspect_recording(plan, &reader),
        Err(FormatError::NotRecording {
            path,
            detail: as_recording,
            ..
        }) => match ExtrapolationReader::open(&plan.file) {
            Ok(reader) => inspect_extrapolation(plan, &reader),
            Err(FormatError::NotRecording {
                detail: as_extrapolation,
                ..
            }) => Err(FormatError::NotRecording {
                path,
                expected: "recording or extrapolation",
                detail: format!(
                    "{as_recording} (read as a recording); {as_extrapolation} (read as an \
                     extrapolation)"
                ),
            }
            .into()),
            Err(e) => Err(e.into()),
        },
        Err(e) => Err(e.into()),
    }
}

/// Where a checkpointed `tdex record` stands, and how long it has left at its pace so far.
#[derive(Debug, Serialize)]
struct CheckpointInspection {
    file: String,
    file_bytes: u64,
    tool_version: String,
    case: String,
    case_path: String,
    /// The recording the run writes (absolute path).
    recording: String,
    recorded_periods: u32,
    reference_periods: u32,
    twins: u32,
    twins_from: u32,
    /// The checkpoint's own words for where the run stands (its first line).
    stands_at: String,
    stage: recorder::record::Stage,
    steps_done: u64,
    steps_total: u64,
    /// Wall-clock seconds the run has taken to this checkpoint (over all its resumptions).
    wall_seconds: f64,
    /// The part of the run it stands in (settling and spin-up, recorded periods, reference
    /// periods, twins), its steps and its wall time so far.
    part: recorder::record::Part,
    steps_done_in_part: u64,
    part_wall_seconds: f64,
    /// The time left; absent before any step.
    left: Option<TimeLeft>,
    resume: String,
}

fn inspect_checkpoint(plan: &InspectPlan) -> Result<()> {
    use recorder::record::Checkpoint;
    let checkpoint = Checkpoint::read(&plan.file)?;
    let case = checkpoint.case(&plan.file)?;
    let steps = checkpoint.steps(&case);
    let e = &checkpoint.elapsed;
    let wall_seconds = e.to_t0 + e.period + e.reference + e.twins;
    let left = steps.total - steps.done;
    let part_wall_seconds = steps.part.seconds(e);
    let pace = if steps.done_in_part > 0 && part_wall_seconds > 0.0 {
        Some((steps.done_in_part, part_wall_seconds, PaceOf::ThePart))
    } else {
        (steps.done > 0).then_some((steps.done, wall_seconds, PaceOf::TheWholeRun))
    };
    let stands_at = checkpoint.stands_at(&case);
    let o = &checkpoint.options;
    let inspection = CheckpointInspection {
        file: plan.file.display().to_string(),
        file_bytes: std::fs::metadata(&plan.file).map_or(0, |m| m.len()),
        tool_version: checkpoint.tool_version.clone(),
        case: case.name.clone(),
        case_path: checkpoint.case_path.display().to_string(),
        recording: checkpoint.dest.display().to_string(),
        recorded_periods: o.recorded_periods,
        reference_periods: o.reference_periods,
        twins: o.twins,
        twins_from: o.twins_from,
        stands_at,
        stage: checkpoint.stage,
        steps_done: steps.done,
        steps_total: steps.total,
        wall_seconds,
        part: steps.part,
        steps_done_in_part: steps.done_in_part,
        part_wall_seconds,
        left: pace.map(|(steps, seconds, pace_of)| TimeLeft {
            seconds: seconds / steps as f64 * left as f64,
            steps_per_minute: 60.0 * steps as f64 / seconds,
            pace_of,
        }),
        resume: format!("tdex record --resume {}", plan.file.display()),
    };
    emit(plan.json, &inspection, print_checkpoint)
}

/// A part of a run in words: "the twins".
fn part_words(part: recorder::record::Part) -> &'static str {
    use recorder::record::Part;
    match part {
        Part::ToT0 => "the settling and spin-up",
        Part::Recorded => "the recorded periods",
        Part::Reference => "the reference periods",
        Part::Twins => "the twins",
    }
}

/// The steps left of a checkpointed run at a pace it has kept.
#[derive(Debug, Serialize)]
struct TimeLeft {
    seconds: f64,
    steps_per_minute: f64,
    pace_of: PaceOf,
}

/// Whose pace [`TimeLeft`] goes at: the part the run stands in (its steps over its wall
/// time), or the whole run so far when that part has not run a step yet. The part's by
/// choice: settling is slower per step, and a machine shared earlier in the run says nothing
/// of the pace now.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum PaceOf {
    ThePart,
    TheWholeRun,
}

/// `, 2 DEM twins from t1` (empty without twins), after the reference periods.
fn twins_phrase(twins: u32, twins_from: u32) -> String {
    match twins {
        0 => String::new(),
        1 => format!(", 1 DEM twin from t{twins_from}"),
        m => format!(", {m} DEM twins from t{twins_from}"),
    }
}

fn print_checkpoint(c: &CheckpointInspection) {
    println!(
        "checkpoint    {} ({:.1} MB, tdex {}): a tdex record run, resumable",
        c.file,
        c.file_bytes as f64 / 1e6,
        c.tool_version
    );
    println!("case          {} ({})", c.case, c.case_path);
    let twins = twins_phrase(c.twins, c.twins_from);
    println!(
        "recording to  {}: {} recorded period{}, {} reference periods{twins}",
        c.recording,
        c.recorded_periods,
        if c.recorded_periods == 1 { "" } else { "s" },
        c.reference_periods
    );
    println!("stands at     {}", c.stands_at);
    println!(
        "done          {} of {} steps ({:.1} %) in {} of wall time",
        c.steps_done,
        c.steps_total,
        100.0 * c.steps_done as f64 / c.steps_total.max(1) as f64,
        crate::progress::duration(std::time::Duration::from_secs_f64(c.wall_seconds.max(0.0)))
    );
    if let Some(left) = &c.left {
        let pace = match left.pace_of {
            PaceOf::ThePart => format!(
                "the pace of {} so far ({} steps a minute)",
                part_words(c.part),
                left.steps_per_minute.round()
            ),
            PaceOf::TheWholeRun => "the pace so far".to_string(),
        };
        println!(
            "left          about {} at {pace}",
            crate::progress::duration(std::time::Duration::from_secs_f64(
                left.seconds.clamp(0.0, 1e9)
            ))
        );
    }
    println!("continue with {}", c.resume);
}

fn inspect_recording(plan: &InspectPlan, reader: &RecordingReader) -> Result<()> {
    let info = reader.info().clone();
    let snapshots = reader.snapshots()?;
    let t0 = snapshots.iter().find(|s| s.index == 0).ok_or_else(|| {
        tdex_format::FormatError::Corrupt {
            path: plan.file.clone(),
            detail: "no snapshot at t0 (index 0)".into(),
        }
    })?;
    let (mut wall_rows, mut contact_steps) = (0u64, 0u64);
    let mut period_rows = vec![0u64; info.recorded_periods as usize];
    let bodies = Bodies::of(&info, t0);
    // with a heated mantle the first period is replayed from t0 in the same pass
    let mut wall_heat = (conducting_walls(&info) > 0).then(|| WallHeatReplay::new(t0, &bodies));
    let found = replay::scan(reader, &bodies, |r, exchange| {
        wall_rows += (r.j >= info.particles) as u64;
        contact_steps += r.duration_steps as u64;
        let period = info.period_of_step(r.start_step) as usize;
        if let Some(rows) = period_rows.get_mut(period) {
            *rows += 1;
        }
        if let Some(replay) = wall_heat.as_mut().filter(|_| period == 0) {
            replay.push(exchange, r.start_step as u32);
        }
    })?;
    if info.recorded_periods == 1 {
        period_rows.clear();
    }
    let t1 = snapshots.iter().find(|s| s.index == 1);
    let recorded_wall_heat = wall_heat.zip(t1).map(|(replay, t1)| replay.finish(t0, t1));
    let summary = reader.summary().cloned();
    let n = info.sample_every as u64;
    let histogram: Vec<HistogramBin> = summary.as_ref().map_or_else(Vec::new, |s| {
        s.duration_histogram
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .map(|(samples, &count)| HistogramBin {
                samples: samples as u32,
                min_steps: (samples as u64 - 1) * n + 1,
                max_steps: (samples as u64 + 1) * n - 1,
                count,
            })
            .collect()
    });
    let collisions: u64 = histogram.iter().map(|b| b.count).sum();
    // the largest n that KEEP_FRACTION of the collisions certainly outlast
    let suggested_n_unconstrained = {
        let mut shorter = 0u64;
        histogram.iter().find_map(|b| {
            shorter += b.count;
            (shorter as f64 > (1.0 - KEEP_FRACTION) * collisions as f64).then_some(b.min_steps)
        })
    };
    let suggested_n = suggested_n_unconstrained
        .map(|n| largest_divisor_up_to(gcd(info.period_steps, info.dtc_max_steps as u64), n));
    let inspection = Inspection {
        kind: "recording",
        file: plan.file.display().to_string(),
        file_bytes: reader.file_bytes(),
        format_version: info.format_version,
        tool_version: info.tool_version.clone(),
        case: case_name(&info),
        sampling: Sampling::of(&info),
        walls: info.walls.len(),
        conducting_walls: conducting_walls(&info),
        size_classes: size_classes(t0),
        axial_period: extrapolate::axial_period(&info),
        area_encoding: format!("{:?}", info.area_encoding).to_lowercase(),
        rows: found.rows,
        wall_rows,
        period_rows,
        batches: found.batches,
        contact_steps,
        table_bytes: reader.table_bytes(),
        bytes_per_row: reader.table_bytes() as f64 / found.rows.max(1) as f64,
        collisions,
        duration_histogram: histogram,
        suggested_n,
        suggested_n_unconstrained,
        max_cfl: found.worst,
        recorded_wall_heat,
        snapshots: snapshots
            .iter()
            .map(|s| {
                let n = s.len().max(1) as f64;
                let mut mean = [0.0; 3];
                for p in &s.pos {
                    for a in 0..3 {
                        mean[a] += p[a] / n;
                    }
                }
                SnapshotSummary {
                    index: s.index,
                    time: s.time,
                    mean_temperature: mean_temperature(s),
                    mean_position: mean,
                }
            })
            .collect(),
        costs: reader.costs().cloned(),
    };
    emit(plan.json, &inspection, print_human)
}

/// The first recorded period's rows applied, as the scan hands them over, to the `t0`
/// temperatures with the explicit scheme (at `t0` particle k plays role k): the wall's heat
/// over the period as the table gives it ([`RecordedWallHeat`]).
struct WallHeatReplay<'a> {
    bodies: &'a Bodies,
    roles: RoleTemperatures,
    scratch: SyncScratch,
    /// Rows waiting to be applied: a batch's worth at a time.
    rows: Exchanges,
}

impl<'a> WallHeatReplay<'a> {
    /// Rows applied at once; the scheme's result does not depend on it.
    const BATCH: usize = 4096;

    fn new(t0: &Snapshot, bodies: &'a Bodies) -> Self {
        Self {
            bodies,
            roles: RoleTemperatures::new(&t0.temp, bodies),
            scratch: SyncScratch::default(),
            rows: Exchanges::with_room_for(Self::BATCH as u64),
        }
    }

    fn push(&mut self, exchange: Exchange, start_step: u32) {
        self.rows.push(exchange, start_step);
        if self.rows.len() == Self::BATCH {
            self.apply();
        }
    }

    fn apply(&mut self) {
        let (bodies, scratch) = (self.bodies, &mut self.scratch);
        replay::apply_rows_with(
            &mut self.roles,
            &self.rows,
            bodies,
            Scheme::Explicit,
            scratch,
        );
        self.rows.clear();
    }

    fn finish(mut self, t0: &Snapshot, t1: &Snapshot) -> RecordedWallHeat {
        self.apply();
        self.scratch.flush(&mut self.roles);
        let start = replay::total_heat(&t0.temp, self.bodies);
        let dem = replay::total_heat(&t1.temp, self.bodies) - start;
        let replayed = self.roles.total_heat(self.bodies) - start;
        RecordedWallHeat {
            dem,
            replayed,
            relative_difference: (replayed - dem) / dem,
        }
    }
}

fn print_human(s: &Inspection) {
    print_file(
        "recording",
        &s.file,
        s.file_bytes,
        s.format_version,
        &s.tool_version,
    );
    println!(
        "case          {}: {} particles, {} walls ({} conducting){}",
        s.case,
        s.sampling.particles,
        s.walls,
        s.conducting_walls,
        match s.axial_period {
            Some(length) => format!(", a periodic section {} mm long", fmt_mm(length)),
            None => String::new(),
        }
    );
    if !s.size_classes.is_empty() {
        let classes: Vec<String> = s
            .size_classes
            .iter()
            .map(|c| format!("{} of {} mm", c.particles, fmt_mm(c.radius)))
            .collect();
        println!(
            "sizes         {} classes by radius: {}",
            s.size_classes.len(),
            classes.join(", ")
        );
    }
    s.sampling.print_period(
        false,
        &format!(
            "{} reference periods{}",
            s.sampling.reference_periods,
            twins_phrase(s.sampling.twins, s.sampling.twins_from)
        ),
    );
    println!(
        "sampling      n = {} steps, Δt_c^max = {} steps, sqrt(a) {}",
        s.sampling.n, s.sampling.dtc_max_steps, s.area_encoding
    );
    println!(
        "table         {} rows ({} wall rows) in {} batches, {} contact-steps; {:.2} bytes per row ({:.1} MB)",
        s.rows, s.wall_rows, s.batches, s.contact_steps, s.bytes_per_row, s.table_bytes as f64 / 1e6
    );
    s.sampling.print_recorded_periods(&s.period_rows);
    println!(
        "collisions    {} (durations: samples seen → steps)",
        s.collisions
    );
    print_durations(s);
    println!("suggested n   {}", suggested_n_line(s));
    if let Some(h) = &s.recorded_wall_heat {
        println!(
            "wall heat     over the recorded period: {} J in the DEM, {} J from its table replayed from t0 ({:+.2} %)",
            fmt::sig(h.dem, 6),
            fmt::sig(h.replayed, 6),
            100.0 * h.relative_difference
        );
    }
    if let Some(w) = &s.max_cfl {
        println!(
            "max CFL c     {:.4} (row {}: bodies {} and {}, m = {} steps, sqrt(a) = {:.4e} m){}",
            w.cfl,
            w.row,
            w.i,
            w.j,
            w.duration_steps,
            w.sqrt_area,
            if w.cfl >= 1.0 {
                " — the explicit replay will refuse this table"
            } else {
                ""
            }
        );
    }
    print_snapshots_and_costs(s);
}

/// The collisions' durations, bin by bin up to the shown bins, then the rest in one line.
fn print_durations(s: &Inspection) {
    let total = s.collisions.max(1) as f64;
    let mut cumulative = 0u64;
    let (shown, tail) = s
        .duration_histogram
        .split_at(s.duration_histogram.len().min(SHOWN_BINS));
    for b in shown {
        cumulative += b.count;
        println!(
            "  {:>4} samples ({:>5}–{:<5} steps) {:>10}  {:5.1} % ≤",
            b.samples,
            b.min_steps,
            b.max_steps,
            b.count,
            100.0 * cumulative as f64 / total
        );
    }
    if let (Some(first), Some(last)) = (tail.first(), tail.last()) {
        let count: u64 = tail.iter().map(|b| b.count).sum();
        println!(
            "  {} more bins, {}–{} samples ({}–{} steps): {} collisions ({:.1} %), not shown one by one; --json has them all",
            tail.len(),
            first.samples,
            last.samples,
            first.min_steps,
            last.max_steps,
            count,
            100.0 * count as f64 / total
        );
    }
}

/// Each snapshot's time, mean temperature and mean position, then the recording's costs.
fn print_snapshots_and_costs(s: &Inspection) {
    for snap in &s.snapshots {
        println!(
            "snapshot {:>3}  t = {}, mean T {:.6} K, mean position [{:.5}, {:.5}, {:.5}] m",
            snap.index,
            fmt::seconds(snap.time),
            snap.mean_temperature,
            snap.mean_position[0],
            snap.mean_position[1],
            snap.mean_position[2]
        );
    }
    if let Some(c) = &s.costs {
        let stages: Vec<String> = c
            .stage_seconds
            .iter()
            .map(|(k, v)| format!("{k} {v:.2} s"))
            .collect();
        println!(
            "costs         {:.1} s to t0, {:.1} s period ({:.1} s recorder), {:.1} s reference; {} threads{}; stages {}",
            c.seconds_to_t0, c.seconds_period, c.seconds_recorder, c.seconds_reference, c.threads,
            crate::report::costs::vectors_clause(&c.vector_instructions),
            stages.join(", ")
        );
    }
}

/// The suggested `n` (it divides the recording's `τ` and `Δt_c^max` steps, so `--n` takes
/// it with them), and when the 97 % share alone would allow a larger one, what to change
/// for it: a second line, indented.
fn suggested_n_line(s: &Inspection) -> String {
    let (Some(n), Some(free)) = (s.suggested_n, s.suggested_n_unconstrained) else {
        return "- (no collisions)".into();
    };
    let (period, dtc) = (s.sampling.period_steps, s.sampling.dtc_max_steps as u64);
    let first = format!(
        "{n} steps (divides τ = {period} and Δt_c^max = {dtc} steps; 97 % of the collisions \
         last at least {free} steps)"
    );
    if n == free {
        return first;
    }
    // the nearest multiple of m (at least m) to `steps`
    let multiple = |steps: u64, m: u64| ((steps as f64 / m as f64).round() as u64).max(1) * m;
    let mut options = Vec::new();
    // τ is usually the one held: the largest n that divides it, with a Δt_c^max to match
    let with_tau = largest_divisor_up_to(period, free);
    if with_tau > n {
        options.push(format!(
            "n = {with_tau} with --dtc-max {}",
            multiple(dtc, with_tau)
        ));
    }
    if with_tau < free {
        let mut changes = vec![format!(
            "--tau {}",
            // enough digits for `--tau` to give these steps back
            fmt::sig(multiple(period, free) as f64 * s.sampling.dt, 12)
        )];
        if dtc % free != 0 {
            changes.push(format!("--dtc-max {}", multiple(dtc, free)));
        }
        options.push(format!("n = {free} needs {}", changes.join(" and ")));
    }
    format!("{first}\n              or {}", options.join("; "))
}

/// Greatest common divisor (`gcd(a, 0) = a`).
fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The largest divisor of `m` (≥ 1) that is at most `limit` (≥ 1); 1 if none is larger.
fn largest_divisor_up_to(m: u64, limit: u64) -> u64 {
    (1..=limit.min(m).max(1))
        .rev()
        .find(|d| m.is_multiple_of(*d))
        .unwrap_or(1)
}

fn inspect_extrapolation(plan: &InspectPlan, reader: &ExtrapolationReader) -> Result<()> {
    let info = reader.info();
    let ri = &info.recording_info;
    // each snapshot's own radii: point j is role j, with the radius of the particle there
    let total_heat = |s: &Snapshot| replay::total_heat(&s.temp, &Bodies::of(ri, s));
    // streamed: one snapshot in memory at a time, whatever the number of periods
    let mut snapshots = Vec::new();
    for s in reader.snapshots_in_order() {
        let s = s?;
        snapshots.push(ExtrapolatedSnapshot {
            index: s.index,
            time: s.time,
            mean_temperature: mean_temperature(&s),
            total_heat: total_heat(&s),
        });
    }
    let (Some(first), Some(last)) = (snapshots.first(), snapshots.last()) else {
        return Err(FormatError::Corrupt {
            path: plan.file.clone(),
            detail: "an extrapolation without snapshots (it holds t1 at least)".into(),
        }
        .into());
    };
    let (start, end) = (first.total_heat, last.total_heat);
    let conducting_walls = conducting_walls(ri);
    let inspection = ExtrapolationInspection {
        kind: "extrapolation",
        file: plan.file.display().to_string(),
        file_bytes: std::fs::metadata(&plan.file).map_or(0, |m| m.len()),
        format_version: info.format_version,
        tool_version: info.tool_version.clone(),
        recording: info.recording.clone(),
        case: case_name(ri),
        sampling: Sampling::of(ri),
        walls: ri.walls.len(),
        conducting_walls,
        scheme: info.scheme.name().into(),
        periods: info.periods,
        // the pairing's keys in the order the file holds them (sorted)
        roles: info.roles.clone(),
        symmetry: info.symmetry,
        mirror_check: info.mirror_check.clone(),
        boundary: info.boundary,
        fresh_pools: info.fresh_pools.clone(),
        total_heat_start: start,
        total_heat_end: end,
        heat_relative_change: (end - start) / start,
        mean_temperature_start: first.mean_temperature,
        mean_temperature_end: last.mean_temperature,
        wall_heat: (conducting_walls > 0).then_some(end - start),
        snapshots,
        costs: reader.costs().cloned(),
    };
    emit(plan.json, &inspection, print_extrapolation)
}

fn print_extrapolation(s: &ExtrapolationInspection) {
    print_file(
        "extrapolation",
        &s.file,
        s.file_bytes,
        s.format_version,
        &s.tool_version,
    );
    println!(
        "recording     {}: case {}, {} particles, {} walls ({} conducting)",
        s.recording, s.case, s.sampling.particles, s.walls, s.conducting_walls
    );
    s.sampling.print_period(false, &s.sampling.n_and_dtc_max());
    let (first, last) = (s.snapshots.first(), s.snapshots.last());
    let at = |snap: Option<&ExtrapolatedSnapshot>| {
        snap.map_or("-".to_string(), |x| {
            format!("t{} = {}", x.index, fmt::seconds(x.time))
        })
    };
    println!(
        "replay        {} periods, {} scheme: {} to {} ({} snapshots)",
        s.periods,
        s.scheme,
        at(first),
        at(last),
        s.snapshots.len()
    );
    match &s.roles {
        Roles::Pairing(p) => println!(
            "pairing       {}{} particles, mean distance {} diameters (total {}), k = {}, {} solve round(s), {}",
            crate::extrapolation::pairing_prefix(s.symmetry),
            p.particles,
            fmt::num(p.mean_distance_diameters),
            fmt::num(p.total_distance_diameters),
            p.k_used,
            p.rounds,
            if p.certified {
                "certified optimal"
            } else {
                "NOT certified"
            }
        ),
        Roles::Path(path) => {
            println!("path          {}", crate::extrapolation::path_words(path));
            for p in &path.pairings {
                println!(
                    "pairing       {}",
                    crate::extrapolation::path_pairing_words(p, s.symmetry)
                );
            }
        }
    }
    if let Some(words) = crate::extrapolation::symmetry_words(s.symmetry) {
        println!("symmetry      {words}");
    }
    for line in crate::extrapolation::mirror_check_lines(&s.mirror_check) {
        println!("mirror check  {line}");
    }
    for line in crate::extrapolation::boundary_lines(s.boundary, &s.fresh_pools) {
        println!("boundary      {line}");
    }
    println!(
        "heat          Σ m c T {:.6e} J at the start, {:.6e} J at the end (relative change {:.2e})",
        s.total_heat_start, s.total_heat_end, s.heat_relative_change
    );
    println!(
        "mean T        {} at the start, {} at the end",
        fmt::kelvin(s.mean_temperature_start),
        fmt::kelvin(s.mean_temperature_end)
    );
    match s.wall_heat {
        Some(q) => println!(
            "walls         {} conducting wall{} gave {} J in total ({} J per period)",
            s.conducting_walls,
            if s.conducting_walls == 1 { "" } else { "s" },
            fmt::num(q),
            fmt::num(q / s.periods.max(1) as f64)
        ),
        None => println!("walls         adiabatic: the total heat is conserved"),
    }
    if let Some(c) = &s.costs {
        println!(
            "costs         pairing {} s{}, table read {} s, replay {} s per period ({:.3e} rows/s, {} rows)",
            fmt::sig(c.seconds_pairing, 3),
            if c.pairing_reused { " (reused)" } else { "" },
            fmt::sig(c.seconds_read_table, 3),
            fmt::sig(c.seconds_per_period, 3),
            c.rows_per_second,
            c.rows
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_suggested_n_divides_the_period_and_dtc_max() {
        assert_eq!(gcd(5000, 100), 100);
        assert_eq!(gcd(7, 0), 7);
        assert_eq!(largest_divisor_up_to(gcd(5000, 100), 11), 10);
        assert_eq!(largest_divisor_up_to(gcd(5000, 100), 10), 10);
        assert_eq!(largest_divisor_up_to(gcd(2500, 100), 7), 5);
        assert_eq!(largest_divisor_up_to(gcd(2503, 100), 9), 1);
        assert_eq!(largest_divisor_up_to(12, 100), 12);
        assert_eq!(largest_divisor_up_to(1, 1), 1);
    }
}
