//! `tdex extrapolate`: K periods of the recorded table replayed through the pairing
//! ([`extrapolate::extrapolate_recording`]), told on the terminal.

use crate::cli::ExtrapolatePlan;
use anyhow::Result;
use extrapolate::boundary::BoundaryMaps;
use extrapolate::replay::memory::human_bytes;
use extrapolate::replay::{self, MemoryPlan, ModeReason, ReplayError, TableMode};
use extrapolate::sidecar::PairingSummary;
use extrapolate::{
    ExtrapolateError, ExtrapolationOutcome, ExtrapolationRequest, MemoryLimit, Notice, TableChoice,
};
use serde::Serialize;
use tdex_format::extrapolation::{Boundary, FreshPool, RecurrencePath, Roles, Symmetry};
use tdex_format::ExtrapolationCosts;

/// `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct ExtrapolationReport {
    output: String,
    scheme: String,
    periods: u32,
    particles: u32,
    rows: u64,
    max_cfl: f64,
    table_in_memory: bool,
    memory: MemoryReport,
    /// `pairing` (one recorded period) or `path` (several).
    #[serde(flatten)]
    roles: RolesReport,
    /// `none` or `axial_mirror`.
    symmetry: Symmetry,
    /// With `--mirror`: each start's mirrored and plain pairings' mean distances.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    mirror_check: Vec<extrapolate::MirrorCheck>,
    /// With `--boundary fresh`: the boundary (pool, cell, seed) and each start's pool;
    /// absent for the exact pairing.
    #[serde(skip_serializing_if = "Boundary::is_exact")]
    boundary: Boundary,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    fresh_pools: Vec<FreshPool>,
    costs: ExtrapolationCosts,
    total_heat_t1: f64,
    total_heat_end: f64,
}

impl ExtrapolationReport {
    fn of(request: &ExtrapolationRequest, outcome: ExtrapolationOutcome) -> Self {
        Self {
            output: request.output.display().to_string(),
            scheme: request.scheme.name().into(),
            periods: request.periods,
            particles: outcome.particles,
            rows: outcome.rows,
            max_cfl: outcome.max_cfl,
            table_in_memory: outcome.memory.mode == TableMode::InMemory,
            memory: MemoryReport::of(&outcome.memory, &outcome.limit),
            roles: match outcome.roles {
                Roles::Pairing(pairing) => RolesReport::Pairing(pairing),
                Roles::Path(path) => RolesReport::Path(PathReport {
                    jumps: path.jumps(),
                    mean_run: path.mean_run(),
                    path,
                }),
            },
            symmetry: outcome.symmetry,
            mirror_check: outcome.mirror_check,
            boundary: outcome.boundary,
            fresh_pools: outcome.fresh_pools,
            costs: outcome.costs,
            total_heat_t1: outcome.total_heat_t1,
            total_heat_end: outcome.total_heat_end,
        }
    }
}

/// The roles in `tdex extrapolate --json`: the pairing's summary in its declared key order
/// (as before several recorded periods), or the path with its jumps counted.
#[derive(Debug, Serialize)]
enum RolesReport {
    #[serde(rename = "pairing")]
    Pairing(PairingSummary),
    #[serde(rename = "path")]
    Path(PathReport),
}

/// `path` in `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct PathReport {
    #[serde(flatten)]
    path: RecurrencePath,
    jumps: usize,
    /// Mean periods replayed between two pairings.
    mean_run: f64,
}

/// A recurrence path in plain words: the periods used, the jumps and the runs between them.
pub fn path_words(path: &RecurrencePath) -> String {
    let k = path.replayed.len();
    let targets = path.jump_targets.as_ref().map_or(String::new(), |t| {
        let list: Vec<String> = t.iter().map(u32::to_string).collect();
        format!(", jumps only into periods {}", list.join(", "))
    });
    let leave = path.leave_every.map_or(String::new(), |n| {
        format!(
            ", leaving after every {n} period{} in a row from where it stood",
            if n == 1 { "" } else { "s" }
        )
    });
    format!(
        "recorded periods 1 to {} (seed {}{targets}{leave}): {} jump{} in {k} period{}, {} \
         periods between jumps on average",
        path.recorded_periods,
        path.seed,
        path.jumps(),
        if path.jumps() == 1 { "" } else { "s" },
        if k == 1 { "" } else { "s" },
        crate::fmt::sig(path.mean_run(), 3)
    )
}

