//! `tdex study horizon`: the extrapolation over many periods against the DEM and its twins,
//! per number of recorded periods P, beside what recording P periods costs, so
//! that a user can pick P for their case.
//!
//! The DEM runs once and records the largest P (or a recording made before is read): a
//! smaller P replays the first P of its periods, which are the tables and snapshots a
//! recording of P periods would hold (the recorder only reads the DEM's state), so every P
//! is judged against the same DEM run and the same twins. With `--mirror` each P runs twice,
//! as the paper does and with the drum's mirror image at every jump, on the same paths.
//!
//! Given several recordings of the case (draws: other seeds, other recorded windows), every
//! P runs on each, and a pooled verdict per P ([`crate::compare::draws`]) weighs the mean
//! median ratio over the draws against a DEM run's judged in the same seat: one recording's
//! median ratio is too noisy a figure to settle whether P passes as one more DEM run.

use super::plots::{self, Line, LineKind};
use super::PathJumps;
use crate::cli::{HorizonSource, StudyPlan};
use crate::compare::draws::{self, Draw, Draws};
use crate::compare::{self, Comparison, GroupMeans};
use crate::extrapolation;
use anyhow::{bail, Context, Result};
use extrapolate::boundary::BoundaryMaps;
use extrapolate::{ExtrapolationRequest, JumpStarts, Leave, MirrorCheck};
use recorder::record;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tdex_format::extrapolation::Symmetry;
use tdex_format::{ExtrapolationReader, RecordingCosts, RecordingReader};

/// One number of recorded periods with one image at the jumps, extrapolated over the
/// reference periods and judged.
#[derive(Debug, Serialize)]
struct Entry {
    recorded_periods: u32,
    /// `none` (the paper's method) or `axial_mirror`.
    symmetry: Symmetry,
    /// The boundary maps at the jumps, `fresh_steps` or `fresh_drift` (left out for the
    /// exact pairing, the paper's method).
    #[serde(skip_serializing_if = "is_exact")]
    boundary: &'static str,
    /// The recording of this draw, with several (left out with one, whose recording is the
    /// study's).
    #[serde(skip_serializing_if = "Option::is_none")]
    recording: Option<String>,
    /// The draw's name in the outputs (the recording's stem), with several.
    #[serde(skip)]
    draw: Option<String>,
    /// With the mirror: each start's mirrored pairing beside its plain one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    mirror_check: Vec<MirrorCheck>,
    extrapolation: String,
    /// DEM seconds to `t0` plus the P recorded periods: what a recording of P periods costs
    /// (null without the recording's costs record).
    recording_seconds: Option<f64>,
    /// The trust verdict of `tdex compare` (median ratio to the DEM runs' spread, the `t_k`
    /// outside their range, the group-mean errors against their spread).
    passes: Option<bool>,
    median_ratio: Option<f64>,
    ratio_min: Option<f64>,
    ratio_max: Option<f64>,
    compared: usize,
    outside_range: usize,
    means_error_max: Option<f64>,
    means_spread_max: Option<f64>,
    /// ε_rel and the DEM-vs-DEM floor's at the last `t_k` (fractions; null where undefined).
    eps_rel_last: Option<f64>,
    floor_eps_rel_last: Option<f64>,
    verdict: String,
    #[serde(skip)]
    comparison: Comparison,
}

#[derive(Debug, Serialize)]
struct HorizonStudy {
    study: &'static str,
    case: String,
    recording: String,
    particles: u32,
    /// Periods the recording holds; the runs use the first `recorded_periods` of them.
    periods_in_recording: u32,
    reference_periods: u32,
    twins: u32,
    tau: f64,
    /// The seed of the recurrence paths (null: the case's seed, the default).
    path_seed: Option<u64>,
    /// `--jump-nearest K`: every path jumps only into the K starts nearest its end (left
    /// out without it: every start).
    #[serde(skip_serializing_if = "Option::is_none")]
    jump_nearest: Option<u32>,
    /// `--jump-every N`: every path leaves the recording after every N periods in a row
    /// (left out without it: at the recording's end only).
    #[serde(skip_serializing_if = "Option::is_none")]
    jump_every: Option<u32>,
    /// What each fresh boundary map of the runs redraws, in words (left out with the exact
    /// pairing alone): the settings every draw's runs share.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    boundary_maps: Vec<String>,
    runs: Vec<Entry>,
    /// With several recordings: each draw's recording (the study's first), and per P (and
    /// image) the pooled verdict over them; both left out with one recording.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    draws: Vec<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pooled: Vec<PooledRun>,
}

