//! `tdex compare`: the extrapolation against the DEM reference at every `t_k` (docs/method.md
//! §7): Voronoi-cell errors, the Eq. 10 energy-transfer error, hot/cold group means. The
//! same measures between two DEM runs of one case give the floor no extrapolation can beat.

pub mod classes;
pub mod draws;
pub mod floor;
pub mod metrics;
mod runs;
pub mod verdict;

use serde::Serialize;
use tdex_format::{Classify, ExtrapolationReader, Fault, FormatError, RecordingReader, Snapshot};
pub use verdict::Verdict;

/// Default number of Voronoi cells (the paper's v = 200).
pub const DEFAULT_CELLS: usize = 200;
/// Default seed of the cell seeds.
pub const DEFAULT_SEED: u64 = 1;

/// What the recording's DEM reference is compared with.
#[derive(Debug, Clone, Copy)]
pub enum Second<'a> {
    /// An extrapolation of the recording: roles at their `t1` positions, each carrying the
    /// id of one of the recording's particles.
    Extrapolation(&'a ExtrapolationReader),
    /// A second DEM run of the same case over the same `t_k` (another seed, a perturbed
    /// case, a run imported from another engine): its own particles, positions and hot and
    /// cold groups. Two runs of a chaotic flow part at the particle scale within a period,
    /// so their errors are the floor an extrapolation is measured against.
    Dem(&'a RecordingReader),
}

/// Which kind of file the second field came from (the JSON's `second`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SecondKind {
    Extrapolation,
    Dem,
}

/// The comparison of one extrapolation (or second DEM run) with a recording's DEM
/// reference. The `*_extra` fields hold the second field whichever kind it is.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub recording: String,
    /// The second file: the extrapolation, or the second DEM run's recording.
    pub extrapolation: String,
    pub second: SecondKind,
    pub particles: u32,
    /// Cells asked for and seed of their centres.
    pub cells: usize,
    pub seed: u64,
    /// Sizes of the initially hot and cold groups (0 if the bed started uniform).
    pub hot_particles: usize,
    pub cold_particles: usize,
    /// DEM runs that measure the floor: the reference, its twins and any further runs given
    /// (1: no floor).
    pub dem_runs: usize,
    /// Which of them the second field's distance goes to, and how fair their spread is for
    /// it; left out of the JSON when it is all of them from where they part.
    #[serde(skip_serializing_if = "floor::Departure::is_with_the_twins")]
    pub departure: floor::Departure,
    /// What `eps_rel` divides by.
    pub contrast: ContrastKind,
    /// One entry per extrapolated `t_k` that has a DEM reference (k ≥ 2; k ≥ 1 against a
    /// second DEM run).
    pub periods: Vec<PeriodComparison>,
    /// Group means of every DEM snapshot (k = 0, 1, then the reference), for plots.
    pub dem_series: Vec<GroupMeans>,
    /// The same for each further DEM run (twins first), at their own reference `t_k`.
    pub dem_runs_series: Vec<Vec<GroupMeans>>,
    /// How far to trust the extrapolation, from the numbers above.
    pub verdict: Verdict,
    /// Extrapolated `t_k` without a DEM reference (recorded with a smaller `--reference`).
    pub unreferenced: Vec<u32>,
    /// A bed of several particle sizes: each size class's mean temperature and the radial
    /// segregation index, for every DEM run and the second field. Absent for a bed of one
    /// size, and then left out of the JSON.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size_classes: Option<classes::ClassComparison>,
    /// The number of distinct radii of a bed with more than [`classes::MAX_CLASSES`] of
    /// them (a continuous size distribution), which is compared without size classes;
    /// absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distinct_radii: Option<usize>,
}

