//! The stages of one comparison: the DEM runs read and checked, the second field opened, and
//! each compared `t_k` measured against them ([`super::compare_runs`] drives them in turn).

use super::floor;
use super::metrics::{self, Cells};
use super::{
    check_same_instants, same_run, CompareError, ContrastKind, GroupMeans, HotCold,
    PeriodComparison, Result, Second, SecondKind, SnapshotStream,
};
use tdex_format::{RecordingReader, Snapshot};

/// The mean temperatures of the hot and cold particles among `temps_by_id` (none for a
/// uniform start).
pub(super) fn group_means(groups: &HotCold, temps_by_id: &[f64]) -> (Option<f64>, Option<f64>) {
    match groups {
        Some((hot, cold)) => (
            Some(metrics::group_mean(temps_by_id, hot)),
            Some(metrics::group_mean(temps_by_id, cold)),
        ),
        None => (None, None),
    }
}

/// The second field opened: its path, its snapshots as they stream by, what it is, how long
/// it follows the recorded run, and whose hot and cold particles it is judged by.
pub(super) struct SecondField<'a> {
    pub path: String,
    pub snapshots: SnapshotStream<'a>,
    pub kind: SecondKind,
    /// The last snapshot index that is still the recorded run's (0: none, a second DEM run;
    /// None: every one, a path that never jumps): periods 1 … j − 1 before the first jump j
    /// end at t2 … t_j.
    pub recorded_until: Option<u32>,
    /// A second DEM run's own hot and cold particles, chosen by the same rule at its own
    /// t0; `None` for an extrapolation, whose ids are the recording's particles and whose
    /// groups are the reference's.
    own_groups: Option<HotCold>,
}

impl<'a> SecondField<'a> {
    /// Opens `second` beside the recording's reference snapshots `dem`: an extrapolation
    /// must be of this recording or of another of the same run, a DEM run must share its
    /// instants.
    pub fn open(second: Second<'a>, recording: &RecordingReader, dem: &[Snapshot]) -> Result<Self> {
        match second {
            Second::Extrapolation(extrapolation) => {
                let path = extrapolation.path().display().to_string();
                let own = &extrapolation.info().recording_info;
                if own != recording.info() && !same_run(own, recording.info()) {
                    return Err(CompareError::OtherRecording {
                        extrapolation: path,
                        recording: recording.path().display().to_string(),
                        names: extrapolation.info().recording.clone(),
                    });
                }
                Ok(Self {
                    path,
                    // streamed: an extrapolation of hundreds of periods is never held whole
                    snapshots: Box::new(
                        extrapolation
                            .snapshots_in_order()
                            .map(|s| s.map_err(CompareError::from)),
                    ),
                    kind: SecondKind::Extrapolation,
                    recorded_until: extrapolation
                        .info()
                        .roles
                        .first_jump()
                        .and_then(|j| u32::try_from(j).ok()),
                    own_groups: None,
                })
            }
            Second::Dem(run) => {
                let snaps = run.snapshots()?;
                check_same_instants((recording, dem), (run, &snaps))?;
                let own_groups = snaps
                    .iter()
                    .find(|s| s.index == 0)
                    .and_then(|s| metrics::hot_cold_groups(&metrics::by_id(&s.id, &s.temp)));
                Ok(Self {
                    path: run.path().display().to_string(),
                    snapshots: Box::new(snaps.into_iter().map(Ok)),
                    kind: SecondKind::Dem,
                    recorded_until: Some(0),
                    own_groups: Some(own_groups),
                })
            }
        }
    }

    /// The hot and cold particles the second field is judged by, given the reference's.
    pub fn groups(&self, reference: &HotCold) -> HotCold {
        self.own_groups.clone().unwrap_or_else(|| reference.clone())
    }
}

/// The DEM side of a comparison: the reference and the further runs (twins, `--dem-run`),
/// each run's hot and cold particles, the Voronoi cells and what scales the errors.
pub(super) struct DemRuns {
    pub path: String,
    /// The reference's snapshots, t0 and t1 first.
    pub dem: Vec<Snapshot>,
    /// Every further run's snapshots.
    pub others: Vec<Vec<Snapshot>>,
    /// The reference's hot and cold particles, and each further run's: a run that starts
    /// at t0 has its own (the same rule at its own t0), a twin starts at t1 from the
    /// reference's state and shares its groups.
    pub groups: HotCold,
    run_groups: Vec<HotCold>,
    pub cells: Cells,
    pub contrast: ContrastKind,
    wall_temperature: Option<f64>,
    pub departure: floor::Departure,
    half_step: f64,
}

/// The recording's reference snapshots and every further run's: its twins, then `dem_runs`
/// (each checked to share the reference's instants).
pub(super) fn read_dem_runs(
    recording: &RecordingReader,
    dem_runs: &[&RecordingReader],
) -> Result<(Vec<Snapshot>, Vec<Vec<Snapshot>>)> {
    let dem = recording.snapshots()?;
    let mut others = recording.twin_snapshots()?;
    for run in dem_runs {
        let snaps = run.snapshots()?;
        check_same_instants((recording, &dem), (run, &snaps))?;
        others.push(snaps);
    }
    Ok((dem, others))
}

