//! Command-line flags (clap derive): types, ranges, lists and defaults are clap's; what needs
//! the case file or several flags together is checked in `plan`.

use super::values::{count, non_negative, positive, Size};
use clap::{Parser, Subcommand};
use extrapolate::replay::Scheme;
use std::path::PathBuf;

/// Default sampling factor n (DEM steps between contact-list samples).
pub const DEFAULT_N: u32 = 10;
/// Default Δt_c^max (DEM steps).
pub const DEFAULT_DTC_MAX: u32 = 100;
/// Default period τ of the studies, as a fraction of a drum revolution.
pub const DEFAULT_TAU_REV: f64 = 1.0;

#[derive(Debug, Parser)]
#[command(
    name = "tdex",
    version,
    about = "Long-time thermal DEM: record one period, extrapolate many"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a case: insert, settle, spin up, assign temperatures at t0 and heat; print a summary.
    Run(RunArgs),
    /// Record one period: run the case to t0, assign temperatures, record the sampled
    /// collision table and the snapshots at t0 and t1 (and K reference periods) into MCAP.
    Record(RecordArgs),
    /// Pair the t0 and t1 snapshots of a recording (minimum total distance, certified
    /// optimal) and store the pairing beside it (RECORDING.pairing.json) for reuse.
    Pair(PairArgs),
    /// Extrapolate K periods: replay the recorded table through the pairing, writing the
    /// extrapolated temperature and position of every particle at every t_k (MCAP).
    Extrapolate(ExtrapolateArgs),
    /// Compare an extrapolation with the recording's DEM reference at every t_k: Voronoi-cell
    /// errors (eps_abs, eps_rel), the Eq. 10 energy-transfer error, hot/cold group means.
    /// Given a second recording instead, compare two DEM runs of one case the same way.
    Compare(CompareArgs),
    /// Write a self-contained report (report.md, report.html, SVG plots) of an extrapolation
    /// against its recording: the error table, the cost table for 100 periods, plots.
    Report(ReportArgs),
    /// The method end to end on the built-in small drum (2 000 particles): record one
    /// revolution with a 6-period DEM reference, extrapolate 6 periods, compare, report.
    Demo(DemoArgs),
    /// Benchmarks (figures for docs/benchmarks.md): `tdex bench CASE` times the DEM engine
    /// on the rotating, heated phase of a case (optionally against LIGGGHTS in the same run);
    /// `tdex bench record CASE` the recording overhead.
    Bench(BenchArgs),
    /// Build a recording from another DEM engine's output (docs/liggghts.md).
    #[command(subcommand)]
    Import(ImportCommand),
    /// Write a recording or an extrapolation for other tools.
    #[command(subcommand)]
    Export(ExportCommand),
    /// Parameter studies (Haydar §3.2–3.3): sampling (n, Δt_c^max), pairing period τ, and
    /// flow regimes (drum speed), each recorded, extrapolated and compared with the DEM.
    #[command(subcommand)]
    Study(StudyCommand),
    /// Summarise a recording: particles, period, rows, bytes per row, duration histogram,
    /// suggested n, costs. Reads the whole table, so it also checks the file. Given an
    /// extrapolation: its recording, periods, scheme, pairing and heat balance. Given a
    /// checkpoint of `tdex record`: where the run stands and the time left at its pace.
    Inspect(InspectArgs),
}