/// The errors at one `t_k`.
#[derive(Debug, Clone, Serialize)]
pub struct PeriodComparison {
    pub k: u32,
    /// Simulated time (s).
    pub t: f64,
    /// `ε_abs` (K) over `cells_used` cells (those holding particles in both fields).
    pub eps_abs: f64,
    pub cells_used: usize,
    /// `ε_abs / |T̄_hot − T̄_cold|` (DEM means at `t_k`); null for a bed without groups.
    pub eps_rel: Option<f64>,
    /// Eq. 10 for the period `t_{k−1} → t_k`; null if the DEM transferred nothing.
    pub energy_error: Option<f64>,
    pub hot_mean_dem: Option<f64>,
    pub hot_mean_extra: Option<f64>,
    pub cold_mean_dem: Option<f64>,
    pub cold_mean_extra: Option<f64>,
    /// Bed means (K, weighted by particle volume: the heat-content mean).
    pub bed_mean_dem: f64,
    pub bed_mean_extra: f64,
    /// What `eps_rel` divides by at this `t_k` (K): `|T̄_hot − T̄_cold|` of the DEM, or for a
    /// bed without groups `|T_wall − T̄_bed|` of the DEM; null when neither exists.
    pub contrast: Option<f64>,
    /// The DEM's own spread (null with a single DEM run): the mean, smallest and largest
    /// `ε_abs` between two DEM runs, the mean relative to `contrast`, the second field's mean
    /// `ε_abs` to the DEM runs and its ratio to the mean floor (null when the floor is 0).
    /// An extrapolation of several recorded periods, the reference itself until its first
    /// jump, is measured to the other runs only ([`floor::Departure`]).
    pub floor_eps_abs: Option<f64>,
    pub floor_eps_abs_min: Option<f64>,
    pub floor_eps_abs_max: Option<f64>,
    pub floor_eps_rel: Option<f64>,
    pub eps_abs_to_dem_runs: Option<f64>,
    pub ratio_to_floor: Option<f64>,
    /// Each DEM run (the reference, then the further runs) judged as the second field is,
    /// against the others: its mean `ε_abs` to them over their mean distance to each other
    /// (empty with fewer than three runs, and then left out of the JSON; null where the
    /// others are identical).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_ratio_to_others: Vec<Option<f64>>,
    /// Each DEM run, in the same order, placed as the second field is in `outside_range`:
    /// whether its mean `ε_abs` to the others exceeds the largest distance between two of
    /// them (empty with fewer than three runs, and then left out of the JSON).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_outside_others_range: Vec<bool>,
    /// Eq. 10 of each further DEM run against the reference, the largest in magnitude.
    pub floor_energy_error: Option<f64>,
    /// Group and bed means of the further DEM runs at this `t_k` (twins first).
    pub dem_runs_hot_mean: Vec<f64>,
    pub dem_runs_cold_mean: Vec<f64>,
    pub dem_runs_bed_mean: Vec<f64>,
    /// With a wall that conducts heat (the bed mean moves): the same ratios on each field
    /// less its own bed mean, its pattern ([`floor::pattern_floor`]); null otherwise, and
    /// then left out of the JSON.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<floor::PatternFloor>,
    /// The extrapolation had not yet left the recorded run at this `t_k`: along a
    /// recurrence path the periods before the first jump are the recording's own
    /// continuation from `t1` (`t2 … tP'` with `P'` recorded periods), so its snapshot is
    /// the DEM's own. Shown, but left out of the verdict, whose median it would only flatter.
    pub within_recording: bool,
}

impl PeriodComparison {
    /// Whether the second field is farther from the DEM runs than the two farthest of them
    /// are from each other at this `t_k` (false without a floor).
    pub fn outside_floor_range(&self) -> bool {
        self.eps_abs_to_dem_runs
            .zip(self.floor_eps_abs_max)
            .is_some_and(|(to_runs, max)| !floor::within(to_runs, max))
    }
}

/// What `eps_rel` is relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContrastKind {
    /// The DEM's hot-group mean minus its cold-group mean (split beds; the paper's).
    HotCold,
    /// The conducting wall's temperature minus the DEM's bed mean (uniform beds, heated wall).
    WallBed,
    /// Neither: `eps_rel` is absent.
    None,
}

