//! Exact sparse linear assignment: Jonker–Volgenant style shortest augmenting paths with
//! Dijkstra on reduced costs, on the candidate graph only, with warm starts when edges
//! are added.
//!
//! Rows are t1 points, columns t0 points. The state keeps the column potentials `v`;
//! the row potential of a matched row is implied, `u[p] = c(p, col(p)) − v[col(p)]`.
//! Invariant between augmentations (dual feasibility + complementary slackness on the
//! candidate graph): every matched row's partner minimises `c(p, q) − v[q]` over the
//! row's edges, i.e. all reduced costs `c − u − v` are ≥ 0 and matched edges are tight.
//! A perfect matching that satisfies it is optimal on the candidate graph.
//!
//! `v` starts at 0 and augmentations only ever lower it, so `max v <= 0`: the
//! certificate uses that to keep its search radii small.

use rayon::prelude::*;

use super::candidates::Graph;

/// Marks a free row or column.
pub(crate) const NONE: u32 = u32::MAX;

/// The auction stops once a potential falls below this. Costs are at most `C = 2³² − 1`
/// and `n · C <= 2⁶⁰` (checked up front), the scale of the potentials of a graph with a
/// perfect matching; on one without, bids inside a Hall-violating set would lower
/// them without end. Stopping here keeps the later potentials (the exact solver lowers
/// them by at most another `n · C`), distances and reduced costs below 2⁶², far from
/// `i64` overflow.
const V_FLOOR: i64 = -(1 << 60);

/// Everything the inner loop touches about a column, in one cache line: the graph walk
/// is memory-bound, and separate arrays cost one miss each per relaxed edge.
#[derive(Clone, Copy, Debug)]
struct Col {
    /// Potential `v[q]`.
    v: i64,
    /// Tentative distance in the current search.
    dist: i64,
    /// Cost of the edge from `pred`.
    pred_cost: i64,
    /// Row through which `dist` was reached.
    pred: u32,
    /// Row matched to this column, or `NONE`.
    row: u32,
    /// `seen == epoch`: `dist` belongs to the current search; `done == epoch`: the
    /// column is finalised in it. Epoch stamps avoid clearing O(n) state for every
    /// (usually tiny) search.
    seen: u32,
    done: u32,
}

/// Assignment state plus the scratch of the Dijkstra searches (allocated once).
pub(crate) struct Lap {
    pub(crate) col_of_row: Vec<u32>,
    /// Cost of the matched edge of each row (meaningful only while matched).
    pub(crate) mcost: Vec<i64>,
    cols: Vec<Col>,
    epoch: u32,
    heap: RadixHeap,
    scanned: Vec<u32>,
    /// Total number of columns finalised over all searches (work counter).
    pub(crate) work: u64,
}

/// The candidate graph has no perfect matching: no augmenting path from this row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Infeasible {
    pub(crate) row: usize,
}

