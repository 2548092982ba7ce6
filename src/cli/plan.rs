//! Validated plans: what clap cannot check — the flags against the case file and against
//! each other, the files to read and write — is checked here, before any simulation starts.

use super::args::{
    BenchArgs, BenchCommand, BenchRecordArgs, BoundaryKind, Cli, Command, CompareArgs, DemoArgs,
    ExportCommand, ExtrapolateArgs, FreshMapOptions, HorizonStudyArgs, ImportCommand, InspectArgs,
    LiggghtsArgs, PairArgs, PeriodStudyArgs, RecordArgs, RecordingFlags, RegimesStudyArgs,
    ReportArgs, RunArgs, SamplingFlags, SamplingStudyArgs, StudyCommand, StudyCommon, VtkArgs,
};
use anyhow::Result;
use extrapolate::boundary::BoundaryMaps;
use extrapolate::replay::Scheme;
use recorder::record::RecordOptions;
use recorder::Case;
use std::path::PathBuf;
use tdex_format::extrapolation::Symmetry;
use tdex_format::{AreaEncoding, RecordingReader};

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

/// Where the horizon study's recording comes from.
pub enum HorizonSource {
    /// Record the case once, with the largest number of recorded periods asked for.
    Record(RecordOptions),
    /// A recording made before (its own periods, reference and twins).
    Recording(PathBuf),
}

/// `tdex study horizon`'s defaults for a case: 25 reference periods, 2 twins.
const DEFAULT_HORIZON_REFERENCE: u32 = 25;
const DEFAULT_HORIZON_TWINS: u32 = 2;

/// Whether `path` starts with the MCAP magic bytes (a recording) rather than a case's TOML.
fn is_recording(path: &std::path::Path) -> bool {
    use std::io::Read;
    let mut magic = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut magic))
        .is_ok_and(|()| &magic == b"\x89MCAP0\r\n")
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
    /// One recording (made or read) replayed with each number of recorded periods over its
    /// reference periods.
    Horizon {
        source: HorizonSource,
        /// Further recordings of the case, each a draw of the pooled verdict (empty: one
        /// recording, no pooled verdict).
        draws: Vec<PathBuf>,
        /// Distinct, ascending.
        recorded_periods: Vec<u32>,
        /// The recurrence paths' seed and the starts their jumps may enter.
        jumps: crate::study::PathJumps,
        /// The images every P is run with: the paper's method, and the mirror if asked.
        images: Vec<Symmetry>,
        /// The boundary maps every P and image is run with, distinct, in the order given.
        boundaries: Vec<BoundaryMaps>,
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
    /// Further draws of the case, (recording, extrapolation), for a pooled verdict
    /// (`--draw`).
    pub draws: Vec<(PathBuf, PathBuf)>,
    pub cells: usize,
    pub seed: u64,
    pub json: bool,
    pub csv: bool,
}

