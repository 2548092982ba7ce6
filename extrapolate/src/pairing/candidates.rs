//! The sparse candidate graph: for every t1 point (row), its k nearest t0 points
//! (columns, found on a uniform grid of cells over the t0 points), plus the exit edges
//! and certificate pairs added since. Stored as compressed rows with the integer cost
//! of each edge. The graph only ever grows, so a warm-started solver never loses the
//! edges it stands on.

use kiddo::ImmutableKdTree;
use rayon::prelude::*;

use super::cost::{dist2, CostScale, EdgeCost};

/// k-d tree over t0 positions (the exit edges' nearest-one queries); items are t0
/// indices.
pub(crate) type Tree = ImmutableKdTree<f64, 3>;

/// Mean number of t0 points per occupied grid cell. A k-nearest query first reads the
/// 27 cells around its own ([`Grid::nearest_in_block`]); at 12 points a cell they hold
/// the 32 nearest for 99 % of the long kiln's queries. 8 and 12 were as fast, 16
/// slower; the shell search alone, before, was fastest at 1 (docs/benchmarks.md).
const POINTS_PER_CELL: f64 = 12.0;

/// The radius within which [`Grid::nearest_in_block`] first keeps points, in radii of
/// the ball that holds k points at the grid's mean density: on a packed bed 1.25 keeps
/// about twice k, so the second pass (every point of the block) is rare, while the
/// selection that follows stays short. 1.0 was slower (more second passes), 1.1 to 1.3
/// alike (docs/benchmarks.md).
const BLOCK_RADIUS: f64 = 1.25;

/// The t0 points bucketed in a uniform grid of cubic cells over their bounding box, for
/// the k-nearest queries of [`knn`]. On a packed bed the points fill the box's cells
/// evenly enough (a drum's bed fills part of its box: the empty cells cost a visit,
/// nothing more) that a query reads the few cells around it, where the k-d tree
/// walked down and back up a deep tree for every query (0.65 s for the long kiln's
/// 80 000 32-nearest queries on the shared 2-core machine, against about 0.3 s here).
pub(crate) struct Grid {
    lo: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    /// Points of cell c: `pts[start[c]..start[c + 1]]` (and their t0 indices in `idx`),
    /// cells in x-fastest order, points within a cell by index.
    start: Vec<u32>,
    pts: Vec<[f64; 3]>,
    idx: Vec<u32>,
    /// On a periodic section, the t0 index of each point ([`Images::of`]): the grid then
    /// holds the images, and only [`knn_images`] queries it.
    images: Option<Vec<u32>>,
}

impl Grid {
    /// The grid of a periodic section's t0 points and their images ([`Images`]).
    pub(crate) fn with_images(images: &Images) -> Self {
        Self {
            images: Some(images.of.clone()),
            ..Self::new(&images.pts)
        }
    }

    pub(crate) fn new(x0: &[[f64; 3]]) -> Self {
        let (lo, hi) = super::order::bounds(x0, &[]);
        let extent: [f64; 3] = std::array::from_fn(|a| (hi[a] - lo[a]).max(0.0));
        // At most ~8 cells per point in all, whatever the box's shape.
        let max_cells = 8 * x0.len().max(1);
        let dims_for = |cell: f64| -> [usize; 3] {
            std::array::from_fn(|a| ((extent[a] / cell).floor() as usize + 1).max(1))
        };
        let fit = |mut cell: f64| -> (f64, [usize; 3]) {
            if !(cell.is_finite() && cell > 0.0) {
                cell = extent.iter().copied().fold(0.0, f64::max).max(1.0);
            }
            let mut dims = dims_for(cell);
            while dims.iter().product::<usize>() > max_cells {
                cell *= 1.5;
                dims = dims_for(cell);
            }
            (cell, dims)
        };
        // Cells of volume POINTS_PER_CELL / density. The density is first that of the
        // box (degenerate axes, as in a flat or linear test bed, count with a sliver
        // of the largest extent), then that of the cells the points occupy: a drum's
        // bed fills a third of its box, where the box's density would put three times
        // too many points in every occupied cell.
        let big = extent.iter().copied().fold(0.0, f64::max);
        let volume: f64 = extent.iter().map(|&e| e.max(big * 1e-9)).product();
        let n = x0.len().max(1) as f64;
        let (coarse, coarse_dims) = fit((volume * POINTS_PER_CELL / n).cbrt());
        let mut occupied = vec![false; coarse_dims.iter().product::<usize>()];
        for p in x0 {
            let c: [usize; 3] = std::array::from_fn(|a| {
                (((p[a] - lo[a]) / coarse).floor().max(0.0) as usize).min(coarse_dims[a] - 1)
            });
            occupied[c[0] + coarse_dims[0] * (c[1] + coarse_dims[1] * c[2])] = true;
        }
        let filled = occupied.iter().filter(|&&o| o).count() as f64;
        let (cell, dims) = fit((filled * coarse.powi(3) * POINTS_PER_CELL / n).cbrt());
        let cells = dims.iter().product::<usize>();
        let mut grid = Self {
            lo,
            cell,
            dims,
            start: vec![0; cells + 1],
            pts: Vec::with_capacity(x0.len()),
            idx: Vec::with_capacity(x0.len()),
            images: None,
        };
        let of: Vec<u32> = x0.iter().map(|p| grid.cell_of(p) as u32).collect();
        for &c in &of {
            grid.start[c as usize + 1] += 1;
        }
        for c in 0..cells {
            grid.start[c + 1] += grid.start[c];
        }
        let mut fill = grid.start.clone();
        grid.pts.resize(x0.len(), [0.0; 3]);
        grid.idx.resize(x0.len(), 0);
        for (i, &c) in of.iter().enumerate() {
            let slot = fill[c as usize] as usize;
            fill[c as usize] += 1;
            grid.pts[slot] = x0[i];
            grid.idx[slot] = i as u32;
        }
        grid
    }

