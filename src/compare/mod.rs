//! `tdex compare`: the extrapolation against the DEM reference at every `t_k` (DESIGN.md
//! §7): Voronoi-cell errors, the Eq. 10 energy-transfer error, hot/cold group means. The
//! same measures between two DEM runs of one case give the floor no extrapolation can beat.

pub mod metrics;

use crate::cli::ComparePlan;
use crate::cli::UsageError;
use anyhow::{Context, Result};
use metrics::Cells;
use recorder::format::{ExtrapolationReader, FormatError, RecordingReader, Snapshot};
use serde::Serialize;

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
    /// One entry per extrapolated `t_k` that has a DEM reference (k ≥ 2; k ≥ 1 against a
    /// second DEM run).
    pub periods: Vec<PeriodComparison>,
    /// Group means of every DEM snapshot (k = 0, 1, then the reference), for plots.
    pub dem_series: Vec<GroupMeans>,
    /// Extrapolated `t_k` without a DEM reference (recorded with a smaller `--reference`).
    pub unreferenced: Vec<u32>,
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
}

/// Mean temperatures of the hot and cold groups in one snapshot.
#[derive(Debug, Clone, Serialize)]
pub struct GroupMeans {
    pub k: u32,
    pub t: f64,
    pub hot: Option<f64>,
    pub cold: Option<f64>,
}

/// The inputs cannot be compared (exit code 2, like any bad input).
macro_rules! refuse {
    ($($arg:tt)*) => {
        return Err(UsageError(format!($($arg)*)).into())
    };
}

pub fn run(plan: &ComparePlan) -> Result<()> {
    let recording = RecordingReader::open(&plan.recording)?;
    // A file without recording metadata is read as an extrapolation, whose reader then
    // names what is missing; any other fault of a recording is reported as it is.
    let c = match RecordingReader::open(&plan.extrapolation) {
        Ok(dem) => compare_with(&recording, Second::Dem(&dem), plan.cells, plan.seed)?,
        Err(FormatError::NotRecording { .. }) => {
            let extrapolation = ExtrapolationReader::open(&plan.extrapolation)?;
            compare(&recording, &extrapolation, plan.cells, plan.seed)?
        }
        Err(e) => return Err(e.into()),
    };
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else if plan.csv {
        print!("{}", csv(&c));
    } else {
        print!("{}", table(&c));
    }
    Ok(())
}

/// Compares `extrapolation` with the DEM reference snapshots of `recording`.
pub fn compare(
    recording: &RecordingReader,
    extrapolation: &ExtrapolationReader,
    cells: usize,
    seed: u64,
) -> Result<Comparison> {
    compare_with(recording, Second::Extrapolation(extrapolation), cells, seed)
}