impl Lap {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            col_of_row: vec![NONE; n],
            mcost: vec![0; n],
            cols: vec![
                Col {
                    v: 0,
                    dist: 0,
                    pred_cost: 0,
                    pred: NONE,
                    row: NONE,
                    seen: 0,
                    done: 0,
                };
                n
            ],
            epoch: 0,
            heap: RadixHeap::default(),
            scanned: Vec::new(),
            work: 0,
        }
    }

    /// A state made elsewhere (the slabs' warm start): each row's partner (`NONE` if
    /// free) and matched cost, and the column potentials (all `<= 0`). The matching must
    /// be one to one; the auction or [`Lap::restore_invariant`] takes it from there.
    pub(crate) fn from_state(col_of_row: Vec<u32>, mcost: Vec<i64>, v: &[i64]) -> Self {
        let mut lap = Self::new(col_of_row.len());
        for (c, &v) in lap.cols.iter_mut().zip(v) {
            debug_assert!(v <= 0);
            c.v = v;
        }
        for (p, &q) in col_of_row.iter().enumerate() {
            if q != NONE {
                debug_assert_eq!(lap.cols[q as usize].row, NONE, "column {q} taken twice");
                lap.cols[q as usize].row = p as u32;
            }
        }
        lap.col_of_row = col_of_row;
        lap.mcost = mcost;
        lap
    }

    /// Sets the column potentials before any matching is made (all must be `<= 0`).
    pub(crate) fn set_potentials(&mut self, v: &[i64]) {
        debug_assert!(self.col_of_row.iter().all(|&q| q == NONE));
        for (c, &v) in self.cols.iter_mut().zip(v) {
            debug_assert!(v <= 0);
            c.v = v;
        }
    }

    /// Column potential `v[q]`.
    #[inline]
    pub(crate) fn v(&self, q: usize) -> i64 {
        self.cols[q].v
    }

    /// Number of free rows.
    pub(crate) fn free_rows(&self) -> usize {
        self.col_of_row.iter().filter(|&&q| q == NONE).count()
    }

    /// Row matched to column `q`, or `NONE`.
    #[cfg(test)]
    pub(crate) fn row_of_col(&self, q: usize) -> u32 {
        self.cols[q].row
    }

    /// The rows matched to each column (`NONE` if free).
    pub(crate) fn row_of_col_vec(&self) -> Vec<u32> {
        self.cols.iter().map(|c| c.row).collect()
    }

    /// Row potential of a matched row.
    #[inline]
    pub(crate) fn u(&self, p: usize) -> i64 {
        self.mcost[p] - self.cols[self.col_of_row[p] as usize].v
    }

    /// With `v = 0`, give each free row its cheapest candidate if that column is still
    /// free (rows in index order, ties to the lower column). This is the row reduction
    /// of the Hungarian method: it satisfies the invariant and typically matches most
    /// rows at once when t1 is close to t0.
    pub(crate) fn greedy_init(&mut self, g: &Graph) {
        for p in 0..g.rows() {
            if self.col_of_row[p] != NONE {
                continue;
            }
            let (cols, costs) = g.row(p);
            let mut best: Option<(i64, u32, i64)> = None;
            for (&q, &c) in cols.iter().zip(costs) {
                let c = i64::from(c);
                let key = (c - self.cols[q as usize].v, q, c);
                if best.is_none_or(|b| (key.0, key.1) < (b.0, b.1)) {
                    best = Some(key);
                }
            }
            if let Some((_, q, c)) = best {
                if self.cols[q as usize].row == NONE {
                    self.col_of_row[p] = q;
                    self.cols[q as usize].row = p as u32;
                    self.mcost[p] = c;
                }
            }
        }
    }

    /// ε-scaling forward auction (Bertsekas), used only as a warm start of the
    /// potentials and the matching: it moves the holes left by the row reduction over
    /// long distances with local bids, where shortest augmenting paths would scan the
    /// whole region between a hole and a free column once per hole.
    ///
    /// Each phase first frees the matched rows that violate ε-CS (partner more than ε
    /// above the row's best `c − v`: after a smaller ε, or after edges were added), then
    /// lets every free row bid for its best column `j1`: `v[j1]` drops by `w2 − w1 + ε`
    /// (`w1`, `w2`: best and second best `c − v`), the row takes `j1` within ε of its
    /// best, and the previous holder is freed and bids next. A phase ends when every
    /// row is matched; ε then shrinks by `theta`, down to `eps_min`. `v` only decreases,
    /// so `max v <= 0` still holds. The auction stops early, leaving a consistent
    /// partial matching, after `budget` bids in total or once a potential falls below
    /// `V_FLOOR` (on a graph without a perfect matching an auction never ends). The
    /// exact solver then starts from this state after [`Lap::restore_invariant`], which
    /// frees every row whose partner is not its exact best: exactness does not depend
    /// on anything the auction does. Returns the number of bids.
    pub(crate) fn auction(
        &mut self,
        g: &Graph,
        eps0: i64,
        theta: i64,
        eps_min: i64,
        budget: u64,
    ) -> u64 {
        // Dense copies of the potentials and holders: the bids touch nothing else, and
        // 8 + 4 bytes per column stay in cache where the 40-byte `Col` would not.
        let mut v: Vec<i64> = self.cols.iter().map(|c| c.v).collect();
        let mut holder: Vec<u32> = self.cols.iter().map(|c| c.row).collect();
        let bids = auction_phases(
            g,
            &mut v,
            &mut holder,
            &mut self.col_of_row,
            &mut self.mcost,
            [eps0, theta, eps_min],
            budget,
        );
        for ((c, v), r) in self.cols.iter_mut().zip(v).zip(holder) {
            c.v = v;
            c.row = r;
        }
        bids
    }

    /// After edges were added to `g`, free every matched row whose partner is no longer
    /// its cheapest reduced-cost column (a new edge undercuts it). That restores the
    /// invariant without touching `v`; the freed rows are re-augmented by [`Lap::solve`].
    /// Returns how many rows were freed.
    pub(crate) fn restore_invariant(&mut self, g: &Graph) -> usize {
        self.restore_invariant_on(g, 0..g.rows())
    }

    /// [`Lap::restore_invariant`] on the given rows only: after a solve the invariant
    /// holds on every row, so a repair round need only look at the rows that gained
    /// edges (a few thousand of 80 000 on the long kiln).
    pub(crate) fn restore_invariant_on(
        &mut self,
        g: &Graph,
        rows: impl IntoIterator<Item = usize>,
    ) -> usize {
        let mut freed = 0;
        for p in rows {
            let q0 = self.col_of_row[p];
            if q0 == NONE {
                continue;
            }
            let u = self.u(p);
            let (cols, costs) = g.row(p);
            if cols
                .iter()
                .zip(costs)
                .any(|(&q, &c)| i64::from(c) - self.cols[q as usize].v < u)
            {
                self.col_of_row[p] = NONE;
                self.cols[q0 as usize].row = NONE;
                freed += 1;
            }
        }
        freed
    }

    /// Augments every free row, in index order. On failure the state is still a valid
    /// (partial) warm start: the caller can enlarge the graph and call again.
    pub(crate) fn solve(&mut self, g: &Graph) -> Result<(), Infeasible> {
        for p in 0..g.rows() {
            if self.col_of_row[p] == NONE && !self.augment(g, p) {
                return Err(Infeasible { row: p });
            }
        }
        Ok(())
    }

    fn next_epoch(&mut self) {
        if self.epoch == u32::MAX {
            for c in &mut self.cols {
                c.seen = 0;
                c.done = 0;
            }
            self.epoch = 0;
        }
        self.epoch += 1;
    }

    /// One shortest augmenting path from the free row `i0` (Dijkstra on reduced costs,
    /// which are ≥ 0 by the invariant), then the Jonker–Volgenant potential update
    /// `v[q] −= μ − dist[q]` on the finalised columns, then the flip along the path.
    /// Returns false, changing nothing, if no free column is reachable.
    ///
    /// Distances are offset by `u[i0]` (left implicit): they start at `c − v >= 0`
    /// (costs are ≥ 0 and `v <= 0`) and never decrease along a path, which is what
    /// the radix heap needs.
    fn augment(&mut self, g: &Graph, i0: usize) -> bool {
        self.next_epoch();
        let ep = self.epoch;
        self.heap.clear();
        self.scanned.clear();
        let (cols, costs) = g.row(i0);
        for (&q, &c) in cols.iter().zip(costs) {
            let c = i64::from(c);
            let col = &mut self.cols[q as usize];
            let d = c - col.v;
            debug_assert!(d >= 0);
            if col.seen != ep || d < col.dist {
                col.seen = ep;
                col.dist = d;
                col.pred = i0 as u32;
                col.pred_cost = c;
                self.heap.push(d as u64, q);
            }
        }
        let mut end = NONE;
        let mut mu = 0i64;
        while let Some((d, q)) = self.heap.pop() {
            let d = d as i64;
            let col = &mut self.cols[q as usize];
            if col.done == ep || d > col.dist {
                continue; // stale heap entry
            }
            col.done = ep;
            self.scanned.push(q);
            let r = col.row;
            if r == NONE {
                end = q;
                mu = d;
                break;
            }
            // Continue through the row matched to q: reduced costs relative to its
            // tight (matched) edge.
            let ri = r as usize;
            let ur = self.mcost[ri] - col.v;
            let (cols, costs) = g.row(ri);
            for (&k, &c) in cols.iter().zip(costs) {
                let c = i64::from(c);
                let col = &mut self.cols[k as usize];
                if col.done == ep {
                    continue;
                }
                let reduced = c - col.v - ur;
                debug_assert!(reduced >= 0, "negative reduced cost");
                let nd = d + reduced;
                if col.seen != ep || nd < col.dist {
                    col.seen = ep;
                    col.dist = nd;
                    col.pred = r;
                    col.pred_cost = c;
                    self.heap.push(nd as u64, k);
                }
            }
        }
        self.work += self.scanned.len() as u64;
        if end == NONE {
            return false;
        }
        for &q in &self.scanned {
            let col = &mut self.cols[q as usize];
            col.v += col.dist - mu;
        }
        // Flip the alternating path back to i0.
        let mut q = end;
        loop {
            let col = &mut self.cols[q as usize];
            let r = col.pred as usize;
            col.row = r as u32;
            let prev = self.col_of_row[r];
            self.col_of_row[r] = q;
            self.mcost[r] = col.pred_cost;
            if r == i0 {
                break;
            }
            q = prev;
        }
        true
    }

    /// Checks the invariant and that the matching is perfect (tests and debugging).
    #[cfg(test)]
    pub(crate) fn check(&self, g: &Graph) -> Result<(), String> {
        for p in 0..g.rows() {
            let q0 = self.col_of_row[p];
            if q0 == NONE {
                return Err(format!("row {p} free"));
            }
            if self.cols[q0 as usize].row != p as u32 {
                return Err(format!("row {p} / column {q0} disagree"));
            }
            let u = self.u(p);
            let (cols, costs) = g.row(p);
            for (&q, &c) in cols.iter().zip(costs) {
                let c = i64::from(c);
                if c - u - self.cols[q as usize].v < 0 {
                    return Err(format!("negative reduced cost on ({p}, {q})"));
                }
                if q == q0 && c != self.mcost[p] {
                    return Err(format!("stale matched cost on row {p}"));
                }
            }
        }
        Ok(())
    }
}