pub struct PairPlan {
    pub file: PathBuf,
    pub threads: usize,
    pub reproducible: bool,
    /// Also pair the end with each start's mirror image (`--mirror`), beside the plain
    /// pairing the mirror check compares it with.
    pub mirror: bool,
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
    /// `--recorded-periods P'`: the first P' recorded periods (`None`: all).
    pub recorded_periods: Option<u32>,
    /// `--seed`: the recurrence path's seed (`None`: the case's).
    pub seed: Option<u64>,
    /// `--jump-to` or `--jump-nearest`: the starts a jump may enter.
    pub jumps: extrapolate::JumpStarts,
    /// `--jump-every`: where the path leaves the recording for a jump.
    pub leave: extrapolate::Leave,
    /// `--mirror`: the drum's mirror symmetry used at the jumps.
    pub symmetry: Symmetry,
    /// `--boundary` with its pool and cell width.
    pub boundary: BoundaryMaps,
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
    /// Checks the parsed flags of the command against the case file and each other, and
    /// builds its plan.
    pub fn from_args(cli: Cli) -> Result<Self> {
        // the engine reads TDEX_SIMD when it first steps; a value it cannot use is refused
        // here, before any work
        recorder::simd::Simd::requested().map_err(|e| UsageError(e.to_string()))?;
        Ok(match cli.command {
            Command::Run(args) => Plan::Run(RunPlan::from_args(args)?),
            Command::Record(args) => Plan::Record(RecordPlan::from_args(args)?),
            Command::Inspect(InspectArgs { file, json }) => {
                Plan::Inspect(InspectPlan { file, json })
            }
            Command::Pair(args) => Plan::Pair(PairPlan::from_args(args)),
            Command::Extrapolate(args) => Plan::Extrapolate(ExtrapolatePlan::from_args(args)?),
            Command::Compare(args) => Plan::Compare(ComparePlan::from_args(args)),
            Command::Report(args) => Plan::Report(ReportPlan::from_args(args)?),
            Command::Demo(args) => Plan::Demo(DemoPlan::from_args(args)?),
            Command::Study(study) => Plan::Study(StudyPlan::from_args(study)?),
            Command::Import(ImportCommand::Liggghts(args)) => {
                Plan::ImportLiggghts(ImportPlan::from_args(args)?)
            }
            Command::Export(ExportCommand::Vtk(args)) => {
                Plan::ExportVtk(ExportVtkPlan::from_args(args)?)
            }
            Command::Bench(args) => match args.command {
                Some(BenchCommand::Record(record)) => {
                    Plan::BenchRecord(BenchRecordPlan::from_args(record)?)
                }
                None => Plan::Bench(BenchPlan::from_args(args)?),
            },
        })
    }
}

impl RunPlan {
    fn from_args(args: RunArgs) -> Result<Self> {
        let case = recorder::case::load(&args.case)?;
        Ok(RunPlan {
            case_path: args.case,
            case,
            threads: workers(args.threads),
            json: args.json,
        })
    }
}

impl RecordPlan {
    fn from_args(args: RecordArgs) -> Result<Self> {
        let (threads, json) = (args.threads, args.json);
        let start = RecordStart::from_args(args)?;
        Ok(RecordPlan {
            start,
            threads: workers(threads),
            json,
        })
    }
}

impl RecordStart {
    fn from_args(args: RecordArgs) -> Result<Self> {
        match (args.resume, args.case, args.output) {
            (Some(path), _, _) => RecordStart::resume(path, args.checkpoint_every),
            (None, Some(case), Some(output)) => {
                let (loaded, case_toml) = recorder::case::load_with_text(&case)?;
                let mut options = table_options(&loaded, &args.recording, args.reference)?;
                check_output(&output)?;
                let (twins, reference) = (args.twins, args.reference);
                if twins > 0 && reference == 0 {
                    return Err(usage(format!(
                        "--twins {twins} needs --reference K: the twins run over the \
                         reference periods"
                    )));
                }
                options.twins = twins;
                options.recorded_periods = args.recorded_periods;
                let twins_from = args.twins_from;
                let latest =
                    tdex_format::latest_twins_parting(args.recorded_periods, reference, twins);
                if twins == 0 && twins_from > 1 {
                    return Err(usage(format!(
                        "--twins-from {twins_from} with --twins 0: there are no twins to part \
                         from the run; give --twins M (at least 1) or leave --twins-from out"
                    )));
                }
                if twins_from > latest {
                    return Err(usage(format!(
                        "--twins-from {twins_from}: the twins part from the run at a recorded \
                         snapshot and run over at least one reference period after it, so S is \
                         at most --recorded-periods ({}) and at most --reference ({reference})",
                        args.recorded_periods
                    )));
                }
                options.twins_from = twins_from;
                Ok(RecordStart::Fresh {
                    case_path: case,
                    case_toml,
                    case: Box::new(loaded),
                    output,
                    options,
                    checkpoint_every: args.checkpoint_every,
                    reproducible: args.reproducible,
                })
            }
            // clap requires both without --resume
            (None, _, _) => Err(usage(
                "give the case file and -o OUTPUT to record, or --resume CHECKPOINT".into(),
            )),
        }
    }

    /// The rest of the run checkpointed in `path`, its case checked again.
    fn resume(path: PathBuf, checkpoint_every: Option<f64>) -> Result<Self> {
        let checkpoint = recorder::record::Checkpoint::read(&path)?;
        let case = checkpoint.case(&path)?;
        Ok(RecordStart::Resume {
            path,
            checkpoint: Box::new(checkpoint),
            case: Box::new(case),
            checkpoint_every,
        })
    }
}

