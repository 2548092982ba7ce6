//! Validated plans: every flag and the case file are checked here, before any simulation starts.

use super::args::{BenchCommand, Cli, Command};
use anyhow::Result;
use extrapolate::replay::Scheme;
use recorder::format::AreaEncoding;
use recorder::record::RecordOptions;
use recorder::Case;
use std::path::PathBuf;

/// A flag value outside its allowed range, or input files the command cannot use together
/// (exit code 2).
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

pub enum Plan {
    Run(RunPlan),
    Record(RecordPlan),
    Inspect(InspectPlan),
    BenchRecord(BenchRecordPlan),
    Pair(PairPlan),
    Extrapolate(ExtrapolatePlan),
    Compare(ComparePlan),
    Report(ReportPlan),
    Demo(DemoPlan),
}

pub struct DemoPlan {
    pub output: PathBuf,
    pub threads: usize,
}

pub struct ReportPlan {
    pub recording: PathBuf,
    pub extrapolation: PathBuf,
    pub output: PathBuf,
    pub cells: usize,
    pub seed: u64,
}

pub struct ComparePlan {
    pub recording: PathBuf,
    pub extrapolation: PathBuf,
    pub cells: usize,
    pub seed: u64,
    pub json: bool,
    pub csv: bool,
}

pub struct PairPlan {
    pub file: PathBuf,
    pub threads: usize,
    pub json: bool,
}

pub struct ExtrapolatePlan {
    pub file: PathBuf,
    pub periods: u32,
    pub output: PathBuf,
    pub scheme: Scheme,
    pub stream: bool,
    pub threads: usize,
    pub json: bool,
}

pub struct BenchRecordPlan {
    pub case_path: PathBuf,
    pub case_toml: String,
    pub case: Case,
    pub options: RecordOptions,
    pub repeats: u32,
    pub threads: usize,
    pub json: bool,
}

pub struct RecordPlan {
    pub case_path: PathBuf,
    pub case_toml: String,
    pub case: Case,
    pub output: PathBuf,
    pub options: RecordOptions,
    pub threads: usize,
    pub json: bool,
}

pub struct InspectPlan {
    pub file: PathBuf,
    pub json: bool,
}

pub struct RunPlan {
    pub case_path: PathBuf,
    pub case: Case,
    pub threads: usize,
    pub json: bool,
}

fn threads(requested: Option<usize>) -> Result<usize> {
    match requested {
        Some(0) => Err(UsageError("--threads = 0 is not allowed: give at least 1".into()).into()),
        Some(n) => Ok(n),
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
    }
}

impl Plan {
    pub fn from_args(cli: Cli) -> Result<Self> {
        match cli.command {
            Command::Run {
                case,
                threads: t,
                json,
            } => {
                let threads = threads(t)?;
                let loaded = recorder::case::load(&case)?;
                Ok(Plan::Run(RunPlan {
                    case_path: case,
                    case: loaded,
                    threads,
                    json,
                }))
            }
            Command::Record {
                case,
                output,
                tau,
                tau_rev,
                n,
                dtc_max,
                reference,
                exact_area,
                threads: t,
                json,
            } => {
                let threads = threads(t)?;
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let options =
                    record_options(&loaded, tau, tau_rev, n, dtc_max, reference, exact_area)?;
                check_output(&output)?;
                Ok(Plan::Record(RecordPlan {
                    case_path: case,
                    case_toml,
                    case: loaded,
                    output,
                    options,
                    threads,
                    json,
                }))
            }
            Command::Inspect { file, json } => Ok(Plan::Inspect(InspectPlan { file, json })),
            Command::Pair {
                file,
                threads: t,
                json,
            } => Ok(Plan::Pair(PairPlan {
                file,
                threads: threads(t)?,
                json,
            })),
            Command::Extrapolate {
                file,
                periods,
                output,
                scheme,
                stream,
                threads: t,
                json,
            } => {
                let threads = threads(t)?;
                if periods == 0 {
                    return Err(usage(
                        "--periods = 0 is not allowed: extrapolate at least 1 period".into(),
                    ));
                }
                let scheme: Scheme = scheme
                    .parse()
                    .map_err(|e: String| usage(format!("--scheme: {e}")))?;
                check_output(&output)?;
                Ok(Plan::Extrapolate(ExtrapolatePlan {
                    file,
                    periods,
                    output,
                    scheme,
                    stream,
                    threads,
                    json,
                }))
            }
            Command::Compare {
                recording,
                extrapolation,
                cells,
                seed,
                json,
                csv,
            } => {
                check_cells(cells)?;
                Ok(Plan::Compare(ComparePlan {
                    recording,
                    extrapolation,
                    cells,
                    seed,
                    json,
                    csv,
                }))
            }
            Command::Report {
                recording,
                extrapolation,
                output,
                cells,
                seed,
            } => {
                check_cells(cells)?;
                check_output_dir(&output)?;
                Ok(Plan::Report(ReportPlan {
                    recording,
                    extrapolation,
                    output,
                    cells,
                    seed,
                }))
            }
            Command::Demo { output, threads: t } => {
                let threads = threads(t)?;
                check_output_dir(&output)?;
                Ok(Plan::Demo(DemoPlan { output, threads }))
            }
            Command::Bench(BenchCommand::Record {
                case,
                tau_rev,
                n,
                dtc_max,
                repeats,
                threads: t,
                json,
            }) => {
                let threads = threads(t)?;
                if repeats == 0 {
                    return Err(usage(
                        "--repeats = 0 is not allowed: give at least 1".into(),
                    ));
                }
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let options = record_options(&loaded, None, Some(tau_rev), n, dtc_max, 0, false)?;
                Ok(Plan::BenchRecord(BenchRecordPlan {
                    case_path: case,
                    case_toml,
                    case: loaded,
                    options,
                    repeats,
                    threads,
                    json,
                }))
            }
        }
    }
}