/// `tdex run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The case file (TOML).
    pub case: PathBuf,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `tdex record`: a new recording, or `--resume` of a checkpointed one.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// The case file (TOML).
    #[arg(required_unless_present = "resume")]
    pub case: Option<PathBuf>,
    /// The recording to write (MCAP); written to a temporary file and renamed at the end.
    /// Required (`tdex record --resume` takes it from the checkpoint).
    #[arg(short = 'o', long = "output", required_unless_present = "resume")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub recording: RecordingFlags,
    /// Continue the DEM K periods after t1, storing a reference snapshot at every t_k.
    #[arg(long, default_value_t = 0)]
    pub reference: u32,
    /// Also continue M more DEM runs ("twins") from the state at t1 over the same K
    /// reference periods, twin m with the drum's angular velocity changed by m units in
    /// its last place: the DEM's own run-to-run spread, against which `compare` and
    /// `report` judge the extrapolation. Each twin costs the reference periods again.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=16), requires = "reference")]
    pub twins: u32,
    /// Record P consecutive periods of the run from t0 (1 to 64): P collision tables one
    /// after the other and the snapshots t0 … tP; the extrapolation replays them in turn.
    /// The reference snapshots up to tP are the recorded ones.
    #[arg(
        long = "recorded-periods",
        value_name = "P",
        default_value_t = 1,
        value_parser = clap::value_parser!(u32).range(1..=tdex_format::MAX_RECORDED_PERIODS as i64)
    )]
    pub recorded_periods: u32,
    /// The twins part from the run at t_S instead of t1 (S from 1 to P, and at most K).
    /// An extrapolation of all P periods starts at tP: with S = P it is judged against
    /// runs that parted where it did (`docs/user-guide.md`).
    #[arg(
        long = "twins-from",
        value_name = "S",
        default_value_t = 1,
        requires = "twins",
        value_parser = clap::value_parser!(u32).range(1..=tdex_format::MAX_RECORDED_PERIODS as i64)
    )]
    pub twins_from: u32,
    /// Worker threads (default: all cores). The recording does not depend on it.
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
    /// Every SECONDS of wall time, save the whole state of the run (atomically) to
    /// OUTPUT.checkpoint, with the table rows so far in OUTPUT.checkpoint.rows; both are
    /// removed when the recording is complete.
    #[arg(
        long = "checkpoint-every",
        value_name = "SECONDS",
        value_parser = positive("give the seconds of wall time between checkpoints, > 0")
    )]
    pub checkpoint_every: Option<f64>,
    /// Continue the run a checkpoint was taken in: `tdex record --resume
    /// OUTPUT.checkpoint`. The recording is the one the run would have written without
    /// the interruption, byte for byte up to its costs record.
    #[arg(
        long,
        value_name = "CHECKPOINT",
        conflicts_with_all = ["case", "output", "tau", "tau_rev", "n", "dtc_max", "exact_area", "reference", "twins", "recorded_periods", "twins_from", "reproducible"]
    )]
    pub resume: Option<PathBuf>,
    /// Leave out the costs record (wall times, thread count): the same case, seed and
    /// flags then give the same file byte for byte, resumed or not.
    #[arg(long)]
    pub reproducible: bool,
}