    /// Cell coordinates of a position, clamped to the grid.
    #[inline]
    fn coords(&self, p: &[f64; 3]) -> [usize; 3] {
        std::array::from_fn(|a| {
            let c = ((p[a] - self.lo[a]) / self.cell).floor();
            if c <= 0.0 {
                0
            } else {
                (c as usize).min(self.dims[a] - 1)
            }
        })
    }

    #[inline]
    fn cell_of(&self, p: &[f64; 3]) -> usize {
        let c = self.coords(p);
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The k nearest points to `q` by squared distance, ties to the lower index,
    /// as (squared distance, t0 index), in `best` (cleared first; k <= number of
    /// points), in no particular order. Reads the cubes of cells of growing half-width
    /// around q's cell until the k-th distance is within the cube (every cell outside
    /// it lies further away).
    ///
    /// The points nearer than the k-th so far are gathered unsorted and cut back to
    /// the k nearest by a selection whenever 2k are held and at the end of every
    /// cube: keeping them sorted (an insertion per point) was a quarter of the query.
    fn nearest(&self, q: &[f64; 3], k: usize, best: &mut Vec<(f64, u32)>) {
        best.clear();
        // The k-th nearest so far, once k are held.
        let mut kth: Option<(f64, u32)> = None;
        let c = self.coords(q);
        let max_r = self.dims.iter().copied().max().unwrap_or(1);
        for r in 0..=max_r {
            // The shell of half-width r: cells with Chebyshev distance r from c.
            let lo: [isize; 3] = std::array::from_fn(|a| c[a] as isize - r as isize);
            let hi: [isize; 3] = std::array::from_fn(|a| c[a] as isize + r as isize);
            for z in lo[2].max(0)..=hi[2].min(self.dims[2] as isize - 1) {
                for y in lo[1].max(0)..=hi[1].min(self.dims[1] as isize - 1) {
                    let on_yz = z == lo[2] || z == hi[2] || y == lo[1] || y == hi[1];
                    let row = self.dims[0] * (y as usize + self.dims[1] * z as usize);
                    let mut visit = |x: isize| {
                        let cell = row + x as usize;
                        let (a, b) = (self.start[cell] as usize, self.start[cell + 1] as usize);
                        for t in a..b {
                            let e = (dist2(q, &self.pts[t]), self.idx[t]);
                            if kth.is_none_or(|m| nearer(&e, &m)) {
                                best.push(e);
                                if best.len() == 2 * k {
                                    kth = Some(keep_nearest(best, k));
                                }
                            }
                        }
                    };
                    if on_yz {
                        for x in lo[0].max(0)..=hi[0].min(self.dims[0] as isize - 1) {
                            visit(x);
                        }
                    } else {
                        for x in [lo[0], hi[0]] {
                            if x >= 0 && x < self.dims[0] as isize {
                                visit(x);
                            }
                        }
                    }
                }
            }
            if best.len() >= k {
                let kth = *kth.insert(keep_nearest(best, k));
                // Distance from q to the outside of the cube of half-width r (an
                // axis whose cube reaches the grid's edge on a side has nothing
                // beyond it on that side).
                let mut reach = f64::INFINITY;
                for a in 0..3 {
                    if lo[a] > 0 {
                        reach = reach.min(q[a] - (self.lo[a] + lo[a] as f64 * self.cell));
                    }
                    if hi[a] < self.dims[a] as isize - 1 {
                        reach = reach.min(self.lo[a] + (hi[a] + 1) as f64 * self.cell - q[a]);
                    }
                }
                // A margin far above the rounding of the cell boundaries, far below
                // any spacing of real points.
                let reach = reach - 1e-9 * self.cell;
                if reach == f64::INFINITY || (reach > 0.0 && kth.0 < reach * reach) {
                    return;
                }
            }
        }
    }
}

/// The 27 cells around one grid cell, as the nine runs of cells (each run three cells
/// along x, contiguous in the grid's arrays) that hold their points, kept from query
/// to query: consecutive rows are near in Morton order and share a cell about half
/// the time on the long kiln.
struct Block {
    /// The grid cell the runs surround (`usize::MAX`: none yet).
    cell: usize,
    /// Every t0 point inside the box `[lo, hi]` is in the runs (an infinite side: no
    /// point lies beyond the runs on that side).
    lo: [f64; 3],
    hi: [f64; 3],
    /// Point ranges `start..end` in the grid's `pts` and `idx`.
    runs: Vec<(u32, u32)>,
    /// Scratch for the points within the kept radius.
    near: Vec<(f64, u32)>,
}

impl Block {
    fn new() -> Self {
        Self {
            cell: usize::MAX,
            lo: [0.0; 3],
            hi: [0.0; 3],
            runs: Vec::with_capacity(9),
            near: Vec::new(),
        }
    }
}

impl Grid {
    /// Square of [`BLOCK_RADIUS`] times the radius of a ball holding k points at the
    /// grid's mean density (POINTS_PER_CELL per cell).
    fn block_radius2(&self, k: usize) -> f64 {
        let volume = k as f64 * self.cell.powi(3) / POINTS_PER_CELL;
        (BLOCK_RADIUS * (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt()).powi(2)
    }

    /// The k nearest points to `q` as [`Grid::nearest`] finds them, from the 27 cells
    /// around q's cell alone, when those provably hold them; false (and `best`
    /// unspecified) when they may not.
    ///
    /// Every point nearer to q than the block's outside (`reach`) is in the block. A
    /// first pass keeps the block's points within `radius2.sqrt()` (or `reach`, if
    /// nearer): if there are k or more, the k nearest of them are the k nearest of all.
    /// Otherwise a second pass keeps every point within `reach`, and fewer than k then
    /// means the answer may lie outside. The passes read the runs straight through and
    /// keep a point by advancing a count, not by a branch: where the cut falls is
    /// unpredictable, and the shell search's branches and per-cell loops were most of
    /// its time (docs/benchmarks.md).
    fn nearest_in_block(
        &self,
        q: &[f64; 3],
        k: usize,
        radius2: f64,
        block: &mut Block,
        best: &mut Vec<(f64, u32)>,
    ) -> bool {
        if !q.iter().all(|x| x.is_finite()) {
            return false; // the shell search decides
        }
        let c = self.coords(q);
        let cell = c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2]);
        if cell != block.cell {
            block.cell = cell;
            block.runs.clear();
            // Cells exist beyond the block's below c − 1 only if c ≥ 2, above c + 1 only
            // if c + 2 is a cell.
            block.lo = std::array::from_fn(|a| {
                if c[a] >= 2 {
                    self.lo[a] + (c[a] - 1) as f64 * self.cell
                } else {
                    f64::NEG_INFINITY
                }
            });
            block.hi = std::array::from_fn(|a| {
                if c[a] + 2 < self.dims[a] {
                    self.lo[a] + (c[a] + 2) as f64 * self.cell
                } else {
                    f64::INFINITY
                }
            });
            let (x_lo, x_hi) = (c[0].saturating_sub(1), (c[0] + 1).min(self.dims[0] - 1));
            for z in c[2].saturating_sub(1)..=(c[2] + 1).min(self.dims[2] - 1) {
                for y in c[1].saturating_sub(1)..=(c[1] + 1).min(self.dims[1] - 1) {
                    let row = self.dims[0] * (y + self.dims[1] * z);
                    let run = (self.start[row + x_lo], self.start[row + x_hi + 1]);
                    if run.0 < run.1 {
                        block.runs.push(run);
                    }
                }
            }
        }
        let reach = (0..3)
            .map(|a| (q[a] - block.lo[a]).min(block.hi[a] - q[a]))
            .fold(f64::INFINITY, f64::min);
        // The same margin as the shell search's.
        let reach = reach - 1e-9 * self.cell;
        if reach <= 0.0 {
            return false; // not reached: rounding at a cell's face
        }
        let reach2 = reach * reach;
        let held: usize = block.runs.iter().map(|&(a, b)| (b - a) as usize).sum();
        if block.near.len() <= held {
            block.near.resize(held + 1, (0.0, 0));
        }
        let mut within2 = radius2.min(reach2);
        let kept = loop {
            let mut kept = 0usize;
            for &(a, b) in &block.runs {
                let (a, b) = (a as usize, b as usize);
                for (p, &i) in self.pts[a..b].iter().zip(&self.idx[a..b]) {
                    let d = dist2(q, p);
                    block.near[kept] = (d, i);
                    kept += usize::from(d < within2);
                }
            }
            if kept >= k {
                break kept;
            }
            if within2 >= reach2 {
                return false;
            }
            within2 = reach2;
        };
        best.clear();
        best.extend_from_slice(&block.near[..kept]);
        keep_nearest(best, k);
        true
    }
}