/// One number of recorded periods with one image, judged over every draw.
#[derive(Debug, Serialize)]
struct PooledRun {
    recorded_periods: u32,
    symmetry: Symmetry,
    #[serde(skip_serializing_if = "is_exact")]
    boundary: &'static str,
    #[serde(flatten)]
    draws: Draws,
}

impl PooledRun {
    fn label(&self) -> String {
        label(self.recorded_periods, self.symmetry, self.boundary)
    }
}

/// `P = 2`, `P = 2, mirror` or `P = 2, fresh steps`: a configuration's name in the table and
/// the plots.
fn label(p: u32, symmetry: Symmetry, boundary: &str) -> String {
    let mut label = format!("P = {p}");
    if symmetry == Symmetry::AxialMirror {
        label += ", mirror";
    }
    if boundary != "exact" {
        label += &format!(", {}", boundary.replace('_', " "));
    }
    label
}

/// The name of boundary maps in the study's outputs.
fn boundary_name(maps: BoundaryMaps) -> &'static str {
    match maps {
        BoundaryMaps::Exact => "exact",
        BoundaryMaps::FreshSteps { .. } => "fresh_steps",
        BoundaryMaps::FreshDrift { .. } => "fresh_drift",
    }
}

fn is_exact(name: &&'static str) -> bool {
    *name == "exact"
}

/// Each recording's name as a draw (its file stem), made distinct by its place where two
/// share a stem.
fn draw_names(recordings: &[PathBuf]) -> Vec<String> {
    let stems: Vec<String> = recordings
        .iter()
        .map(|r| {
            r.file_stem()
                .map_or_else(|| "draw".to_string(), |s| s.to_string_lossy().into_owned())
        })
        .collect();
    stems
        .iter()
        .enumerate()
        .map(|(i, stem)| {
            if stems.iter().filter(|s| *s == stem).count() > 1 {
                format!("{stem}_{}", i + 1)
            } else {
                stem.clone()
            }
        })
        .collect()
}

pub fn run(
    plan: &StudyPlan,
    source: &HorizonSource,
    draws: &[PathBuf],
    recorded_periods: &[u32],
    jumps: &PathJumps,
    images: &[Symmetry],
    boundaries: &[BoundaryMaps],
) -> Result<()> {
    let recording = recording_of(plan, source)?;
    let recordings: Vec<PathBuf> = std::iter::once(recording.clone())
        .chain(draws.iter().cloned())
        .collect();
    let several = recordings.len() > 1;
    let names = draw_names(&recordings);
    let configurations: Vec<(u32, Symmetry, BoundaryMaps)> = recorded_periods
        .iter()
        .flat_map(|&p| {
            images
                .iter()
                .flat_map(move |&s| boundaries.iter().map(move |&b| (p, s, b)))
        })
        .collect();
    // per draw, every configuration in order
    let mut by_draw: Vec<Vec<Entry>> = Vec::with_capacity(recordings.len());
    let mut info = None;
    for (path, name) in recordings.iter().zip(&names) {
        let rec = RecordingReader::open(path)?;
        // with one recording the files keep their names; with several each draw's name
        // ends them
        let draw = several.then_some(name.as_str());
        by_draw.push(run_draw(plan, &rec, path, draw, &configurations, jumps)?);
        info.get_or_insert_with(|| rec.info().clone());
    }
    let info = info.expect("one recording at least");
    let (runs, pooled) = in_table_order(by_draw, &configurations)?;
    let study = HorizonStudy {
        study: "horizon",
        case: plan.case_path.display().to_string(),
        recording: recording.display().to_string(),
        particles: info.particles,
        periods_in_recording: info.recorded_periods,
        reference_periods: info.reference_periods,
        twins: info.twins,
        tau: info.tau,
        path_seed: jumps.seed,
        jump_nearest: match jumps.starts {
            JumpStarts::Nearest(k) => Some(k.get()),
            JumpStarts::Every | JumpStarts::Listed(_) => None,
        },
        jump_every: match jumps.leave {
            Leave::AtEnd => None,
            Leave::Every(n) => Some(n.get()),
        },
        boundary_maps: boundaries
            .iter()
            .filter_map(|&maps| extrapolation::boundary_settings(maps))
            .collect(),
        runs,
        draws: if several {
            recordings.iter().map(|r| r.display().to_string()).collect()
        } else {
            Vec::new()
        },
        pooled,
    };
    let table = table(&study);
    super::finish(
        plan,
        &study,
        &table,
        &markdown(&study, &table),
        svgs(&study)?,
    )
}