/// `tdex pair`.
#[derive(Debug, clap::Args)]
pub struct PairArgs {
    /// The recording (MCAP).
    pub file: PathBuf,
    /// Worker threads (default: all cores). The pairing does not depend on it.
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Leave the time and thread count out of the stored pairing: the same recording
    /// then gives the same file byte for byte.
    #[arg(long)]
    pub reproducible: bool,
    /// Also pair the end with the drum's mirror image of each start (what `tdex extrapolate
    /// --mirror` uses, stored beside the recording) and say whether the bed is its own
    /// mirror image: the mirror check.
    #[arg(long)]
    pub mirror: bool,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `tdex extrapolate`.
#[derive(Debug, clap::Args)]
pub struct ExtrapolateArgs {
    /// The recording (MCAP).
    pub file: PathBuf,
    /// Periods to extrapolate after t1.
    #[arg(long, value_parser = periods())]
    pub periods: u32,
    /// The extrapolation to write (MCAP).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// How the rows update the temperatures.
    #[arg(long, value_enum, default_value_t = Scheme::Explicit)]
    pub scheme: Scheme,
    /// Read the table from the file every period instead of keeping it in memory.
    #[arg(long)]
    pub stream: bool,
    /// Memory the extrapolation may use, e.g. 512M, 4G (K, M, G, T: powers of 1024); a
    /// table that does not fit is streamed from the file. Default: 80 % of MemAvailable
    /// (and of what the cgroup still allows).
    #[arg(long = "max-memory", value_name = "SIZE", value_parser = Size)]
    pub max_memory: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Leave the costs record (wall times, thread count) out of the extrapolation: the
    /// same recording and flags then give the same file byte for byte.
    #[arg(long)]
    pub reproducible: bool,
    /// Recorded periods to use, P': the first P' of a recording made with
    /// --recorded-periods P (default: all P). 1 is the paper's method on the first period.
    #[arg(long = "recorded-periods", value_name = "P", value_parser = periods_used())]
    pub recorded_periods: Option<u32>,
    /// Seed of the recurrence path's jumps through several recorded periods (default: the
    /// case's seed). The same seed gives the same path and the same bytes.
    #[arg(long)]
    pub seed: Option<u64>,
    /// The recorded periods a jump may enter, comma-separated (default: all the periods
    /// used): e.g. those whose start is close to the recording's end (`tdex pair` prints
    /// each pairing's mean distance).
    #[arg(
        long = "jump-to",
        value_name = "PERIODS",
        value_delimiter = ',',
        value_parser = periods_used()
    )]
    pub jump_to: Option<Vec<u32>>,
    /// Jump only into the K recorded periods whose start is nearest the recording's end
    /// (the mean distance of its pairing with the end), as recurrence CFD jumps to the
    /// recorded states most like the current one: for a bed that drifts slowly over the
    /// recording. Pairs every start (stored beside the recording for the next run).
    #[arg(
        long = "jump-nearest",
        value_name = "K",
        conflicts_with = "jump_to",
        value_parser = nearest_starts()
    )]
    pub jump_nearest: Option<std::num::NonZeroU32>,
    /// Leave the recording after every N periods replayed in a row, from the end of the
    /// period just replayed, instead of only at the recording's end: the path then jumps from
    /// many recorded snapshots, not one (a pairing per end and start it jumps along, stored
    /// beside the recording), as recurrence CFD leaves from the current state, and the last
    /// recorded period is no longer replayed before every jump (docs/method.md §6).
    #[arg(
        long = "jump-every",
        value_name = "N",
        conflicts_with = "jump_nearest",
        value_parser = periods_in_a_row()
    )]
    pub jump_every: Option<std::num::NonZeroU32>,
    /// Use the drum's mirror symmetry (its mid-plane y = 0): every jump enters the mirror
    /// image of the recorded start, so the periods replayed alternate between the recording
    /// and its mirror image (docs/method.md §6). Costs one more pairing per start; needs a
    /// tdex drum.
    #[arg(long)]
    pub mirror: bool,
    /// How the roles are handed over at each jump: `exact` is the one optimal pairing of the
    /// paper's method; `fresh-steps` and `fresh-drift` draw one of a pool of pairings in which
    /// the recorded period's displacement along the drum's axis is drawn again, so that it is
    /// fresh every period instead of repeated (docs/method.md §6): `fresh-steps` redraws each
    /// particle's axial step (for a bed heated through its mantle), `fresh-drift` moves the
    /// period's coarse axial drift along the axis (for heat that varies along the axis).
    #[arg(long, value_enum, default_value_t = BoundaryKind::Exact)]
    pub boundary: BoundaryKind,
    #[command(flatten)]
    pub fresh: FreshMapOptions,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The fresh boundary maps' settings (`tdex extrapolate`, `tdex study horizon`): each applies