/// Mean temperatures of the hot and cold groups in one snapshot.
#[derive(Debug, Clone, Serialize)]
pub struct GroupMeans {
    pub k: u32,
    pub t: f64,
    pub hot: Option<f64>,
    pub cold: Option<f64>,
    /// Volume-weighted bed mean (K).
    pub bed: f64,
}

/// Why two fields cannot be compared. Every kind but a file's own fault
/// ([`CompareError::Format`]) is bad input: files that do not belong together.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error(
        "{extrapolation} was not extrapolated from {recording} nor from another recording \
         of the same DEM run (it names {names}; the case, the particle count, the time step \
         and t0 must agree)"
    )]
    OtherRecording {
        extrapolation: String,
        recording: String,
        names: String,
    },
    #[error("{path}: no snapshot at t{index}")]
    MissingSnapshot { path: String, index: u32 },
    #[error("{path} has no DEM reference after t1")]
    NoReference { path: String },
    #[error("{path}: only {drawn} of {cells} Voronoi seeds could be drawn inside the bed at t1")]
    TooFewSeeds {
        path: String,
        drawn: usize,
        cells: usize,
    },
    #[error("t_{k}: no Voronoi cell holds particles of both fields")]
    NoSharedCell { k: u32 },
    #[error(
        "{second} and {recording} share no extrapolated t_k: the recording's reference ends \
         at t_{last}"
    )]
    NoSharedInstant {
        second: String,
        recording: String,
        last: u32,
    },
    #[error(
        "{run} holds {run_particles} particles and {recording} {particles}: two DEM runs are \
         compared only with the same particle count"
    )]
    ParticleCount {
        run: String,
        run_particles: u32,
        recording: String,
        particles: u32,
    },
    #[error(
        "{run}: its t_{k} is at {run_time} s and {recording}'s at {time} s; two DEM runs are \
         compared at the same instants (t0 and the period τ must agree to half a step, \
         {half_step} s)"
    )]
    Instants {
        run: String,
        k: u32,
        run_time: f64,
        recording: String,
        time: f64,
        half_step: f64,
    },
    #[error(
        "a pooled verdict is over at least 2 draws, and {draws} was given: over one, the \
         verdict of `tdex compare RECORDING EXTRAPOLATION` is the judgement"
    )]
    TooFewDraws { draws: usize },
    #[error(
        "{draw} is not a draw of the case of {first}: {what}; the draws of a pooled verdict \
         are recordings of one case (another seed, or another recorded window)"
    )]
    OtherCase {
        draw: String,
        first: String,
        what: String,
    },
    #[error(
        "{recording} has {dem_runs} DEM run(s) (the reference and its twins): a pooled verdict \
         judges each DEM run in the extrapolation's seat against the others, which takes at \
         least 3; record it with --twins 2"
    )]
    DrawTooFewRuns { recording: String, dem_runs: usize },
    #[error(
        "{extrapolation} against {recording} has no median ratio for itself or for the DEM \
         runs in its seat, so it cannot be pooled (its verdict: {verdict})"
    )]
    DrawNotJudged {
        extrapolation: String,
        recording: String,
        verdict: String,
    },
}

impl Classify for CompareError {
    /// The inputs are at fault (files that do not belong together), unless reading a file
    /// failed on the machine's side.
    fn fault(&self) -> Fault {
        match self {
            CompareError::Format(e) => e.fault(),
            _ => Fault::Input,
        }
    }
}

type Result<T, E = CompareError> = std::result::Result<T, E>;

/// The second field's snapshots in index order, one at a time.
type SnapshotStream<'a> = Box<dyn Iterator<Item = Result<Snapshot>> + 'a>;

/// The initially hot and cold particles of a run (`None`: a uniform start).
type HotCold = Option<(Vec<u32>, Vec<u32>)>;

/// The further DEM runs given with `--dem-run`, opened as recordings.
pub fn open_dem_runs(paths: &[std::path::PathBuf]) -> Result<Vec<RecordingReader>, FormatError> {
    paths.iter().map(|p| RecordingReader::open(p)).collect()
}