/// Compares the `second` field with the DEM reference snapshots of `recording`.
pub fn compare_with(
    recording: &RecordingReader,
    second: Second,
    cells: usize,
    seed: u64,
) -> Result<Comparison> {
    let rec_path = recording.path().display().to_string();
    let dem = recording.snapshots()?;
    let (extra_path, extra, kind) = match second {
        Second::Extrapolation(extrapolation) => {
            let extra_path = extrapolation.path().display().to_string();
            if extrapolation.info().recording_info != *recording.info() {
                refuse!(
                    "{extra_path} was not extrapolated from {rec_path} (it names {}, and the \
                     recordings' metadata differ)",
                    extrapolation.info().recording
                );
            }
            (
                extra_path,
                extrapolation.snapshots()?,
                SecondKind::Extrapolation,
            )
        }
        Second::Dem(twin) => {
            let snaps = twin.snapshots()?;
            check_same_instants((recording, &dem), (twin, &snaps))?;
            (twin.path().display().to_string(), snaps, SecondKind::Dem)
        }
    };
    let dem_at = |k: u32| dem.iter().find(|s| s.index == k);
    let t0 = dem_at(0).with_context(|| format!("{rec_path}: no snapshot at t0"))?;
    let t1 = dem_at(1).with_context(|| format!("{rec_path}: no snapshot at t1"))?;
    if dem.len() <= 2 {
        refuse!(
            "{rec_path} has no DEM reference after t1: record it with `--reference K` \
             (K ≥ the periods to compare) to compare an extrapolation"
        );
    }
    let reach = t1.radius.iter().copied().fold(0.0, f64::max);
    let cells_v = Cells::inside_bed(&t1.pos, reach, cells, seed);
    if cells_v.len() < cells {
        refuse!(
            "{rec_path}: only {} of {cells} Voronoi seeds could be drawn inside the bed at t1",
            cells_v.len()
        );
    }
    let groups = metrics::hot_cold_groups(&t0.temp);
    // An extrapolation's ids are the recording's particles; a second run has its own, and
    // its own hot and cold particles, chosen by the same rule at its own t0.
    let extra_groups = match kind {
        SecondKind::Extrapolation => groups.clone(),
        SecondKind::Dem => extra
            .iter()
            .find(|s| s.index == 0)
            .and_then(|s| metrics::hot_cold_groups(&metrics::by_id(&s.id, &s.temp))),
    };
    let means_in = |groups: &Option<(Vec<u32>, Vec<u32>)>, temps_by_id: &[f64]| match groups {
        Some((hot, cold)) => (
            Some(metrics::group_mean(temps_by_id, hot)),
            Some(metrics::group_mean(temps_by_id, cold)),
        ),
        None => (None, None),
    };
    let means = |temps_by_id: &[f64]| means_in(&groups, temps_by_id);
    let by_id = |s: &Snapshot| metrics::by_id(&s.id, &s.temp);

    let dem_series = dem
        .iter()
        .map(|s| {
            let (hot, cold) = means(&s.temp);
            GroupMeans {
                k: s.index,
                t: s.time,
                hot,
                cold,
            }
        })
        .collect();

    // The extrapolated positions are the roles' positions at t1: one cell assignment; a
    // second DEM run moves, so each of its snapshots is assigned anew.
    let mut role_cells: Option<Vec<u32>> = None;
    let mut periods = Vec::new();
    let mut unreferenced = Vec::new();
    for pair in extra.windows(2) {
        let (before, after) = (&pair[0], &pair[1]);
        let k = after.index;
        let (Some(dem_before), Some(dem_after)) = (dem_at(before.index), dem_at(k)) else {
            unreferenced.push(k);
            continue;
        };
        let dem_means = cells_v.means(&dem_after.pos, &dem_after.temp);
        let moved;
        let extra_cells: &[u32] = match kind {
            SecondKind::Extrapolation => {
                role_cells.get_or_insert_with(|| cells_v.assign(&after.pos))
            }
            SecondKind::Dem => {
                moved = cells_v.assign(&after.pos);
                &moved
            }
        };
        let extra_means = metrics::cell_means(extra_cells, &after.temp, cells_v.len());
        let (eps_abs, cells_used) = metrics::eps_abs(&dem_means, &extra_means)
            .with_context(|| format!("t_{k}: no Voronoi cell holds particles of both fields"))?;
        let (hot_dem, cold_dem) = means(&dem_after.temp);
        let extra_after = by_id(after);
        let (hot_extra, cold_extra) = means_in(&extra_groups, &extra_after);
        let scale = hot_dem.zip(cold_dem).map(|(h, c)| (h - c).abs());
        periods.push(PeriodComparison {
            k,
            t: after.time,
            eps_abs,
            cells_used,
            eps_rel: scale.filter(|s| *s > 0.0).map(|s| eps_abs / s),
            energy_error: metrics::energy_error(
                &dem_before.temp,
                &dem_after.temp,
                &by_id(before),
                &extra_after,
            ),
            hot_mean_dem: hot_dem,
            hot_mean_extra: hot_extra,
            cold_mean_dem: cold_dem,
            cold_mean_extra: cold_extra,
        });
    }
    if periods.is_empty() {
        refuse!(
            "{extra_path} and {rec_path} share no extrapolated t_k: the recording's reference \
             ends at t_{}",
            dem.last().map_or(0, |s| s.index)
        );
    }
    let (hot_particles, cold_particles) =
        groups.as_ref().map_or((0, 0), |(h, c)| (h.len(), c.len()));
    Ok(Comparison {
        recording: rec_path,
        extrapolation: extra_path,
        second: kind,
        particles: recording.info().particles,
        cells: cells_v.len(),
        seed,
        hot_particles,
        cold_particles,
        periods,
        dem_series,
        unreferenced,
    })
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
        refuse!(
            "{twin_path} holds {n_twin} particles and {rec_path} {n}: two DEM runs are compared \
             only with the same particle count"
        );
    }
    let half_step = 0.5 * recording.info().dt;
    for s in twin_snaps {
        if let Some(d) = dem.iter().find(|d| d.index == s.index) {
            if (d.time - s.time).abs() > half_step {
                refuse!(
                    "{twin_path}: its t_{k} is at {} s and {rec_path}'s at {} s; two DEM runs \
                     are compared at the same instants (t0 and the period τ must agree to half \
                     a step, {half_step} s)",
                    s.time,
                    d.time,
                    k = s.index
                );
            }
        }
    }
    Ok(())
}

