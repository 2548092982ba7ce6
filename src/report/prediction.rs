//! What an extrapolation predicts, from its file alone: at every `t_k` of all its
//! periods, the bed mean, the hot and cold group means, the temperature spread, the heat
//! content (whose change is what the walls gave) and the mixing of the hot and cold labels.
//! The same measures on DEM snapshots (the reference and its twins) overlay the prediction
//! where the recording has them.

use crate::compare::metrics::{self, Cells};
use anyhow::{Context, Result};
use tdex_format::{RecordingInfo, Snapshot};

/// Fewest particles per Voronoi cell, on average, that the Lacey index is computed on: with
/// one or two particles in a cell the hot fraction of a cell is 0 or 1 whatever the mixing,
/// and σr² nears σ0², so the index would be noise. A bed too small for the comparison's
/// cells gets fewer (`particles / 10`).
pub const LACEY_MIN_PER_CELL: usize = 10;

/// The measures at one snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    pub k: u32,
    /// Simulated time (s).
    pub t: f64,
    /// Bed mean (K), weighted by particle volume: [`metrics::bed_mean`], as the comparison.
    pub bed: f64,
    /// Means of the initially hot and cold particles (K); `None` for a bed without groups.
    pub hot: Option<f64>,
    pub cold: Option<f64>,
    /// Standard deviation of the temperature about `bed` over the bed's volume (K).
    pub std: f64,
    /// The temperatures below which 5 % and 95 % of the bed's volume lie (K).
    pub p05: f64,
    pub p95: f64,
    /// The bed's heat content Σ C_i T_i (J), C_i = ρ c_p (4/3)π r_i³.
    pub heat: f64,
    /// Lacey index of the hot and cold labels; `None` for a bed without groups.
    pub lacey: Option<f64>,
}

/// How the measures are taken: the material, the groups and the cells of the Lacey index.
pub struct Measures {
    /// ρ c_p (4/3)π: C_i = this · r_i³ (J/K per m³).
    capacity_per_r3: f64,
    groups: Option<(Vec<u32>, Vec<u32>)>,
    /// `hot[id]`: whether particle `id` was initially hot.
    hot: Vec<bool>,
    cells: Option<Cells>,
}

impl Measures {
    /// The groups from the recording's `t0`, the Lacey index's cells drawn inside the bed
    /// at `t1` as the comparison draws them (`cells` of them, `seed`), fewer for a bed with
    /// fewer than [`LACEY_MIN_PER_CELL`] particles per cell.
    pub fn new(
        info: &RecordingInfo,
        t0: &Snapshot,
        t1: &Snapshot,
        cells: usize,
        seed: u64,
    ) -> Self {
        let groups = metrics::hot_cold_groups(&metrics::by_id(&t0.id, &t0.temp));
        let mut hot = vec![false; t0.len()];
        if let Some((h, _)) = &groups {
            for &p in h {
                hot[p as usize] = true;
            }
        }
        let cells = groups.as_ref().map(|_| {
            let v = cells.min(t1.len() / LACEY_MIN_PER_CELL).max(1);
            let reach = t1.radius.iter().copied().fold(0.0, f64::max);
            Cells::inside_bed(&t1.pos, reach, v, seed)
        });
        Self {
            capacity_per_r3: info.density * info.heat_capacity * 4.0 / 3.0 * std::f64::consts::PI,
            groups,
            hot,
            cells,
        }
    }

    /// Sizes of the initially hot and cold groups (0, 0 for a bed without groups).
    pub fn group_sizes(&self) -> (usize, usize) {
        self.groups
            .as_ref()
            .map_or((0, 0), |(h, c)| (h.len(), c.len()))
    }

    /// Voronoi cells of the Lacey index (`None` for a bed without groups).
    pub fn lacey_cells(&self) -> Option<usize> {
        self.cells.as_ref().map(Cells::len)
    }

    /// The heat capacity Σ C_i of the particles of `s` (J/K).
    pub fn capacity(&self, s: &Snapshot) -> f64 {
        self.capacity_per_r3 * s.radius.iter().map(|r| r * r * r).sum::<f64>()
    }

