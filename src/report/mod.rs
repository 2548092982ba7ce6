//! `tdex report`: a self-contained report of an extrapolation (docs/method.md §7): `report.md` and
//! `report.html` opening with a summary of what was predicted, the prediction over all
//! extrapolated periods (bed and group means, the walls' heat, the spread, the mixing, the
//! field), and where the recording has a DEM reference the error table (Table 5 form)
//! against it; the cost table (Table 6 form) and SVG plots.

mod content;
pub(crate) mod costs;
mod document;
pub(crate) mod plots;
pub mod prediction;

use crate::cli::ReportPlan;
use crate::compare::{self, Comparison};
use anyhow::{Context, Result};
use content::{
    BED_MEAN_SVG, CLASS_MEANS_SVG, DURATIONS_SVG, ERRORS_SVG, FIELDS_SVG, FIELD_SVG, LACEY_SVG,
    MEANS_SVG, SEGREGATION_SVG, SPEEDUP_SVG, SPREAD_SVG, WALL_HEAT_SVG,
};
use costs::CostTable;
use prediction::{Measures, Prediction};
use std::path::{Path, PathBuf};
use tdex_format::output::OutputSet;
use tdex_format::{ExtrapolationReader, RecordingReader};

/// The report's own files; those of an older report that this one does not write again are
/// removed once the new report is in place.
const MARKDOWN: &str = "report.md";
const HTML: &str = "report.html";
const ALL_FILES: [&str; 14] = [
    MARKDOWN,
    HTML,
    BED_MEAN_SVG,
    MEANS_SVG,
    WALL_HEAT_SVG,
    SPREAD_SVG,
    LACEY_SVG,
    FIELDS_SVG,
    ERRORS_SVG,
    SPEEDUP_SVG,
    DURATIONS_SVG,
    FIELD_SVG,
    CLASS_MEANS_SVG,
    SEGREGATION_SVG,
];

pub fn run(plan: &ReportPlan) -> Result<()> {
    let recording = RecordingReader::open(&plan.recording)?;
    let extrapolation = ExtrapolationReader::open(&plan.extrapolation)?;
    let comparison = if recording.info().reference_periods > 0 {
        let dem_runs = compare::open_dem_runs(&plan.dem_runs)?;
        let dem_runs: Vec<&RecordingReader> = dem_runs.iter().collect();
        Some(compare::compare_runs(
            &recording,
            compare::Second::Extrapolation(&extrapolation),
            &dem_runs,
            plan.cells,
            plan.seed,
        )?)
    } else if let Some(run) = plan.dem_runs.first() {
        return Err(crate::cli::UsageError(format!(
            "{} has no DEM reference to measure further DEM runs such as {} against: record it \
             with --reference K to compare",
            recording.path().display(),
            run.display()
        ))
        .into());
    } else {
        None
    };
    let files = write_with(
        &plan.output,
        &recording,
        &extrapolation,
        comparison.as_ref(),
        plan.cells,
        plan.seed,
    )?;
    for f in files {
        println!("{}", f.display());
    }
    Ok(())
}

/// Writes the report into `dir` (created if missing); returns the files written. Every file
/// is written and fsynced to a temporary name first and renamed into place only when all
/// are (plots first, the two reports last): a full disk leaves the previous report whole.
/// `comparison` is the extrapolation against the recording's DEM reference (None without
/// one); the Lacey index is computed on the comparison's Voronoi cells, or on the default
/// ones without a comparison.
pub fn write(
    dir: &Path,
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
    comparison: Option<&Comparison>,
) -> Result<Vec<PathBuf>> {
    let (cells, seed) = comparison.map_or((compare::DEFAULT_CELLS, compare::DEFAULT_SEED), |c| {
        (c.cells, c.seed)
    });
    write_with(dir, recording, extrapolation, comparison, cells, seed)
}

