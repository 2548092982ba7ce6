//! Optimality certificate against every pair left out of the candidate graph.
//!
//! The sparse solution is optimal on the candidate graph, with integer potentials
//! `u` (rows, t1) and `v` (columns, t0) such that `c(p, q) − u[p] − v[q] >= 0` on every
//! candidate edge and `= 0` on matched edges. If the same inequality holds for *all*
//! n² pairs, LP duality makes the matching optimal for the complete problem.
//!
//! A pair (p, q) violates it iff `c(p, q) < u[p] + v[q]`. Costs and potentials are
//! integers, so then `c <= u[p] + v[q] − 1`, and `c = round(d / unit) >= d / unit − 0.5`
//! gives `d(p, q) <= (u[p] + v[q] − 0.5) · unit`. Writing `W_q = (v_max − v[q]) · unit
//! >= 0`, a violator satisfies
//!
//! ```text
//! d(p, q) + W_q <= (u[p] + v_max − 0.5) · unit   <   R_p = (u[p] + v_max + 0.5) · unit
//! ```
//!
//! A plain radius query of radius `R_p` (i.e. `W_q` bounded below by 0) would already be
//! sound, but potentials drift by tens of diameters across a long bed, which makes
//! `R_p` useless. So the search is an additively weighted one on our own k-d tree over
//! the t0 points whose nodes carry the minimum `W` of their subtree: a node is skipped
//! when `mindist(p, box) + W_min >= R_p`, which by the inequality above cannot hide a
//! violator. Every point that survives is tested exactly, on the integers. Candidate
//! edges never test negative (the solver's invariant), so whatever fails the test is an
//! excluded pair. `R_p` carries an extra relative margin for floating-point error.

use rayon::prelude::*;

use super::candidates::{Graph, Images};
use super::cost::CostScale;
use super::sparse_lap::Lap;

/// In the exact repair rounds, at most this many violating pairs per row are returned
/// (the most negative reduced costs). Every violating row still gains an edge, so
/// repair rounds still make progress, while a row on an expensive edge cannot flood
/// the graph. (The searches on the auction's potentials return more: see
/// `AUCTION_PAIRS_PER_ROW` in `super::sparse`.)
pub(crate) const MAX_ADDED_PER_ROW: usize = 8;
/// Points per leaf of the weighted tree (at most 64: a leaf's hits are the bits of a
/// `u64`, [`WeightedTree::leaf_hits`]). 32 until the leaves' test lost its branches;
/// since then 64 visits fewer nodes for the same points found, 8 % less time in the
/// certificate on the long kiln (docs/benchmarks.md#what-each-accepted-change-bought).
const LEAF: usize = 64;
const _: () = assert!(LEAF <= 64);
/// Relative safety margin on `R_p` and the bounds: floating-point distances and the
/// conversion of potentials to lengths err by ~1e-16 relative, far below this.
const REL_MARGIN: f64 = 1e-9;

#[derive(Clone, Debug)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Range of the node's points in the tree order.
    start: u32,
    end: u32,
    /// Children (0 for a leaf: the root is never a child).
    left: u32,
    right: u32,
}

/// Lower bounds of `d(p, q) + W_q` over a node's points, from per-node minima of the
/// weights `W` (refreshed for every certificate pass, as `v` changes).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    /// Slope bound along the bed's long axis `a` (the root's widest): `[s, e, m]` with
    /// `s` the node's least-squares slope of `W` against `x_a`, `e = sqrt(1 − s²)` and
    /// `m = min(W − s·x_a)`. Since `d(p, q) >= s·(p_a − q_a) + e·L` for `L` the
    /// distance across the axis (Cauchy–Schwarz, `s² + e² <= 1`), `d + W_q >= s·p_a +
    /// e·L_min + m`. Where `W` slopes along the axis almost as steeply as the cost
    /// itself (`|s|` near 1: a long drum whose particles drift along its axis), the
    /// set `d + W < r` is a long thin ellipsoid along the axis, whose width the axis
    /// bounds of `lin` (`e = 0`) do not see.
    slope: [f64; 3],
    /// Minimum of `W`: `d + W_q >= mindist(p, box) + min W`.
    min: f64,
    /// Minima of `W − x_a` (`[0..3]`) and `W + x_a` (`[3..6]`) per axis `a`: since
    /// `d(p, q) >= ±(p_a − q_a)`, `d + W_q >= p_a + min(W − x_a)` and `>= −p_a +
    /// min(W + x_a)`.
    lin: [f64; 6],
}

