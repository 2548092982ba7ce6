//! `tdex report`: a self-contained report of an extrapolation against its recording
//! (DESIGN.md §7): `report.md` and `report.html` with the error table (Table 5 form), the
//! cost table (Table 6 form) and SVG plots (Figures 7 and 9, errors, speedup, the field).

mod content;
pub(crate) mod costs;
mod document;
pub(crate) mod plots;

use crate::cli::ReportPlan;
use crate::compare::{self, Comparison};
use anyhow::{Context, Result};
use content::{DURATIONS_SVG, ERRORS_SVG, FIELD_SVG, MEANS_SVG, SPEEDUP_SVG};
use costs::CostTable;
use recorder::format::{ExtrapolationReader, RecordingReader};
use recorder::output::OutputSet;
use std::path::{Path, PathBuf};

/// The report's own files; those of an older report that this one does not write again are
/// removed once the new report is in place.
const MARKDOWN: &str = "report.md";
const HTML: &str = "report.html";
const ALL_FILES: [&str; 7] = [
    MARKDOWN,
    HTML,
    MEANS_SVG,
    ERRORS_SVG,
    SPEEDUP_SVG,
    DURATIONS_SVG,
    FIELD_SVG,
];

pub fn run(plan: &ReportPlan) -> Result<()> {
    let recording = RecordingReader::open(&plan.recording)?;
    let extrapolation = ExtrapolationReader::open(&plan.extrapolation)?;
    let comparison = compare::compare(&recording, &extrapolation, plan.cells, plan.seed)?;
    let files = write(&plan.output, &recording, &extrapolation, &comparison)?;
    for f in files {
        println!("{}", f.display());
    }
    Ok(())
}

/// Writes the report into `dir` (created if missing); returns the files written. Every file
/// is written and fsynced to a temporary name first and renamed into place only when all
/// are (plots first, the two reports last): a full disk leaves the previous report whole.
pub fn write(
    dir: &Path,
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
    comparison: &Comparison,
) -> Result<Vec<PathBuf>> {
    recorder::output::create_dir_all(dir)?;
    let info = recording.info();
    let rec_path = recording.path().display().to_string();

    let costs = match (recording.costs(), extrapolation.costs()) {
        (Some(rc), Some(ec)) => {
            let pairing_seconds = extrapolation
                .info()
                .pairing
                .get("seconds")
                .and_then(|v| v.as_f64());
            Ok(CostTable::new(
                rc,
                info.reference_periods,
                ec,
                pairing_seconds,
            ))
        }
        (None, _) => Err(format!(
            "{rec_path} has no costs record (its writer was interrupted)"
        )),
        (_, None) => Err(format!(
            "{} has no costs record (its writer was interrupted)",
            extrapolation.path().display()
        )),
    };

    let mut svgs: Vec<(&'static str, String)> = Vec::new();
    let plot = |name: &str, r: Result<String>| {
        r.with_context(|| format!("{}: cannot draw the plot", dir.join(name).display()))
    };
    svgs.push((MEANS_SVG, plot(MEANS_SVG, plots::means(comparison))?));
    svgs.push((ERRORS_SVG, plot(ERRORS_SVG, plots::errors(comparison))?));
    if let Ok(t) = &costs {
        svgs.push((
            SPEEDUP_SVG,
            plot(SPEEDUP_SVG, plots::error_vs_speedup(comparison, t))?,
        ));
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
    let field = match comparison.periods.last() {
        None => Err("no extrapolated t_k has a DEM reference".to_string()),
        Some(last) => {
            let k = last.k;
            let dem = recording
                .snapshot(k)
                .with_context(|| format!("{rec_path}: cannot read the snapshot at t_{k}"))?;
            let extra = extrapolation
                .snapshots()
                .with_context(|| {
                    format!(
                        "{}: cannot read the extrapolated snapshots",
                        extrapolation.path().display()
                    )
                })?
                .into_iter()
                .find(|s| s.index == k);
            match (dem, extra) {
                (Some(dem), Some(extra)) => {
                    svgs.push((FIELD_SVG, plot(FIELD_SVG, plots::field(&dem, &extra, k))?));
                    Ok(k)
                }
                (None, _) => Err(format!("{rec_path} has no DEM snapshot at t_{k}")),
                (_, None) => Err(format!(
                    "{} has no snapshot at t_{k}",
                    extrapolation.path().display()
                )),
            }
        }
    };

    let doc = content::document(&content::Inputs {
        recording_path: rec_path.clone(),
        extrapolation_path: extrapolation.path().display().to_string(),
        info,
        extrapolation: extrapolation.info(),
        summary: recording.summary(),
        comparison,
        costs,
        field,
        plots: svgs.iter().map(|(name, _)| *name).collect(),
    });

    let mut set = OutputSet::new();
    for (name, svg) in &svgs {
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
