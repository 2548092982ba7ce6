//! `tdex study horizon`: the extrapolation over many periods against the DEM and its twins,
//! per number of recorded periods P, beside what recording P periods costs, so
//! that a user can pick P for their case.
//!
//! The DEM runs once and records the largest P (or a recording made before is read): a
//! smaller P replays the first P of its periods, which are the tables and snapshots a
//! recording of P periods would hold (the recorder only reads the DEM's state), so every P
//! is judged against the same DEM run and the same twins. With `--mirror` each P runs twice,
//! as the paper does and with the drum's mirror image at every jump, on the same paths.

use super::plots::{self, Line, LineKind};
use crate::cli::{HorizonSource, StudyPlan};
use crate::compare::{self, Comparison, GroupMeans};
use crate::extrapolation;
use anyhow::{bail, Context, Result};
use extrapolate::{ExtrapolationRequest, MirrorCheck};
use recorder::record;
use serde::Serialize;
use std::path::Path;
use tdex_format::extrapolation::Symmetry;
use tdex_format::{ExtrapolationReader, RecordingCosts, RecordingReader};

/// One number of recorded periods with one image at the jumps, extrapolated over the
/// reference periods and judged.
#[derive(Debug, Serialize)]
struct Entry {
    recorded_periods: u32,
    /// `none` (the paper's method) or `axial_mirror`.
    symmetry: Symmetry,
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
    runs: Vec<Entry>,
}

pub fn run(
    plan: &StudyPlan,
    source: &HorizonSource,
    recorded_periods: &[u32],
    seed: Option<u64>,
    images: &[Symmetry],
) -> Result<()> {
    let dir = &plan.output;
    let recording = match source {
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
    };
    let rec = RecordingReader::open(&recording)?;
    let info = rec.info().clone();
    if let Some(&p) = recorded_periods
        .iter()
        .find(|&&p| p > info.recorded_periods)
    {
        bail!(
            "{}: holds {} recorded period(s); --recorded-periods {p} cannot be replayed from it",
            recording.display(),
            info.recorded_periods
        );
    }
    let mut runs = Vec::new();
    for (&p, &symmetry) in recorded_periods
        .iter()
        .flat_map(|p| images.iter().map(move |s| (p, s)))
    {
        let extra = dir.join(match symmetry {
            Symmetry::None => format!("horizon_p{p}.extra.mcap"),
            Symmetry::AxialMirror => format!("horizon_p{p}_mirror.extra.mcap"),
        });
        let request = ExtrapolationRequest {
            recorded_periods: Some(p),
            path_seed: seed,
            symmetry,
            ..ExtrapolationRequest::new(
                recording.clone(),
                info.reference_periods,
                extra.clone(),
                extrapolation::memory_limit(None),
            )
        };
        let outcome = crate::with_workers(plan.threads, || {
            Ok(extrapolate::extrapolate_recording(
                &request,
                extrapolation::tell,
            )?)
        })
        .with_context(|| format!("extrapolating with {p} recorded period(s)"))?;
        let ext = ExtrapolationReader::open(&extra)?;
        let comparison = compare::compare(&rec, &ext, plan.cells, compare::DEFAULT_SEED)?;
        runs.push(Entry::new(
            p,
            symmetry,
            outcome.mirror_check,
            &extra,
            rec.costs(),
            comparison,
        ));
    }
    let study = HorizonStudy {
        study: "horizon",
        case: plan.case_path.display().to_string(),
        recording: recording.display().to_string(),
        particles: info.particles,
        periods_in_recording: info.recorded_periods,
        reference_periods: info.reference_periods,
        twins: info.twins,
        tau: info.tau,
        path_seed: seed,
        runs,
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
    /// `P = 2`, or `P = 2, mirror`: the run's name in the table and the plots.
    fn label(&self) -> String {
        match self.symmetry {
            Symmetry::None => format!("P = {}", self.recorded_periods),
            Symmetry::AxialMirror => format!("P = {}, mirror", self.recorded_periods),
        }
    }

    fn new(
        p: u32,
        symmetry: Symmetry,
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
    let mut t = format!(
        "{:<13} {:>14} {:>12} {:>13} {:>18} {:>22} {:>18}\n",
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
            "{:<13} {:>14} {:>12} {:>13} {:>18} {:>22} {:>18}\n",
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
    for e in &s.runs {
        t += &format!("{}: {}\n", e.label(), e.verdict);
        for line in extrapolation::mirror_check_lines(&e.mirror_check) {
            t += &format!("{}: mirror check {line}\n", e.label());
        }
    }
    if let Some(best) = s
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

fn markdown(s: &HorizonStudy, table: &str) -> String {
    format!(
        "# Long-horizon study: {}\n\n{} particles, τ = {} s; the recording `{}` holds {} \
         recorded period(s), {} reference periods and {} DEM twin(s). Each row replays the \
         first P recorded periods along a recurrence path (seed: {}) over the {} reference \
         periods (`mirror`: entering the drum's mirror image at every jump) and compares it \
         with the DEM and its twins at every t_k (200 Voronoi cells \
         unless `--cells` says otherwise). ratio: the extrapolation's mean cell distance to \
         the DEM runs over the DEM runs' own mean distance; outside DEM range: the t_k where \
         it is farther from them than the two farthest DEM runs are from each other; means \
         error/spread: the largest error of the group (or bed) means against the largest \
         difference between two DEM runs' means; recording: DEM seconds to t0 and through the \
         P recorded periods.\n\n```\n{table}```\n\n![ratio to the DEM's spread](ratio.svg)\n\n\
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
        s.reference_periods,
    )
}

/// Each run's line: one colour per P (in the order the runs come), the mirror's line
/// dashed in its P's colour.
fn line_kinds(runs: &[Entry]) -> Vec<LineKind> {
    let mut colour = 0;
    let mut last_p = None;
    runs.iter()
        .map(|e| {
            if last_p.is_some_and(|p| p != e.recorded_periods) {
                colour += 1;
            }
            last_p = Some(e.recorded_periods);
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
    for (e, &kind) in s.runs.iter().zip(&kinds) {
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