/// The order of the nearest: squared distance, ties to the lower index.
#[inline]
fn order(a: &(f64, u32), b: &(f64, u32)) -> std::cmp::Ordering {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
}

/// `a` comes before `b` in [`order`].
#[inline]
fn nearer(a: &(f64, u32), b: &(f64, u32)) -> bool {
    order(a, b).is_lt()
}

/// Cuts `best` (at least k entries) back to its k nearest; returns the k-th.
fn keep_nearest(best: &mut Vec<(f64, u32)>, k: usize) -> (f64, u32) {
    best.select_nth_unstable_by(k - 1, order);
    best.truncate(k);
    best[k - 1]
}

/// The k nearest t0 points of every t1 point's query centre, as a flat row-major array
/// (`k` entries per row) of column indices and the matching integer costs. Within a
/// row, entries are ordered by (cost, column); the nearest are chosen by squared
/// distance, ties to the lower index, so the result never depends on the number of
/// threads.
pub(crate) fn knn(
    grid: &Grid,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    centres: &[[f64; 3]],
    k: usize,
    scale: &CostScale,
) -> (Vec<u32>, Vec<EdgeCost>) {
    let n = x1.len();
    let k = k.clamp(1, x0.len());
    let mut cols = vec![0u32; n * k];
    let mut costs: Vec<EdgeCost> = vec![0; n * k];
    let radius2 = grid.block_radius2(k);
    // Each row writes only its own k-slot chunk: embarrassingly parallel and
    // deterministic (no collection order to worry about; both searches give the same
    // k nearest).
    cols.par_chunks_mut(k)
        .zip(costs.par_chunks_mut(k))
        .enumerate()
        .with_min_len(256)
        .for_each_init(
            || {
                (
                    Vec::with_capacity(2 * k),
                    Vec::with_capacity(k),
                    Block::new(),
                )
            },
            |(found, row, block), (p, (cc, cs))| {
                if !grid.nearest_in_block(&centres[p], k, radius2, block, found) {
                    grid.nearest(&centres[p], k, found);
                }
                row.clear();
                row.extend(
                    found
                        .iter()
                        .map(|&(_, q)| (scale.edge_cost(&x1[p], &x0[q as usize]), q)),
                );
                row.sort_unstable();
                debug_assert_eq!(row.len(), k);
                for (s, &(c, q)) in row.iter().enumerate() {
                    cc[s] = q;
                    cs[s] = c;
                }
            },
        );
    (cols, costs)
}