/// Compares `extrapolation` with the DEM reference snapshots of `recording`.
pub fn compare(
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
    cells: usize,
    seed: u64,
) -> Result<Comparison> {
    compare_runs(
        recording,
        Second::Extrapolation(extrapolation),
        &[],
        cells,
        seed,
    )
}

/// Compares the `second` field with the DEM reference snapshots of `recording`, and measures
/// the DEM's own spread between the reference, the recording's twins and `dem_runs`
/// (further recordings of the same case over the same `t_k`).
pub fn compare_runs(
    recording: &RecordingReader,
    second: Second,
    dem_runs: &[&RecordingReader],
    cells: usize,
    seed: u64,
) -> Result<Comparison> {
    let (dem, others) = runs::read_dem_runs(recording, dem_runs)?;
    let second = runs::SecondField::open(second, recording, &dem)?;
    let runs = runs::DemRuns::new(recording, (dem, others), cells, seed, second.recorded_until)?;
    let second_groups = second.groups(&runs.groups);
    let size_classes = classes::SizeClasses::of_run(&runs.dem);
    // the second field's class states, one per compared t_k, made as its snapshots stream by
    let mut class_states: Vec<(classes::ClassState, bool)> = Vec::new();
    // The extrapolated positions are the roles' positions at the end of the recorded period
    // just replayed: always t1's for one recorded period (one cell assignment), t_p's along
    // a recurrence path (assigned anew when they change); a second DEM run moves, so each of
    // its snapshots is assigned anew.
    let mut role_cells: Option<(Vec<[f64; 3]>, Vec<u32>)> = None;
    let mut periods = Vec::new();
    let mut unreferenced = Vec::new();
    // The second field's snapshots between two reference instants are skipped, and each
    // compared one is measured over the stretch since the last compared one.
    let mut previous: Option<(u32, Snapshot)> = None;
    for after in second.snapshots {
        let after = after?;
        let Some(k) = runs.index_at(after.time) else {
            unreferenced.push(after.index);
            continue;
        };
        // the snapshot before moves out, this one stays as the next one's before: no copy
        let Some((k_before, before)) = previous.replace((k, after)) else {
            continue;
        };
        let (before, after) = (&before, &previous.as_ref().expect("set just above").1);
        let (Some(dem_before), Some(dem_after)) = (runs.at(k_before), runs.at(k)) else {
            unreferenced.push(after.index);
            continue;
        };
        let moved;
        let second_cells: &[u32] = match second.kind {
            SecondKind::Extrapolation => {
                if role_cells.as_ref().is_none_or(|(pos, _)| *pos != after.pos) {
                    role_cells = Some((after.pos.clone(), runs.cells.assign(&after.pos)));
                }
                &role_cells.as_ref().expect("assigned just above").1
            }
            SecondKind::Dem => {
                moved = runs.cells.assign(&after.pos);
                &moved
            }
        };
        let within_recording = second
            .recorded_until
            .is_none_or(|until| after.index <= until);
        periods.push(runs.period(
            (dem_before, dem_after),
            (before, after),
            second_cells,
            &second_groups,
            within_recording,
        )?);
        if let Some(size_classes) = &size_classes {
            let state = classes::ClassState {
                k,
                ..classes::ClassState::of(size_classes, after)
            };
            class_states.push((state, within_recording));
        }
    }
    if periods.is_empty() {
        return Err(CompareError::NoSharedInstant {
            second: second.path,
            recording: runs.path,
            last: runs.dem.last().map_or(0, |s| s.index),
        });
    }
    let (hot_particles, cold_particles) = runs
        .groups
        .as_ref()
        .map_or((0, 0), |(h, c)| (h.len(), c.len()));
    let verdict = Verdict::of(
        &periods,
        1 + runs.others.len(),
        runs.departure,
        runs.contrast,
    );
    let distinct_radii = classes::too_many_classes(&runs.dem);
    let (dem_series, dem_runs_series) = runs.series();
    let size_classes = size_classes
        .map(|sizes| classes::ClassComparison::new(sizes, &runs.dem, &runs.others, class_states));
    Ok(Comparison {
        recording: runs.path,
        extrapolation: second.path,
        second: second.kind,
        particles: recording.info().particles,
        cells: runs.cells.len(),
        seed,
        hot_particles,
        cold_particles,
        dem_runs: 1 + runs.others.len(),
        departure: runs.departure,
        contrast: runs.contrast,
        periods,
        dem_series,
        dem_runs_series,
        verdict,
        unreferenced,
        size_classes,
        distinct_radii,
    })
}

