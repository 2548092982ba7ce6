//! `tdex study`: parameter studies over recordings (Haydar §3.2–3.3). Each run is recorded,
//! extrapolated and compared with the DEM reference; the study writes a grid on
//! the terminal (or JSON), `study.json`, `study.md` and SVG plots into its directory.

pub use tdex::flow;
mod horizon;
mod period;
mod plots;
mod regimes;
mod sampling;

use crate::cli::{StudyKind, StudyPlan};
use crate::compare::{self, Comparison};
use crate::extrapolation;
use anyhow::Result;
use extrapolate::ExtrapolationRequest;
// the study's speedups are the report's (Table 6 form)
use crate::report::costs::{CostTable, TABLE_PERIODS};
use serde::Serialize;
use std::path::{Path, PathBuf};
use tdex_format::{ExtrapolationReader, RecordingReader};

/// How a horizon study's recurrence paths jump: their seed (`None`: the case's), the
/// starts they may enter and where they leave the recording.
#[derive(Debug, Clone)]
pub struct PathJumps {
    pub seed: Option<u64>,
    pub starts: extrapolate::JumpStarts,
    pub leave: extrapolate::Leave,
}

pub fn run(plan: &StudyPlan) -> Result<()> {
    tdex_format::output::create_dir_all(&plan.output)?;
    match &plan.kind {
        StudyKind::Sampling {
            runs,
            skipped,
            tau_rev,
        } => sampling::run(plan, runs, skipped, *tau_rev),
        StudyKind::Period { runs, revolutions } => period::run(plan, runs, *revolutions),
        StudyKind::Regimes {
            runs,
            tau_rev,
            min_relative,
        } => regimes::run(plan, runs, *tau_rev, *min_relative),
        StudyKind::Horizon {
            source,
            draws,
            recorded_periods,
            jumps,
            images,
            boundaries,
        } => horizon::run(
            plan,
            source,
            draws,
            recorded_periods,
            jumps,
            images,
            boundaries,
        ),
    }
}

// the DEM phases log plain lines when stderr is not a terminal (a study in the background)
pub(crate) use crate::progress::{dem_bar, on_phase_logged, runs_bar};

/// The errors and costs of one recording extrapolated against its DEM reference.
#[derive(Debug, Clone, Serialize)]
pub struct Outcome {
    pub recording: String,
    pub extrapolation: Option<String>,
    pub rows: u64,
    pub table_bytes: u64,
    pub bytes_per_row: f64,
    /// Periods extrapolated (and compared).
    pub periods: u32,
    pub replay_seconds_per_period: Option<f64>,
    /// The compared `t_k` (k ≥ 2) and, at each, ε_rel and the Eq. 10 error of the period
    /// ending there (fractions, not %; null where undefined).
    pub k: Vec<u32>,
    pub eps_rel: Vec<Option<f64>>,
    pub eps_rel_max: Option<f64>,
    pub energy_error: Vec<Option<f64>>,
    pub energy_error_mean_abs: Option<f64>,
    /// Complete DEM seconds / extrapolated DEM seconds to reach t1 + 100 τ (Table 6 form).
    pub speedup_100: Option<f64>,
    /// Why there is no extrapolation (the extrapolation's error or a refusal).
    pub error: Option<String>,
    #[serde(skip)]
    pub comparison: Option<Comparison>,
}

impl Outcome {
    /// The recording's table alone (no extrapolation), with `error` saying why.
    pub fn table_only(rec: &RecordingReader, error: String) -> Self {
        let rows = rec.summary().map_or(0, |s| s.rows);
        Outcome {
            recording: rec.path().display().to_string(),
            extrapolation: None,
            rows,
            table_bytes: rec.table_bytes(),
            bytes_per_row: rec.table_bytes() as f64 / rows.max(1) as f64,
            periods: 0,
            replay_seconds_per_period: None,
            k: Vec::new(),
            eps_rel: Vec::new(),
            eps_rel_max: None,
            energy_error: Vec::new(),
            energy_error_mean_abs: None,
            speedup_100: None,
            error: Some(error),
            comparison: None,
        }
    }
}