/// to the maps that have it, and is refused where none of the asked maps does.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FreshMapOptions {
    /// With a fresh boundary: pairings in each start's pool [default: 32].
    #[arg(long = "boundary-pool", value_name = "N", value_parser = pool())]
    pub pool: Option<u32>,
    /// With a fresh boundary: width of the cells of the cross-section whose particles' axial
    /// steps (`fresh-steps`) or drift (`fresh-drift`) are taken together, in particle
    /// diameters [default: 3].
    #[arg(
        long = "boundary-cell",
        value_name = "DIAMETERS",
        value_parser = positive("give a width in particle diameters > 0")
    )]
    pub cell: Option<f64>,
    /// With `--boundary fresh-drift`: length of the axial bins of the drift, in particle
    /// diameters [default: 2].
    #[arg(
        long = "boundary-bin",
        value_name = "DIAMETERS",
        value_parser = positive("give a length in particle diameters > 0")
    )]
    pub bin: Option<f64>,
    /// With `--boundary fresh-drift`: keep the drift within this many particle diameters of
    /// an end cap (the caps' own circulation, which the DEM repeats every period) and move
    /// only the middle's, among the middle's bins [default: 0, every bin's is moved]. For a
    /// drum short for its radius (docs/method.md §6, "The drift at the end caps").
    #[arg(
        long = "boundary-cap-zone",
        value_name = "DIAMETERS",
        value_parser = non_negative("give a distance in particle diameters ≥ 0")
    )]
    pub cap_zone: Option<f64>,
}

/// `tdex extrapolate --boundary`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BoundaryKind {
    /// One optimal pairing per start, the same at every jump (the paper's method).
    Exact,
    /// A pool of pairings with each particle's axial step redrawn, one drawn at each jump.
    FreshSteps,
    /// A pool of pairings with the coarse axial drift moved along the axis, one drawn at
    /// each jump.
    FreshDrift,
}

/// `tdex compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// The recording, made with --reference K.
    pub recording: PathBuf,
    /// The extrapolation of that recording; or a second DEM run of the same case, recorded
    /// with a reference over the same t_k (another seed, a perturbed case, a LIGGGHTS
    /// import), to see how far apart two DEM runs are on the same measures.
    pub extrapolation: PathBuf,
    /// Voronoi cells (seeds drawn inside the bed).
    #[arg(long, default_value_t = crate::compare::DEFAULT_CELLS, value_parser = cells())]
    pub cells: usize,
    /// Seed of the cell centres.
    #[arg(long, default_value_t = crate::compare::DEFAULT_SEED)]
    pub seed: u64,
    /// Print the comparison as one JSON object on stdout.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print one CSV line per t_k on stdout.
    #[arg(long)]
    pub csv: bool,
    /// A further DEM run of the same case over the same t_k (a recording: another
    /// engine's run imported, a perturbed case), added to the recording's own twins to
    /// measure the DEM's run-to-run spread. Repeatable.
    #[arg(long = "dem-run", value_name = "RECORDING")]
    pub dem_runs: Vec<PathBuf>,
    /// A further draw of the same case: another recording (another seed, another recorded
    /// window, with --twins 2 or more) and its extrapolation, judged as the first pair is.
    /// With one or more, a pooled verdict over all the draws follows: the mean median ratio
    /// and the share of t_k outside the DEM runs' range, ± their standard errors, beside a
    /// DEM run's judged in the same seat. Repeatable.
    #[arg(
        long = "draw",
        num_args = 2,
        value_names = ["RECORDING", "EXTRAPOLATION"],
        conflicts_with_all = ["csv", "dem_runs"]
    )]
    pub draws: Vec<PathBuf>,
}

/// `tdex report`.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    /// The recording, made with --reference K.
    pub recording: PathBuf,
    /// The extrapolation of that recording.
    pub extrapolation: PathBuf,
    /// The report directory (created if missing; files in it are replaced).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// A further DEM run of the same case over the same t_k, added to the recording's
    /// own twins to measure the DEM's run-to-run spread (as `compare --dem-run`).
    #[arg(long = "dem-run", value_name = "RECORDING")]
    pub dem_runs: Vec<PathBuf>,
    /// Voronoi cells (seeds drawn inside the bed).
    #[arg(long, default_value_t = crate::compare::DEFAULT_CELLS, value_parser = cells())]
    pub cells: usize,
    /// Seed of the cell centres.
    #[arg(long, default_value_t = crate::compare::DEFAULT_SEED)]
    pub seed: u64,
}

/// `tdex demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Directory for the case, the recording, the extrapolation and the report.
    #[arg(short = 'o', long = "output", default_value = "tdex-demo")]
    pub output: PathBuf,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
}