/// Whether two recordings were made of the same DEM run: the same resolved case (seed
/// included), particle count, time step and `t0`. The engine does not depend on how a run is
/// recorded (`τ`, `n`, `Δt_c^max`, the periods recorded or referenced), so their snapshots
/// at the same instant are the same state, and an extrapolation of one can be compared with
/// the other's reference at the instants they share.
fn same_run(a: &tdex_format::RecordingInfo, b: &tdex_format::RecordingInfo) -> bool {
    a.case_resolved == b.case_resolved
        && a.particles == b.particles
        && a.dt == b.dt
        && a.step_t0 == b.step_t0
}

/// A second DEM run is compared only with the same particle count and at the same instants:
/// each of its snapshots that the recording also has must be within half a step of it.
fn check_same_instants(
    (recording, dem): (&RecordingReader, &[Snapshot]),
    (twin, twin_snaps): (&RecordingReader, &[Snapshot]),
) -> Result<()> {
    let rec_path = recording.path().display().to_string();
    let twin_path = twin.path().display().to_string();
    let (n, n_twin) = (recording.info().particles, twin.info().particles);
    if n != n_twin {
        return Err(CompareError::ParticleCount {
            run: twin_path,
            run_particles: n_twin,
            recording: rec_path,
            particles: n,
        });
    }
    let half_step = 0.5 * recording.info().dt;
    for s in twin_snaps {
        if let Some(d) = dem.iter().find(|d| d.index == s.index) {
            if (d.time - s.time).abs() > half_step {
                return Err(CompareError::Instants {
                    run: twin_path,
                    k: s.index,
                    run_time: s.time,
                    recording: rec_path,
                    time: d.time,
                    half_step,
                });
            }
        }
    }
    Ok(())
}

/// Snapshot indices in words, runs of three or more consecutive ones shortened:
/// `t_1, t_3, t_5 … t_9`.
pub fn span_of(ks: &[u32]) -> String {
    let mut words = Vec::new();
    let mut rest = ks;
    while let [first, ..] = rest {
        let run = 1 + rest.windows(2).take_while(|w| w[1] == w[0] + 1).count();
        words.push(if run >= 3 {
            format!("t_{first} … t_{}", rest[run - 1])
        } else {
            rest[..run]
                .iter()
                .map(|k| format!("t_{k}"))
                .collect::<Vec<_>>()
                .join(", ")
        });
        rest = &rest[run..];
    }
    words.join(", ")
}

fn opt(x: Option<f64>, scale: f64, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{:.digits$}", v * scale))
}