impl PairPlan {
    fn from_args(args: PairArgs) -> Self {
        PairPlan {
            file: args.file,
            threads: workers(args.threads),
            reproducible: args.reproducible,
            mirror: args.mirror,
            json: args.json,
        }
    }
}

impl ExtrapolatePlan {
    fn from_args(args: ExtrapolateArgs) -> Result<Self> {
        check_output(&args.output)?;
        check_fresh_options(&[args.boundary], &args.fresh)?;
        let boundary = boundary_maps(args.boundary, &args.fresh);
        Ok(ExtrapolatePlan {
            file: args.file,
            periods: args.periods,
            output: args.output,
            scheme: args.scheme,
            stream: args.stream,
            max_memory: args.max_memory,
            threads: workers(args.threads),
            reproducible: args.reproducible,
            recorded_periods: args.recorded_periods,
            seed: args.seed,
            jumps: match (args.jump_to, args.jump_nearest) {
                (Some(listed), _) => extrapolate::JumpStarts::Listed(listed),
                (None, Some(k)) => extrapolate::JumpStarts::Nearest(k),
                (None, None) => extrapolate::JumpStarts::Every,
            },
            leave: args
                .jump_every
                .map_or(extrapolate::Leave::AtEnd, extrapolate::Leave::Every),
            symmetry: if args.mirror {
                Symmetry::AxialMirror
            } else {
                Symmetry::None
            },
            boundary,
            json: args.json,
        })
    }
}

/// The boundary maps of `kind` with the fresh maps' `options` where given, their defaults
/// elsewhere.
fn boundary_maps(kind: BoundaryKind, options: &FreshMapOptions) -> BoundaryMaps {
    use extrapolate::boundary::{
        DEFAULT_BIN_DIAMETERS, DEFAULT_CAP_ZONE_DIAMETERS, DEFAULT_CELL_DIAMETERS, DEFAULT_POOL,
    };
    let pool = options.pool.unwrap_or(DEFAULT_POOL);
    let cell_diameters = options.cell.unwrap_or(DEFAULT_CELL_DIAMETERS);
    match kind {
        BoundaryKind::Exact => BoundaryMaps::Exact,
        BoundaryKind::FreshSteps => BoundaryMaps::FreshSteps {
            pool,
            cell_diameters,
        },
        BoundaryKind::FreshDrift => BoundaryMaps::FreshDrift {
            pool,
            bin_diameters: options.bin.unwrap_or(DEFAULT_BIN_DIAMETERS),
            cell_diameters,
            cap_zone_diameters: options.cap_zone.unwrap_or(DEFAULT_CAP_ZONE_DIAMETERS),
        },
    }
}

/// `--boundary-pool` and `--boundary-cell` set the fresh maps, `--boundary-bin` and
/// `--boundary-cap-zone` the drift: each is refused unless one of the `kinds` asked for has
/// it, so that no setting is silently ignored.
fn check_fresh_options(kinds: &[BoundaryKind], options: &FreshMapOptions) -> Result<()> {
    let fresh = kinds.iter().any(|&k| k != BoundaryKind::Exact);
    let drift = kinds.contains(&BoundaryKind::FreshDrift);
    let any_given = options.pool.is_some()
        || options.cell.is_some()
        || options.bin.is_some()
        || options.cap_zone.is_some();
    if any_given && !fresh {
        return Err(usage(
            "--boundary-pool, --boundary-cell, --boundary-bin and --boundary-cap-zone set the \
             fresh boundary maps; with --boundary exact there is one pairing per start (add \
             --boundary fresh-steps or fresh-drift)"
                .into(),
        ));
    }
    if (options.bin.is_some() || options.cap_zone.is_some()) && !drift {
        return Err(usage(
            "--boundary-bin and --boundary-cap-zone set the drift of --boundary fresh-drift; \
             fresh-steps redraws each particle's step and has no drift"
                .into(),
        ));
    }
    Ok(())
}