impl DemRuns {
    /// The DEM runs of `recording`, with `cells` Voronoi cells drawn from `seed` inside the
    /// bed at t1, judging a second field that follows the recorded run up to
    /// `recorded_until` ([`SecondField::recorded_until`]).
    pub fn new(
        recording: &RecordingReader,
        (dem, others): (Vec<Snapshot>, Vec<Vec<Snapshot>>),
        cells: usize,
        seed: u64,
        recorded_until: Option<u32>,
    ) -> Result<Self> {
        let path = recording.path().display().to_string();
        let at = |k: u32| {
            dem.iter()
                .find(|s| s.index == k)
                .ok_or_else(|| CompareError::MissingSnapshot {
                    path: path.clone(),
                    index: k,
                })
        };
        let (t0, t1) = (at(0)?, at(1)?);
        if dem.len() <= 2 {
            return Err(CompareError::NoReference { path });
        }
        let reach = t1.radius.iter().copied().fold(0.0, f64::max);
        let cells_v = Cells::inside_bed(&t1.pos, reach, cells, seed);
        if cells_v.len() < cells {
            return Err(CompareError::TooFewSeeds {
                path,
                drawn: cells_v.len(),
                cells,
            });
        }
        let groups = metrics::hot_cold_groups(&t0.temp);
        let run_groups = others
            .iter()
            .map(|o| match o.iter().find(|s| s.index == 0) {
                Some(t0) => metrics::hot_cold_groups(&t0.temp),
                None => groups.clone(),
            })
            .collect();
        let wall_temperature = recording.info().walls.iter().find_map(|w| w.temperature);
        let contrast = match (&groups, wall_temperature) {
            (Some(_), _) => ContrastKind::HotCold,
            (None, Some(_)) => ContrastKind::WallBed,
            (None, None) => ContrastKind::None,
        };
        Ok(Self {
            path,
            dem,
            others,
            groups,
            run_groups,
            cells: cells_v,
            contrast,
            wall_temperature,
            // An extrapolation that follows the reference past the twins' parting t_s
            // (several recorded periods, twins from t1) is measured against the runs that
            // parted from that shared past at t_s: the twins and any further runs, not the
            // reference (floor::Departure). One that leaves the reference where the twins
            // do is one more run; one that leaves it before they part is measured to all,
            // its verdict saying so.
            departure: floor::Departure::of(recorded_until, recording.info().twins_from),
            half_step: 0.5 * recording.info().dt,
        })
    }

    /// The reference's snapshot at t_k.
    pub fn at(&self, k: u32) -> Option<&Snapshot> {
        self.dem.iter().find(|s| s.index == k)
    }

    /// The index of the reference snapshot at `time`, to half a step: the second field's
    /// snapshots are matched to the DEM's by time (the same index for an extrapolation of
    /// this recording; for one of another recording of the same run, another τ or more
    /// recorded periods, the reference t_k it lands on).
    pub fn index_at(&self, time: f64) -> Option<u32> {
        self.dem
            .iter()
            .find(|d| (d.time - time).abs() <= self.half_step)
            .map(|d| d.index)
    }

    /// The hot, cold and bed means of every snapshot of the reference, then of each further
    /// run, each by its own groups.
    pub fn series(&self) -> (Vec<GroupMeans>, Vec<Vec<GroupMeans>>) {
        let series = |snaps: &[Snapshot], groups: &HotCold| -> Vec<GroupMeans> {
            snaps
                .iter()
                .map(|s| {
                    let (hot, cold) = group_means(groups, &s.temp);
                    GroupMeans {
                        k: s.index,
                        t: s.time,
                        hot,
                        cold,
                        bed: metrics::bed_mean(&s.radius, &s.temp),
                    }
                })
                .collect()
        };
        let runs = self
            .others
            .iter()
            .zip(&self.run_groups)
            .map(|(o, g)| series(o, g))
            .collect();
        (series(&self.dem, &self.groups), runs)
    }

