//! Validated plans: what clap cannot check — the flags against the case file and against
//! each other, the files to read and write — is checked here, before any simulation starts.

use super::args::{
    BenchArgs, BenchCommand, Cli, Command, ExportCommand, ImportCommand, RecordingFlags,
    SamplingFlags, StudyCommand,
};
use anyhow::Result;
use extrapolate::replay::Scheme;
use recorder::record::RecordOptions;
use recorder::Case;
use std::path::PathBuf;
use tdex_format::AreaEncoding;

/// Flags that do not fit the case or each other, or outputs that cannot be written
/// (exit code 2). A CLI type: the libraries and analysis modules report bad input with their
/// own error types.
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
    Bench(BenchPlan),
    BenchRecord(BenchRecordPlan),
    Pair(PairPlan),
    Extrapolate(ExtrapolatePlan),
    Compare(ComparePlan),
    Report(ReportPlan),
    Demo(DemoPlan),
    Study(StudyPlan),
    ImportLiggghts(ImportPlan),
    ExportVtk(ExportVtkPlan),
}

/// `tdex import liggghts`: the dumps, the case describing the run and the recording settings
/// (`reference_periods` is found in the dumps).
pub struct ImportPlan {
    pub dumps: recorder::import::liggghts::Dumps,
    pub case_path: PathBuf,
    pub case_toml: String,
    pub case: Case,
    pub output: PathBuf,
    pub options: RecordOptions,
    pub json: bool,
}

/// `tdex export vtk`.
pub struct ExportVtkPlan {
    pub file: PathBuf,
    pub output: PathBuf,
    pub reference: Option<PathBuf>,
}

/// `tdex study ...`: the case, the study directory and what to run.
pub struct StudyPlan {
    pub case_path: PathBuf,
    pub case_toml: String,
    pub case: Case,
    pub output: PathBuf,
    pub cells: usize,
    pub threads: usize,
    pub json: bool,
    pub kind: StudyKind,
}

pub enum StudyKind {
    /// One DEM run, one recording per `(n, Δt_c^max)` in `runs`.
    Sampling {
        runs: Vec<RecordOptions>,
        /// Combinations skipped: Δt_c^max not a multiple of n.
        skipped: Vec<(u32, u32)>,
        tau_rev: f64,
    },
    /// One recording per τ, each extrapolated over the same simulated time.
    Period {
        runs: Vec<(f64, RecordOptions)>,
        revolutions: f64,
    },
    /// One recording per drum speed (the case with its rotation period replaced).
    Regimes {
        runs: Vec<RegimeRun>,
        tau_rev: f64,
        min_relative: f64,
    },
}

pub struct RegimeRun {
    pub rotation_period: f64,
    pub case: Case,
    pub case_toml: String,
    pub options: RecordOptions,
}

pub struct DemoPlan {
    pub output: PathBuf,
    pub threads: usize,
}

pub struct ReportPlan {
    pub recording: PathBuf,
    pub extrapolation: PathBuf,
    pub output: PathBuf,
    /// Further DEM runs of the case for the floor (`--dem-run`).
    pub dem_runs: Vec<PathBuf>,
    pub cells: usize,
    pub seed: u64,
}

pub struct ComparePlan {
    pub recording: PathBuf,
    pub extrapolation: PathBuf,
    /// Further DEM runs of the case for the floor (`--dem-run`).
    pub dem_runs: Vec<PathBuf>,
    pub cells: usize,
    pub seed: u64,
    pub json: bool,
    pub csv: bool,
}

pub struct PairPlan {
    pub file: PathBuf,
    pub threads: usize,
    pub reproducible: bool,
    pub json: bool,
}

pub struct ExtrapolatePlan {
    pub file: PathBuf,
    pub periods: u32,
    pub output: PathBuf,
    pub scheme: Scheme,
    pub stream: bool,
    /// `--max-memory` in bytes; `None`: a share of the memory available when it starts.
    pub max_memory: Option<u64>,
    pub threads: usize,
    pub reproducible: bool,
    pub json: bool,
}