/// `tdex inspect`.
#[derive(Debug, clap::Args)]
pub struct InspectArgs {
    /// The recording or extrapolation (MCAP), or a `tdex record` checkpoint.
    pub file: PathBuf,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `tdex bench CASE [...]` or `tdex bench record CASE [...]`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub command: Option<BenchCommand>,
    /// The case file (TOML): it is run to t0 (settle, spin-up), then the heated, rotating
    /// phase is timed.
    #[arg(required = true)]
    pub case: Option<PathBuf>,
    /// DEM steps to time after t0.
    #[arg(
        long,
        default_value_t = 5000,
        value_parser = count::<u64>(1, "a whole number of steps", "give at least 1")
    )]
    pub steps: u64,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Also run the same case in LIGGGHTS 3.8 (`liggghts` on PATH, one process) for the same
    /// steps and print both rates and their ratio.
    #[arg(long = "vs-liggghts")]
    pub vs_liggghts: bool,
    /// Where the LIGGGHTS deck, mesh and log are written (default: a new temporary directory).
    #[arg(long = "liggghts-dir", requires = "vs_liggghts")]
    pub liggghts_dir: Option<PathBuf>,
    /// Print the result as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Recording overhead: from one state at t0, time the period plain and recorded; report
    /// the ratio and the bytes per row of the table.
    Record(BenchRecordArgs),
}

/// `tdex bench record CASE [...]`.
#[derive(Debug, clap::Args)]
pub struct BenchRecordArgs {
    /// The case file (TOML).
    pub case: PathBuf,
    #[command(flatten)]
    pub recording: RecordingFlags,
    /// Plain/recorded pairs to run (the fastest of each is reported).
    #[arg(
        long,
        default_value_t = 1,
        value_parser = count::<u32>(1, "a whole number", "give at least 1")
    )]
    pub repeats: u32,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Print the result as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// How a recording's table is sampled, over which period τ and at which precision: shared by
/// `record`, `import liggghts` and `bench record`.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct RecordingFlags {
    /// Period τ in seconds (default: one drum revolution).
    #[arg(long, conflicts_with = "tau_rev", value_parser = positive("give a period > 0 s"))]
    pub tau: Option<f64>,
    /// Period τ as a fraction of a drum revolution.
    #[arg(long = "tau-rev", value_parser = tau_rev())]
    pub tau_rev: Option<f64>,
    #[command(flatten)]
    pub sampling: SamplingFlags,
    /// Store sqrt(a) as exact f64 instead of 16-bit codes (larger file; for exact replays).
    #[arg(long = "exact-area")]
    pub exact_area: bool,
}

/// How the contact list is sampled: every n DEM steps, collisions cut at Δt_c^max. Shared by
/// every command that records (the sampling study takes lists of both instead).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct SamplingFlags {
    /// Sampling factor n: the contact list is sampled every n DEM steps.
    #[arg(
        long = "n",
        default_value_t = DEFAULT_N,
        value_parser = count::<u32>(1, "a whole number of steps", "the sampling factor is at least 1 step")
    )]
    pub n: u32,
    /// Δt_c^max in DEM steps (a multiple of n): longer collisions are split into rows.
    #[arg(long = "dtc-max", default_value_t = DEFAULT_DTC_MAX)]
    pub dtc_max: u32,
}

impl Default for SamplingFlags {
    /// The flags' defaults, for the commands that record without them (`demo`).
    fn default() -> Self {
        SamplingFlags {
            n: DEFAULT_N,
            dtc_max: DEFAULT_DTC_MAX,
        }
    }
}

#[derive(Debug, Subcommand)]
pub enum ImportCommand {
    /// A recording from LIGGGHTS text dumps: the atoms (`dump custom ... id type x y z vx vy
    /// vz radius f_Temp`) at t0, t1 = t0 + τ and every later t_k, and the contacts
    /// (`compute pair/gran/local id contactArea` through `dump local`) every n steps of the
    /// period; the same table and snapshots as `tdex record` (docs/liggghts.md).
    Liggghts(LiggghtsArgs),
}