/// What the symmetry did to the jumps, in plain words (`None` without one).
pub fn symmetry_words(symmetry: Symmetry) -> Option<&'static str> {
    match symmetry {
        Symmetry::None => None,
        Symmetry::AxialMirror => Some(
            "axial mirror: every jump entered the mirror image (y → −y) of its start, so the \
             periods replayed alternate between the recording and its mirror image",
        ),
    }
}

/// How much longer the mirrored pairing may be than the plain one before the mirror is
/// called unsafe: measured, 1.01 on `heated_drum` and 0.99 on `small_drum`, where the mirror
/// helped, 0.98–1.03 over the starts of `heated_drum` with 2 to 8 recorded periods, where
/// it helped or did no harm, and 1.39 on `axial_drum`, where it made the extrapolation far
/// worse (docs/validation.md#long-horizons-100-periods-and-more). A judgement from these
/// cases.
const MIRROR_LONGER_AT_MOST: f64 = 1.1;

/// The mirror checks of a path in plain words: one line per start, and the verdict on the
/// line of the one start or, with several, on a last line over all of them. The jumps enter
/// the starts alike, so the path moves the bed by the starts' mean distance: one start a
/// little over the threshold among several within it is no reason to drop the mirror
/// (measured on `heated_drum` with six recorded periods: one start at 1.104, the path at
/// 1.010, the mirror as accurate as the paper's method; docs/validation.md).
pub fn mirror_check_lines(checks: &[extrapolate::MirrorCheck]) -> Vec<String> {
    let verdict = |ratio: f64| {
        if ratio <= MIRROR_LONGER_AT_MOST {
            "the bed is its own mirror image to within 10 %"
        } else {
            "the bed is not its own mirror image, so the mirror's jumps move the particles, and \
             their heat, further than the plain pairing does: extrapolate without --mirror"
        }
    };
    // three decimals on the ratio, so that one just over the threshold does not read as on it
    let distances = |plain: f64, mirrored: f64| {
        format!(
            "mean distance {} diameters plain, {} to the mirror image ({:.3} times)",
            crate::fmt::sig(plain, 4),
            crate::fmt::sig(mirrored, 4),
            mirrored / plain.max(f64::MIN_POSITIVE),
        )
    };
    let each = checks.iter().map(|c| {
        let words = format!(
            "t{} to t{}: {}",
            c.end,
            c.start,
            distances(c.plain_mean_diameters, c.mirrored_mean_diameters)
        );
        match checks {
            [_] => format!("{words}: {}", verdict(c.ratio())),
            _ => words,
        }
    });
    let mut lines: Vec<String> = each.collect();
    if checks.len() > 1 {
        let n = checks.len() as f64;
        let plain = checks.iter().map(|c| c.plain_mean_diameters).sum::<f64>() / n;
        let mirrored = checks
            .iter()
            .map(|c| c.mirrored_mean_diameters)
            .sum::<f64>()
            / n;
        lines.push(format!(
            "over the {} starts: {}: {}",
            checks.len(),
            distances(plain, mirrored),
            verdict(mirrored / plain.max(f64::MIN_POSITIVE))
        ));
    }
    lines
}

/// What fresh boundary maps redraw, in words, without their seed (`None` for the exact
/// map): the line `tdex extrapolate` and `tdex study horizon` print.
pub fn boundary_settings(maps: BoundaryMaps) -> Option<String> {
    let sig = |x: f64| crate::fmt::sig(x, 3);
    match maps {
        BoundaryMaps::Exact => None,
        BoundaryMaps::FreshSteps {
            pool,
            cell_diameters,
        } => Some(format!(
            "fresh steps: each jump draws one of {pool} pairings in which every particle's \
             step along the axis is redrawn within {}-diameter cells of the cross-section",
            sig(cell_diameters)
        )),
        BoundaryMaps::FreshDrift {
            pool,
            bin_diameters,
            cell_diameters,
            cap_zone_diameters,
        } => Some(format!(
            "fresh drift: each jump draws one of {pool} pairings in which the period's axial \
             drift ({}-diameter bins, {}-diameter cells of the cross-section) is moved along \
             the axis{}",
            sig(bin_diameters),
            sig(cell_diameters),
            if cap_zone_diameters > 0.0 {
                format!(
                    ", but within {} diameters of an end cap, where it is kept",
                    sig(cap_zone_diameters)
                )
            } else {
                String::new()
            }
        )),
    }
}