impl ComparePlan {
    fn from_args(args: CompareArgs) -> Self {
        ComparePlan {
            recording: args.recording,
            extrapolation: args.extrapolation,
            dem_runs: args.dem_runs,
            // clap takes two values per --draw
            draws: args
                .draws
                .chunks_exact(2)
                .map(|pair| (pair[0].clone(), pair[1].clone()))
                .collect(),
            cells: args.cells,
            seed: args.seed,
            json: args.json,
            csv: args.csv,
        }
    }
}

impl ReportPlan {
    fn from_args(args: ReportArgs) -> Result<Self> {
        check_output_dir(&args.output)?;
        Ok(ReportPlan {
            recording: args.recording,
            extrapolation: args.extrapolation,
            output: args.output,
            dem_runs: args.dem_runs,
            cells: args.cells,
            seed: args.seed,
        })
    }
}

impl DemoPlan {
    fn from_args(args: DemoArgs) -> Result<Self> {
        check_output_dir(&args.output)?;
        Ok(DemoPlan {
            output: args.output,
            threads: workers(args.threads),
        })
    }
}

impl ImportPlan {
    fn from_args(args: LiggghtsArgs) -> Result<Self> {
        let (case, case_toml) = recorder::case::load_with_text(&args.case)?;
        let options = table_options(&case, &args.recording, 0)?;
        check_output(&args.output)?;
        Ok(ImportPlan {
            dumps: recorder::import::liggghts::Dumps {
                atoms: args.atoms,
                contacts: args.contacts,
                walls: args
                    .wall_contacts
                    .map(|pattern| recorder::import::liggghts::WallDumps {
                        pattern,
                        mantle_mesh: args.mantle_mesh,
                    }),
            },
            case_path: args.case,
            case_toml,
            case,
            output: args.output,
            options,
            json: args.json,
        })
    }
}

impl ExportVtkPlan {
    fn from_args(args: VtkArgs) -> Result<Self> {
        check_output_dir(&args.output)?;
        Ok(ExportVtkPlan {
            file: args.file,
            output: args.output,
            reference: args.reference,
        })
    }
}

impl BenchPlan {
    /// `tdex bench CASE`: the arguments without a subcommand.
    fn from_args(args: BenchArgs) -> Result<Self> {
        let Some(case_path) = args.case else {
            return Err(usage(
                "tdex bench needs a case file (tdex bench CASE) or a subcommand (tdex bench record CASE)".into(),
            ));
        };
        let case = recorder::case::load(&case_path)?;
        if let Some(dir) = &args.liggghts_dir {
            check_dir("--liggghts-dir", dir, "the LIGGGHTS deck and log")?;
        }
        if args.vs_liggghts {
            // before the DEM to t0, which on a large case takes minutes
            crate::bench::check_deck(&case)
                .map_err(|e| usage(format!("{}: {e:#}", case_path.display())))?;
        }
        Ok(BenchPlan {
            case_path,
            case,
            steps: args.steps,
            threads: workers(args.threads),
            liggghts: args.vs_liggghts.then_some(args.liggghts_dir),
            json: args.json,
        })
    }
}