/// `tdex import liggghts`.
#[derive(Debug, clap::Args)]
pub struct LiggghtsArgs {
    /// The atom dump files: a path or a pattern (`*`, `%`, `?` in the file name; quote it),
    /// plain or gzip, several timesteps and MPI processes merged by timestep.
    #[arg(long)]
    pub atoms: String,
    /// The contact dump files (`dump local`), as --atoms.
    #[arg(long)]
    pub contacts: String,
    /// For a heated mantle (`drum.wall_temperature`): the wall contact dump files
    /// (`compute wall/gran/local id contactArea` through `dump local`), as --atoms.
    #[arg(long)]
    pub wall_contacts: Option<String>,
    /// The mantle's mesh id in the wall contact dumps: its place (0-based) in `fix wall/gran
    /// ... meshes`; the drum's other mesh is the adiabatic end caps.
    #[arg(long, default_value_t = 0, requires = "wall_contacts", value_parser = clap::value_parser!(u32).range(0..2))]
    pub mantle_mesh: u32,
    /// The case file describing the run (time step, materials, conduction, drum).
    #[arg(long)]
    pub case: PathBuf,
    /// The recording to write (MCAP); written to a temporary file and renamed at the end.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    #[command(flatten)]
    pub recording: RecordingFlags,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum ExportCommand {
    /// ParaView files: one VTK PolyData file (.vtp) per snapshot with temperature, radius, id
    /// and velocity, and a .pvd time series that opens them all.
    Vtk(VtkArgs),
}

/// `tdex export vtk`.
#[derive(Debug, clap::Args)]
pub struct VtkArgs {
    /// A recording or an extrapolation (MCAP).
    pub file: PathBuf,
    /// The directory for the files (created if missing; files of the same name replaced).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// For an extrapolation: its recording, to add the DEM − extrapolated temperature
    /// differences at every t_k that has a DEM reference.
    #[arg(long)]
    pub reference: Option<PathBuf>,
}

/// Flags shared by the studies.
#[derive(Debug, Clone, clap::Args)]
pub struct StudyCommon {
    /// The case file (TOML).
    pub case: PathBuf,
    /// The study directory (created if missing): recordings, extrapolations, study.md,
    /// study.json and the SVG plots.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Voronoi cells of the comparison.
    #[arg(long, default_value_t = crate::compare::DEFAULT_CELLS, value_parser = cells())]
    pub cells: usize,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = threads())]
    pub threads: Option<usize>,
    /// Print the study as one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum StudyCommand {
    /// Sampling study (Figure 10): every (n, Δt_c^max) with Δt_c^max a multiple of n, all
    /// sampled from ONE DEM run, each extrapolated K periods against the DEM reference.
    Sampling(SamplingStudyArgs),
    /// Pairing-period study (Figures 13–15, Table 8): per τ, record and extrapolate over the
    /// same simulated time (R revolutions) against a DEM reference.
    Period(PeriodStudyArgs),
    /// Flow-regime study (Figures 11–12): per drum rotation period, the Froude number, the
    /// regime (Mellmann 2001), the dynamic angle of repose, the active-layer thickness and
    /// (where particles move relative to the drum) the extrapolation error and speedup.
    Regimes(RegimesStudyArgs),
    /// Long-horizon study: per number of recorded periods P, the extrapolation
    /// over the reference periods against the DEM and its twins (median ratio to their
    /// spread, the t_k outside their range) beside what recording P periods costs. CASE may
    /// also be a recording made with `tdex record --recorded-periods P --reference K --twins M`
    /// (for long DEM runs: record it in the background with `--checkpoint-every`); several
    /// recordings of the case give a pooled verdict per P over them.
    Horizon(HorizonStudyArgs),
}