/// The terminal table (Table 5 form, plus the group means; with DEM twins the floor and
/// the ratio), then the verdict.
pub fn table(c: &Comparison) -> String {
    let (hot, cold) = match c.second {
        SecondKind::Extrapolation => ("hot extra", "cold ext"),
        SecondKind::Dem => ("hot DEM 2", "cold DEM2"),
    };
    let groups = c.hot_particles > 0;
    let floors = c.periods.iter().any(|p| p.floor_eps_abs.is_some());
    let mut s = format!(
        "{}{} vs {}: {} particles, {} Voronoi cells (seed {}), {}\n",
        match c.second {
            SecondKind::Extrapolation => "",
            SecondKind::Dem => "second DEM run ",
        },
        c.extrapolation,
        c.recording,
        c.particles,
        c.cells,
        c.seed,
        if groups {
            format!("{} hot / {} cold", c.hot_particles, c.cold_particles)
        } else {
            "no hot and cold groups (uniform start)".to_string()
        }
    );
    s += match c.contrast {
        ContrastKind::HotCold => "eps_rel = eps_abs / (hot − cold mean of the DEM)",
        ContrastKind::WallBed => "eps_rel = eps_abs / (wall − bed mean of the DEM)",
        ContrastKind::None => "eps_rel: no temperature contrast to divide by",
    };
    if floors {
        s += &format!(
            "; floor = eps_abs between {} DEM runs (mean, max); ratio = the second field's \
             mean eps_abs to {} / mean floor",
            c.dem_runs,
            c.departure
                .runs_measured_to()
                .unwrap_or_else(|| "them".to_string())
        );
    }
    s += "; temperatures in K\n";
    let mut head = format!(
        "{:>4} {:>8} {:>9} {:>8} {:>8}",
        "k", "t (s)", "eps_abs", "eps_rel%", "eq10 %"
    );
    if floors {
        head += &format!(" {:>9} {:>9} {:>6}", "floor", "floor max", "ratio");
    }
    if groups {
        head += &format!(" {:>9} {:>9} {:>9} {:>9}", "hot DEM", hot, "cold DEM", cold);
    } else {
        head += &format!(" {:>9} {:>9}", "bed DEM", "bed 2nd");
    }
    s += &head;
    s += "\n";
    for p in &c.periods {
        let mut line = format!(
            "{:>4} {:>8} {:>9.5} {:>8} {:>8}",
            p.k,
            format!("{:.3}", p.t),
            p.eps_abs,
            opt(p.eps_rel, 100.0, 3),
            opt(p.energy_error, 100.0, 3),
        );
        if floors {
            line += &format!(
                " {:>9} {:>9} {:>6}",
                opt(p.floor_eps_abs, 1.0, 5),
                opt(p.floor_eps_abs_max, 1.0, 5),
                p.ratio_to_floor
                    .map_or("-".into(), |r| if p.within_recording {
                        // the recorded run itself: shown, left out of the verdict
                        format!("({})", verdict::num(r))
                    } else {
                        verdict::num(r)
                    })
            );
        }
        if groups {
            line += &format!(
                " {:>9} {:>9} {:>9} {:>9}",
                opt(p.hot_mean_dem, 1.0, 4),
                opt(p.hot_mean_extra, 1.0, 4),
                opt(p.cold_mean_dem, 1.0, 4),
                opt(p.cold_mean_extra, 1.0, 4),
            );
        } else {
            line += &format!(" {:>9.4} {:>9.4}", p.bed_mean_dem, p.bed_mean_extra);
        }
        s += &line;
        s += "\n";
    }
    if !c.unreferenced.is_empty() {
        s += &format!(
            "not compared, no DEM snapshot at their instant: {}\n",
            span_of(&c.unreferenced)
        );
    }
    s += &format!("verdict: {}\n", c.verdict.text);
    if let Some(size_classes) = &c.size_classes {
        s += &classes::table(size_classes, c.second);
    }
    if let Some(n) = c.distinct_radii {
        s += &format!(
            "{n} distinct particle radii: a continuous size distribution, compared on the bed \
             mean alone (size classes are compared up to {} radii)\n",
            classes::MAX_CLASSES
        );
    }
    s
}