/// `tdex bench CASE`: engine throughput on the heated phase, optionally against LIGGGHTS.
pub struct BenchPlan {
    pub case_path: PathBuf,
    pub case: Case,
    pub steps: u64,
    pub threads: usize,
    /// `Some(dir)`: run the LIGGGHTS peer there (`None` inside: a temporary directory).
    pub liggghts: Option<Option<PathBuf>>,
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
    pub start: RecordStart,
    pub threads: usize,
    pub json: bool,
}

/// A new recording, or the rest of a checkpointed one.
pub enum RecordStart {
    Fresh {
        case_path: PathBuf,
        case_toml: String,
        case: Box<Case>,
        output: PathBuf,
        options: RecordOptions,
        /// Wall-clock seconds between checkpoints.
        checkpoint_every: Option<f64>,
        reproducible: bool,
    },
    Resume {
        /// The checkpoint file, read and checked.
        path: PathBuf,
        checkpoint: Box<recorder::record::Checkpoint<'static>>,
        /// Its case, parsed and validated again from the text it stores.
        case: Box<Case>,
        /// A new interval between checkpoints, if given.
        checkpoint_every: Option<f64>,
    },
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

/// `--threads` (at least 1, checked by clap), or all cores.
fn workers(requested: Option<usize>) -> usize {
    requested.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// The period τ as given on the command line.
#[derive(Debug, Clone, Copy)]
pub enum Tau {
    /// `--tau`: seconds.
    Seconds(f64),
    /// `--tau-rev`: a fraction of the case's drum revolution.
    Revolutions(f64),
}

impl Tau {
    /// τ when no flag sets it: one revolution.
    pub const ONE_REVOLUTION: Tau = Tau::Revolutions(1.0);

    fn seconds(self, revolution: f64) -> f64 {
        match self {
            Tau::Seconds(t) => t,
            Tau::Revolutions(f) => f * revolution,
        }
    }
}

impl Plan {
    pub fn from_args(cli: Cli) -> Result<Self> {
        match cli.command {
            Command::Run {
                case,
                threads,
                json,
            } => {
                let loaded = recorder::case::load(&case)?;
                Ok(Plan::Run(RunPlan {
                    case_path: case,
                    case: loaded,
                    threads: workers(threads),
                    json,
                }))
            }
            Command::Record {
                case,
                output,
                recording,
                reference,
                twins,
                threads,
                json,
                checkpoint_every,
                resume,
                reproducible,
            } => {
                let start = match (resume, case, output) {
                    (Some(path), _, _) => {
                        let checkpoint = recorder::record::Checkpoint::read(&path)?;
                        let case = checkpoint.case(&path)?;
                        RecordStart::Resume {
                            path,
                            checkpoint: Box::new(checkpoint),
                            case: Box::new(case),
                            checkpoint_every,
                        }
                    }
                    (None, Some(case), Some(output)) => {
                        let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                        let mut options = table_options(&loaded, &recording, reference)?;
                        check_output(&output)?;
                        if twins > 0 && reference == 0 {
                            return Err(usage(format!(
                                "--twins {twins} needs --reference K: the twins run over the \
                                 reference periods"
                            )));
                        }
                        options.twins = twins;
                        RecordStart::Fresh {
                            case_path: case,
                            case_toml,
                            case: Box::new(loaded),
                            output,
                            options,
                            checkpoint_every,
                            reproducible,
                        }
                    }
                    // clap requires both without --resume
                    (None, _, _) => {
                        return Err(usage(
                            "give the case file and -o OUTPUT to record, or --resume CHECKPOINT"
                                .into(),
                        ))
                    }
                };
                Ok(Plan::Record(RecordPlan {
                    start,
                    threads: workers(threads),
                    json,
                }))
            }
            Command::Inspect { file, json } => Ok(Plan::Inspect(InspectPlan { file, json })),
            Command::Pair {
                file,
                threads,
                reproducible,
                json,
            } => Ok(Plan::Pair(PairPlan {
                file,
                threads: workers(threads),
                reproducible,
                json,
            })),
            Command::Extrapolate {
                file,
                periods,
                output,
                scheme,
                stream,
                max_memory,
                threads,
                reproducible,
                json,
            } => {
                check_output(&output)?;
                Ok(Plan::Extrapolate(ExtrapolatePlan {
                    file,
                    periods,
                    output,
                    scheme,
                    stream,
                    max_memory,
                    threads: workers(threads),
                    reproducible,
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
                dem_runs,
            } => Ok(Plan::Compare(ComparePlan {
                recording,
                extrapolation,
                dem_runs,
                cells,
                seed,
                json,
                csv,
            })),
            Command::Report {
                recording,
                extrapolation,
                output,
                dem_runs,
                cells,
                seed,
            } => {
                check_output_dir(&output)?;
                Ok(Plan::Report(ReportPlan {
                    recording,
                    extrapolation,
                    output,
                    dem_runs,
                    cells,
                    seed,
                }))
            }
            Command::Demo { output, threads } => {
                check_output_dir(&output)?;
                Ok(Plan::Demo(DemoPlan {
                    output,
                    threads: workers(threads),
                }))
            }
            Command::Study(study) => Ok(Plan::Study(study_plan(study)?)),
            Command::Import(ImportCommand::Liggghts {
                atoms,
                contacts,
                case,
                output,
                recording,
                json,
            }) => {
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let options = table_options(&loaded, &recording, 0)?;
                check_output(&output)?;
                Ok(Plan::ImportLiggghts(ImportPlan {
                    dumps: recorder::import::liggghts::Dumps { atoms, contacts },
                    case_path: case,
                    case_toml,
                    case: loaded,
                    output,
                    options,
                    json,
                }))
            }
            Command::Export(ExportCommand::Vtk {
                file,
                output,
                reference,
            }) => {
                check_output_dir(&output)?;
                Ok(Plan::ExportVtk(ExportVtkPlan {
                    file,
                    output,
                    reference,
                }))
            }
            Command::Bench(BenchArgs {
                command: None,
                case: Some(case),
                steps,
                threads,
                vs_liggghts,
                liggghts_dir,
                json,
            }) => {
                let loaded = recorder::case::load(&case)?;
                if let Some(dir) = &liggghts_dir {
                    check_dir("--liggghts-dir", dir, "the LIGGGHTS deck and log")?;
                }
                Ok(Plan::Bench(BenchPlan {
                    case_path: case,
                    case: loaded,
                    steps,
                    threads: workers(threads),
                    liggghts: vs_liggghts.then_some(liggghts_dir),
                    json,
                }))
            }
            Command::Bench(BenchArgs { command: None, case: None, .. }) => Err(usage(
                "tdex bench needs a case file (tdex bench CASE) or a subcommand (tdex bench record CASE)".into(),
            )),
            Command::Bench(BenchArgs {
                command:
                    Some(BenchCommand::Record {
                        case,
                        recording,
                        repeats,
                        threads,
                        json,
                    }),
                ..
            }) => {
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let options = table_options(&loaded, &recording, 0)?;
                Ok(Plan::BenchRecord(BenchRecordPlan {
                    case_path: case,
                    case_toml,
                    case: loaded,
                    options,
                    repeats,
                    threads: workers(threads),
                    json,
                }))
            }
        }
    }
}

fn usage(message: String) -> anyhow::Error {
    UsageError(message).into()
}

/// The recording flags of `record`, `import` and `bench record` checked against the case.
fn table_options(case: &Case, flags: &RecordingFlags, reference: u32) -> Result<RecordOptions> {
    // clap lets at most one of --tau and --tau-rev through
    let tau = match (flags.tau, flags.tau_rev) {
        (Some(t), _) => Tau::Seconds(t),
        (None, Some(f)) => Tau::Revolutions(f),
        (None, None) => Tau::ONE_REVOLUTION,
    };
    let area = if flags.exact_area {
        AreaEncoding::Exact
    } else {
        AreaEncoding::Quantized
    };
    record_options(case, tau, flags.sampling, reference, area)
}

/// Checks the recording settings against the case: `τ` a whole number of steps and, with
/// `Δt_c^max`, a multiple of `n`.
pub(crate) fn record_options(
    case: &Case,
    tau: Tau,
    sampling: SamplingFlags,
    reference: u32,
    area_encoding: AreaEncoding,
) -> Result<RecordOptions> {
    let SamplingFlags { n, dtc_max } = sampling;
    let tau_seconds = tau.seconds(case.drum.rotation_period);
    // clap refuses n = 0 on the command line; this guards the other callers
    if n == 0 {
        return Err(usage(
            "--n = 0 is not allowed: the sampling factor is at least 1 step".into(),
        ));
    }
    if dtc_max == 0 || !dtc_max.is_multiple_of(n) {
        return Err(usage(format!(
            "--dtc-max = {dtc_max} is not allowed: Δt_c^max must be a positive multiple of n = {n} steps (e.g. {})",
            n * (dtc_max / n).max(1)
        )));
    }
    let exact_steps = tau_seconds / case.time.dt;
    let period_steps = exact_steps.round() as u64;
    if period_steps == 0
        || (exact_steps - period_steps as f64).abs() > 1e-6 * exact_steps
        || !period_steps.is_multiple_of(u64::from(n))
    {
        let valid = (exact_steps / n as f64).round().max(1.0) * n as f64 * case.time.dt;
        return Err(usage(format!(
            "τ = {} s is {} DEM steps of {}: it must be a whole multiple of n = {n} steps (nearest allowed τ = {} s)",
            crate::fmt::sig(tau_seconds, 12),
            crate::fmt::sig(exact_steps, 9),
            crate::fmt::seconds(case.time.dt),
            crate::fmt::sig(valid, 12)
        )));
    }
    Ok(RecordOptions {
        sample_every: n,
        dtc_max_steps: dtc_max,
        period_steps,
        reference_periods: reference,
        twins: 0,
        area_encoding,
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
    check_parent(output)
}

/// The directory that will hold `output` must exist.
fn check_parent(output: &std::path::Path) -> Result<()> {
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

/// An output directory: an existing directory, or a new one whose parent exists.
fn check_output_dir(dir: &std::path::Path) -> Result<()> {
    check_dir("-o", dir, "the output")
}

/// `dir` (given with `flag`) is a directory or can be created as one; `what` goes in it.
fn check_dir(flag: &str, dir: &std::path::Path, what: &str) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(usage(format!(
            "{flag} {}: is a file; give a directory for {what}",
            dir.display()
        )));
    }
    check_parent(dir)
}

/// The list's values, each kept once in the order given.
fn distinct<T: PartialEq>(values: Vec<T>) -> Vec<T> {
    let mut kept = Vec::with_capacity(values.len());
    for v in values {
        if !kept.contains(&v) {
            kept.push(v);
        }
    }
    kept
}

/// The case text with `drum.rotation_period` replaced (`None`: the case does not set it).
/// Everything else, comments and layout included, is kept as written.
fn with_rotation_period(text: &str, period: f64) -> Option<String> {
    let mut doc: toml_edit::DocumentMut = text.parse().ok()?;
    let value = doc
        .get_mut("drum")?
        .as_table_like_mut()?
        .get_mut("rotation_period")?;
    value.as_value()?;
    let mut new = toml_edit::Value::from(period);
    new.decor_mut().set_prefix(" ");
    new.decor_mut().set_suffix(" # set by tdex study regimes");
    *value = toml_edit::Item::Value(new);
    Some(doc.to_string())
}

fn study_plan(study: StudyCommand) -> Result<StudyPlan> {
    let (common, kind_name) = match &study {
        StudyCommand::Sampling { common, .. } => (common.clone(), "sampling"),
        StudyCommand::Period { common, .. } => (common.clone(), "period"),
        StudyCommand::Regimes { common, .. } => (common.clone(), "regimes"),
    };
    let output = common
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("tdex-study-{kind_name}")));
    check_output_dir(&output)?;
    let (case, case_toml) = recorder::case::load_with_text(&common.case)?;
    let kind = match study {
        StudyCommand::Sampling {
            n,
            dtc_max,
            periods,
            tau_rev,
            ..
        } => {
            let (ns, dtcs) = (distinct(n), distinct(dtc_max));
            let mut runs = Vec::new();
            let mut skipped = Vec::new();
            for &n in &ns {
                for &dtc_max in &dtcs {
                    if !dtc_max.is_multiple_of(n) {
                        skipped.push((n, dtc_max));
                        continue;
                    }
                    runs.push(record_options(
                        &case,
                        Tau::Revolutions(tau_rev),
                        SamplingFlags { n, dtc_max },
                        periods,
                        AreaEncoding::Quantized,
                    )?);
                }
            }
            if runs.is_empty() {
                return Err(usage(format!(
                    "--n {} --dtc-max {}: no Δt_c^max is a multiple of any n, so there is nothing to run",
                    comma_separated(&ns),
                    comma_separated(&dtcs)
                )));
            }
            StudyKind::Sampling {
                runs,
                skipped,
                tau_rev,
            }
        }
        StudyCommand::Period {
            tau_rev,
            revolutions,
            sampling,
            ..
        } => {
            let mut runs = Vec::new();
            for f in distinct(tau_rev) {
                let k = revolutions / f;
                let periods = k.round();
                if periods < 1.0 || (k - periods).abs() > 1e-9 * k {
                    return Err(usage(format!(
                        "--tau-rev {f} with --revolutions {revolutions}: {revolutions} revolutions are {} periods of {f} revolution; they must be a whole number ≥ 1",
                        crate::fmt::sig(k, 9)
                    )));
                }
                runs.push((
                    f,
                    record_options(
                        &case,
                        Tau::Revolutions(f),
                        sampling,
                        periods as u32,
                        AreaEncoding::Quantized,
                    )?,
                ));
            }
            StudyKind::Period { runs, revolutions }
        }
        StudyCommand::Regimes {
            rev_period,
            periods,
            tau_rev,
            sampling,
            min_relative,
            ..
        } => {
            let mut runs = Vec::new();
            for t in distinct(rev_period) {
                let text = with_rotation_period(&case_toml, t).ok_or_else(|| {
                    usage(format!(
                        "{}: no `rotation_period = ...` line in its [drum] table to vary",
                        common.case.display()
                    ))
                })?;
                let case_t = recorder::case::parse(&text, &common.case)?;
                // no DEM reference where the extrapolation is refused anyway (Fr ≥ 1)
                let reference = if crate::study::flow::froude(&case_t) >= 1.0 {
                    0
                } else {
                    periods
                };
                let options = record_options(
                    &case_t,
                    Tau::Revolutions(tau_rev),
                    sampling,
                    reference,
                    AreaEncoding::Quantized,
                )
                .map_err(|e| usage(format!("--rev-period {t}: {e}")))?;
                runs.push(RegimeRun {
                    rotation_period: t,
                    case: case_t,
                    case_toml: text,
                    options,
                });
            }
            StudyKind::Regimes {
                runs,
                tau_rev,
                min_relative,
            }
        }
    };
    Ok(StudyPlan {
        case_path: common.case,
        case_toml,
        case,
        output,
        cells: common.cells,
        threads: workers(common.threads),
        json: common.json,
        kind,
    })
}

/// Values as a comma-separated list, as the flag takes them.
fn comma_separated(values: &[u32]) -> String {
    values
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

#[cfg(test)]
mod tests {
    use super::with_rotation_period;

    /// Every shipped case: only the rotation period's line changes, as the line-by-line
    /// rewrite it replaces wrote it (checked byte for byte against it when it was replaced).
    #[test]
    fn rotation_period_replaced_in_place() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/cases");
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            for period in [15.0, 0.1, 2.5e-3] {
                let new = with_rotation_period(&text, period).unwrap();
                assert_eq!(new.lines().count(), text.lines().count());
                let changed: Vec<_> = text
                    .lines()
                    .zip(new.lines())
                    .filter(|(a, b)| a != b)
                    .collect();
                assert_eq!(changed.len(), 1, "{}", path.display());
                assert_eq!(
                    changed[0].1,
                    format!("rotation_period = {period:?} # set by tdex study regimes")
                );
            }
        }
        assert!(with_rotation_period("[drum]\nradius = 0.1\n", 1.0).is_none());
    }
}