fn usage(message: String) -> anyhow::Error {
    UsageError(message).into()
}

/// Checks the recording settings against the case: `τ` and `Δt_c^max` multiples of `n`.
pub(crate) fn record_options(
    case: &Case,
    tau: Option<f64>,
    tau_rev: Option<f64>,
    n: u32,
    dtc_max: u32,
    reference: u32,
    exact_area: bool,
) -> Result<RecordOptions> {
    let revolution = case.drum.rotation_period;
    let tau_seconds = match (tau, tau_rev) {
        (Some(t), _) if !(t.is_finite() && t > 0.0) => {
            return Err(usage(format!(
                "--tau = {t} is not allowed: give a period > 0 s"
            )))
        }
        (_, Some(f)) if !(f.is_finite() && f > 0.0) => {
            return Err(usage(format!(
                "--tau-rev = {f} is not allowed: give a fraction of a revolution > 0"
            )))
        }
        (Some(t), _) => t,
        (_, Some(f)) => f * revolution,
        (None, None) => revolution,
    };
    if n == 0 {
        return Err(usage(
            "--n = 0 is not allowed: the sampling factor is at least 1 step".into(),
        ));
    }
    if dtc_max == 0 || dtc_max % n != 0 {
        return Err(usage(format!(
            "--dtc-max = {dtc_max} is not allowed: Δt_c^max must be a positive multiple of n = {n} steps (e.g. {})",
            n * (dtc_max / n).max(1)
        )));
    }
    let exact_steps = tau_seconds / case.time.dt;
    let period_steps = exact_steps.round() as u64;
    if period_steps == 0
        || (exact_steps - period_steps as f64).abs() > 1e-6 * exact_steps
        || period_steps % n as u64 != 0
    {
        let valid = (exact_steps / n as f64).round().max(1.0) * n as f64 * case.time.dt;
        return Err(usage(format!(
            "τ = {tau_seconds} s is {exact_steps} DEM steps of {} s: it must be a whole multiple of n = {n} steps (nearest allowed τ = {valid} s)",
            case.time.dt
        )));
    }
    Ok(RecordOptions {
        sample_every: n,
        dtc_max_steps: dtc_max,
        period_steps,
        reference_periods: reference,
        area_encoding: if exact_area {
            AreaEncoding::Exact
        } else {
            AreaEncoding::Quantized
        },
    })
}

/// The output must be a file path in an existing directory.
fn check_output(output: &std::path::Path) -> Result<()> {
    if output.is_dir() {
        return Err(usage(format!(
            "-o {}: is a directory; give a file name such as run.mcap",
            output.display()
        )));
    }
    let parent = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    if !parent.is_dir() {
        return Err(usage(format!(
            "-o {}: the directory {} does not exist",
            output.display(),
            parent.display()
        )));
    }
    Ok(())
}

fn check_cells(cells: usize) -> Result<()> {
    if cells == 0 {
        return Err(usage(
            "--cells = 0 is not allowed: give at least 1 Voronoi cell".into(),
        ));
    }
    Ok(())
}

/// A report directory: an existing directory, or a new one whose parent exists.
fn check_output_dir(dir: &std::path::Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(usage(format!(
            "-o {}: is a file; give a directory for the report",
            dir.display()
        )));
    }
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    if !parent.is_dir() {
        return Err(usage(format!(
            "-o {}: the directory {} does not exist",
            dir.display(),
            parent.display()
        )));
    }
    Ok(())
}