/// One line per `t_k`; empty fields for undefined values.
pub fn csv(c: &Comparison) -> String {
    let f = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    let mut s = String::from(
        "k,t,eps_abs,eps_rel,energy_error,cells_used,hot_mean_dem,hot_mean_extra,cold_mean_dem,cold_mean_extra,bed_mean_dem,bed_mean_extra,floor_eps_abs,floor_eps_abs_max,floor_eps_rel,ratio_to_floor,within_recording\n",
    );
    for p in &c.periods {
        s += &format!(
            "{},{:e},{:e},{},{},{},{},{},{},{},{:e},{:e},{},{},{},{},{}\n",
            p.k,
            p.t,
            p.eps_abs,
            f(p.eps_rel),
            f(p.energy_error),
            p.cells_used,
            f(p.hot_mean_dem),
            f(p.hot_mean_extra),
            f(p.cold_mean_dem),
            f(p.cold_mean_extra),
            p.bed_mean_dem,
            p.bed_mean_extra,
            f(p.floor_eps_abs),
            f(p.floor_eps_abs_max),
            f(p.floor_eps_rel),
            f(p.ratio_to_floor),
            p.within_recording
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A comparison of a bed without groups at t2 and t3 with one twin, its size classes
    /// `size_classes`.
    fn comparison(size_classes: Option<classes::ClassComparison>) -> Comparison {
        let periods: Vec<PeriodComparison> = [2u32, 3]
            .iter()
            .map(|&k| PeriodComparison {
                k,
                t: 0.5 * f64::from(k),
                eps_abs: 0.2,
                cells_used: 200,
                eps_rel: None,
                energy_error: None,
                hot_mean_dem: None,
                hot_mean_extra: None,
                cold_mean_dem: None,
                cold_mean_extra: None,
                bed_mean_dem: 310.0,
                bed_mean_extra: 309.5,
                contrast: None,
                floor_eps_abs: Some(0.25),
                floor_eps_abs_min: Some(0.25),
                floor_eps_abs_max: Some(0.25),
                floor_eps_rel: None,
                eps_abs_to_dem_runs: Some(0.2),
                ratio_to_floor: Some(0.8),
                dem_runs_ratio_to_others: Vec::new(),
                dem_runs_outside_others_range: Vec::new(),
                floor_energy_error: None,
                dem_runs_hot_mean: Vec::new(),
                dem_runs_cold_mean: Vec::new(),
                dem_runs_bed_mean: vec![310.2],
                pattern: None,
                within_recording: false,
            })
            .collect();
        let departure = floor::Departure::WithTheTwins;
        Comparison {
            recording: "run.mcap".into(),
            extrapolation: "extra.mcap".into(),
            second: SecondKind::Extrapolation,
            particles: 6,
            cells: 200,
            seed: 1,
            hot_particles: 0,
            cold_particles: 0,
            dem_runs: 2,
            departure,
            contrast: ContrastKind::None,
            verdict: Verdict::of(&periods, 2, departure, ContrastKind::None),
            periods,
            dem_series: Vec::new(),
            dem_runs_series: Vec::new(),
            unreferenced: Vec::new(),
            size_classes,
            distinct_radii: None,
        }
    }

    #[test]
    fn the_size_classes_follow_the_table_and_a_bed_of_one_size_has_none() {
        let one_size = comparison(None);
        let plain = table(&one_size);
        assert!(!plain.contains("size class"), "{plain}");
        let json = serde_json::to_string(&one_size).expect("serialisable");
        assert!(!json.contains("size_classes") && !json.contains("distinct_radii"));

        let three = comparison(Some(classes::synthetic::three_class_comparison()));
        let text = table(&three);
        // the one-size table, then the classes
        let classes_text = text.strip_prefix(plain.as_str()).expect("same table first");
        assert!(
            classes_text.starts_with("size classes at t_3"),
            "{classes_text}"
        );
        assert!(classes_text
            .contains("class 3 (2 mm) mean within the DEM runs' spread at 1 of 2 compared t_k\n"));
        let json = serde_json::to_value(&three).expect("serialisable");
        let series = &json["size_classes"]["extra_series"];
        assert_eq!(series[1]["k"], 3);
        assert_eq!(
            series[1]["mean_temperature"],
            serde_json::json!([302.0, 312.0, 322.0])
        );
        assert_eq!(
            json["size_classes"]["radii"],
            serde_json::json!([0.001, 0.0015, 0.002])
        );
    }

    #[test]
    fn runs_of_three_or_more_indices_are_shortened() {
        assert_eq!(span_of(&[3, 4, 5]), "t_3 … t_5");
        assert_eq!(span_of(&[3, 5]), "t_3, t_5");
        assert_eq!(span_of(&[3, 4]), "t_3, t_4");
        assert_eq!(
            span_of(&[1, 3, 5, 7, 8, 9, 10]),
            "t_1, t_3, t_5, t_7 … t_10"
        );
        assert_eq!(span_of(&[]), "");
    }
}