/// A static k-d tree over the t0 points (built once per pairing), with per-node minima
/// of the weights `W` (refreshed for every certificate pass, as `v` changes).
pub(crate) struct WeightedTree {
    nodes: Vec<Node>,
    /// The weight bounds of each node, parallel to `nodes` (one record per node: the
    /// search reads them together).
    bounds: Vec<Bounds>,
    /// The long axis of [`Bounds::slope`].
    axis: usize,
    /// The points' coordinates, one array per axis, and their t0 indices, in tree order
    /// (leaves contiguous). One array per axis so that a leaf's test runs on whole
    /// registers without branches ([`Self::leaf_hits`]).
    axes: [Vec<f64>; 3],
    idx: Vec<u32>,
    /// Weights in tree order.
    w: Vec<f64>,
    /// The tree holds a periodic section's images ([`WeightedTree::with_images`]): a pair
    /// is then costed from the t0 point itself, not from the image that found it.
    images: bool,
}

impl WeightedTree {
    /// Median splits on the widest axis of each box. Deterministic: the split uses
    /// `select_nth_unstable_by` with a total order (coordinate, then index).
    pub(crate) fn new(x0: &[[f64; 3]]) -> Self {
        let mut idx: Vec<u32> = (0..x0.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * x0.len() / LEAF + 2);
        build(x0, &mut idx, 0, &mut nodes);
        let axes = std::array::from_fn(|a| idx.iter().map(|&i| x0[i as usize][a]).collect());
        let n = nodes.len();
        let root: &Node = &nodes[0];
        let axis = (0..3)
            .max_by(|&a, &b| (root.hi[a] - root.lo[a]).total_cmp(&(root.hi[b] - root.lo[b])))
            .unwrap_or(0);
        Self {
            nodes,
            bounds: vec![
                Bounds {
                    slope: [0.0, 1.0, 0.0],
                    min: 0.0,
                    lin: [0.0; 6],
                };
                n
            ],
            axis,
            axes,
            idx,
            w: vec![0.0; x0.len()],
            images: false,
        }
    }

    /// The tree of a periodic section's t0 points and their images one period away on
    /// either side ([`Images`]), each image carrying its original's index and so its weight.
    /// A radius query then reaches every image of every t0 point, and among them the
    /// nearest, whose distance is the pair's periodic distance: every violator of the
    /// periodic problem is found (docs/pairing.md#periodic-sections).
    pub(crate) fn with_images(images: &Images) -> Self {
        let mut tree = Self::new(&images.pts);
        for i in &mut tree.idx {
            *i = images.of[*i as usize];
        }
        tree.images = true;
        tree
    }

    /// Loads `W_q = (v_max − v(q)) · unit` and recomputes the node minima.
    fn set_weights(&mut self, v: impl Fn(usize) -> i64, v_max: i64, unit: f64) {
        for (w, &q) in self.w.iter_mut().zip(&self.idx) {
            *w = (v_max - v(q as usize)) as f64 * unit;
        }
        // Children come after their parent in `nodes`, so a reverse sweep is bottom-up.
        for i in (0..self.nodes.len()).rev() {
            let nd = &self.nodes[i];
            if nd.left == 0 {
                let mut m = f64::INFINITY;
                let mut lin = [f64::INFINITY; 6];
                for t in nd.start as usize..nd.end as usize {
                    let (w, x) = (self.w[t], self.point(t));
                    m = m.min(w);
                    for a in 0..3 {
                        lin[a] = lin[a].min(w - x[a]);
                        lin[a + 3] = lin[a + 3].min(w + x[a]);
                    }
                }
                self.bounds[i].min = m;
                self.bounds[i].lin = lin;
            } else {
                let (l, r) = (
                    &self.bounds[nd.left as usize],
                    &self.bounds[nd.right as usize],
                );
                let m = l.min.min(r.min);
                let lin = std::array::from_fn(|j| l.lin[j].min(r.lin[j]));
                self.bounds[i].min = m;
                self.bounds[i].lin = lin;
            }
        }
        let (w, along) = (&self.w, &self.axes[self.axis]);
        self.nodes
            .par_iter()
            .zip(self.bounds.par_iter_mut())
            .with_min_len(64)
            .for_each(|(nd, bounds)| {
                let range = nd.start as usize..nd.end as usize;
                let len = range.len() as f64;
                let (mut sx, mut sw) = (0.0, 0.0);
                for t in range.clone() {
                    sx += along[t];
                    sw += w[t];
                }
                let (mx, mw) = (sx / len, sw / len);
                let (mut sxx, mut sxw) = (0.0, 0.0);
                for t in range.clone() {
                    let dx = along[t] - mx;
                    sxx += dx * dx;
                    sxw += dx * (w[t] - mw);
                }
                let s = if sxx > 0.0 {
                    (sxw / sxx).clamp(-1.0, 1.0)
                } else {
                    0.0
                };
                // Rounding could make s² + e² exceed 1 by an ulp; shrink e instead.
                let e = (1.0 - s * s).max(0.0).sqrt() * (1.0 - 1e-12);
                let m = range
                    .map(|t| w[t] - s * along[t])
                    .fold(f64::INFINITY, f64::min);
                bounds.slope = [s, e, m];
            });
    }