/// `tdex study sampling`.
#[derive(Debug, clap::Args)]
pub struct SamplingStudyArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Sampling factors n (steps), comma-separated.
    #[arg(
        long = "n",
        value_delimiter = ',',
        default_value = "1,5,10,20",
        allow_hyphen_values = true,
        value_parser = steps()
    )]
    pub n: Vec<u32>,
    /// Δt_c^max values (steps), comma-separated.
    #[arg(
        long = "dtc-max",
        value_delimiter = ',',
        default_value = "10,50,100,200",
        allow_hyphen_values = true,
        value_parser = steps()
    )]
    pub dtc_max: Vec<u32>,
    /// Periods extrapolated and simulated by the DEM for reference.
    #[arg(long, default_value_t = 6, value_parser = periods())]
    pub periods: u32,
    /// Period τ as a fraction of a drum revolution.
    #[arg(
        long = "tau-rev",
        default_value_t = DEFAULT_TAU_REV,
        allow_negative_numbers = true,
        value_parser = tau_rev()
    )]
    pub tau_rev: f64,
}

/// `tdex study period`.
#[derive(Debug, clap::Args)]
pub struct PeriodStudyArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Periods τ as fractions of a revolution, comma-separated.
    #[arg(
        long = "tau-rev",
        value_delimiter = ',',
        default_value = "0.25,0.5,1",
        allow_hyphen_values = true,
        value_parser = positive("give fractions of a revolution > 0")
    )]
    pub tau_rev: Vec<f64>,
    /// Revolutions covered after t1 by every τ (R / τ_rev periods each).
    #[arg(
        long,
        default_value_t = 3.0,
        allow_negative_numbers = true,
        value_parser = positive("give a number of revolutions > 0")
    )]
    pub revolutions: f64,
    #[command(flatten)]
    pub sampling: SamplingFlags,
}

/// `tdex study horizon`.
#[derive(Debug, clap::Args)]
pub struct HorizonStudyArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Further recordings of the same case (another seed, another recorded window), each
    /// with --twins 2 or more, when CASE is a recording too: every P runs on each of them,
    /// and a pooled verdict over these draws follows per P.
    #[arg(value_name = "RECORDING")]
    pub draws: Vec<PathBuf>,
    /// Numbers of recorded periods P to compare, comma-separated. The DEM runs once and
    /// records the largest; a smaller P replays the first P of its periods (the tables and
    /// snapshots a recording of P periods holds).
    #[arg(
        long = "recorded-periods",
        value_delimiter = ',',
        default_value = "1,2,4",
        value_parser = clap::value_parser!(u32).range(1..=tdex_format::MAX_RECORDED_PERIODS as i64)
    )]
    pub recorded_periods: Vec<u32>,
    /// Reference periods K after t1: the DEM, its twins and every extrapolation run to
    /// t_{K+1} [default: 25]. Given a recording, its own.
    #[arg(long, value_parser = periods())]
    pub reference: Option<u32>,
    /// DEM twins, the yardstick: the extrapolation is judged against their spread
    /// [default: 2]. Given a recording, its own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=tdex_format::MAX_TWINS as i64))]
    pub twins: Option<u32>,
    /// Period τ as a fraction of a drum revolution [default: 1]. Given a recording, its own.
    #[arg(long = "tau-rev", allow_negative_numbers = true, value_parser = tau_rev())]
    pub tau_rev: Option<f64>,
    /// Seed of the recurrence paths (default: the case's seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Every path jumps only into the K recorded periods whose start is nearest the end of
    /// the P used (`tdex extrapolate --jump-nearest`); a P of K periods or fewer jumps as
    /// without it.
    #[arg(long = "jump-nearest", value_name = "K", value_parser = nearest_starts())]
    pub jump_nearest: Option<std::num::NonZeroU32>,
    /// Every path leaves the recording after every N periods in a row, from where it stands
    /// (`tdex extrapolate --jump-every`); a P of N periods or fewer leaves as without it.
    #[arg(
        long = "jump-every",
        value_name = "N",
        conflicts_with = "jump_nearest",
        value_parser = periods_in_a_row()
    )]
    pub jump_every: Option<std::num::NonZeroU32>,
    /// Run every P twice: as the paper does, and with the drum's mirror image entered at
    /// every jump (`tdex extrapolate --mirror`, docs/method.md §6), so that the table says
    /// which of the two passes as one more DEM run on this case.
    #[arg(long)]
    pub mirror: bool,
    /// The boundary maps every P runs with, comma-separated (`tdex extrapolate --boundary`,
    /// with the settings below): e.g. `exact,fresh-steps,fresh-drift` puts the three side by
    /// side on this case.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "exact")]
    pub boundary: Vec<BoundaryKind>,
    #[command(flatten)]
    pub fresh: FreshMapOptions,
}