/// The phases of [`Lap::auction`] on dense arrays (see there).
fn auction_phases(
    g: &Graph,
    v: &mut [i64],
    holder: &mut [u32],
    col_of_row: &mut [u32],
    mcost: &mut [i64],
    [eps0, theta, eps_min]: [i64; 3],
    budget: u64,
) -> u64 {
    let n = g.rows();
    let mut eps = eps0.max(1);
    let eps_min = eps_min.max(1);
    let mut bids = 0u64;
    let mut stack: Vec<u32> = Vec::new();
    loop {
        // Free the rows that violate ε-CS (a new, smaller ε, or edges added since). The
        // test reads every edge of the graph and nothing it changes, so it runs on all
        // threads (the same rows, in the same order, whatever their number).
        let violating: Vec<u32> = (0..n)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&p| {
                let q0 = col_of_row[p];
                if q0 == NONE {
                    return false;
                }
                let w0 = mcost[p] - v[q0 as usize];
                let (cols, costs) = g.row(p);
                cols.iter()
                    .zip(costs)
                    .any(|(&q, &c)| i64::from(c) - v[q as usize] + eps < w0)
            })
            .map(|p| p as u32)
            .collect();
        for p in violating {
            let q0 = std::mem::replace(&mut col_of_row[p as usize], NONE);
            holder[q0 as usize] = NONE;
        }
        stack.clear();
        stack.extend(
            (0..n as u32)
                .rev()
                .filter(|&p| col_of_row[p as usize] == NONE),
        );
        while let Some(i) = stack.pop() {
            if bids >= budget {
                return bids;
            }
            let i = i as usize;
            let (cols, costs) = g.row(i);
            let (mut w1, mut w2) = (i64::MAX, i64::MAX);
            let (mut j1, mut c1) = (NONE, 0);
            for (&q, &c) in cols.iter().zip(costs) {
                let c = i64::from(c);
                let w = c - v[q as usize];
                if w < w1 {
                    w2 = w1;
                    w1 = w;
                    j1 = q;
                    c1 = c;
                } else if w < w2 {
                    w2 = w;
                }
            }
            if j1 == NONE {
                continue; // a row without edges: left to the exact solver
            }
            if w2 == i64::MAX {
                w2 = w1; // a single edge: any bid keeps ε-CS
            }
            bids += 1;
            let j = j1 as usize;
            v[j] -= w2 - w1 + eps;
            let prev = holder[j];
            holder[j] = i as u32;
            col_of_row[i] = j1;
            mcost[i] = c1;
            if prev != NONE {
                col_of_row[prev as usize] = NONE;
                stack.push(prev);
            }
            if v[j] < V_FLOOR {
                return bids; // only on a graph without a perfect matching
            }
        }
        if eps <= eps_min {
            return bids;
        }
        eps = (eps / theta.max(2)).max(eps_min);
    }
}

