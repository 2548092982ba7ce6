//! The error measures of Haydar et al. 2023 §3 on plain arrays: Voronoi cells, cell means,
//! `ε_abs`/`ε_rel` (Eq. 9), the energy-transfer error (Eq. 10) and hot/cold group means.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The Voronoi cells of the comparison: their seeds and a tree to find a point's cell.
pub struct Cells {
    pub seeds: Vec<[f64; 3]>,
    tree: ImmutableKdTree<f64, 3>,
}

impl Cells {
    pub fn from_seeds(seeds: Vec<[f64; 3]>) -> Self {
        let tree = tree_of(&seeds);
        Self { seeds, tree }
    }

    /// `v` seeds drawn uniformly inside the bed: uniform in the bounding box of `bed`
    /// (particle centres), kept when a particle centre lies within `reach` of the point,
    /// so no seed falls in the empty part of the drum. Deterministic in `seed`.
    pub fn inside_bed(bed: &[[f64; 3]], reach: f64, v: usize, seed: u64) -> Self {
        let bed_tree = tree_of(bed);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in bed {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut uniform = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let mut seeds = Vec::with_capacity(v);
        // A bed fills a good part of its own bounding box; the bound only guards against
        // a degenerate bed (acceptance would be ~0) looping forever.
        let max_draws = 1000 * v.max(1);
        let mut draws = 0;
        while seeds.len() < v && draws < max_draws {
            draws += 1;
            let x = std::array::from_fn(|a| lo[a] + uniform() * (hi[a] - lo[a]));
            let near = bed_tree
                .query(&x)
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            if near.distance <= reach * reach {
                seeds.push(x);
            }
        }
        Self::from_seeds(seeds)
    }

    pub fn len(&self) -> usize {
        self.seeds.len()
    }

    pub fn is_empty(&self) -> bool {
        self.seeds.is_empty()
    }

    /// The cell of each point (index of its nearest seed).
    pub fn assign(&self, points: &[[f64; 3]]) -> Vec<u32> {
        points
            .iter()
            .map(|p| {
                self.tree
                    .query(p)
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .item
            })
            .collect()
    }

    /// Mean temperature of each cell (`None`: no particle in it).
    pub fn means(&self, points: &[[f64; 3]], temps: &[f64]) -> Vec<Option<f64>> {
        cell_means(&self.assign(points), temps, self.len())
    }
}

/// A k-d tree over `points` (fewer than 2³² of them: particle ids are u32 in every tdex
/// file, and there are fewer seeds than particles).
fn tree_of(points: &[[f64; 3]]) -> ImmutableKdTree<f64, 3> {
    ImmutableKdTree::new_from_slice(points).expect("fewer than 2^32 points")
}

/// Mean of `temps` per cell, given each point's cell (`None` for an empty cell).
pub fn cell_means(cell_of: &[u32], temps: &[f64], cells: usize) -> Vec<Option<f64>> {
    let mut sum = vec![0.0; cells];
    let mut count = vec![0u32; cells];
    for (&c, &t) in cell_of.iter().zip(temps) {
        sum[c as usize] += t;
        count[c as usize] += 1;
    }
    sum.iter()
        .zip(&count)
        .map(|(&s, &n)| (n > 0).then(|| s / f64::from(n)))
        .collect()
}

/// `ε_abs = (1/v) Σ_i |T̄_DEM(i) − T̄_extra(i)|` over the cells that hold particles in
/// both fields; returns it and that count `v`. `None` if no cell is shared.
pub fn eps_abs(dem: &[Option<f64>], extra: &[Option<f64>]) -> Option<(f64, usize)> {
    let diffs: Vec<f64> = dem
        .iter()
        .zip(extra)
        .filter_map(|(d, e)| Some((d.as_ref()? - e.as_ref()?).abs()))
        .collect();
    (!diffs.is_empty()).then(|| (diffs.iter().sum::<f64>() / diffs.len() as f64, diffs.len()))
}

/// Eq. 10: `(Σ|T_{n+1} − T_n| − Σ|T'_{n+1} − T'_n|) / Σ|T_{n+1} − T_n|`, DEM (`T`) against
/// extrapolation (`T'`), each sum over particles followed by id. Positive when the
/// extrapolation transfers less than the DEM. `None` when the DEM transferred nothing.
pub fn energy_error(
    dem_before: &[f64],
    dem_after: &[f64],
    extra_before: &[f64],
    extra_after: &[f64],
) -> Option<f64> {
    let moved = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(x, y)| (y - x).abs()).sum() };
    let dem = moved(dem_before, dem_after);
    let extra = moved(extra_before, extra_after);
    (dem > 0.0).then(|| (dem - extra) / dem)
}

/// The initially hot and cold particles: above and below the midpoint of the temperature
/// range at `t0`. `None` if the bed starts at one temperature (no groups to follow).
pub fn hot_cold_groups(temps_t0: &[f64]) -> Option<(Vec<u32>, Vec<u32>)> {
    let lo = temps_t0.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = temps_t0.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // also None for NaN temperatures
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let mid = 0.5 * (lo + hi);
    let (hot, cold): (Vec<u32>, Vec<u32>) =
        (0..temps_t0.len() as u32).partition(|&p| temps_t0[p as usize] > mid);
    Some((hot, cold))
}