/// [`write`] with the Voronoi cells of the Lacey index drawn as the comparison draws its own:
/// `cells` of them (fewer for a small bed, see [`prediction::LACEY_MIN_PER_CELL`]) from
/// `seed`.
pub fn write_with(
    dir: &Path,
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
    comparison: Option<&Comparison>,
    cells: usize,
    seed: u64,
) -> Result<Vec<PathBuf>> {
    tdex_format::output::create_dir_all(dir)?;
    let info = recording.info();
    let rec_path = recording.path().display().to_string();
    let extra_path = extrapolation.path().display().to_string();

    if extrapolation.info().recording_info != *info {
        return Err(compare::CompareError::OtherRecording {
            extrapolation: extra_path,
            recording: rec_path,
            names: extrapolation.info().recording.clone(),
        }
        .into());
    }
    let dem = recording
        .snapshots()
        .with_context(|| format!("{rec_path}: cannot read the snapshots"))?;
    let (i0, i1) = prediction::t0_t1(&dem, &rec_path)?;
    let measures = Measures::new(info, &dem[i0], &dem[i1], cells, seed);
    // the extrapolated snapshots are streamed: memory holds the few the plots draw
    let field_snap = comparison.and_then(|c| c.periods.last()).map(|last| last.k);
    let extra_snaps = extrapolation.snapshots_in_order().map(|s| {
        s.with_context(|| format!("{extra_path}: cannot read the extrapolated snapshots"))
    });
    let (pred, field_extra) = Prediction::new(
        info,
        &measures,
        extrapolation.snapshot_count(),
        extra_snaps,
        field_snap,
    )
    .with_context(|| format!("{extra_path}: nothing to report"))?;
    // the DEM's own spread and mixing where the recording has a reference: the reference,
    // then its twins
    let dem_points: Vec<Vec<prediction::Point>> = if comparison.is_some() {
        let mut v = vec![prediction::dem_points(&measures, &dem)];
        for twin in recording
            .twin_snapshots()
            .with_context(|| format!("{rec_path}: cannot read the twins' snapshots"))?
        {
            v.push(prediction::dem_points(&measures, &twin));
        }
        v
    } else {
        Vec::new()
    };

    let costs = cost_table(recording, extrapolation);

    let mut svgs = draw_plots(dir, recording, &pred, comparison, &dem_points, &costs)?;
    let field = field_snap.map(|k| {
        let dem_k = dem.iter().find(|s| s.index == k);
        match (dem_k, &field_extra) {
            (Some(dem_k), Some(extra)) => {
                svgs.push((
                    FIELD_SVG,
                    drawn(
                        dir,
                        FIELD_SVG,
                        plots::field(dem_k, extra, k, pred.drum_radius),
                    )?,
                ));
                Ok::<_, anyhow::Error>(Ok(k))
            }
            (None, _) => Ok(Err(format!("{rec_path} has no DEM snapshot at t_{k}"))),
            (_, None) => Ok(Err(format!("{extra_path} has no snapshot at t_{k}"))),
        }
    });
    let field = field.transpose()?;

    let doc = content::document(&content::Inputs {
        recording_path: rec_path.clone(),
        extrapolation_path: extrapolation.path().display().to_string(),
        info,
        extrapolation: extrapolation.info(),
        summary: recording.summary(),
        prediction: &pred,
        comparison,
        costs,
        field,
        plots: svgs.iter().map(|(name, _)| *name).collect(),
    });

    commit(dir, &svgs, &doc)
}

/// The costs of Table 6, or why there are none: a recording or extrapolation written with
/// `--reproducible` has no wall times.
fn cost_table(
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
) -> std::result::Result<CostTable, String> {
    let info = recording.info();
    let rec_path = recording.path().display().to_string();
    let extra_path = extrapolation.path().display().to_string();
    match (recording.costs(), extrapolation.costs()) {
        (Some(rc), Some(ec)) => {
            let pairing_seconds = extrapolation.info().roles.pairing_seconds();
            Ok(CostTable::new(
                rc,
                info.reference_periods,
                info.recorded_periods,
                extrapolation.info().roles.recorded_periods_used(),
                ec,
                pairing_seconds,
            ))
        }
        (None, _) => Err(format!(
            "{rec_path} has no costs record (written with --reproducible, which leaves out the wall times)"
        )),
        (_, None) => Err(format!(
            "{extra_path} has no costs record (written with --reproducible, which leaves out the wall times)"
        )),
    }
}