    /// The point at tree position `t`.
    fn point(&self, t: usize) -> [f64; 3] {
        std::array::from_fn(|a| self.axes[a][t])
    }

    /// The points of one leaf (tree positions `leaf`, at most 64) with `d + W < r`, as the
    /// bits of their offsets in the leaf. Without branches, so that the compiler runs it
    /// on vector registers: the certificate's passes spend 13 % less time than with a test
    /// and a call per point (docs/benchmarks.md#what-each-accepted-change-bought).
    fn leaf_hits(&self, leaf: std::ops::Range<usize>, p: &[f64; 3], r: f64) -> u64 {
        let [xs, ys, zs] = self.axes.each_ref().map(|a| &a[leaf.clone()]);
        let ws = &self.w[leaf];
        let mut hits = 0u64;
        for j in 0..ws.len() {
            let (dx, dy, dz) = (xs[j] - p[0], ys[j] - p[1], zs[j] - p[2]);
            let reach = r - ws[j];
            let hit = (reach > 0.0) & (dx * dx + dy * dy + dz * dz < reach * reach);
            hits |= u64::from(hit) << j;
        }
        hits
    }

    /// Calls `visit(tree position)` for every point with `d + W < r`, skipping every
    /// node one of whose [`Bounds`] is at least `r` (the slope bound first: on a long
    /// drum it prunes the most). `stack` is scratch. The tests involving distances are
    /// made on squares (`d < r − W` with `r − W > 0`), without square roots; the
    /// rounding of either form is far below the margin built into `r`.
    fn search(&self, p: &[f64; 3], r: f64, stack: &mut Vec<u32>, mut visit: impl FnMut(usize)) {
        stack.clear();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let i = i as usize;
            let (nd, b) = (&self.nodes[i], &self.bounds[i]);
            // Squared gaps from p to the box per axis, shared by the two box bounds.
            let gap2: [f64; 3] = std::array::from_fn(|a| {
                let d = (nd.lo[a] - p[a]).max(p[a] - nd.hi[a]).max(0.0);
                d * d
            });
            let across: f64 = (0..3).filter(|&a| a != self.axis).map(|a| gap2[a]).sum();
            let [s, e, m] = b.slope;
            let rest = r - s * p[self.axis] - m;
            if rest <= 0.0 || e * e * across >= rest * rest {
                continue;
            }
            let reach = r - b.min;
            if reach <= 0.0 || across + gap2[self.axis] >= reach * reach {
                continue;
            }
            let lin = &b.lin;
            if (0..3).any(|a| p[a] + lin[a] >= r || lin[a + 3] - p[a] >= r) {
                continue;
            }
            if nd.left == 0 {
                let start = nd.start as usize;
                let mut hits = self.leaf_hits(start..nd.end as usize, p, r);
                while hits != 0 {
                    visit(start + hits.trailing_zeros() as usize);
                    hits &= hits - 1;
                }
            } else {
                stack.push(nd.right);
                stack.push(nd.left);
            }
        }
    }
}