/// The fresh boundary maps in plain words: what each jump draws, then each start's pool
/// (nothing for the exact pairing, which the pairing line already tells).
pub fn boundary_lines(boundary: Boundary, pools: &[FreshPool]) -> Vec<String> {
    let (Some(what), Some(seed)) = (boundary_settings(boundary.into()), boundary.seed()) else {
        return Vec::new();
    };
    let what = format!("{what} (seed {seed})");
    let mut lines = vec![what];
    lines.extend(pools.iter().map(|p| {
        format!(
            "t{} to t{}: {} pairings, mean distance {} diameters ({} to {})",
            p.end,
            p.start,
            p.pairings,
            crate::fmt::sig(p.mean_distance_diameters, 4),
            crate::fmt::sig(p.min_mean_distance_diameters, 4),
            crate::fmt::sig(p.max_mean_distance_diameters, 4)
        )
    }));
    lines
}

/// The start a pairing joins the end to: `t<start>`, or its mirror image.
pub fn start_words(start: u32, symmetry: Symmetry) -> String {
    match symmetry {
        Symmetry::None => format!("t{start}"),
        Symmetry::AxialMirror => format!("the mirror image of t{start}"),
    }
}

/// What the line of the one pairing says first: nothing for `t1` to `t0` (as it always
/// read), which images it joins under a symmetry.
pub fn pairing_prefix(symmetry: Symmetry) -> String {
    match symmetry {
        Symmetry::None => String::new(),
        Symmetry::AxialMirror => format!("t1 to {}: ", start_words(0, symmetry)),
    }
}

/// A pairing of a path in plain words: its snapshots and mean distance.
pub fn path_pairing_words(
    p: &tdex_format::extrapolation::PathPairing,
    symmetry: Symmetry,
) -> String {
    format!(
        "t{} to {}: mean distance {} diameters, {}",
        p.end,
        start_words(p.start, symmetry),
        crate::fmt::sig(p.summary.mean_distance_diameters, 4),
        if p.summary.certified {
            "certified"
        } else {
            "not certified"
        }
    )
}

pub fn run(plan: &ExtrapolatePlan) -> Result<()> {
    let request = ExtrapolationRequest {
        recording: plan.file.clone(),
        periods: plan.periods,
        output: plan.output.clone(),
        scheme: plan.scheme,
        table: if plan.stream {
            TableChoice::Streamed
        } else {
            TableChoice::InMemoryIfItFits
        },
        memory_limit: memory_limit(plan.max_memory),
        reproducible: plan.reproducible,
        recorded_periods: plan.recorded_periods,
        path_seed: plan.seed,
        jumps: plan.jumps.clone(),
        leave: plan.leave,
        symmetry: plan.symmetry,
        boundary: plan.boundary,
    };
    let outcome = crate::with_workers(plan.threads, || {
        extrapolate::extrapolate_recording(&request, tell).map_err(advice)
    })?;
    print(&request, outcome, plan.json)
}