/// A plot drawn, or why not, naming its file.
fn drawn(dir: &Path, name: &str, r: Result<String>) -> Result<String> {
    r.with_context(|| format!("{}: cannot draw the plot", dir.join(name).display()))
}

/// The report's plots, each with its file name, but the field at the last compared `t_k`.
fn draw_plots(
    dir: &Path,
    recording: &RecordingReader,
    pred: &Prediction,
    comparison: Option<&Comparison>,
    dem_points: &[Vec<prediction::Point>],
    costs: &std::result::Result<CostTable, String>,
) -> Result<Vec<(&'static str, String)>> {
    let info = recording.info();
    let mut svgs: Vec<(&'static str, String)> = Vec::new();
    let plot = |name: &str, r: Result<String>| drawn(dir, name, r);
    svgs.push((
        BED_MEAN_SVG,
        plot(BED_MEAN_SVG, plots::bed_mean(pred, comparison))?,
    ));
    if pred.has_groups() {
        svgs.push((
            MEANS_SVG,
            plot(MEANS_SVG, plots::group_means(pred, comparison))?,
        ));
    }
    if pred.wall_heat().is_some() {
        svgs.push((
            WALL_HEAT_SVG,
            plot(WALL_HEAT_SVG, plots::wall_heat(pred, comparison))?,
        ));
    }
    svgs.push((
        SPREAD_SVG,
        plot(SPREAD_SVG, plots::spread(pred, dem_points))?,
    ));
    if pred.has_groups() {
        svgs.push((LACEY_SVG, plot(LACEY_SVG, plots::lacey(pred, dem_points))?));
    }
    let panels: Vec<(&tdex_format::Snapshot, String)> = pred
        .fields
        .iter()
        .map(|s| {
            let what = if s.index == 1 { ", DEM state" } else { "" };
            (
                s,
                format!("t{} (t = {} s{what})", s.index, plots::tick(s.time)),
            )
        })
        .collect();
    svgs.push((
        FIELDS_SVG,
        plot(FIELDS_SVG, plots::fields(&panels, pred.drum_radius))?,
    ));
    if let Some(c) = comparison {
        svgs.push((ERRORS_SVG, plot(ERRORS_SVG, plots::errors(c))?));
        if let Some(size_classes) = &c.size_classes {
            svgs.push((
                CLASS_MEANS_SVG,
                plot(CLASS_MEANS_SVG, plots::class_means(size_classes))?,
            ));
            svgs.push((
                SEGREGATION_SVG,
                plot(SEGREGATION_SVG, plots::segregation(size_classes))?,
            ));
        }
        if let Ok(t) = costs {
            svgs.push((
                SPEEDUP_SVG,
                plot(SPEEDUP_SVG, plots::error_vs_speedup(c, t))?,
            ));
        }
    }
    if let Some(summary) = recording.summary() {
        svgs.push((
            DURATIONS_SVG,
            plot(
                DURATIONS_SVG,
                plots::duration_cdf(
                    &summary.duration_histogram,
                    info.sample_every,
                    info.dtc_max_steps,
                ),
            )?,
        ));
    }
    Ok(svgs)
}

/// Writes the plots and the document together (each to a temporary file, renamed once all
/// are written), then removes what an older report in `dir` had and this one has not.
fn commit(
    dir: &Path,
    svgs: &[(&'static str, String)],
    doc: &document::Document,
) -> Result<Vec<PathBuf>> {
    let mut set = OutputSet::new();
    for (name, svg) in svgs {
        set.add(&dir.join(name), svg.as_bytes())?;
    }
    set.add(&dir.join(MARKDOWN), doc.markdown().as_bytes())?;
    set.add(&dir.join(HTML), doc.html().as_bytes())?;
    let written = set.commit()?;
    // a plot of an older report that this one has not (say, no costs this time) would
    // contradict it: it goes, now that the new report is in place
    for name in ALL_FILES {
        let path = dir.join(name);
        if !written.contains(&path) {
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(e).with_context(|| {
                        format!("{}: cannot remove the older report's file", path.display())
                    })
                }
                _ => {}
            }
        }
    }
    Ok(written)
}