/// The runs in the table's order, configuration by configuration with the draws of each
/// together (`by_draw`: per draw, every configuration in order), and with several draws
/// each configuration's pooled verdict.
fn in_table_order(
    by_draw: Vec<Vec<Entry>>,
    configurations: &[(u32, Symmetry, BoundaryMaps)],
) -> Result<(Vec<Entry>, Vec<PooledRun>)> {
    let several = by_draw.len() > 1;
    let mut by_draw: Vec<std::vec::IntoIter<Entry>> =
        by_draw.into_iter().map(Vec::into_iter).collect();
    let mut runs = Vec::new();
    let mut pooled = Vec::new();
    for &(p, symmetry, maps) in configurations {
        let entries: Vec<Entry> = by_draw
            .iter_mut()
            .map(|d| d.next().expect("one entry per configuration"))
            .collect();
        if several {
            let each = entries
                .iter()
                .map(|e| Draw::of(&e.comparison))
                .collect::<Result<Vec<_>, _>>()?;
            pooled.push(PooledRun {
                recorded_periods: p,
                symmetry,
                boundary: boundary_name(maps),
                draws: Draws::pool(each)?,
            });
        }
        runs.extend(entries);
    }
    Ok((runs, pooled))
}

/// The study's recording: the one given, or one recorded now into the output directory
/// (the long part).
fn recording_of(plan: &StudyPlan, source: &HorizonSource) -> Result<PathBuf> {
    let dir = &plan.output;
    Ok(match source {
        HorizonSource::Recording(path) => path.clone(),
        HorizonSource::Record(options) => {
            let path = dir.join("horizon.mcap");
            if !plan.json {
                println!(
                    "record        {} periods and {} reference periods with {} DEM twins (the \
                     DEM runs once; this is the long part)",
                    options.recorded_periods, options.reference_periods, options.twins
                );
            }
            let bar = super::dem_bar(plan.json, "study");
            crate::with_workers(plan.threads, || {
                Ok(record::record(
                    &plan.case,
                    &plan.case_path,
                    &plan.case_toml,
                    options,
                    &path,
                    &mut super::on_phase_logged(&bar),
                )?)
            })
            .with_context(|| format!("recording {}", plan.case_path.display()))?;
            bar.finish_and_clear();
            path
        }
    })
}

/// Every configuration `(P, image, boundary maps)` run on one draw `rec` (at `path`), in
/// order, after checking that the recording holds the largest P asked.
fn run_draw(
    plan: &StudyPlan,
    rec: &RecordingReader,
    path: &Path,
    draw: Option<&str>,
    configurations: &[(u32, Symmetry, BoundaryMaps)],
    jumps: &PathJumps,
) -> Result<Vec<Entry>> {
    let held = rec.info().recorded_periods;
    if let Some(&(p, ..)) = configurations.iter().find(|&&(p, ..)| p > held) {
        bail!(
            "{}: holds {held} recorded period(s); --recorded-periods {p} cannot be replayed \
             from it",
            path.display(),
        );
    }
    configurations
        .iter()
        .map(|&configuration| run_one(plan, rec, path, draw, configuration, jumps))
        .collect()
}

