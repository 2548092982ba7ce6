//! Warm start of a long bed by axial slabs: the auction run on square sub-problems cut
//! across the bed's long axis, in parallel, their prices then joined into one global
//! ε-complementary-slackness state (docs/pairing.md#axial-slabs).
//!
//! On a long drum with an axial transport the global auction's price war runs along the
//! whole bed: every row takes part in carrying the transport from one end to the other,
//! and the bids per row grow with the bed's length. The one-dimensional transport
//! (`candidates::Axial`, rank r of t1 to rank r of t0) says which t0 points the t1 points
//! of an axial section must mostly take: cutting t0 and t1 at the same ranks gives
//! square slabs whose own optimal assignments are nearly the global one. Each slab is a
//! short bed, solved by the same auction. The slabs' potentials are each defined up to
//! a constant. Each slab is solved with an overlap into its neighbours, and the
//! constants are chosen, seam by seam, as the median difference of the two solves'
//! potentials over the overlap; the global auction then only repairs the rows near the
//! seams that still violate ε-CS.
//!
//! Nothing here changes the problem or the exactness argument: the result is only the
//! warm start of the global solver (potentials and a matching), which the exact phase
//! and the certificate treat like any other. The number of slabs depends on the bed
//! alone (never on the thread count), and each slab is solved serially, so the state
//! handed on is the same whatever the number of threads.

use rayon::prelude::*;

use super::candidates::{Axial, Graph};
use super::cost::CostScale;
use super::sparse_lap::{Lap, NONE};

/// A slab holds at least this many rows: shorter slabs leave too much of every slab at
/// its seams.
const MIN_SLAB_ROWS: usize = 2_000;

/// A slab is at least this many mean cheapest pair distances long along the axis
/// (18 diameters on the long kiln). On the long kiln, 17, 34, 68 and 136 slabs took 31,
/// 22, 17 and 15 bids per row, and the seams 8, 9, 14 and 40 (docs/benchmarks.md).
const MIN_SLAB_LENGTH_RHO: f64 = 40.0;

/// Each slab is solved with 1/`OVERLAP_DEN` of its ranks more on either side: the
/// overlap where its potentials are compared with its neighbours'.
const OVERLAP_DEN: usize = 10;

/// The slabs of a bed: t0 and t1 cut at the same ranks along the axis, rank r in slab
/// `r · count / n`.
pub(crate) struct Slabs {
    count: usize,
    n: usize,
}

impl Slabs {
    /// The slabs of a bed of `n` points, `length` long along its axis: as many as keep
    /// every slab at least `MIN_SLAB_ROWS` rows and `MIN_SLAB_LENGTH_RHO` times `rho`
    /// long; `None` (no decomposition) if that is one slab.
    pub(crate) fn for_bed(n: usize, length: f64, rho: f64) -> Option<Self> {
        let by_rows = n / MIN_SLAB_ROWS;
        let by_length = if rho > 0.0 && length.is_finite() {
            (length / (MIN_SLAB_LENGTH_RHO * rho)).floor() as usize
        } else {
            1
        };
        let count = by_rows.min(by_length);
        (count > 1).then_some(Self { count, n })
    }

    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// First rank of slab `s` (`n` for `s = count`): the least r with
    /// `r · count / n >= s`.
    fn start(&self, s: usize) -> usize {
        (s * self.n).div_ceil(self.count)
    }

    /// The slab of rank r.
    fn of_rank(&self, r: usize) -> usize {
        r * self.count / self.n
    }
}

/// What a slab's auction leaves, by axial rank from the slab's first rank (its solve
/// covers its own ranks and the overlap on either side): the rows' partners (ranks in
/// the same frame, `NONE` if free), their matched costs, the columns' potentials and
/// holders.
struct SlabState {
    lo: usize,
    col_of_row: Vec<u32>,
    mcost: Vec<i64>,
    v: Vec<i64>,
    holder: Vec<u32>,
    bids: u64,
}