fn opt(x: Option<f64>, scale: f64, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{:.digits$}", v * scale))
}

/// The terminal table (Table 5 form, plus the group means).
pub fn table(c: &Comparison) -> String {
    let (hot, cold) = match c.second {
        SecondKind::Extrapolation => ("hot extra", "cold ext"),
        SecondKind::Dem => ("hot DEM 2", "cold DEM2"),
    };
    let mut s = format!(
        "{}{} vs {}: {} particles, {} Voronoi cells (seed {}), {} hot / {} cold\n",
        match c.second {
            SecondKind::Extrapolation => "",
            SecondKind::Dem => "second DEM run ",
        },
        c.extrapolation,
        c.recording,
        c.particles,
        c.cells,
        c.seed,
        c.hot_particles,
        c.cold_particles
    );
    s += &format!(
        "{:>4} {:>9} {:>10} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9}\n",
        "k", "t (s)", "eps_abs K", "eps_rel%", "eq10 %", "hot DEM", hot, "cold DEM", cold
    );
    for p in &c.periods {
        s += &format!(
            "{:>4} {:>9.3} {:>10.5} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9}\n",
            p.k,
            p.t,
            p.eps_abs,
            opt(p.eps_rel, 100.0, 3),
            opt(p.energy_error, 100.0, 3),
            opt(p.hot_mean_dem, 1.0, 4),
            opt(p.hot_mean_extra, 1.0, 4),
            opt(p.cold_mean_dem, 1.0, 4),
            opt(p.cold_mean_extra, 1.0, 4),
        );
    }
    if !c.unreferenced.is_empty() {
        s += &format!("no DEM reference for t_k, k = {:?}\n", c.unreferenced);
    }
    s
}

/// One line per `t_k`; empty fields for undefined values.
pub fn csv(c: &Comparison) -> String {
    let f = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    let mut s = String::from(
        "k,t,eps_abs,eps_rel,energy_error,cells_used,hot_mean_dem,hot_mean_extra,cold_mean_dem,cold_mean_extra\n",
    );
    for p in &c.periods {
        s += &format!(
            "{},{:e},{:e},{},{},{},{},{},{},{}\n",
            p.k,
            p.t,
            p.eps_abs,
            f(p.eps_rel),
            f(p.energy_error),
            p.cells_used,
            f(p.hot_mean_dem),
            f(p.hot_mean_extra),
            f(p.cold_mean_dem),
            f(p.cold_mean_extra)
        );
    }
    s
}