fn build(x0: &[[f64; 3]], idx: &mut [u32], offset: usize, nodes: &mut Vec<Node>) -> u32 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in idx.iter() {
        let p = &x0[i as usize];
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let me = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        start: offset as u32,
        end: (offset + idx.len()) as u32,
        left: 0,
        right: 0,
    });
    if idx.len() > LEAF {
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap();
        let mid = idx.len() / 2;
        idx.select_nth_unstable_by(mid, |&a, &b| {
            x0[a as usize][axis]
                .total_cmp(&x0[b as usize][axis])
                .then(a.cmp(&b))
        });
        let (l, r) = idx.split_at_mut(mid);
        let left = build(x0, l, offset, nodes);
        let right = build(x0, r, offset + mid, nodes);
        nodes[me].left = left;
        nodes[me].right = right;
    }
    me as u32
}

/// Outcome of one certificate pass.
pub(crate) struct Check {
    /// Violating pairs (row, column), sorted.
    pub(crate) violations: Vec<(u32, u32)>,
    /// Pairs that are not candidate edges and hold within the memo's slack (`0 <=
    /// c − u − v < slack`), at most `per_row` per row, the tightest first; sorted. Added
    /// to the graph with the violations, they cannot become violations when a repair
    /// solve raises their row's `u` by less than their margin: on the long kiln one exact
    /// round fewer (docs/benchmarks.md#what-each-accepted-change-bought). Empty with a
    /// slack of 0.
    pub(crate) close: Vec<(u32, u32)>,
    /// How many pairs were tested exactly (work counter).
    pub(crate) examined: u64,
}

/// One row's part of a pass (the default: a row not examined).
#[derive(Default)]
struct RowCheck {
    /// Violating columns, the most negative `limit`, sorted.
    violating: Vec<u32>,
    /// Close columns ([`Check::close`]), sorted.
    close: Vec<u32>,
    /// Points tested exactly.
    examined: u64,
    /// More violations than `limit`: examine the row again next pass.
    truncated: bool,
    /// The row's new bound (`None`: not examined, the old one holds).
    bound: Option<i64>,
}

/// The columns of the `limit` smallest reduced costs of `pairs` (reduced cost, column),
/// sorted by column, and the reduced cost of the first pair left out, if any.
fn tightest(mut pairs: Vec<(i64, u32)>, limit: usize) -> (Vec<u32>, Option<i64>) {
    pairs.sort_unstable();
    // Two images of one t0 point found by the same row give the same pair twice.
    pairs.dedup();
    let left_out = pairs.get(limit).map(|&(reduced, _)| reduced);
    pairs.truncate(limit);
    let mut cols: Vec<u32> = pairs.into_iter().map(|(_, q)| q).collect();
    cols.sort_unstable();
    (cols, left_out)
}

/// What the previous passes proved, so that a pass only re-examines the rows where a
/// violation can have appeared since.
///
/// A pass that examines row `p` proves a lower bound `b[p]` of `c(p, q) − v[q]` over
/// every column `q` that is neither a candidate edge of `p` nor returned (unless it
/// returned more than its limit of pairs per row: then the row is examined again next
/// time). Its search reaches `slack` units beyond the violations (`c − v < u[p] +
/// slack`): every column it does not reach has `c − v >= u[p] + slack`, and the ones
/// it reaches give their exact `c − v`. Candidate edges and returned pairs (violating
/// or [`Check::close`]) stay in the graph, where the solver keeps them non-violating.
/// Column potentials never increase in this solver (augmentations and auction bids only
/// lower them; this is checked, and a full pass is made if it ever fails), so `c − v`
/// only grows and the bound still holds later: the row needs examining again only once
/// its own `u[p]` exceeds `b[p]`. With `slack = 0` that is as soon as `u[p]` grew at all
/// since its last examination; a small slack spares the rows whose `u` a repair solve
/// raises by a little, for a slightly larger search, and the pairs within it join the
/// graph before they can violate.
pub(crate) struct Memo {
    /// `b[p]` (`i64::MIN`: never examined).
    bound: Vec<i64>,
    /// `v[q]` at the last pass.
    v: Vec<i64>,
    /// Row returned more than `per_row` violations: examine again.
    again: Vec<bool>,
    /// How far beyond the violations a search reaches, in cost units (>= 0).
    slack: i64,
    /// At most this many violating pairs, and as many close ones, per row are returned
    /// (at least 1). One cap for both: on the long kiln caps of 4, 8, 16 and 32 changed
    /// the exact rounds' work by a few per cent and the pairing's time not measurably
    /// (docs/benchmarks.md#tried-and-not-kept).
    per_row: usize,
}