/// The t0 points of a periodic section and their images one period away along y on
/// either side: the points the candidate search and the certificate's radius queries run
/// on. `of[t]` is the t0 index of point `t` (images carry their original's index, and
/// hence its potential).
///
/// With every position in `[−L/2, L/2]`, `|Δy| <= L` for every pair, so the nearest image
/// of `x0[q]` seen from any t1 point is `x0[q]` shifted by `−L`, 0 or `+L`: every pair's
/// periodic distance is the Euclidean distance to one of these points (up to the rounding
/// of `y ± L`, a few ulps of `L`, far below the one cost unit of slack the certificate
/// keeps). The periodic distance is the minimum over the images, so no image is nearer.
pub(crate) struct Images {
    pub(crate) pts: Vec<[f64; 3]>,
    pub(crate) of: Vec<u32>,
}

impl Images {
    /// `x0`, then `x0` shifted by `+period` along y, then by `−period`.
    pub(crate) fn of(x0: &[[f64; 3]], period: f64) -> Self {
        let n = x0.len();
        let mut pts = Vec::with_capacity(3 * n);
        pts.extend_from_slice(x0);
        for shift in [period, -period] {
            pts.extend(x0.iter().map(|&[x, y, z]| [x, y + shift, z]));
        }
        let of = (0..3).flat_map(|_| 0..n as u32).collect();
        Self { pts, of }
    }
}

/// [`knn`] on a periodic section: the k nearest of `grid`'s points (built by
/// [`Grid::with_images`]) to every query centre, each taken to its t0 index `images[t]` and
/// costed with the periodic distance from the t0 point itself, so that an edge costs the
/// same whichever image found it. Two images of one t0 point can both be among a row's k
/// nearest (a section a few k-th neighbour distances long): the row keeps the column once
/// (its cost is the same), so rows hold at most k edges. Rows sorted by (cost, column).
pub(crate) fn knn_images(
    grid: &Grid,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    centres: &[[f64; 3]],
    k: usize,
    scale: &CostScale,
) -> Graph {
    let images: &[u32] = grid.images.as_deref().unwrap_or(&[]);
    let k = k.clamp(1, images.len());
    let radius2 = grid.block_radius2(k);
    let rows: Vec<Vec<(EdgeCost, u32)>> = (0..x1.len())
        .into_par_iter()
        .with_min_len(256)
        .map_init(
            || (Vec::with_capacity(2 * k), Block::new()),
            |(found, block), p| {
                if !grid.nearest_in_block(&centres[p], k, radius2, block, found) {
                    grid.nearest(&centres[p], k, found);
                }
                let mut row: Vec<(EdgeCost, u32)> = found
                    .iter()
                    .map(|&(_, t)| {
                        let q = images[t as usize];
                        (scale.edge_cost(&x1[p], &x0[q as usize]), q)
                    })
                    .collect();
                row.sort_unstable();
                row.dedup();
                row
            },
        )
        .collect();
    Graph::from_rows(&rows)
}