/// The rows' cheapest candidate costs, summed in one pass over the graph: the solver
/// needs their mean (the typical pair distance) and the auction's initial ε from it.
pub(crate) struct Cheapest {
    sum: i128,
    /// At least 1, so that an empty graph divides safely.
    rows: usize,
}

impl Cheapest {
    pub(crate) fn of(g: &Graph) -> Self {
        let sum = (0..g.rows())
            .map(|p| g.row(p).1.iter().copied().min().unwrap_or(0) as i128)
            .sum();
        Self {
            sum,
            rows: g.rows().max(1),
        }
    }

    /// Mean cost of the rows' cheapest candidates (at least 0).
    pub(crate) fn mean(&self) -> f64 {
        self.sum as f64 / self.rows as f64
    }

    /// Initial ε of the auction: the power of two nearest to twice the mean cost of the
    /// rows' cheapest candidates (a million units, one diameter at the default unit, on
    /// a packed bed), at least 1.
    pub(crate) fn initial_eps(&self) -> i64 {
        let target = (2 * self.sum / self.rows as i128).max(1) as u64;
        let up = target.next_power_of_two();
        let eps = if up - target > target - up / 2 {
            up / 2
        } else {
            up
        };
        eps.max(1) as i64
    }
}

/// Monotone priority queue for non-negative integer keys (radix heap): a key goes to
/// the bucket of the highest bit in which it differs from the last key popped. Push is
/// O(1), pop amortised O(log C). Valid because Dijkstra never pushes a key below the
/// last one popped.
struct RadixHeap {
    last: u64,
    len: usize,
    buckets: [Vec<(u64, u32)>; 65],
}