/// Extrapolates the first `p` recorded periods of `rec` (at `path`) with `symmetry` and the
/// boundary `maps` at the jumps over its reference periods and compares it with the DEM
/// runs; `draw` names the recording in the file name and the outputs when there are several.
fn run_one(
    plan: &StudyPlan,
    rec: &RecordingReader,
    path: &Path,
    draw: Option<&str>,
    (p, symmetry, maps): (u32, Symmetry, BoundaryMaps),
    jumps: &PathJumps,
) -> Result<Entry> {
    let image = match symmetry {
        Symmetry::None => "",
        Symmetry::AxialMirror => "_mirror",
    };
    // `_fresh-steps`: the flag's own spelling
    let boundary = match boundary_name(maps) {
        "exact" => String::new(),
        name => format!("_{}", name.replace('_', "-")),
    };
    let suffix = draw.map_or(String::new(), |d| format!("_{d}"));
    let extra = plan
        .output
        .join(format!("horizon_p{p}{image}{boundary}{suffix}.extra.mcap"));
    let request = ExtrapolationRequest {
        recorded_periods: Some(p),
        path_seed: jumps.seed,
        jumps: jumps.starts.clone(),
        leave: jumps.leave,
        symmetry,
        boundary: maps,
        ..ExtrapolationRequest::new(
            path.to_path_buf(),
            rec.info().reference_periods,
            extra.clone(),
            extrapolation::memory_limit(None),
        )
    };
    let outcome =
        extrapolation::extrapolate_on(plan.threads, &request, extrapolation::tell_unless_it_fits)
            .with_context(|| match draw {
            Some(d) => format!("extrapolating {d} with {p} recorded period(s)"),
            None => format!("extrapolating with {p} recorded period(s)"),
        })?;
    let ext = ExtrapolationReader::open(&extra)?;
    let comparison = compare::compare(rec, &ext, plan.cells, compare::DEFAULT_SEED)?;
    let mut entry = Entry::new(
        (p, symmetry, boundary_name(maps)),
        outcome.mirror_check,
        &extra,
        rec.costs(),
        comparison,
    );
    if let Some(d) = draw {
        entry.recording = Some(path.display().to_string());
        entry.draw = Some(d.to_string());
    }
    Ok(entry)
}

/// DEM seconds to `t0` and through the first `p` recorded periods.
fn recording_seconds(costs: &RecordingCosts, p: u32) -> Option<f64> {
    let periods = if costs.seconds_each_period.is_empty() {
        // a single recorded period: its wall time is the whole of `seconds_period`
        (p == 1).then_some(costs.seconds_period)?
    } else {
        costs
            .seconds_each_period
            .get(..p as usize)?
            .iter()
            .sum::<f64>()
    };
    Some(costs.seconds_to_t0 + periods)
}

impl Entry {
    /// `P = 2`, or `P = 2, mirror`, and the draw's name with several (`P = 2 (seed6)`): the
    /// run's name in the table and the plots.
    fn label(&self) -> String {
        let label = label(self.recorded_periods, self.symmetry, self.boundary);
        match &self.draw {
            Some(d) => format!("{label} ({d})"),
            None => label,
        }
    }