/// Mean cost of the cheapest of the k candidates of every `stride`-th row (rows 0,
/// stride, 2·stride, …): the mean cheapest candidate cost of the k-graph, estimated from a
/// fixed sample of its rows without building the graph. With `stride = 1` it is exactly
/// that mean.
pub(crate) fn mean_cheapest_sampled(
    grid: &Grid,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    centres: &[[f64; 3]],
    k: usize,
    stride: usize,
    scale: &CostScale,
) -> f64 {
    let (rows, row_centres): (Vec<[f64; 3]>, Vec<[f64; 3]>) = x1
        .iter()
        .zip(centres)
        .step_by(stride.max(1))
        .map(|(p, c)| (*p, *c))
        .unzip();
    if grid.images.is_some() {
        let graph = knn_images(grid, x0, &rows, &row_centres, k, scale);
        // Each row's entries are sorted by cost: the first is its cheapest.
        let sum: u64 = (0..graph.rows())
            .map(|p| u64::from(graph.row(p).1[0]))
            .sum();
        return sum as f64 / rows.len().max(1) as f64;
    }
    let k = k.clamp(1, x0.len());
    let (_, costs) = knn(grid, x0, &rows, &row_centres, k, scale);
    // Each row's entries are sorted by cost: the first is its cheapest.
    let sum: u64 = costs.chunks(k).map(|row| u64::from(row[0])).sum();
    sum as f64 / rows.len().max(1) as f64
}

/// Half-width, in ranks, of the window over which the axial transport estimate of
/// [`Axial`] is averaged.
const AXIAL_WINDOW: usize = 64;

/// The one-dimensional transport along the bed's long axis, an estimate of the
/// large-scale part of the pairing (docs/pairing.md#long-drums).
///
/// In a long drum the particles drift along the axis, and the count of particles on
/// either side of a cross-section differs between t0 and t1 by hundreds: the optimal
/// pairing then shifts whole slabs of the bed by a diameter or more along the axis.
/// A t1 point's optimal partner then often lies outside its k nearest t0 points (the
/// kNN graph may even lose its perfect matching), and both the auction and the
/// shortest augmenting paths have to carry the surplus along the whole bed. The
/// monotone map between the two marginals along the axis (rank r of t1 to rank r of
/// t0) is that transport in one dimension; its displacement `δ` (t1 → t0), averaged
/// over `2·AXIAL_WINDOW + 1` ranks, gives the kNN query centres and warm-start
/// potentials. Neither changes the problem: costs stay those of the true pairs, the
/// solver accepts any starting potentials `<= 0`, and the certificate proves the
/// result against every pair as before. Deterministic: the sorts break ties by index.
pub(crate) struct Axial {
    axis: usize,
    /// t0 and t1 indices sorted along the axis.
    s0: Vec<u32>,
    s1: Vec<u32>,
    /// Smoothed displacement t1 → t0 along the axis, by rank.
    delta: Vec<f64>,
}