    /// The measures of `s`, whose point `j` is particle `s.id[j]` (a recording's snapshot
    /// in fixed-id order or an extrapolation's in role order).
    pub fn point(&self, s: &Snapshot) -> Point {
        let bed = metrics::bed_mean(&s.radius, &s.temp);
        let (hot, cold) = match &self.groups {
            Some((h, c)) => {
                let by_id = metrics::by_id(&s.id, &s.temp);
                (
                    Some(metrics::group_mean(&by_id, h)),
                    Some(metrics::group_mean(&by_id, c)),
                )
            }
            None => (None, None),
        };
        let weights: Vec<f64> = s.radius.iter().map(|r| r * r * r).collect();
        let (p05, p95) = (
            weighted_quantile(&s.temp, &weights, 0.05),
            weighted_quantile(&s.temp, &weights, 0.95),
        );
        let volume: f64 = weights.iter().sum();
        let var = weights
            .iter()
            .zip(&s.temp)
            .map(|(w, t)| w * (t - bed) * (t - bed))
            .sum::<f64>()
            / volume;
        let heat =
            self.capacity_per_r3 * weights.iter().zip(&s.temp).map(|(w, t)| w * t).sum::<f64>();
        let lacey = self.cells.as_ref().and_then(|cells| {
            let labels: Vec<bool> = s.id.iter().map(|&p| self.hot[p as usize]).collect();
            lacey(&cells.assign(&s.pos), &labels, cells.len())
        });
        Point {
            k: s.index,
            t: s.time,
            bed,
            hot,
            cold,
            std: var.max(0.0).sqrt(),
            p05,
            p95,
            heat,
            lacey,
        }
    }
}

/// The temperature below which the fraction `q` of the total weight lies (the smallest
/// temperature whose cumulative weight reaches `q`).
pub fn weighted_quantile(temps: &[f64], weights: &[f64], q: f64) -> f64 {
    let mut order: Vec<usize> = (0..temps.len()).collect();
    order.sort_by(|&a, &b| temps[a].total_cmp(&temps[b]));
    let total: f64 = weights.iter().sum();
    let mut seen = 0.0;
    for &i in &order {
        seen += weights[i];
        if seen >= q * total {
            return temps[i];
        }
    }
    order.last().map_or(f64::NAN, |&i| temps[i])
}

/// The Lacey mixing index of two labels (hot, cold) over cells:
///
/// `M = (σ0² − σ²) / (σ0² − σr²)`, with `p` the hot fraction of all particles,
/// `σ² = (1/N_c) Σ_c (x_c − p)²` the variance about `p` of the hot fraction `x_c` of the
/// `N_c` cells that hold particles, `σ0² = p(1 − p)` its value fully segregated (every cell
/// one label) and `σr² = p(1 − p)/n̄` its value fully random, `n̄` the mean number of
/// particles per non-empty cell. `M` is 0 segregated and 1 randomly mixed (it can pass 1 by
/// chance). `None` when it is undefined: one label only, or one particle per cell
/// (σr² = σ0²).
pub fn lacey(cell_of: &[u32], hot: &[bool], cells: usize) -> Option<f64> {
    let mut n = vec![0u32; cells];
    let mut h = vec![0u32; cells];
    for (&c, &is_hot) in cell_of.iter().zip(hot) {
        n[c as usize] += 1;
        h[c as usize] += u32::from(is_hot);
    }
    let total: u32 = n.iter().sum();
    let used: Vec<(u32, u32)> = n.into_iter().zip(h).filter(|(n, _)| *n > 0).collect();
    if total == 0 || used.is_empty() {
        return None;
    }
    let p = used.iter().map(|(_, h)| *h as f64).sum::<f64>() / total as f64;
    let s0 = p * (1.0 - p);
    let n_bar = total as f64 / used.len() as f64;
    let sr = s0 / n_bar;
    let s2 = used
        .iter()
        .map(|&(n, h)| (h as f64 / n as f64 - p).powi(2))
        .sum::<f64>()
        / used.len() as f64;
    (s0 - sr > 0.0).then(|| (s0 - s2) / (s0 - sr))
}