impl Memo {
    /// Nothing proven yet; searches reach `slack` cost units beyond the violations and
    /// return at most `per_row` violating pairs and `per_row` close ones per row.
    pub(crate) fn new(slack: i64, per_row: usize) -> Self {
        Self {
            bound: Vec::new(),
            v: Vec::new(),
            again: Vec::new(),
            slack: slack.max(0),
            per_row: per_row.max(1),
        }
    }
}

/// One certificate pass (in parallel over rows, results collected in row order).
/// `lap` must hold a perfect matching that satisfies the invariant on the candidate
/// graph `graph`, or ε-CS on it (a pass on the auction's potentials: it may then also
/// return candidate edges). `memo` carries what earlier passes proved (start with
/// [`Memo::new`]); rows that cannot have gained a violation since are skipped.
pub(crate) fn check(
    tree: &mut WeightedTree,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    lap: &Lap,
    graph: &Graph,
    scale: &CostScale,
    memo: &mut Memo,
) -> Check {
    let n = x1.len();
    let v_now: Vec<i64> = (0..n).map(|q| lap.v(q)).collect();
    // The skip rule needs every column potential to be at most what it was at the
    // previous pass; otherwise forget everything and examine all rows.
    if memo.v.len() != n || memo.v.iter().zip(&v_now).any(|(old, new)| new > old) {
        memo.bound = vec![i64::MIN; n];
        memo.again = vec![true; n];
    }
    memo.v = v_now;
    let v_max = memo.v.iter().copied().max().unwrap_or(0);
    let unit = scale.unit();
    tree.set_weights(|q| lap.v(q), v_max, unit);
    let tree = &*tree;
    let (memo_bound, memo_again, slack, limit) =
        (&memo.bound, &memo.again, memo.slack, memo.per_row);
    let per_row: Vec<RowCheck> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map_init(Vec::new, |stack, p| {
            let u = lap.u(p);
            if !memo_again[p] && u <= memo_bound[p] {
                return RowCheck::default(); // proven at an earlier pass, still holds
            }
            if u + v_max <= 0 {
                // c >= 0 and v <= v_max: c − v >= −v_max >= u for every column.
                return RowCheck {
                    bound: Some(-v_max),
                    ..RowCheck::default()
                };
            }
            // Every column with c − v <= u + slack − 1 has d + W < r (the module
            // documentation's argument, with u + slack for u).
            let r = ((u + slack + v_max) as f64 + 0.5) * unit * (1.0 + REL_MARGIN);
            // (reduced cost, column)
            let mut bad: Vec<(i64, u32)> = Vec::new();
            let mut close: Vec<(i64, u32)> = Vec::new();
            let mut examined = 0u64;
            let edges = graph.row(p).0;
            tree.search(&x1[p], r, stack, |t| {
                examined += 1;
                let q = tree.idx[t];
                let at_t0 = if tree.images {
                    x0[q as usize]
                } else {
                    tree.point(t)
                };
                let reduced = scale.cost(&x1[p], &at_t0) - u - lap.v(q as usize);
                if reduced < 0 {
                    bad.push((reduced, q));
                } else if reduced < slack && !edges.contains(&q) {
                    close.push((reduced, q));
                }
            });
            let (violating, violation_left_out) = tightest(bad, limit);
            let (close, left_out) = tightest(close, limit);
            // The bound holds over the columns neither candidates nor returned: the first
            // close one left out, or the slack.
            let near = left_out.unwrap_or(slack);
            RowCheck {
                violating,
                close,
                examined,
                truncated: violation_left_out.is_some(),
                bound: Some(u + near),
            }
        })
        .collect();
    let (mut violations, mut close) = (Vec::new(), Vec::new());
    let mut examined = 0;
    for (p, row) in per_row.into_iter().enumerate() {
        if let Some(b) = row.bound {
            memo.bound[p] = b;
            memo.again[p] = row.truncated;
        }
        examined += row.examined;
        violations.extend(row.violating.into_iter().map(|q| (p as u32, q)));
        close.extend(row.close.into_iter().map(|q| (p as u32, q)));
    }
    Check {
        violations,
        close,
        examined,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass's close pairs are non-candidate pairs within the slack, at most `per_row`
    /// a row, and the bound it keeps holds over every column it neither has as an edge
    /// nor returned (brute force over all n² pairs), with far more close columns than it
    /// may return.
    #[test]
    fn close_pairs_and_the_bound_past_them() {
        let mut rnd = super::super::test_uniform(777);
        let n = 300;
        let x0: Vec<[f64; 3]> = (0..n).map(|_| [rnd(), rnd(), 3.0 * rnd()]).collect();
        // Each t1 point next to its own t0 point, so that its nearest candidates hold a
        // perfect matching and a solve on them succeeds.
        let x1: Vec<[f64; 3]> = x0
            .iter()
            .map(|p| {
                [
                    p[0] + 1e-4 * rnd(),
                    p[1] + 1e-4 * rnd(),
                    p[2] + 1e-4 * rnd(),
                ]
            })
            .collect();
        let unit = 1e-6;
        let scale = CostScale::new(&x0, &x1, unit).unwrap();
        let grid = super::super::candidates::Grid::new(&x0);
        let k = 3;
        let (kc, kw) = super::super::candidates::knn(&grid, &x0, &x1, &x1, k, &scale);
        let graph = Graph::from_knn(k, kc, kw);
        let mut lap = Lap::new(n);
        lap.solve(&graph).unwrap();
        let mut tree = WeightedTree::new(&x0);
        // A slack of 0.3 (a few point spacings): dozens of close columns per row.
        let per_row = 2;
        let mut memo = Memo::new((0.3 / unit) as i64, per_row);
        let check = check(&mut tree, &x0, &x1, &lap, &graph, &scale, &mut memo);
        assert!(!check.close.is_empty());
        let mut returned = vec![Vec::new(); n];
        for &(p, q) in check.violations.iter().chain(&check.close) {
            returned[p as usize].push(q);
        }
        for &(p, q) in &check.close {
            let (p, q) = (p as usize, q as usize);
            let reduced = scale.cost(&x1[p], &x0[q]) - lap.u(p) - lap.v(q);
            assert!((0..memo.slack).contains(&reduced), "{p} {q}: {reduced}");
            assert!(!graph.row(p).0.contains(&(q as u32)));
        }
        let mut bound_below_slack = 0;
        for p in 0..n {
            let close = check.close.iter().filter(|e| e.0 as usize == p).count();
            assert!(close <= per_row);
            bound_below_slack += usize::from(memo.bound[p] < lap.u(p) + memo.slack);
            if memo.again[p] {
                continue; // no bound claimed
            }
            for (q, at_t0) in x0.iter().enumerate() {
                if graph.row(p).0.contains(&(q as u32)) || returned[p].contains(&(q as u32)) {
                    continue;
                }
                let margin = scale.cost(&x1[p], at_t0) - lap.v(q);
                assert!(margin >= memo.bound[p], "row {p}, column {q}");
            }
        }
        // The bound stops at a close column left out on many rows, not at the slack.
        assert!(bound_below_slack > n / 2, "{bound_below_slack}");
    }

    /// The weighted search returns exactly the brute-force set {q : d + W_q < r}.
    #[test]
    fn weighted_search_matches_brute_force() {
        let mut rnd = super::super::test_uniform(12345);
        let x0: Vec<[f64; 3]> = (0..700).map(|_| [rnd(), rnd(), 2.0 * rnd()]).collect();
        // Potentials sloping along z, gently and (as in a long drum whose particles
        // drift along its axis) nearly as steeply as the cost itself, where the axis
        // bounds of the search prune.
        for (slope, rmax) in [(300.0, 0.5), (950.0, 2.0), (-990.0, 2.0)] {
            let v: Vec<i64> = x0
                .iter()
                .map(|p| -((p[2] * slope) as i64) - (rnd() * 50.0) as i64)
                .collect();
            let v_max = *v.iter().max().unwrap();
            let unit = 1e-3;
            let mut tree = WeightedTree::new(&x0);
            tree.set_weights(|q| v[q], v_max, unit);
            let mut stack = Vec::new();
            for _ in 0..50 {
                let p = [rnd(), rnd(), 2.0 * rnd()];
                let r = 0.05 + rnd() * rmax;
                let mut got = Vec::new();
                tree.search(&p, r, &mut stack, |t| got.push(tree.idx[t]));
                got.sort_unstable();
                let want: Vec<u32> = (0..x0.len())
                    .filter(|&q| {
                        super::super::cost::distance(&p, &x0[q]) + (v_max - v[q]) as f64 * unit < r
                    })
                    .map(|q| q as u32)
                    .collect();
                assert_eq!(got, want);
            }
        }
    }
}