    fn new(
        (p, symmetry, boundary): (u32, Symmetry, &'static str),
        mirror_check: Vec<MirrorCheck>,
        extra: &Path,
        costs: Option<&RecordingCosts>,
        comparison: Comparison,
    ) -> Self {
        let v = &comparison.verdict;
        let last = comparison.periods.last();
        Entry {
            recorded_periods: p,
            symmetry,
            boundary,
            recording: None,
            draw: None,
            mirror_check,
            extrapolation: extra.display().to_string(),
            recording_seconds: costs.and_then(|c| recording_seconds(c, p)),
            passes: v.passes,
            median_ratio: v.median_ratio,
            ratio_min: v.ratio_min,
            ratio_max: v.ratio_max,
            compared: v.compared.len(),
            outside_range: v.outside_range.len(),
            means_error_max: v.means_error_max,
            means_spread_max: v.means_spread_max,
            eps_rel_last: last.and_then(|p| p.eps_rel),
            floor_eps_rel_last: last.and_then(|p| p.floor_eps_rel),
            verdict: v.text.clone(),
            comparison,
        }
    }
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{v:.digits$}"))
}

fn table(s: &HorizonStudy) -> String {
    let last = s.reference_periods + 1;
    // as wide as `P = 2, mirror`, wider for the draws' names
    let w = s
        .runs
        .iter()
        .map(|e| e.label().chars().count())
        .max()
        .unwrap_or(0)
        .max(13);
    let mut t = format!(
        "{:<w$} {:>14} {:>12} {:>13} {:>18} {:>22} {:>18}\n",
        "run",
        "recording (s)",
        "median ratio",
        "ratio range",
        "outside DEM range",
        "means error/spread (K)",
        format!("eps_rel t{last} (%)"),
    );
    for e in &s.runs {
        t += &format!(
            "{:<w$} {:>14} {:>12} {:>13} {:>18} {:>22} {:>18}\n",
            e.label(),
            opt(e.recording_seconds, 1),
            opt(e.median_ratio, 2),
            format!("{}–{}", opt(e.ratio_min, 2), opt(e.ratio_max, 2)),
            format!("{} of {} t_k", e.outside_range, e.compared),
            format!(
                "{} / {}",
                opt(e.means_error_max, 3),
                opt(e.means_spread_max, 3)
            ),
            format!(
                "{} (DEM {})",
                super::pct(e.eps_rel_last),
                super::pct(e.floor_eps_rel_last)
            ),
        );
    }
    for settings in &s.boundary_maps {
        t += &format!("{settings}\n");
    }
    if let Some(k) = s.jump_nearest {
        t += &format!(
            "jumps: only into {} the end of the P used (the mean distance of the pairing)\n",
            nearest_starts(k)
        );
    }
    if let Some(n) = s.jump_every {
        t += &format!("{}\n", leaving_every(n));
    }
    for e in &s.runs {
        t += &format!("{}: {}\n", e.label(), e.verdict);
        for line in extrapolation::mirror_check_lines(&e.mirror_check) {
            t += &format!("{}: mirror check {line}\n", e.label());
        }
    }
    if !s.pooled.is_empty() {
        t += &pooled_table(s);
    } else if let Some(best) = s
        .runs
        .iter()
        .filter(|e| e.median_ratio.is_some())
        .min_by(|a, b| a.median_ratio.unwrap().total_cmp(&b.median_ratio.unwrap()))
    {
        t += &format!(
            "closest to one more DEM run: {} (median ratio {})\n",
            best.label(),
            opt(best.median_ratio, 2)
        );
    }
    t
}

/// With several recordings: per P (and image), the pooled figures over the draws (mean ±
/// standard error), the extrapolation's beside a DEM run's judged in the same seat, then
/// each pooled verdict and the P closest to one more DEM run over the draws.
fn pooled_table(s: &HorizonStudy) -> String {
    let mut t = format!(
        "\npooled over the {} draws (mean ± standard error over them; beyond range: the share \
         of compared t_k farther from the DEM runs than the two farthest of them):\n",
        s.draws.len()
    );
    // as wide as `P = 2, mirror`, wider for the boundaries' names
    let w = s
        .pooled
        .iter()
        .map(|r| r.label().chars().count())
        .max()
        .unwrap_or(0)
        .max(13);
    t += &format!(
        "{:<w$} {:>14} {:>16} {:>22} {:>24} {:>7}\n",
        "run",
        "median ratio",
        "beyond range",
        "DEM run: median ratio",
        "DEM run: beyond range",
        "passes"
    );
    for r in &s.pooled {
        let d = &r.draws;
        t += &format!(
            "{:<w$} {:>14} {:>16} {:>22} {:>24} {:>7}\n",
            r.label(),
            draws::plus_minus(d.median_ratio),
            draws::percent_plus_minus(d.outside_share),
            draws::plus_minus(d.dem_runs_median_ratio),
            draws::percent_plus_minus(d.dem_runs_outside_share),
            if d.passes { "yes" } else { "no" },
        );
    }
    t += &format!(
        "\nthe {} means over the draws (draws beyond: where they stray beyond the DEM runs' \
         spread at some t_k, which fails the pooled verdict; then in a DEM run's seat, against \
         the other runs, beside a DEM run judged the same way: the share of seats where they \
         stray beyond those runs' spread, and their largest error over that spread):\n",
        if s.pooled.first().is_some_and(|r| r.draws.of_groups()) {
            "group"
        } else {
            "bed"
        }
    );
    t += &format!(
        "{:<w$} {:>12} {:>14} {:>16} {:>16} {:>22}\n",
        "run",
        "draws beyond",
        "seats beyond",
        "DEM run: beyond",
        "error / spread",
        "DEM run: error / spread"
    );
    let or_dash = |m: Option<draws::MeanSe>| m.map_or("-".to_string(), draws::plus_minus);
    for r in &s.pooled {
        let d = &r.draws;
        t += &format!(
            "{:<w$} {:>12} {:>14} {:>16} {:>16} {:>22}\n",
            r.label(),
            format!("{} of {}", d.means_outside_spread_draws, d.draws),
            draws::percent_plus_minus(d.means_outside_share_in_seat),
            draws::percent_plus_minus(d.dem_runs_means_outside_share),
            or_dash(d.means_error_to_spread),
            or_dash(d.dem_runs_means_error_to_spread),
        );
    }
    // a bed heated through a wall: the same medians on each field less its own bed mean
    t += &beside_table(
        s,
        w,
        "each field less its own bed mean, over the draws (where the heat is, apart from how \
         fast the bed heats; it informs, the verdict is on the field)",
        |d| d.pattern,
    );
    // a horizon long enough to tell its last fifth: whether the error is still growing
    t += &beside_table(
        s,
        w,
        "the last fifth of each draw's compared t_k, over the draws (where the horizon ends: \
         above the whole horizon's median, the error still grows, and a longer horizon will be \
         farther off; it informs, the verdict is on the whole horizon)",
        |d| d.late,
    );
    t.push('\n');
    for r in &s.pooled {
        t += &format!("{} over the draws: {}\n", r.label(), r.draws.text);
    }
    if let Some(best) = s.pooled.iter().min_by(|a, b| {
        a.draws
            .median_ratio
            .mean
            .total_cmp(&b.draws.median_ratio.mean)
    }) {
        t += &format!(
            "closest to one more DEM run over the draws: {} (mean median ratio {})\n",
            best.label(),
            draws::plus_minus(best.draws.median_ratio)
        );
    }
    t
}

/// A median ratio the pooled verdict informs by and does not judge on, per row, the
/// extrapolation's beside a DEM run's; nothing where no row has it.
fn beside_table(
    s: &HorizonStudy,
    w: usize,
    heading: &str,
    figure: impl Fn(&draws::Draws) -> Option<draws::Beside<draws::MeanSe>>,
) -> String {
    if s.pooled.iter().all(|r| figure(&r.draws).is_none()) {
        return String::new();
    }
    let or_dash = |m: Option<draws::MeanSe>| m.map_or("-".to_string(), draws::plus_minus);
    let mut t = format!(
        "\n{heading}:\n{:<w$} {:>14} {:>22}\n",
        "run", "median ratio", "DEM run: median ratio"
    );
    for r in &s.pooled {
        let beside = figure(&r.draws);
        t += &format!(
            "{:<w$} {:>14} {:>22}\n",
            r.label(),
            or_dash(beside.map(|b| b.extrapolation)),
            or_dash(beside.map(|b| b.dem_run)),
        );
    }
    t
}

fn markdown(s: &HorizonStudy, table: &str) -> String {
    // with several recordings: what the rows and the pooled verdict are
    let pooled = if s.draws.is_empty() {
        String::new()
    } else {
        format!(
            "\n\nEvery row runs on each of the {} recordings of the case (the draws: {}), \
             named after its file. Per P, the pooled verdict weighs the mean median ratio over \
             the draws (± its standard error, the sample standard deviation over √n) against a \
             DEM run's judged in the same seat against the other runs (per draw the mean of the \
             runs' medians); it passes when that mean is at most the DEM runs' plus two \
             standard errors of the difference, the share of t_k beyond the DEM runs' range at \
             most theirs plus 10 points, and the group (or bed) means within the DEM runs' \
             spread in every draw (beside it, the means in a DEM run's seat: the extrapolation \
             and each DEM run judged against the other runs, so against as many runs). The plot \
             of the means shows the first draw.",
            s.draws.len(),
            s.draws
                .iter()
                .map(|d| format!("`{d}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    format!(
        "# Long-horizon study: {}\n\n{} particles, τ = {} s; the recording `{}` holds {} \
         recorded period(s), {} reference periods and {} DEM twin(s). Each row replays the \
         first P recorded periods along a recurrence path (seed: {}{}) over the {} reference \
         periods (`mirror`: entering the drum's mirror image at every jump) and compares it \
         with the DEM and its twins at every t_k (200 Voronoi cells \
         unless `--cells` says otherwise). ratio: the extrapolation's mean cell distance to \
         the DEM runs over the DEM runs' own mean distance; outside DEM range: the t_k where \
         it is farther from them than the two farthest DEM runs are from each other; means \
         error/spread: the largest error of the group (or bed) means against the largest \
         difference between two DEM runs' means; recording: DEM seconds to t0 and through the \
         P recorded periods.{pooled}\n\n```\n{table}```\n\n![ratio to the DEM's spread](ratio.svg)\n\n\
         ![means](means.svg)\n",
        s.case,
        s.particles,
        crate::fmt::sig(s.tau, 6),
        s.recording,
        s.periods_in_recording,
        s.reference_periods,
        s.twins,
        s.path_seed
            .map_or("the case's".to_string(), |x| x.to_string()),
        s.jump_nearest.map_or(String::new(), |k| format!(
            "; jumps only into {} the end of the P used",
            nearest_starts(k)
        )) + &s
            .jump_every
            .map_or(String::new(), |n| format!("; {}", leaving_every(n))),
        s.reference_periods,
    )
}

/// Each run's line: one colour per P and boundary (in the order the runs come), the
/// mirror's line dashed in its colour.
fn line_kinds(runs: &[Entry]) -> Vec<LineKind> {
    let mut colour = 0;
    let mut last = None;
    runs.iter()
        .map(|e| {
            let this = (e.recorded_periods, e.boundary);
            if last.is_some_and(|l| l != this) {
                colour += 1;
            }
            last = Some(this);
            match e.symmetry {
                Symmetry::None => LineKind::Extrapolation(colour),
                Symmetry::AxialMirror => LineKind::MirroredExtrapolation(colour),
            }
        })
        .collect()
}

fn svgs(s: &HorizonStudy) -> Result<Vec<(&'static str, String)>> {
    let kinds = line_kinds(&s.runs);
    let ratio_lines: Vec<Line> = s
        .runs
        .iter()
        .zip(&kinds)
        .map(|(e, &kind)| Line {
            kind,
            label: e.label(),
            points: e
                .comparison
                .periods
                .iter()
                .filter_map(|p| Some((p.t, p.ratio_to_floor?)))
                .collect(),
        })
        .collect();
    let ratio = plots::lines(
        "Distance to the DEM runs over their own spread, per number of recorded periods",
        "t (s)",
        "ratio to the DEM runs' spread",
        &ratio_lines,
        Some((1.0, "one more DEM run (1)")),
    )?;
    // group means where the bed has hot and cold groups, the bed mean otherwise (a heated
    // wall): DEM and twins as lines, each P as a line
    let groups = s
        .runs
        .first()
        .is_some_and(|e| e.comparison.hot_particles > 0);
    let mut mean_lines = Vec::new();
    let mut push_means = |name: String, kind: LineKind, series: &[GroupMeans]| {
        if groups {
            for (which, hot) in [("hot", true), ("cold", false)] {
                mean_lines.push(Line {
                    kind,
                    label: format!("{name}, {which}"),
                    points: series
                        .iter()
                        .filter_map(|g| Some((g.t, if hot { g.hot? } else { g.cold? })))
                        .collect(),
                });
            }
        } else {
            mean_lines.push(Line {
                kind,
                label: format!("{name}, bed"),
                points: series.iter().map(|g| (g.t, g.bed)).collect(),
            });
        }
    };
    if let Some(first) = s.runs.first() {
        let c = &first.comparison;
        push_means("DEM".into(), LineKind::Dem, &c.dem_series);
        for (m, twin) in c.dem_runs_series.iter().enumerate() {
            push_means(format!("DEM twin {}", m + 1), LineKind::DemRun, twin);
        }
    }
    // the DEM runs above are the first draw's: the extrapolations beside them too
    let first_draw = s.runs.first().and_then(|e| e.draw.clone());
    for (e, &kind) in s
        .runs
        .iter()
        .zip(&kinds)
        .filter(|(e, _)| e.draw == first_draw)
    {
        let extrapolated: Vec<GroupMeans> = e
            .comparison
            .periods
            .iter()
            .map(|p| GroupMeans {
                k: p.k,
                t: p.t,
                hot: p.hot_mean_extra,
                cold: p.cold_mean_extra,
                bed: p.bed_mean_extra,
            })
            .collect();
        push_means(format!("extrapolated, {}", e.label()), kind, &extrapolated);
    }
    let means = plots::lines(
        if groups {
            "Hot and cold group means: the DEM runs and each P"
        } else {
            "Bed mean: the DEM runs and each P"
        },
        "t (s)",
        "mean temperature (K)",
        &mean_lines,
        None,
    )?;
    Ok(vec![("ratio.svg", ratio), ("means.svg", means)])
}

/// `--jump-nearest K` in words: the recorded periods a path may enter.
fn nearest_starts(k: u32) -> String {
    if k == 1 {
        "the recorded period whose start is nearest".into()
    } else {
        format!("the {k} recorded periods whose starts are nearest")
    }
}

/// Where the paths leave the recording with `--jump-every n`, in words.
fn leaving_every(n: u32) -> String {
    format!(
        "jumps: leaving the recording after every {n} period{} in a row, from where the path stands",
        if n == 1 { "" } else { "s" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recording_cost_of_p_periods_adds_the_first_p() {
        let costs = RecordingCosts {
            seconds_to_t0: 10.0,
            seconds_period: 12.0,
            seconds_each_period: vec![2.0, 3.0, 3.0, 4.0],
            ..RecordingCosts::default()
        };
        assert_eq!(recording_seconds(&costs, 1), Some(12.0));
        assert_eq!(recording_seconds(&costs, 2), Some(15.0));
        assert_eq!(recording_seconds(&costs, 4), Some(22.0));
        assert_eq!(recording_seconds(&costs, 5), None);
        let single = RecordingCosts {
            seconds_each_period: Vec::new(),
            ..costs
        };
        assert_eq!(recording_seconds(&single, 1), Some(22.0));
        assert_eq!(recording_seconds(&single, 2), None);
    }
}