/// The auction of every slab from the potentials `v0` down to `eps_min`, joined into
/// one state of the whole bed: returns the global [`Lap`] and the number of bids.
///
/// Each slab is solved with `n / count / OVERLAP_DEN` ranks more on either side: its
/// own ranks stay away from the distortion of its cut (a row next to a cut can only
/// take columns on its own side), and the overlaps give the potentials' offsets
/// ([`seam_offsets`]). A row keeps its partner only if the partner's own slab matched
/// the same pair (which keeps the joined matching one to one); the others are left
/// free for the global auction.
///
/// A slab's graph is the global graph restricted to the slab, plus the pair of equal
/// axial rank for every row (the one-dimensional transport): those pairs form a perfect
/// matching of the slab, so its auction always ends. Rows left matched to such a pair
/// that is not in the global graph are freed when the slabs are joined.
#[allow(clippy::too_many_arguments)]
pub(crate) fn warm_start(
    slabs: &Slabs,
    axial: &Axial,
    graph: &Graph,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    scale: &CostScale,
    v0: &[i64],
    [eps0, theta, eps_min]: [i64; 3],
    bids_per_row: u64,
) -> (Lap, u64) {
    let n = x1.len();
    let (s0, s1) = axial.sorted();
    let mut rank0 = vec![0u32; n];
    for (r, &q) in s0.iter().enumerate() {
        rank0[q as usize] = r as u32;
    }
    let start = |s: usize| slabs.start(s);
    let overlap = n / slabs.count / OVERLAP_DEN;
    let states: Vec<SlabState> = (0..slabs.count)
        .into_par_iter()
        .map(|s| {
            let lo = start(s).saturating_sub(overlap);
            let hi = (start(s + 1) + overlap).min(n);
            let g = slab_graph(lo, hi, s0, s1, &rank0, graph, x0, x1, scale);
            let m = hi - lo;
            let mut lap = Lap::new(m);
            let v_local: Vec<i64> = s0[lo..hi].iter().map(|&q| v0[q as usize]).collect();
            lap.set_potentials(&v_local);
            lap.greedy_init(&g);
            let bids = lap.auction(&g, eps0, theta, eps_min, bids_per_row * m as u64);
            SlabState {
                lo,
                col_of_row: lap.col_of_row.clone(),
                mcost: lap.mcost.clone(),
                v: (0..m).map(|c| lap.v(c)).collect(),
                holder: lap.row_of_col_vec(),
                bids,
            }
        })
        .collect();

    // Every rank r belongs to slab `home(r)`; its row's partner and its column's
    // potential and holder come from that slab's solve.
    let home = |r: usize| {
        let s = slabs.of_rank(r);
        debug_assert!(start(s) <= r && r < start(s + 1));
        s
    };
    let mut v = vec![0i64; n];
    let mut col_of_row = vec![NONE; n];
    let mut mcost = vec![0i64; n];
    let bids = states.iter().map(|st| st.bids).sum();
    for r in 0..n {
        let st = &states[home(r)];
        v[s0[r] as usize] = st.v[r - st.lo];
        let c = st.col_of_row[r - st.lo];
        if c == NONE {
            continue;
        }
        let rc = st.lo + c as usize; // the partner's rank
        let other = &states[home(rc)];
        // The partner's own slab must agree (it always does inside one slab).
        let holder = other.holder[rc - other.lo];
        if holder != NONE && holder as usize + other.lo == r {
            col_of_row[s1[r] as usize] = s0[rc];
            mcost[s1[r] as usize] = st.mcost[r - st.lo];
        }
    }
    let offsets = seam_offsets(&states);
    for (r, &q) in s0.iter().enumerate() {
        v[q as usize] += offsets[home(r)];
    }
    let v_max = v.iter().copied().max().unwrap_or(0);
    for vq in &mut v {
        *vq -= v_max; // the solver keeps max v <= 0
    }
    // A row matched to its equal-rank pair outside the global graph is freed: the
    // global state stands on the global graph's edges only.
    for (p, q) in col_of_row.iter_mut().enumerate() {
        if *q != NONE && !graph.row(p).0.contains(q) {
            *q = NONE;
        }
    }
    (Lap::from_state(col_of_row, mcost, &v), bids)
}

