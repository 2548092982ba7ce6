//! Validated plans: every flag and the case file are checked here, before any simulation starts.

use super::args::{
    BenchArgs, BenchCommand, Cli, Command, ExportCommand, ImportCommand, StudyCommand, StudyCommon,
    TableFlags,
};
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
                table,
                reference,
                twins,
                threads: t,
                json,
                checkpoint_every,
                resume,
                reproducible,
            } => {
                let threads = threads(t)?;
                if let Some(s) = checkpoint_every.filter(|s| !(s.is_finite() && *s > 0.0)) {
                    return Err(usage(format!(
                        "--checkpoint-every = {s} is not allowed: give the seconds of wall time between checkpoints, > 0"
                    )));
                }
                let start = match (resume, case) {
                    (Some(path), _) => {
                        let checkpoint = recorder::record::Checkpoint::read(&path)?;
                        let case = checkpoint.case(&path)?;
                        RecordStart::Resume {
                            path,
                            checkpoint: Box::new(checkpoint),
                            case: Box::new(case),
                            checkpoint_every,
                        }
                    }
                    (None, Some(case)) => {
                        let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                        let (mut options, output) = table_options(&loaded, &table, reference)?;
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
                    (None, None) => {
                        return Err(usage(
                            "give the case file to record, or --resume CHECKPOINT".into(),
                        ))
                    }
                };
                Ok(Plan::Record(RecordPlan {
                    start,
                    threads,
                    json,
                }))
            }
            Command::Inspect { file, json } => Ok(Plan::Inspect(InspectPlan { file, json })),
            Command::Pair {
                file,
                threads: t,
                reproducible,
                json,
            } => Ok(Plan::Pair(PairPlan {
                file,
                threads: threads(t)?,
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
                threads: t,
                reproducible,
                json,
            } => {
                let threads = threads(t)?;
                let max_memory = max_memory
                    .map(|m| parse_size(&m).map_err(|e| usage(format!("--max-memory {m}: {e}"))))
                    .transpose()?;
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
                    max_memory,
                    threads,
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
            } => {
                check_cells(cells)?;
                Ok(Plan::Compare(ComparePlan {
                    recording,
                    extrapolation,
                    dem_runs,
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
                dem_runs,
                cells,
                seed,
            } => {
                check_cells(cells)?;
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
            Command::Demo { output, threads: t } => {
                let threads = threads(t)?;
                check_output_dir(&output)?;
                Ok(Plan::Demo(DemoPlan { output, threads }))
            }
            Command::Study(study) => Ok(Plan::Study(study_plan(study)?)),
            Command::Import(ImportCommand::Liggghts {
                atoms,
                contacts,
                case,
                table,
                json,
            }) => {
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let (options, output) = table_options(&loaded, &table, 0)?;
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
                threads: t,
                vs_liggghts,
                liggghts_dir,
                json,
            }) => {
                let threads = threads(t)?;
                if steps == 0 {
                    return Err(usage("--steps = 0 is not allowed: give at least 1".into()));
                }
                let loaded = recorder::case::load(&case)?;
                if let Some(dir) = &liggghts_dir {
                    check_dir("--liggghts-dir", dir, "the LIGGGHTS deck and log")?;
                }
                Ok(Plan::Bench(BenchPlan {
                    case_path: case,
                    case: loaded,
                    steps,
                    threads,
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
                        tau_rev,
                        n,
                        dtc_max,
                        repeats,
                        threads: t,
                        json,
                    }),
                ..
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

/// The recording settings of `record` and `import` checked against the case, and their
/// output file (required).
fn table_options(case: &Case, t: &TableFlags, reference: u32) -> Result<(RecordOptions, PathBuf)> {
    let options = record_options(
        case,
        t.tau,
        t.tau_rev,
        t.n,
        t.dtc_max,
        reference,
        t.exact_area,
    )?;
    let Some(output) = t.output.clone() else {
        return Err(usage(
            "-o/--output is required: give the recording to write, such as run.mcap".into(),
        ));
    };
    check_output(&output)?;
    Ok((options, output))
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

/// A size such as `512M`, `4G`, `1.5G`, `100K` or `1048576` (bytes): K, M, G, T are powers
/// of 1024, an optional `B` or `iB` may follow; at least 1 MiB.
pub(crate) fn parse_size(text: &str) -> std::result::Result<u64, String> {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let lower = lower
        .strip_suffix("ib")
        .or_else(|| lower.strip_suffix('b'))
        .unwrap_or(&lower);
    let (number, shift) = match lower.chars().last() {
        Some('k') => (&lower[..lower.len() - 1], 10),
        Some('m') => (&lower[..lower.len() - 1], 20),
        Some('g') => (&lower[..lower.len() - 1], 30),
        Some('t') => (&lower[..lower.len() - 1], 40),
        _ => (lower, 0),
    };
    let allowed =
        "give a size such as 512M, 4G or 1.5G (K, M, G, T: powers of 1024; a bare number is bytes)";
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("not a size; {allowed}"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= (1u64 << 20) as f64 && bytes < u64::MAX as f64) {
        return Err(format!("too small or too large: at least 1M; {allowed}"));
    }
    Ok(bytes as u64)
}

fn check_cells(cells: usize) -> Result<()> {
    if cells == 0 {
        return Err(usage(
            "--cells = 0 is not allowed: give at least 1 Voronoi cell".into(),
        ));
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

/// A comma-separated list of values for `flag`: no empty list, no empty or unparsable item;
/// repeated values are kept once, in the order given.
fn parse_list<T: std::str::FromStr + PartialEq + Copy>(
    flag: &str,
    text: &str,
    kind: &str,
) -> Result<Vec<T>> {
    let mut values = Vec::new();
    if text.trim().is_empty() {
        return Err(usage(format!(
            "{flag} is empty: give at least one {kind}, comma-separated"
        )));
    }
    for item in text.split(',').map(str::trim) {
        let v: T = item.parse().map_err(|_| {
            usage(format!(
                "{flag} = {text:?}: {item:?} is not {kind} (give a comma-separated list)"
            ))
        })?;
        if !values.contains(&v) {
            values.push(v);
        }
    }
    Ok(values)
}

/// Whole-number lists (`--n`, `--dtc-max`): every value ≥ 1.
fn positive_steps(flag: &str, text: &str) -> Result<Vec<u32>> {
    let values: Vec<i64> = parse_list(flag, text, "a whole number of steps")?;
    values
        .into_iter()
        .map(|v| {
            u32::try_from(v).ok().filter(|v| *v > 0).ok_or_else(|| {
                usage(format!(
                    "{flag} = {v} is not allowed: give whole numbers of steps ≥ 1"
                ))
            })
        })
        .collect()
}

/// Real-valued lists (`--tau-rev`, `--rev-period`): every value finite and > 0.
fn positive_reals(flag: &str, text: &str, what: &str) -> Result<Vec<f64>> {
    let values: Vec<f64> = parse_list(flag, text, "a number")?;
    for v in &values {
        if !(v.is_finite() && *v > 0.0) {
            return Err(usage(format!(
                "{flag} = {v} is not allowed: give {what} > 0"
            )));
        }
    }
    Ok(values)
}

/// The case text with `drum.rotation_period` replaced (the line in the `[drum]` table).
fn with_rotation_period(text: &str, period: f64) -> Option<String> {
    let mut table = String::new();
    let mut replaced = false;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let t = line.trim_start();
            if t.starts_with('[') {
                table = t.trim_end().to_string();
            }
            let key = t.split('=').next().unwrap_or("").trim();
            if !replaced && table.starts_with("[drum]") && key == "rotation_period" {
                replaced = true;
                format!("rotation_period = {period:?} # set by tdex study regimes")
            } else {
                line.to_string()
            }
        })
        .collect();
    replaced.then(|| lines.join("\n") + "\n")
}

fn study_plan(study: StudyCommand) -> Result<StudyPlan> {
    let common_of = |c: &StudyCommon| -> Result<(usize, PathBuf)> {
        let threads = threads(c.threads)?;
        check_cells(c.cells)?;
        Ok((threads, c.output.clone().unwrap_or_default()))
    };
    let (common, kind_name) = match &study {
        StudyCommand::Sampling { common, .. } => (common, "sampling"),
        StudyCommand::Period { common, .. } => (common, "period"),
        StudyCommand::Regimes { common, .. } => (common, "regimes"),
    };
    let (threads, mut output) = common_of(common)?;
    if output.as_os_str().is_empty() {
        output = PathBuf::from(format!("tdex-study-{kind_name}"));
    }
    check_output_dir(&output)?;
    let (case, case_toml) = recorder::case::load_with_text(&common.case)?;
    let kind = match &study {
        StudyCommand::Sampling {
            n,
            dtc_max,
            periods,
            tau_rev,
            ..
        } => {
            let ns = positive_steps("--n", n)?;
            let dtcs = positive_steps("--dtc-max", dtc_max)?;
            if *periods == 0 {
                return Err(usage(
                    "--periods = 0 is not allowed: extrapolate at least 1 period".into(),
                ));
            }
            let mut runs = Vec::new();
            let mut skipped = Vec::new();
            for &n in &ns {
                for &d in &dtcs {
                    if d % n != 0 {
                        skipped.push((n, d));
                        continue;
                    }
                    runs.push(record_options(
                        &case,
                        None,
                        Some(*tau_rev),
                        n,
                        d,
                        *periods,
                        false,
                    )?);
                }
            }
            if runs.is_empty() {
                return Err(usage(format!(
                    "--n {n} --dtc-max {dtc_max}: no Δt_c^max is a multiple of any n, so there is nothing to run"
                )));
            }
            StudyKind::Sampling {
                runs,
                skipped,
                tau_rev: *tau_rev,
            }
        }
        StudyCommand::Period {
            tau_rev,
            revolutions,
            n,
            dtc_max,
            ..
        } => {
            let taus = positive_reals("--tau-rev", tau_rev, "fractions of a revolution")?;
            if !(revolutions.is_finite() && *revolutions > 0.0) {
                return Err(usage(format!(
                    "--revolutions = {revolutions} is not allowed: give a number of revolutions > 0"
                )));
            }
            let mut runs = Vec::new();
            for &f in &taus {
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
                    record_options(&case, None, Some(f), *n, *dtc_max, periods as u32, false)?,
                ));
            }
            StudyKind::Period {
                runs,
                revolutions: *revolutions,
            }
        }
        StudyCommand::Regimes {
            rev_period,
            periods,
            tau_rev,
            n,
            dtc_max,
            min_relative,
            ..
        } => {
            let speeds = positive_reals("--rev-period", rev_period, "rotation periods in seconds")?;
            if *periods == 0 {
                return Err(usage(
                    "--periods = 0 is not allowed: extrapolate at least 1 period".into(),
                ));
            }
            if !(min_relative.is_finite() && *min_relative >= 0.0) {
                return Err(usage(format!(
                    "--min-relative = {min_relative} is not allowed: give a fraction of the wall speed ≥ 0"
                )));
            }
            let mut runs = Vec::new();
            for &t in &speeds {
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
                    *periods
                };
                let options = record_options(
                    &case_t,
                    None,
                    Some(*tau_rev),
                    *n,
                    *dtc_max,
                    reference,
                    false,
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
                tau_rev: *tau_rev,
                min_relative: *min_relative,
            }
        }
    };
    Ok(StudyPlan {
        case_path: common.case.clone(),
        case_toml,
        case,
        output,
        cells: common.cells,
        threads,
        json: common.json,
        kind,
    })
}