/// The prediction over all the extrapolation's snapshots.
pub struct Prediction {
    /// One point per snapshot: `t1` (the DEM state the extrapolation starts from), then
    /// every extrapolated `t_k`.
    pub points: Vec<Point>,
    /// Temperature of the conducting wall (the first one) when a wall conducts.
    pub wall_temperature: Option<f64>,
    /// Sizes of the initially hot and cold groups.
    pub hot_particles: usize,
    pub cold_particles: usize,
    /// Voronoi cells of the Lacey index (split beds).
    pub lacey_cells: Option<usize>,
    /// The drum's radius (m), from the resolved case.
    pub drum_radius: Option<f64>,
    /// The bed's heat capacity Σ C_i (J/K).
    pub capacity: f64,
    /// The snapshots of the field plot: the first, a middle and the last.
    pub fields: Vec<Snapshot>,
}

impl Prediction {
    /// Measures every snapshot of `snaps` (an extrapolation's, streamed by index; `count`
    /// of them, for the middle one) and keeps the first, middle and last for the field plot,
    /// and the one with index `also` if asked: memory holds those and one point per snapshot,
    /// whatever the number of periods.
    pub fn new(
        info: &RecordingInfo,
        measures: &Measures,
        count: usize,
        snaps: impl IntoIterator<Item = Result<Snapshot>>,
        also: Option<u32>,
    ) -> Result<(Self, Option<Snapshot>)> {
        let mut points = Vec::with_capacity(count);
        let mut fields: Vec<Snapshot> = Vec::new();
        let mut last: Option<Snapshot> = None;
        let mut kept = None;
        let mut capacity = None;
        for (i, s) in snaps.into_iter().enumerate() {
            let s = s?;
            points.push(measures.point(&s));
            capacity.get_or_insert_with(|| measures.capacity(&s));
            if also == Some(s.index) {
                kept = Some(s.clone());
            }
            if i == 0 || i == count / 2 {
                fields.push(s.clone());
            }
            last = Some(s);
        }
        let last = last.context("the extrapolation holds no snapshot")?;
        if !fields.iter().any(|f| f.index == last.index) {
            fields.push(last);
        }
        let (hot_particles, cold_particles) = measures.group_sizes();
        Ok((
            Self {
                points,
                wall_temperature: info.walls.iter().find_map(|w| w.temperature),
                hot_particles,
                cold_particles,
                lacey_cells: measures.lacey_cells(),
                drum_radius: drum_radius(info),
                capacity: capacity.unwrap_or_default(),
                fields,
            },
            kept,
        ))
    }

    pub fn first(&self) -> &Point {
        &self.points[0]
    }

    pub fn last(&self) -> &Point {
        self.points.last().expect("at least one point")
    }

    /// Extrapolated periods (the points after `t1`).
    pub fn periods(&self) -> usize {
        self.points.len() - 1
    }

    /// Whether the bed has initially hot and cold groups.
    pub fn has_groups(&self) -> bool {
        self.hot_particles > 0 && self.cold_particles > 0
    }

    /// The heat the walls gave in each period `t_(k−1) → t_k` (J), as `(k, t_k, Q)`:
    /// particle-particle conduction conserves Σ C_i T_i, so its change is the walls'.
    /// `None` when no wall conducts.
    pub fn wall_heat(&self) -> Option<Vec<(u32, f64, f64)>> {
        self.wall_temperature?;
        Some(
            self.points
                .windows(2)
                .map(|w| (w[1].k, w[1].t, w[1].heat - w[0].heat))
                .collect(),
        )
    }
}

/// The drum's radius from the recording's resolved case.
pub fn drum_radius(info: &RecordingInfo) -> Option<f64> {
    info.case_resolved
        .get("drum")?
        .get("radius")?
        .as_f64()
        .filter(|r| r.is_finite() && *r > 0.0)
}

/// The measures of a recording's DEM snapshots from `t1` on (`k ≥ 1`), for overlays.
pub fn dem_points(measures: &Measures, snaps: &[Snapshot]) -> Vec<Point> {
    snaps
        .iter()
        .filter(|s| s.index >= 1)
        .map(|s| measures.point(s))
        .collect()
}