impl Default for RadixHeap {
    fn default() -> Self {
        Self {
            last: 0,
            len: 0,
            buckets: std::array::from_fn(|_| Vec::new()),
        }
    }
}

impl RadixHeap {
    #[inline]
    fn bucket(&self, key: u64) -> usize {
        (64 - (key ^ self.last).leading_zeros()) as usize
    }

    fn clear(&mut self) {
        if self.len > 0 {
            for b in &mut self.buckets {
                b.clear();
            }
        }
        self.len = 0;
        self.last = 0;
    }

    #[inline]
    fn push(&mut self, key: u64, item: u32) {
        debug_assert!(key >= self.last, "radix heap key below the last pop");
        let b = self.bucket(key);
        self.buckets[b].push((key, item));
        self.len += 1;
    }

    #[inline]
    fn pop(&mut self) -> Option<(u64, u32)> {
        if self.len == 0 {
            return None;
        }
        if self.buckets[0].is_empty() {
            let i = (1..65)
                .find(|&i| !self.buckets[i].is_empty())
                .expect("len > 0");
            // Every key of bucket i moves to a lower bucket once `last` is its minimum.
            let mut b = std::mem::take(&mut self.buckets[i]);
            self.last = b.iter().map(|e| e.0).min().expect("non-empty");
            for e in b.drain(..) {
                let j = self.bucket(e.0);
                self.buckets[j].push(e);
            }
            self.buckets[i] = b; // keep the allocation
        }
        self.len -= 1;
        self.buckets[0].pop()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn radix_heap_pops_in_order() {
        let mut h = super::RadixHeap::default();
        let mut s = 99u64;
        let mut popped = Vec::new();
        let mut last = 0;
        for round in 0..200 {
            for j in 0..(round % 7) {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                h.push(last + (s >> 40) % 1000, j);
            }
            if let Some((k, _)) = h.pop() {
                assert!(k >= last);
                last = k;
                popped.push(k);
            }
        }
        while let Some((k, _)) = h.pop() {
            assert!(k >= last);
            last = k;
        }
        h.clear();
        assert!(h.pop().is_none());
    }

    use super::*;
    use crate::pairing::cost::EdgeCost;

    fn graph(rows: &[&[(u32, EdgeCost)]]) -> Graph {
        let mut g = Graph::default();
        g.offsets.push(0);
        for r in rows {
            for &(q, c) in r.iter() {
                g.cols.push(q);
                g.costs.push(c);
            }
            g.offsets.push(g.cols.len());
        }
        g
    }

    #[test]
    fn solves_a_small_dense_problem() {
        // Optimal: row0→col1 (1), row1→col0 (2), row2→col2 (2): total 5.
        let g = graph(&[
            &[(0, 4), (1, 1), (2, 3)],
            &[(0, 2), (1, 0), (2, 5)],
            &[(0, 3), (1, 2), (2, 2)],
        ]);
        let mut lap = Lap::new(3);
        lap.greedy_init(&g);
        lap.solve(&g).unwrap();
        lap.check(&g).unwrap();
        assert_eq!(lap.col_of_row, vec![1, 0, 2]);
        let total: i64 = lap.mcost.iter().sum();
        assert_eq!(total, 5);
        assert!((0..3).all(|q| lap.v(q) <= 0));
        assert_eq!(lap.row_of_col(1), 0);
    }

    /// The auction warm start changes nothing in the outcome: after it (and the
    /// restoration of the exact invariant), the solver reaches the same optimal total
    /// on random sparse graphs, including ones without a perfect matching, where the
    /// auction must stop on its budget.
    #[test]
    fn auction_warm_start_reaches_the_same_optimum() {
        let mut s = 0x9e3779b97f4a7c15u64;
        let mut rnd = |m: u64| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s % m
        };
        let mut feasible = 0;
        for case in 0..300 {
            let n = 1 + rnd(40) as usize;
            let deg = 1 + rnd(6) as usize;
            let spread = [3, 50, 1_000_000][case % 3];
            let mut g = Graph::default();
            g.offsets.push(0);
            for p in 0..n {
                let mut cols: Vec<u32> = (0..deg).map(|_| rnd(n as u64) as u32).collect();
                // Keep the diagonal often, so that many graphs have a perfect matching.
                if rnd(4) > 0 {
                    cols.push(p as u32);
                }
                cols.sort_unstable();
                cols.dedup();
                for q in cols {
                    g.cols.push(q);
                    g.costs.push(rnd(spread) as EdgeCost);
                }
                g.offsets.push(g.cols.len());
            }
            let mut plain = Lap::new(n);
            plain.greedy_init(&g);
            let ok = plain.solve(&g).is_ok();
            let mut warm = Lap::new(n);
            warm.greedy_init(&g);
            let eps0 = Cheapest::of(&g).initial_eps();
            warm.auction(&g, eps0, 8, 1, 50 * n as u64);
            assert!((0..n).all(|q| warm.v(q) <= 0));
            for p in 0..n {
                let q = warm.col_of_row[p];
                assert!(q == NONE || warm.row_of_col(q as usize) == p as u32);
            }
            warm.restore_invariant(&g);
            assert_eq!(warm.solve(&g).is_ok(), ok, "case {case}");
            if ok {
                feasible += 1;
                plain.check(&g).unwrap();
                warm.check(&g).unwrap();
                let a: i64 = plain.mcost.iter().sum();
                let b: i64 = warm.mcost.iter().sum();
                assert_eq!(a, b, "case {case}");
            }
        }
        assert!(feasible > 50, "{feasible}");
    }

    #[test]
    fn reports_infeasible_graph() {
        // Rows 0 and 1 both only see column 0.
        let g = graph(&[&[(0, 1)], &[(0, 2)], &[(1, 0), (2, 0)]]);
        let mut lap = Lap::new(3);
        lap.greedy_init(&g);
        assert_eq!(lap.solve(&g), Err(Infeasible { row: 1 }));
    }
}