/// Extrapolates `recording` over `periods` into `extra` (the explicit scheme, on `threads`
/// workers) and compares it with the DEM reference.
pub fn evaluate(
    recording: &Path,
    extra: &Path,
    periods: u32,
    threads: usize,
    cells: usize,
) -> Result<Outcome> {
    let rec = RecordingReader::open(recording)?;
    let request = ExtrapolationRequest::new(
        recording.to_path_buf(),
        periods,
        extra.to_path_buf(),
        extrapolation::memory_limit(None),
    );
    if let Err(e) =
        extrapolation::extrapolate_on(threads, &request, extrapolation::tell_unless_it_fits)
    {
        // a refused extrapolation (e.g. the explicit scheme's CFL guard) is a study result
        return Ok(Outcome::table_only(&rec, format!("{e:#}")));
    }
    let ext = ExtrapolationReader::open(extra)?;
    let c = compare::compare(&rec, &ext, cells, compare::DEFAULT_SEED)?;
    let mut o = Outcome::table_only(&rec, String::new());
    o.error = None;
    o.extrapolation = Some(extra.display().to_string());
    o.periods = periods;
    o.replay_seconds_per_period = ext.costs().map(|c| c.seconds_per_period);
    o.k = c.periods.iter().map(|p| p.k).collect();
    o.eps_rel = c.periods.iter().map(|p| p.eps_rel).collect();
    o.eps_rel_max = o.eps_rel.iter().flatten().copied().reduce(f64::max);
    o.energy_error = c.periods.iter().map(|p| p.energy_error).collect();
    let abs: Vec<f64> = o.energy_error.iter().flatten().map(|e| e.abs()).collect();
    o.energy_error_mean_abs = (!abs.is_empty()).then(|| abs.iter().sum::<f64>() / abs.len() as f64);
    if let (Some(rc), Some(ec)) = (rec.costs(), ext.costs()) {
        let pairing = ext.info().roles.pairing_seconds();
        let info = rec.info();
        let table = CostTable::new(
            rc,
            info.reference_periods,
            info.recorded_periods,
            ext.info().roles.recorded_periods_used(),
            ec,
            pairing,
        );
        o.speedup_100 = table.speedup(TABLE_PERIODS as f64);
    }
    o.comparison = Some(c);
    Ok(o)
}

/// `x` as a percentage with 3 decimals, or "-".
/// The columns that end the sampling and period tables: an outcome's replay time, errors
/// and speedup.
pub(crate) fn outcome_header() -> String {
    format!(
        "{:>10} {:>12} {:>10} {:>9}",
        "replay s/τ", "max eps_rel%", "|eq10| %", "speedup"
    )
}

impl Outcome {
    /// This outcome's cells under [`outcome_header`].
    pub(crate) fn cells(&self) -> String {
        format!(
            "{:>10} {:>12} {:>10} {:>9}",
            num(self.replay_seconds_per_period, 4),
            pct(self.eps_rel_max),
            pct(self.energy_error_mean_abs),
            num(self.speedup_100, 2),
        )
    }
}

pub(crate) fn pct(x: Option<f64>) -> String {
    x.map_or("-".into(), |v| format!("{:.3}", 100.0 * v))
}

pub(crate) fn num(x: Option<f64>, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// Writes the study into its directory (`study.json`, the plots, `study.md`) and prints
/// its JSON, or the table and the files written.
pub(crate) fn finish(
    plan: &StudyPlan,
    study: &impl Serialize,
    table: &str,
    markdown: &str,
    svgs: Vec<(&str, String)>,
) -> Result<()> {
    let json = serde_json::to_string_pretty(study)?;
    let dir = &plan.output;
    let mut files = vec![write_file(dir, "study.json", &json)?];
    for (name, svg) in &svgs {
        files.push(write_file(dir, name, svg)?);
    }
    files.push(write_file(dir, "study.md", markdown)?);
    if plan.json {
        println!("{json}");
    } else {
        print!("{table}");
        for f in files {
            println!("wrote         {}", f.display());
        }
    }
    Ok(())
}

/// Writes `dir/name` (through a temporary file renamed into place); returns its path.
pub(crate) fn write_file(dir: &Path, name: &str, text: &str) -> Result<PathBuf> {
    Ok(tdex_format::output::write_atomically(
        &dir.join(name),
        text.as_bytes(),
    )?)
}

/// The paths of one run's files in the study directory.
pub(crate) fn run_paths(dir: &Path, stem: &str) -> (PathBuf, PathBuf) {
    (
        dir.join(format!("{stem}.mcap")),
        dir.join(format!("{stem}.extra.mcap")),
    )
}