/// The graph of the ranks `[lo, hi)` in local indices (rank − lo): the global edges
/// inside the range, then the pair of equal axial rank if it is not among them.
#[allow(clippy::too_many_arguments)]
fn slab_graph(
    lo: usize,
    hi: usize,
    s0: &[u32],
    s1: &[u32],
    rank0: &[u32],
    graph: &Graph,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    scale: &CostScale,
) -> Graph {
    let mut g = Graph::default();
    g.offsets.push(0);
    for r in lo..hi {
        let p = s1[r] as usize;
        let start = g.cols.len();
        let (cs, ws) = graph.row(p);
        for (&q, &w) in cs.iter().zip(ws) {
            let rq = rank0[q as usize] as usize;
            if (lo..hi).contains(&rq) {
                g.cols.push((rq - lo) as u32);
                g.costs.push(w);
            }
        }
        let d = (r - lo) as u32;
        if !g.cols[start..].contains(&d) {
            g.cols.push(d);
            g.costs.push(scale.edge_cost(&x1[p], &x0[s0[r] as usize]));
        }
        g.offsets.push(g.cols.len());
    }
    g
}

/// The constant added to each slab's potentials: slab 0 keeps its own, and the step
/// across each seam is the median, over the ranks both neighbours solved, of the
/// difference of their potentials. Two ε-CS solutions of overlapping beds agree up to a
/// constant and a spread of a few ε (on the long kiln, 5–95 % within ±0.4 diameters at
/// ε = 0.065 d, without trend along the overlap); the median is that constant, where
/// the extreme edges across the seam would set it by the spread.
fn seam_offsets(states: &[SlabState]) -> Vec<i64> {
    let mut offsets = vec![0i64; states.len()];
    for s in 1..states.len() {
        let (a, b) = (&states[s - 1], &states[s]);
        let (lo, hi) = (b.lo, a.lo + a.v.len());
        let mut diff: Vec<i64> = (lo..hi).map(|r| a.v[r - a.lo] - b.v[r - b.lo]).collect();
        let step = if diff.is_empty() {
            0
        } else {
            let mid = diff.len() / 2;
            *diff.select_nth_unstable(mid).1
        };
        offsets[s] = offsets[s - 1] + step;
    }
    offsets
}

#[cfg(test)]
mod tests {
    use super::super::{cost::CostScale, sparse::solve as sparse, PairingOptions};

    /// A tube 400 diameters long, 4 × 4 particles across, whose t1 is its t0 moved by
    /// about a diameter along the axis with jitter: the transport of a long kiln. The
    /// solver cuts it into slabs and reaches the same certified optimum as without them.
    #[test]
    fn slabs_reach_the_optimum_of_the_whole_bed() {
        let mut uniform = super::super::test_uniform(0x2545f4914f6cdd1d);
        let mut rnd = || uniform() - 0.5;
        let n = 6400;
        let site = |i: usize| [(i % 4) as f64, ((i / 4) % 4) as f64, (i / 16) as f64];
        let x0: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let p = site(i);
                [p[0] + 0.2 * rnd(), p[1] + 0.2 * rnd(), p[2] + 0.2 * rnd()]
            })
            .collect();
        // t1 in another order, every particle moved 0.7–1.3 diameters along z.
        let x1: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let p = x0[(i * 7919) % n];
                [
                    p[0] + 0.3 * rnd(),
                    p[1] + 0.3 * rnd(),
                    p[2] + 1.0 + 0.6 * rnd(),
                ]
            })
            .collect();
        let opts = PairingOptions::for_diameter(1.0);
        let scale = CostScale::new(&x0, &x1, opts.unit).unwrap();
        let (with, slabs) = sparse(&x0, &x1, &opts, &scale, true);
        let (without, none) = sparse(&x0, &x1, &opts, &scale, false);
        assert!(slabs > 1, "the tube was not cut into slabs");
        assert_eq!(none, 1);
        assert!(with.certified && without.certified);
        assert_eq!(with.total_cost, without.total_cost);
        assert_eq!(with.g, without.g);
    }
}