/// Mean of `temps` over the particles `group`.
pub fn group_mean(temps: &[f64], group: &[u32]) -> f64 {
    group.iter().map(|&p| temps[p as usize]).sum::<f64>() / group.len() as f64
}

/// The bed's mean temperature weighted by particle volume (`r³`): with one material, the
/// mean of the heat content, which only the walls change.
pub fn bed_mean(radius: &[f64], temps: &[f64]) -> f64 {
    let (heat, volume) = radius
        .iter()
        .zip(temps)
        .fold((0.0, 0.0), |(h, v), (&r, &t)| {
            (h + r * r * r * t, v + r * r * r)
        });
    heat / volume
}

/// Temperatures indexed by particle id from a snapshot whose point `j` is particle `id[j]`.
pub fn by_id(id: &[u32], temps: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; temps.len()];
    for (&p, &t) in id.iter().zip(temps) {
        out[p as usize] = t;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two seeds on the x axis; particles left of x = 0 belong to the first.
    fn two_cells() -> Cells {
        Cells::from_seeds(vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    }

    #[test]
    fn a_cell_has_the_mean_of_its_particles() {
        let cells = two_cells();
        let pos = [
            [-0.5, 0.0, 0.0],
            [-1.5, 0.2, 0.0],
            [0.7, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let temps = [10.0, 20.0, 30.0, 50.0];
        assert_eq!(cells.assign(&pos), vec![0, 0, 1, 1]);
        assert_eq!(cells.means(&pos, &temps), vec![Some(15.0), Some(40.0)]);
        // An empty cell has no mean and does not count in ε_abs.
        let third = Cells::from_seeds(vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [9.0, 9.0, 9.0]]);
        let m = third.means(&pos, &temps);
        assert_eq!(m[2], None);
        assert_eq!(
            eps_abs(&m, &[Some(14.0), Some(40.0), Some(3.0)]),
            Some((0.5, 2))
        );
    }

    #[test]
    fn swapping_the_particles_of_two_cells_gives_the_mean_difference() {
        let cells = two_cells();
        let pos = [
            [-1.0, 0.1, 0.0],
            [-0.9, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.9, 0.0, 0.0],
        ];
        let dem = [30.0, 30.0, 10.0, 10.0];
        // The extrapolation put the hot pair on the right: both cells are off by 20 K.
        let extra = [10.0, 10.0, 30.0, 30.0];
        let (e, v) = eps_abs(&cells.means(&pos, &dem), &cells.means(&pos, &extra)).unwrap();
        assert_eq!((e, v), (20.0, 2));
        // ε_rel against the DEM hot/cold means (30 − 10).
        let (hot, cold) = hot_cold_groups(&dem).unwrap();
        assert_eq!((hot.clone(), cold.clone()), (vec![0, 1], vec![2, 3]));
        assert_eq!(
            e / (group_mean(&dem, &hot) - group_mean(&dem, &cold)).abs(),
            1.0
        );
        // Swapping two particles within a cell changes nothing.
        let dem = [30.0, 20.0, 10.0, 0.0];
        let within = [20.0, 30.0, 0.0, 10.0];
        let (e, _) = eps_abs(&cells.means(&pos, &dem), &cells.means(&pos, &within)).unwrap();
        assert_eq!(e, 0.0);
    }

    #[test]
    fn energy_error_of_a_two_particle_system() {
        // DEM: 30/10 relax to 25/15: 5 + 5 = 10 K moved.
        let (before, dem_after) = ([30.0, 10.0], [25.0, 15.0]);
        // Extrapolation moves only 4 + 4: 20 % less transfer.
        assert!(
            (energy_error(&before, &dem_after, &before, &[26.0, 14.0]).unwrap() - 0.2).abs()
                < 1e-15
        );
        // Moving more is a negative error, exact agreement zero.
        assert!(
            (energy_error(&before, &dem_after, &before, &[24.0, 16.0]).unwrap() + 0.2).abs()
                < 1e-15
        );
        assert_eq!(
            energy_error(&before, &dem_after, &before, &dem_after),
            Some(0.0)
        );
        // Nothing moved in the DEM: no relative error.
        assert_eq!(energy_error(&before, &before, &before, &dem_after), None);
    }

    #[test]
    fn ids_reorder_and_uniform_beds_have_no_groups() {
        assert_eq!(by_id(&[2, 0, 1], &[7.0, 8.0, 9.0]), vec![8.0, 9.0, 7.0]);
        assert!(hot_cold_groups(&[300.0; 4]).is_none());
    }

    #[test]
    fn seeds_fall_inside_the_bed_and_depend_only_on_the_seed() {
        // A bed of 1 000 points in the lower half of a unit box.
        let mut s = 1u64;
        let bed: Vec<[f64; 3]> = (0..1000)
            .map(|_| {
                std::array::from_fn(|a| {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let u = (s >> 11) as f64 / (1u64 << 53) as f64;
                    if a == 2 {
                        0.5 * u
                    } else {
                        u
                    }
                })
            })
            .collect();
        let a = Cells::inside_bed(&bed, 0.05, 200, 7);
        let b = Cells::inside_bed(&bed, 0.05, 200, 7);
        let c = Cells::inside_bed(&bed, 0.05, 200, 8);
        assert_eq!(a.len(), 200);
        assert_eq!(a.seeds, b.seeds);
        assert_ne!(a.seeds, c.seeds);
        assert!(a.seeds.iter().all(|x| x[2] <= 0.5));
    }
}