impl Axial {
    pub(crate) fn new(x0: &[[f64; 3]], x1: &[[f64; 3]]) -> Self {
        let n = x1.len();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in x0.iter().chain(x1) {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
            .expect("three axes");
        let sorted = |x: &[[f64; 3]]| {
            let mut idx: Vec<u32> = (0..x.len() as u32).collect();
            idx.sort_unstable_by(|&i, &j| {
                x[i as usize][axis]
                    .total_cmp(&x[j as usize][axis])
                    .then(i.cmp(&j))
            });
            idx
        };
        let (s0, s1) = (sorted(x0), sorted(x1));
        // Prefix sums of the displacement by rank, then a centred moving average.
        let mut prefix = vec![0.0f64; n + 1];
        for r in 0..n {
            prefix[r + 1] = prefix[r] + (x0[s0[r] as usize][axis] - x1[s1[r] as usize][axis]);
        }
        let delta = (0..n)
            .map(|r| {
                let (a, b) = (
                    r.saturating_sub(AXIAL_WINDOW),
                    (r + AXIAL_WINDOW + 1).min(n),
                );
                (prefix[b] - prefix[a]) / (b - a) as f64
            })
            .collect();
        Self {
            axis,
            s0,
            s1,
            delta,
        }
    }

    /// The t0 and t1 indices sorted along the axis.
    pub(crate) fn sorted(&self) -> (&[u32], &[u32]) {
        (&self.s0, &self.s1)
    }

    /// Extent of the t0 points along the axis.
    pub(crate) fn length(&self, x0: &[[f64; 3]]) -> f64 {
        match (self.s0.first(), self.s0.last()) {
            (Some(&a), Some(&b)) => x0[b as usize][self.axis] - x0[a as usize][self.axis],
            _ => 0.0,
        }
    }

    /// Mean |δ|, in the units of the coordinates.
    pub(crate) fn mean_abs_shift(&self) -> f64 {
        self.delta.iter().map(|d| d.abs()).sum::<f64>() / self.delta.len().max(1) as f64
    }

    /// kNN query centres: every t1 point moved along the axis by `δ` at its rank.
    pub(crate) fn centres(&self, x1: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut c = x1.to_vec();
        for (r, &p) in self.s1.iter().enumerate() {
            c[p as usize][self.axis] += self.delta[r];
        }
        c
    }

    /// Warm-start column potentials `v = −(Φ − min Φ) / unit` (integers, `max v = 0`),
    /// with `Φ' = −δ / sqrt(ρ² + δ²)` along the t0 points in axis order (δ at the same
    /// rank). A row p whose partner lies `δ` further along the axis at a lateral
    /// distance ρ then finds its smallest `c − v` there: the derivative of
    /// `sqrt(ρ² + (y − y_p)²) + Φ(y)` vanishes at `y − y_p = δ`. `rho` is the typical
    /// pair distance (the mean cheapest candidate cost).
    pub(crate) fn potentials(&self, x0: &[[f64; 3]], rho: f64, unit: f64) -> Vec<i64> {
        let n = x0.len();
        let mut phi = vec![0.0f64; n];
        let mut acc = 0.0;
        for r in 1..n {
            let d = self.delta[r];
            let norm = (rho * rho + d * d).sqrt();
            let slope = if norm > 0.0 { -d / norm } else { 0.0 };
            let (q, q_prev) = (self.s0[r] as usize, self.s0[r - 1] as usize);
            acc += slope * (x0[q][self.axis] - x0[q_prev][self.axis]);
            phi[q] = acc;
        }
        let pmin = phi.iter().copied().fold(f64::INFINITY, f64::min);
        phi.iter()
            .map(|&f| -((f - pmin) / unit).round() as i64)
            .collect()
    }
}

/// Compressed sparse rows: row `p`'s edges are `cols[offsets[p]..offsets[p + 1]]` with
/// costs `costs[..]` at the same positions.
#[derive(Debug, Default)]
pub(crate) struct Graph {
    pub(crate) offsets: Vec<usize>,
    pub(crate) cols: Vec<u32>,
    pub(crate) costs: Vec<EdgeCost>,
    /// The arrays [`Graph::insert`] writes the next graph into, then swaps in: their
    /// allocations are kept, since fresh ones (24 MB at 80 000 rows and k = 32) cost
    /// more in page faults than the copy itself.
    spare_cols: Vec<u32>,
    spare_costs: Vec<EdgeCost>,
}

impl Graph {
    /// The graph of the kNN lists (`k` entries per row, as [`knn`] returns them), taking
    /// their arrays over.
    pub(crate) fn from_knn(k: usize, knn_cols: Vec<u32>, knn_costs: Vec<EdgeCost>) -> Self {
        debug_assert_eq!(knn_cols.len(), knn_costs.len());
        let rows = knn_cols.len() / k.max(1);
        Self {
            offsets: (0..=rows).map(|p| p * k).collect(),
            cols: knn_cols,
            costs: knn_costs,
            spare_cols: Vec::new(),
            spare_costs: Vec::new(),
        }
    }

    /// The graph of rows of (cost, column) edges, each row in the order given.
    pub(crate) fn from_rows(rows: &[Vec<(EdgeCost, u32)>]) -> Self {
        let mut offsets = Vec::with_capacity(rows.len() + 1);
        offsets.push(0);
        let total: usize = rows.iter().map(Vec::len).sum();
        let (mut cols, mut costs) = (Vec::with_capacity(total), Vec::with_capacity(total));
        for row in rows {
            for &(c, q) in row {
                costs.push(c);
                cols.push(q);
            }
            offsets.push(cols.len());
        }
        Self {
            offsets,
            cols,
            costs,
            spare_cols: Vec::new(),
            spare_costs: Vec::new(),
        }
    }

    /// Number of rows.
    pub(crate) fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of edges.
    pub(crate) fn edges(&self) -> usize {
        self.cols.len()
    }