impl BenchRecordPlan {
    fn from_args(args: BenchRecordArgs) -> Result<Self> {
        let (case, case_toml) = recorder::case::load_with_text(&args.case)?;
        let options = table_options(&case, &args.recording, 0)?;
        Ok(BenchRecordPlan {
            case_path: args.case,
            case_toml,
            case,
            options,
            repeats: args.repeats,
            threads: workers(args.threads),
            json: args.json,
        })
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
        recorded_periods: 1,
        twins_from: 1,
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

impl StudyCommand {
    /// The flags every study takes.
    fn common(&self) -> &StudyCommon {
        match self {
            StudyCommand::Sampling(args) => &args.common,
            StudyCommand::Period(args) => &args.common,
            StudyCommand::Regimes(args) => &args.common,
            StudyCommand::Horizon(args) => &args.common,
        }
    }

    /// The study's name, as on the command line.
    fn name(&self) -> &'static str {
        match self {
            StudyCommand::Sampling(_) => "sampling",
            StudyCommand::Period(_) => "period",
            StudyCommand::Regimes(_) => "regimes",
            StudyCommand::Horizon(_) => "horizon",
        }
    }
}

impl StudyPlan {
    fn from_args(study: StudyCommand) -> Result<Self> {
        let common = study.common().clone();
        let output = common
            .output
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("tdex-study-{}", study.name())));
        check_output_dir(&output)?;
        let recording = match &study {
            StudyCommand::Horizon(_) if is_recording(&common.case) => {
                Some(RecordingReader::open(&common.case)?)
            }
            _ => None,
        };
        // a recording carries its case: the study is of that case
        let (case_path, (case, case_toml)) = match &recording {
            Some(r) => {
                let path = PathBuf::from(&r.info().case_path);
                let text = r.info().case_toml.clone();
                let case = recorder::case::parse(&text, &path)?;
                (path, (case, text))
            }
            None => (
                common.case.clone(),
                recorder::case::load_with_text(&common.case)?,
            ),
        };
        let kind = match study {
            StudyCommand::Sampling(args) => StudyKind::sampling(args, &case)?,
            StudyCommand::Period(args) => StudyKind::period(args, &case)?,
            StudyCommand::Regimes(args) => StudyKind::regimes(args, &case_toml)?,
            StudyCommand::Horizon(args) => StudyKind::horizon(args, &case, recording.as_ref())?,
        };
        Ok(StudyPlan {
            case_path,
            case_toml,
            case,
            output,
            cells: common.cells,
            threads: workers(common.threads),
            json: common.json,
            kind,
        })
    }
}

/// The further recordings of `tdex study horizon`, each a draw of the pooled verdict beside
/// the first recording `first` (at `first_path`): every one a recording of the same case
/// that holds the `most` recorded periods asked for, and every one (the first too) with
/// the 3 DEM runs a DEM run judged in the extrapolation's seat needs.
fn check_horizon_draws(
    first_path: &std::path::Path,
    first: &RecordingReader,
    draws: &[PathBuf],
    most: u32,
) -> Result<()> {
    use crate::compare::draws::{check_same_case, MIN_DEM_RUNS};
    if draws.is_empty() {
        return Ok(());
    }
    let first_name = first_path.display().to_string();
    let runs = |path: &std::path::Path, r: &RecordingReader| {
        let dem_runs = 1 + r.info().twins as usize;
        if dem_runs < MIN_DEM_RUNS {
            return Err(usage(format!(
                "{}: has {} DEM twin(s); a pooled verdict over several recordings judges each \
                 DEM run in the extrapolation's seat against the others, which takes at least \
                 2 twins: record it with --twins 2",
                path.display(),
                r.info().twins
            )));
        }
        Ok(())
    };
    runs(first_path, first)?;
    for path in draws {
        if !is_recording(path) {
            return Err(usage(format!(
                "{}: not a recording; several inputs are allowed only if all are recordings \
                 (the draws of a pooled verdict)",
                path.display()
            )));
        }
        let r = RecordingReader::open(path)?;
        check_same_case(
            (&first_name, first.info()),
            (&path.display().to_string(), r.info()),
        )?;
        runs(path, &r)?;
        if most > r.info().recorded_periods {
            return Err(usage(format!(
                "--recorded-periods {most}: {} holds {} recorded period(s); record it with --recorded-periods {most}",
                path.display(),
                r.info().recorded_periods
            )));
        }
    }
    Ok(())
}

impl StudyKind {
    /// Every `(n, Δt_c^max)` of the lists with Δt_c^max a multiple of n, checked against the
    /// case; the others are skipped.
    fn sampling(args: SamplingStudyArgs, case: &Case) -> Result<Self> {
        let SamplingStudyArgs {
            n,
            dtc_max,
            periods,
            tau_rev,
            ..
        } = args;
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
                    case,
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
        Ok(StudyKind::Sampling {
            runs,
            skipped,
            tau_rev,
        })
    }