/// `tdex study regimes`.
#[derive(Debug, clap::Args)]
pub struct RegimesStudyArgs {
    #[command(flatten)]
    pub common: StudyCommon,
    /// Drum rotation periods (s per revolution), comma-separated.
    #[arg(
        long = "rev-period",
        value_delimiter = ',',
        default_value = "15,5,0.1",
        allow_hyphen_values = true,
        value_parser = positive("give rotation periods in seconds > 0")
    )]
    pub rev_period: Vec<f64>,
    /// Periods extrapolated and simulated by the DEM for reference.
    #[arg(long, default_value_t = 2, value_parser = periods())]
    pub periods: u32,
    /// Period τ as a fraction of a revolution.
    #[arg(
        long = "tau-rev",
        default_value_t = DEFAULT_TAU_REV,
        allow_negative_numbers = true,
        value_parser = tau_rev()
    )]
    pub tau_rev: f64,
    #[command(flatten)]
    pub sampling: SamplingFlags,
    /// No relative motion below this mean speed relative to solid-body rotation, as a
    /// fraction of the wall speed ωR: extrapolation is then refused.
    #[arg(
        long = "min-relative",
        default_value_t = crate::study::flow::MIN_RELATIVE,
        allow_negative_numbers = true,
        value_parser = non_negative("give a fraction of the wall speed ≥ 0")
    )]
    pub min_relative: f64,
}

impl Cli {
    pub fn parse_args() -> Self {
        Self::parse()
    }
}

/// `--threads`: at least one worker.
fn threads() -> super::values::Count<usize> {
    count(1, "a whole number", "give at least 1")
}

/// `--periods` to extrapolate: at least one.
fn periods() -> super::values::Count<u32> {
    count(1, "a whole number", "extrapolate at least 1 period")
}

/// `tdex extrapolate --recorded-periods`: at least one.
fn periods_used() -> super::values::Count<u32> {
    count(1, "a whole number", "use at least 1 recorded period")
}

/// `tdex extrapolate --jump-nearest`: at least one start, so never zero.
fn nearest_starts() -> impl clap::builder::TypedValueParser<Value = std::num::NonZeroU32> {
    use clap::builder::TypedValueParser;
    count::<u32>(1, "a whole number", "give at least 1 start to jump to")
        .try_map(std::num::NonZeroU32::try_from)
}

/// `tdex extrapolate --jump-every`: at least one period between jumps, so never zero.
fn periods_in_a_row() -> impl clap::builder::TypedValueParser<Value = std::num::NonZeroU32> {
    use clap::builder::TypedValueParser;
    count::<u32>(
        1,
        "a whole number",
        "replay at least 1 period between jumps",
    )
    .try_map(std::num::NonZeroU32::try_from)
}

/// `tdex extrapolate --boundary-pool`: at least one pairing.
fn pool() -> super::values::Count<u32> {
    count(1, "a whole number", "give at least 1 pairing")
}

/// `--cells`: at least one Voronoi cell.
fn cells() -> super::values::Count<usize> {
    count(1, "a whole number", "give at least 1 Voronoi cell")
}

/// The items of the sampling study's `--n` and `--dtc-max` lists.
fn steps() -> super::values::Count<u32> {
    count(
        1,
        "a whole number of steps",
        "give whole numbers of steps ≥ 1",
    )
}

/// `--tau-rev`: τ as a fraction of a revolution.
fn tau_rev() -> super::values::Real {
    positive("give a fraction of a revolution > 0")
}