    /// How local the rows are in memory, for the trace: the mean over rows of the span
    /// of their column indices (largest less smallest) and of the number of distinct
    /// 64-byte lines their columns occupy in an array of 8 bytes per column (the
    /// auction's potentials). A bid or a Dijkstra scan waits on those lines, so the
    /// renumbering (`order.rs`) is judged by them
    /// (docs/benchmarks.md#what-each-accepted-change-bought).
    pub(crate) fn locality(&self) -> (f64, f64) {
        let (span, lines) = (0..self.rows())
            .into_par_iter()
            .map(|p| {
                let cols = self.row(p).0;
                let (Some(lo), Some(hi)) = (cols.iter().min(), cols.iter().max()) else {
                    return (0u64, 0u64);
                };
                let mut line: Vec<u32> = cols.iter().map(|&q| q / 8).collect();
                line.sort_unstable();
                line.dedup();
                (u64::from(hi - lo), line.len() as u64)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        let rows = self.rows().max(1) as f64;
        (span as f64 / rows, lines as f64 / rows)
    }

    /// The edges of row `p`: columns and costs.
    #[inline]
    pub(crate) fn row(&self, p: usize) -> (&[u32], &[EdgeCost]) {
        let (a, b) = (self.offsets[p], self.offsets[p + 1]);
        (&self.cols[a..b], &self.costs[a..b])
    }

    /// Adds `edges` (sorted by row then column; those already in the graph, or repeated,
    /// are skipped), each appended to its row with its cost; returns how many were new.
    /// The rows between two touched rows move as one block, and only the new edges are
    /// costed and looked up in their row: a repair round that adds 18 edges to the long
    /// kiln's 3·10⁶ costs a copy, where merging every extra edge into the kNN lists again
    /// cost 7 ms a round.
    pub(crate) fn insert(
        &mut self,
        edges: &[(u32, u32)],
        x0: &[[f64; 3]],
        x1: &[[f64; 3]],
        scale: &CostScale,
    ) -> usize {
        debug_assert!(edges.is_sorted());
        if edges.is_empty() {
            return 0;
        }
        let n = self.rows();
        let (mut cols, mut costs) = (
            std::mem::take(&mut self.spare_cols),
            std::mem::take(&mut self.spare_costs),
        );
        cols.clear();
        costs.clear();
        cols.reserve(self.cols.len() + edges.len());
        costs.reserve(self.cols.len() + edges.len());
        // Rows [copied, p] move as one block. `offsets` is shifted in place: entries
        // below `copied` are already the new graph's, the others still the old one's
        // (which the block copy reads), and the start of every row in the block moves by
        // the edges added before it.
        let (mut copied, mut added, mut e) = (0usize, 0usize, 0usize);
        while e < edges.len() {
            let p = edges[e].0 as usize;
            let (a, b) = (self.offsets[copied], self.offsets[p + 1]);
            cols.extend_from_slice(&self.cols[a..b]);
            costs.extend_from_slice(&self.costs[a..b]);
            for r in copied..=p {
                self.offsets[r] += added;
            }
            let row_start = self.offsets[p];
            while e < edges.len() && edges[e].0 as usize == p {
                let q = edges[e].1;
                // A row holds a few dozen edges: a linear scan beats any set structure.
                if !cols[row_start..].contains(&q) {
                    cols.push(q);
                    costs.push(scale.edge_cost(&x1[p], &x0[q as usize]));
                    added += 1;
                }
                e += 1;
            }
            copied = p + 1;
        }
        let a = self.offsets[copied];
        cols.extend_from_slice(&self.cols[a..]);
        costs.extend_from_slice(&self.costs[a..]);
        for r in copied..=n {
            self.offsets[r] += added;
        }
        debug_assert_eq!(self.offsets[n], cols.len());
        self.spare_cols = std::mem::replace(&mut self.cols, cols);
        self.spare_costs = std::mem::replace(&mut self.costs, costs);
        added
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knn_rows_are_sorted_and_exact() {
        let x0: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 0.0, 0.0]).collect();
        let x1 = vec![[10.2, 0.0, 0.0], [-3.0, 0.0, 0.0]];
        let scale = CostScale::new(&x0, &x1, 1e-3).unwrap();
        let grid = Grid::new(&x0);
        let (c, w) = knn(&grid, &x0, &x1, &x1, 3, &scale);
        assert_eq!(&c[..3], &[10, 11, 9]);
        assert_eq!(&w[..3], &[200, 800, 1200]);
        assert_eq!(&c[3..], &[0, 1, 2]);
        let mut g = Graph::from_knn(3, c, w);
        assert_eq!(g.insert(&[(1, 2), (1, 30), (1, 40)], &x0, &x1, &scale), 2);
        assert_eq!(g.row(0).0, &[10, 11, 9]);
        assert_eq!(g.row(1).0, &[0, 1, 2, 30, 40]);
        assert_eq!(g.row(1).1[4], 43000);
        assert_eq!(g.edges(), 8);
        assert_eq!(g.rows(), 2);
    }

    /// Edges inserted batch after batch (touching the first row, the last, neighbours,
    /// repeats, edges already present) give every row its old edges in order, then its
    /// new ones in the order they came, each once, with its cost.
    #[test]
    fn inserted_edges_join_their_rows_once() {
        let mut rnd = super::super::test_uniform(2024);
        let (n, k) = (40usize, 4usize);
        let x0: Vec<[f64; 3]> = (0..n).map(|_| [rnd(), rnd(), rnd()]).collect();
        let x1: Vec<[f64; 3]> = (0..n).map(|_| [rnd(), rnd(), rnd()]).collect();
        let scale = CostScale::new(&x0, &x1, 1e-6).unwrap();
        let (c, w) = knn(&Grid::new(&x0), &x0, &x1, &x1, k, &scale);
        let mut want: Vec<Vec<u32>> = c.chunks(k).map(<[u32]>::to_vec).collect();
        let mut g = Graph::from_knn(k, c, w);
        for batch in 0..30 {
            let mut edges: Vec<(u32, u32)> = (0..[0, 1, 3, 25][batch % 4])
                .map(|_| ((rnd() * n as f64) as u32, (rnd() * n as f64) as u32))
                .collect();
            if batch % 5 == 1 {
                edges.extend([(0, 7), (0, 7), (n as u32 - 1, 3), (n as u32 - 1, 3)]);
            }
            edges.sort_unstable();
            let mut added = 0;
            for &(p, q) in &edges {
                if !want[p as usize].contains(&q) {
                    want[p as usize].push(q);
                    added += 1;
                }
            }
            assert_eq!(g.insert(&edges, &x0, &x1, &scale), added, "batch {batch}");
            assert_eq!(g.rows(), n);
            for (p, cols) in want.iter().enumerate() {
                let (gc, gw) = g.row(p);
                assert_eq!(gc, &cols[..], "batch {batch}, row {p}");
                for (&q, &cost) in gc.iter().zip(gw) {
                    assert_eq!(cost, scale.edge_cost(&x1[p], &x0[q as usize]));
                }
            }
        }
    }

    /// Two rows of three columns: 0, 7, 8 span 8 indices on two lines of eight
    /// columns; 100, 101, 102 span 2 on one.
    #[test]
    fn locality_counts_spans_and_lines() {
        let g = Graph::from_knn(3, vec![0, 7, 8, 100, 101, 102], vec![1; 6]);
        assert_eq!(g.locality(), (5.0, 1.5));
    }

    /// The grid's k nearest are the brute force's (by squared distance, ties to the
    /// lower index) for queries inside and outside the points' box, on a bulk bed, a
    /// flat one, a line and a lattice with exact ties: the shell search always, the
    /// block search whenever it answers (with its first radius, and with none, which
    /// forces its second pass), and it answers for most queries of the bulk bed.
    #[test]
    fn grid_nearest_matches_brute_force() {
        let mut rnd = super::super::test_uniform(77);
        let bulk: Vec<[f64; 3]> = (0..900).map(|_| [rnd(), 3.0 * rnd(), rnd()]).collect();
        let flat: Vec<[f64; 3]> = (0..300).map(|_| [rnd(), rnd(), 0.5]).collect();
        let line: Vec<[f64; 3]> = (0..200).map(|_| [0.0, 10.0 * rnd(), 0.0]).collect();
        let lattice: Vec<[f64; 3]> = (0..343)
            .map(|i| [(i % 7) as f64, ((i / 7) % 7) as f64, (i / 49) as f64])
            .collect();
        let one = vec![[1.0, 2.0, 3.0]; 5];
        for (bed, x0) in [bulk, flat, line, lattice, one].into_iter().enumerate() {
            let grid = Grid::new(&x0);
            let mut best = Vec::new();
            let mut block = Block::new();
            let (mut asked, mut answered) = (0, 0);
            for t in 0..60 {
                let q = if t % 3 == 0 {
                    x0[t % x0.len()]
                } else {
                    [8.0 * rnd() - 2.0, 14.0 * rnd() - 2.0, 8.0 * rnd() - 2.0]
                };
                for k in [1, 3, 24, x0.len()] {
                    let k = k.min(x0.len());
                    grid.nearest(&q, k, &mut best);
                    best.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    let mut all: Vec<(f64, u32)> = x0
                        .iter()
                        .enumerate()
                        .map(|(i, p)| (dist2(&q, p), i as u32))
                        .collect();
                    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    all.truncate(k);
                    assert_eq!(best, all, "k {k}, query {q:?}");
                    // Queries at the bed's own points, with k below the whole bed: the
                    // case the block is for.
                    let typical = t % 3 == 0 && k <= 24;
                    for radius2 in [grid.block_radius2(k), 0.0] {
                        asked += usize::from(typical);
                        if grid.nearest_in_block(&q, k, radius2, &mut block, &mut best) {
                            answered += usize::from(typical);
                            best.sort_by(order);
                            assert_eq!(best, all, "block, k {k}, r² {radius2}, query {q:?}");
                        }
                    }
                }
            }
            if bed == 0 {
                assert!(
                    2 * answered > asked,
                    "the block answered {answered} of {asked} queries at the bed's points"
                );
            }
        }
    }

    /// With every row sampled, the estimate is the graph's own mean cheapest cost; a
    /// sparser sample stays near it on a bed whose rows are alike.
    #[test]
    fn the_sampled_mean_cheapest_cost_is_the_graphs_with_every_row() {
        let lattice = |shift: f64| -> Vec<[f64; 3]> {
            (0..400)
                .map(|i| {
                    let (a, b, c) = ((i % 7) as f64, ((i / 7) % 7) as f64, (i / 49) as f64);
                    [
                        a + 0.31 * (i % 3) as f64,
                        b + shift,
                        c + 0.17 * (i % 5) as f64,
                    ]
                })
                .collect()
        };
        let (x0, x1) = (lattice(0.0), lattice(0.6));
        let scale = CostScale::new(&x0, &x1, 1e-3).unwrap();
        let grid = Grid::new(&x0);
        for centres in [x1.clone(), lattice(-1.4)] {
            for k in [1, 4, 24] {
                let (c, w) = knn(&grid, &x0, &x1, &centres, k, &scale);
                let g = Graph::from_knn(k, c, w);
                let whole = crate::pairing::sparse_lap::Cheapest::of(&g).mean();
                let every = mean_cheapest_sampled(&grid, &x0, &x1, &centres, k, 1, &scale);
                assert_eq!(every, whole, "k {k}");
                let sampled = mean_cheapest_sampled(&grid, &x0, &x1, &centres, k, 7, &scale);
                assert!(
                    (sampled - whole).abs() < 0.2 * whole,
                    "k {k}: {sampled} vs {whole}"
                );
            }
        }
    }
}