    /// One recording per τ, over a whole number of periods covering the same revolutions.
    fn period(args: PeriodStudyArgs, case: &Case) -> Result<Self> {
        let PeriodStudyArgs {
            tau_rev,
            revolutions,
            sampling,
            ..
        } = args;
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
                    case,
                    Tau::Revolutions(f),
                    sampling,
                    periods as u32,
                    AreaEncoding::Quantized,
                )?,
            ));
        }
        Ok(StudyKind::Period { runs, revolutions })
    }

    /// The numbers of recorded periods to compare, and the recording to read or to make:
    /// a recording's own periods, reference and twins; a case's from the flags.
    fn horizon(
        args: HorizonStudyArgs,
        case: &Case,
        recording: Option<&RecordingReader>,
    ) -> Result<Self> {
        let HorizonStudyArgs {
            common,
            draws,
            recorded_periods,
            reference,
            twins,
            tau_rev,
            seed,
            jump_nearest,
            jump_every,
            mirror,
            boundary,
            fresh,
        } = args;
        let mut recorded_periods = distinct(recorded_periods);
        recorded_periods.sort_unstable();
        let most = recorded_periods.iter().copied().max().unwrap_or(1);
        let source = match recording {
            Some(r) => {
                let info = r.info();
                let given = [
                    ("--reference", reference.is_some()),
                    ("--twins", twins.is_some()),
                    ("--tau-rev", tau_rev.is_some()),
                ];
                if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
                    return Err(usage(format!(
                        "{flag}: {} is a recording, which has its own; give the flag with a case file",
                        common.case.display()
                    )));
                }
                if most > info.recorded_periods {
                    return Err(usage(format!(
                        "--recorded-periods {most}: {} holds {} recorded period(s); record it with --recorded-periods {most}",
                        common.case.display(),
                        info.recorded_periods
                    )));
                }
                if info.twins == 0 {
                    return Err(usage(format!(
                        "{}: has no DEM twins, the yardstick of this study; record it with --twins 2 (at least 1)",
                        common.case.display()
                    )));
                }
                check_horizon_draws(&common.case, r, &draws, most)?;
                HorizonSource::Recording(common.case.clone())
            }
            None if !draws.is_empty() => {
                return Err(usage(format!(
                    "{}: a case file, given with {} further input(s); several inputs are \
                     allowed only if all are recordings (the draws of a pooled verdict)",
                    common.case.display(),
                    draws.len()
                )));
            }
            None => {
                let mut options = record_options(
                    case,
                    Tau::Revolutions(tau_rev.unwrap_or(1.0)),
                    SamplingFlags::default(),
                    reference.unwrap_or(DEFAULT_HORIZON_REFERENCE),
                    AreaEncoding::Quantized,
                )?;
                options.twins = twins.unwrap_or(DEFAULT_HORIZON_TWINS);
                options.recorded_periods = most;
                HorizonSource::Record(options)
            }
        };
        let images = if mirror {
            vec![Symmetry::None, Symmetry::AxialMirror]
        } else {
            vec![Symmetry::None]
        };
        check_fresh_options(&boundary, &fresh)?;
        let mut boundaries: Vec<BoundaryMaps> = Vec::new();
        for &kind in &boundary {
            let maps = boundary_maps(kind, &fresh);
            if !boundaries.contains(&maps) {
                boundaries.push(maps);
            }
        }
        let jumps = crate::study::PathJumps {
            seed,
            starts: jump_nearest.map_or(
                extrapolate::JumpStarts::Every,
                extrapolate::JumpStarts::Nearest,
            ),
            leave: jump_every.map_or(extrapolate::Leave::AtEnd, extrapolate::Leave::Every),
        };
        Ok(StudyKind::Horizon {
            source,
            draws,
            recorded_periods,
            jumps,
            images,
            boundaries,
        })
    }

    /// One case per drum rotation period, made from the case text `case_toml`.
    fn regimes(args: RegimesStudyArgs, case_toml: &str) -> Result<Self> {
        let RegimesStudyArgs {
            common,
            rev_period,
            periods,
            tau_rev,
            sampling,
            min_relative,
        } = args;
        let mut runs = Vec::new();
        for t in distinct(rev_period) {
            let text = with_rotation_period(case_toml, t).ok_or_else(|| {
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
        Ok(StudyKind::Regimes {
            runs,
            tau_rev,
            min_relative,
        })
    }
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