/// Extrapolates `request` on `threads` workers, its notices told by `told` ([`tell`], or
/// [`tell_unless_it_fits`] for a study): the demo's and the studies' own context, not `tdex
/// extrapolate`'s advice about flags.
pub fn extrapolate_on(
    threads: usize,
    request: &ExtrapolationRequest,
    told: fn(Notice<'_>),
) -> Result<ExtrapolationOutcome> {
    crate::with_workers(threads, || {
        Ok(extrapolate::extrapolate_recording(request, told)?)
    })
}

/// The memory an extrapolation may use: `--max-memory` when given, else a share of what the
/// machine has (and how to change it).
pub fn memory_limit(max_memory: Option<u64>) -> MemoryLimit {
    match max_memory {
        Some(bytes) => MemoryLimit {
            bytes,
            source: "--max-memory".into(),
        },
        None => {
            let mut limit = MemoryLimit::available();
            let verb = if limit.is_known() {
                "set it"
            } else {
                "set one"
            };
            limit.source = format!("{}; {verb} with --max-memory", limit.source);
            limit
        }
    }
}

/// The library's refusal, with the flags that get past it.
pub fn advice(e: ExtrapolateError) -> anyhow::Error {
    match e {
        ExtrapolateError::Refused { recording, error } => {
            let advice = match &error {
                ReplayError::Memory { .. } => "allow more with --max-memory or free memory",
                ReplayError::Cfl { .. } => {
                    "record with a smaller --dtc-max or replay with --scheme exact"
                }
                ReplayError::Roles { .. } => {
                    return ExtrapolateError::Refused { recording, error }.into()
                }
            };
            anyhow::Error::new(error).context(format!("{}: {advice}", recording.display()))
        }
        ExtrapolateError::RecordedPeriods { recorded, .. } => {
            let advice = format!("give --recorded-periods between 1 and {recorded}");
            anyhow::Error::new(e).context(advice)
        }
        ExtrapolateError::JumpTarget { used, .. } => {
            let advice = format!("give --jump-to periods between 1 and {used}");
            anyhow::Error::new(e).context(advice)
        }
        e => e.into(),
    }
}

/// Tells an extrapolation's [`Notice`] on stderr: the memory plan before any work, a
/// pairing that could not be stored.
pub fn tell(notice: Notice<'_>) {
    match notice {
        Notice::Memory { plan, limit } => eprintln!("{}", memory_statement(plan, limit)),
        Notice::PairingNotStored(e) => {
            eprintln!("warning: {e}; the pairing will be computed again next time")
        }
    }
}

/// Tells a [`Notice`] as [`tell`] does, but for a memory plan whose table fits in memory. A
/// study replays one recording many times (every P, map and draw), and a line for each
/// replay that fits would bury its table.
pub fn tell_unless_it_fits(notice: Notice<'_>) {
    if let Notice::Memory { plan, .. } = &notice {
        if matches!(plan.reason, ModeReason::Fits) {
            return;
        }
    }
    tell(notice)
}

/// Rows a second that decoding the table costs, each period, when it is streamed: the
/// `bench_drum` recording (23.2 million rows) replays in 1.02 s per period streamed against
/// 0.101 s in memory (docs/benchmarks.md), 0.92 s to decode them.
const STREAM_DECODE_ROWS_PER_SECOND: f64 = 2.5e7;

/// The line stated before any work: what the replay needs, the limit, where the table goes.
fn memory_statement(memory: &MemoryPlan, limit: &MemoryLimit) -> String {
    let n = &memory.needs;
    let limit_text = if limit.is_known() {
        format!("limit {} ({})", human_bytes(limit.bytes), limit.source)
    } else {
        format!("no limit ({})", limit.source)
    };
    let parts = format!(
        "table {} = {} rows × {} B, particles {}, pairing {}, buffers {}",
        human_bytes(n.table_bytes),
        n.rows,
        replay::memory::ROW_BYTES,
        human_bytes(n.particle_bytes),
        if n.pairing_bytes == 0 {
            "stored".to_string()
        } else {
            human_bytes(n.pairing_bytes)
        },
        human_bytes(n.buffer_bytes)
    );
    let slower = n.rows as f64 / STREAM_DECODE_ROWS_PER_SECOND;
    match memory.reason {
        ModeReason::Fits => format!(
            "memory        needs {} with the table in memory ({parts}); {limit_text}",
            human_bytes(n.in_memory())
        ),
        ModeReason::TooLarge => format!(
            "memory        table {} (whole replay {}) > {limit_text}: streaming from disk, \
             ~{slower:.2} s per period slower; needs {} ({parts})",
            human_bytes(n.table_bytes),
            human_bytes(n.in_memory()),
            human_bytes(n.streamed())
        ),
        ModeReason::Requested => format!(
            "memory        --stream: the table is read from disk every period, ~{slower:.2} s \
             per period slower; needs {} ({parts}); {limit_text}",
            human_bytes(n.streamed())
        ),
    }
}

/// `memory` in `tdex extrapolate --json` (keys in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct MemoryReport {
    /// `null` when no limit is known.
    limit_bytes: Option<u64>,
    limit_source: String,
    /// `in_memory` or `streamed`, and why: `fits`, `too_large`, `requested`.
    table: &'static str,
    reason: &'static str,
    needed_bytes: u64,
    in_memory_bytes: u64,
    streamed_bytes: u64,
    table_bytes: u64,
    particle_bytes: u64,
    pairing_bytes: u64,
    buffer_bytes: u64,
}