/// The recording's snapshots at `t0` and `t1`.
pub fn t0_t1(snaps: &[Snapshot], path: &str) -> Result<(usize, usize)> {
    let at = |k: u32| snaps.iter().position(|s| s.index == k);
    let t0 = at(0).with_context(|| format!("{path}: no snapshot at t0"))?;
    let t1 = at(1).with_context(|| format!("{path}: no snapshot at t1"))?;
    Ok((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lacey_is_zero_segregated_and_near_one_mixed() {
        // two cells of four particles, all hot left and all cold right: segregated
        let cells = [0, 0, 0, 0, 1, 1, 1, 1];
        let seg = [true, true, true, true, false, false, false, false];
        assert_eq!(lacey(&cells, &seg, 2), Some(0.0));
        // each cell half hot: σ² = 0, M = σ0² / (σ0² − σr²) = 1 / (1 − 1/4)
        let mixed = [true, false, true, false, true, false, true, false];
        assert!((lacey(&cells, &mixed, 2).unwrap() - 4.0 / 3.0).abs() < 1e-12);
        // one label only, or a particle per cell: undefined
        assert_eq!(lacey(&cells, &[true; 8], 2), None);
        assert_eq!(lacey(&[0, 1], &[true, false], 2), None);
    }

    #[test]
    fn quantiles_are_weighted_by_volume() {
        let t = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(weighted_quantile(&t, &[1.0; 4], 0.5), 2.0);
        assert_eq!(weighted_quantile(&t, &[1.0; 4], 0.95), 4.0);
        assert_eq!(weighted_quantile(&t, &[1.0; 4], 0.05), 1.0);
        // the last particle holds most of the volume
        assert_eq!(weighted_quantile(&t, &[1.0, 1.0, 1.0, 7.0], 0.5), 4.0);
    }

    #[test]
    fn the_walls_heat_is_the_change_of_the_heat_content() {
        let info: RecordingInfo = serde_json::from_value(serde_json::json!({
            "format_version": 1, "tool_version": "x", "case_toml": "", "case_path": "",
            "case_resolved": {"drum": {"radius": 0.05}}, "particles": 2,
            "walls": [{"id": 2, "kind": "mantle", "temperature": 350.0}],
            "dt": 1e-4, "sample_every": 10, "dtc_max_steps": 100, "period_steps": 1000,
            "tau": 0.1, "t0": 0.0, "step_t0": 0, "reference_periods": 0,
            "area_encoding": "exact", "sqrt_area_unit": 0.0, "pair_conductivity": 1.0,
            "wall_conductivity": 1.0, "density": 1000.0, "heat_capacity": 1.0,
            "conductivity": 1.0
        }))
        .unwrap();
        let snap = |index: u32, temp: [f64; 2]| Snapshot {
            index,
            time: 0.1 * index as f64,
            id: vec![1, 0],
            pos: vec![[0.0; 3], [0.01, 0.0, 0.0]],
            radius: vec![0.01, 0.02],
            temp: temp.to_vec(),
            vel: vec![[0.0; 3]; 2],
        };
        let t0 = Snapshot {
            id: vec![0, 1],
            ..snap(0, [300.0, 300.0])
        };
        let m = Measures::new(&info, &t0, &t0, 200, 1);
        let snaps = vec![snap(1, [300.0, 300.0]), snap(2, [310.0, 301.0])];
        let (p, kept) = Prediction::new(&info, &m, 2, snaps.into_iter().map(Ok), Some(2)).unwrap();
        // the snapshot asked for is kept, and the field plot has the first and the last
        assert_eq!(kept.map(|s| s.index), Some(2));
        assert_eq!(p.fields.iter().map(|s| s.index).collect::<Vec<_>>(), [1, 2]);
        assert_eq!(p.drum_radius, Some(0.05));
        assert!(!p.has_groups());
        let c = |r: f64| 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let q = p.wall_heat().unwrap();
        assert_eq!(q.len(), 1);
        assert!((q[0].2 - (10.0 * c(0.01) + 1.0 * c(0.02))).abs() < 1e-12);
        // the bed mean is the volume-weighted one
        let bed = (310.0 + 8.0 * 301.0) / 9.0;
        assert!((p.last().bed - bed).abs() < 1e-9);
        assert_eq!((p.last().p05, p.last().p95), (301.0, 310.0));
    }
}