    /// One compared t_k: the second field's snapshots `before` and `after`, matched to the
    /// reference's `dem_before` (t_{k−1}, or the last compared instant) and `dem_after`
    /// (t_k), the particles of `after` in `second_cells` and judged by `second_groups`,
    /// against every DEM run at t_k and the reference over the stretch between.
    pub fn period(
        &self,
        (dem_before, dem_after): (&Snapshot, &Snapshot),
        (before, after): (&Snapshot, &Snapshot),
        second_cells: &[u32],
        second_groups: &HotCold,
        within_recording: bool,
    ) -> Result<PeriodComparison> {
        let k = dem_after.index;
        // the DEM runs at t_k: the reference, then every further run that reached t_k
        let (at_k, at_k_groups): (Vec<&Snapshot>, Vec<&HotCold>) = self
            .others
            .iter()
            .zip(&self.run_groups)
            .filter_map(|(o, g)| Some((o.iter().find(|s| s.index == k)?, g)))
            .unzip();
        // each run's cell means, the reference's first, found once for the errors, the
        // floor and the pattern
        let run_means: Vec<Vec<Option<f64>>> = std::iter::once(dem_after)
            .chain(at_k.iter().copied())
            .map(|s| self.cells.means(&s.pos, &s.temp))
            .collect();
        let extra_means = metrics::cell_means(second_cells, &after.temp, self.cells.len());
        let (eps_abs, cells_used) = metrics::eps_abs(&run_means[0], &extra_means)
            .ok_or(CompareError::NoSharedCell { k })?;
        let (hot_dem, cold_dem) = group_means(&self.groups, &dem_after.temp);
        let extra_after = metrics::by_id(&after.id, &after.temp);
        let (hot_extra, cold_extra) = group_means(second_groups, &extra_after);
        let bed_mean_dem = metrics::bed_mean(&dem_after.radius, &dem_after.temp);
        let scale = match self.contrast {
            ContrastKind::HotCold => hot_dem.zip(cold_dem).map(|(h, c)| (h - c).abs()),
            ContrastKind::WallBed => self.wall_temperature.map(|w| (w - bed_mean_dem).abs()),
            ContrastKind::None => None,
        }
        .filter(|s| *s > 0.0);
        let floor = floor::floor(&run_means, &extra_means, self.departure);
        let bed_mean_extra = metrics::bed_mean(&after.radius, &after.temp);
        let run_bed_means: Vec<f64> = std::iter::once(bed_mean_dem)
            .chain(at_k.iter().map(|s| metrics::bed_mean(&s.radius, &s.temp)))
            .collect();
        // a wall that conducts heat: the bed mean moves at a rate the recorded periods set,
        // so the same distances are also measured on each field less its own bed mean
        let pattern = self.wall_temperature.and_then(|_| {
            floor::pattern_floor(
                &run_means,
                &run_bed_means,
                &extra_means,
                bed_mean_extra,
                self.departure,
            )
        });
        let floor_energy_error = self.floor_energy_error(dem_before, dem_after);
        Ok(PeriodComparison {
            k,
            t: after.time,
            eps_abs,
            cells_used,
            eps_rel: scale.map(|s| eps_abs / s),
            energy_error: metrics::energy_error(
                &dem_before.temp,
                &dem_after.temp,
                &metrics::by_id(&before.id, &before.temp),
                &extra_after,
            ),
            hot_mean_dem: hot_dem,
            hot_mean_extra: hot_extra,
            cold_mean_dem: cold_dem,
            cold_mean_extra: cold_extra,
            bed_mean_dem,
            bed_mean_extra,
            contrast: scale,
            floor_eps_abs: floor.as_ref().map(|f| f.floor_eps_abs),
            floor_eps_abs_min: floor.as_ref().map(|f| f.floor_eps_abs_min),
            floor_eps_abs_max: floor.as_ref().map(|f| f.floor_eps_abs_max),
            floor_eps_rel: floor.as_ref().zip(scale).map(|(f, s)| f.floor_eps_abs / s),
            eps_abs_to_dem_runs: floor.as_ref().map(|f| f.eps_abs_to_dem_runs),
            ratio_to_floor: floor.as_ref().and_then(|f| f.ratio_to_floor),
            dem_runs_ratio_to_others: floor
                .as_ref()
                .map_or_else(Vec::new, |f| f.runs_ratio_to_others.clone()),
            dem_runs_outside_others_range: floor
                .as_ref()
                .map_or_else(Vec::new, |f| f.runs_outside_others_range.clone()),
            floor_energy_error,
            dem_runs_hot_mean: at_k
                .iter()
                .zip(&at_k_groups)
                .filter_map(|(s, g)| group_means(g, &s.temp).0)
                .collect(),
            dem_runs_cold_mean: at_k
                .iter()
                .zip(&at_k_groups)
                .filter_map(|(s, g)| group_means(g, &s.temp).1)
                .collect(),
            dem_runs_bed_mean: run_bed_means[1..].to_vec(),
            pattern,
            within_recording,
        })
    }

    /// The largest Eq. 10 error of a further DEM run against the reference over
    /// `dem_before` → `dem_after` (t_{k−1} → t_k): the energy error's floor. A twin has no
    /// snapshot at t1, where it is the reference.
    fn floor_energy_error(&self, dem_before: &Snapshot, dem_after: &Snapshot) -> Option<f64> {
        let (k_before, k) = (dem_before.index, dem_after.index);
        self.others
            .iter()
            .filter_map(|o| {
                let twin_after = o.iter().find(|s| s.index == k)?;
                let twin_before = o
                    .iter()
                    .find(|s| s.index == k_before)
                    .map_or(&dem_before.temp, |s| &s.temp);
                metrics::energy_error(
                    &dem_before.temp,
                    &dem_after.temp,
                    twin_before,
                    &twin_after.temp,
                )
            })
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
    }
}