impl MemoryReport {
    fn of(memory: &MemoryPlan, limit: &MemoryLimit) -> Self {
        let n = &memory.needs;
        Self {
            limit_bytes: limit.is_known().then_some(limit.bytes),
            limit_source: limit.source.clone(),
            table: match memory.mode {
                TableMode::InMemory => "in_memory",
                TableMode::Streamed => "streamed",
            },
            reason: match memory.reason {
                ModeReason::Fits => "fits",
                ModeReason::TooLarge => "too_large",
                ModeReason::Requested => "requested",
            },
            needed_bytes: memory.needed(),
            in_memory_bytes: n.in_memory(),
            streamed_bytes: n.streamed(),
            table_bytes: n.table_bytes,
            particle_bytes: n.particle_bytes,
            pairing_bytes: n.pairing_bytes,
            buffer_bytes: n.buffer_bytes,
        }
    }
}

/// Prints the extrapolation's summary, or its JSON (`--json`).
pub fn print(
    request: &ExtrapolationRequest,
    outcome: ExtrapolationOutcome,
    json: bool,
) -> Result<()> {
    let report = &ExtrapolationReport::of(request, outcome);
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        let c = &report.costs;
        println!(
            "extrapolation {} ({} periods, {} scheme, {} particles, {} rows, max CFL {})",
            report.output,
            report.periods,
            report.scheme,
            report.particles,
            report.rows,
            crate::fmt::sig(report.max_cfl, 4)
        );
        let reused = if c.pairing_reused { ", reused" } else { "" };
        match &report.roles {
            RolesReport::Pairing(pairing) => println!(
                "pairing       {}mean distance {} diameters, {} ({:.2} s{reused})",
                pairing_prefix(report.symmetry),
                crate::fmt::sig(pairing.mean_distance_diameters, 4),
                if pairing.certified {
                    "certified"
                } else {
                    "not certified"
                },
                c.seconds_pairing,
            ),
            RolesReport::Path(PathReport { path, .. }) => {
                println!("path          {}", path_words(path));
                if path.pairings.is_empty() {
                    println!("pairings      none: the path stayed inside the recording");
                }
                for p in &path.pairings {
                    println!("pairing       {}", path_pairing_words(p, report.symmetry));
                }
                if !path.pairings.is_empty() {
                    println!(
                        "pairings      {} computed or reused in {:.2} s{reused}",
                        path.pairings.len(),
                        c.seconds_pairing
                    );
                }
            }
        }
        if let Some(words) = symmetry_words(report.symmetry) {
            println!("symmetry      {words}");
        }
        for line in mirror_check_lines(&report.mirror_check) {
            println!("mirror check  {line}");
        }
        for line in boundary_lines(report.boundary, &report.fresh_pools) {
            println!("boundary      {line}");
        }
        println!(
            "replay        {:.3} s per period, {:.3e} rows/s (table read {:.2} s, {})",
            c.seconds_per_period,
            c.rows_per_second,
            c.seconds_read_table,
            if report.table_in_memory {
                "in memory"
            } else {
                "streamed"
            }
        );
        println!(
            "heat          sum C T {:.10e} J at t1, {:.10e} J at the end",
            report.total_heat_t1, report.total_heat_end
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use extrapolate::MirrorCheck;

    fn check(start: u32, plain: f64, mirrored: f64) -> MirrorCheck {
        MirrorCheck {
            end: 6,
            start,
            plain_mean_diameters: plain,
            mirrored_mean_diameters: mirrored,
        }
    }

    #[test]
    fn the_mirror_check_judges_one_start_or_the_path_over_all() {
        // one start: its line carries the verdict
        let one = mirror_check_lines(&[check(0, 0.552, 0.765)]);
        assert_eq!(one.len(), 1);
        assert!(one[0].contains("(1.386 times)"), "{}", one[0]);
        assert!(
            one[0].ends_with("extrapolate without --mirror"),
            "{}",
            one[0]
        );
        // several: the starts' numbers, then one verdict on their means; one start just
        // over 10 % among others within it does not condemn the path
        let several = mirror_check_lines(&[
            check(0, 0.4684, 0.4992),
            check(2, 0.4682, 0.5169),
            check(5, 0.5249, 0.4789),
        ]);
        assert_eq!(several.len(), 4);
        assert!(several[1].ends_with("(1.104 times)"), "{}", several[1]);
        assert!(
            several[3].starts_with("over the 3 starts: mean distance 0.4872 diameters plain")
                && several[3].ends_with("to within 10 %"),
            "{}",
            several[3]
        );
        let leaning = mirror_check_lines(&[check(0, 0.5, 0.7), check(1, 0.5, 0.5)]);
        assert!(
            leaning[2].ends_with("extrapolate without --mirror"),
            "{}",
            leaning[2]
        );
        assert!(mirror_check_lines(&[]).is_empty());
    }
}
