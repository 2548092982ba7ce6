//! The sparse solver of the pairing, stage by stage: the bed in Morton order with its
//! candidate graph, the warm start (row reduction and ε-scaling auction, on axial slabs for
//! a long bed), certificate searches on the auction's potentials, then exact solves
//! repaired until the certificate holds (docs/pairing.md).

use super::{candidates, certificate, cost, feasibility, order, slabs, sparse_lap};
use super::{total_distance, Pairing, PairingOptions};
use std::time::Instant;

/// Bid budget of each auction call, per row. All calls together took 73–114 bids per
/// row on the beds of docs/pairing.md; on a graph without a perfect matching an auction
/// would bid forever.
const AUCTION_BIDS_PER_ROW: u64 = 200;

/// ε shrinks by this factor between auction phases.
const AUCTION_THETA: i64 = 8;

/// When the mean axial transport exceeds the mean cheapest pair distance, k is
/// multiplied by `AXIAL_K_NUM / AXIAL_K_DEN` (24 → 32).
const AXIAL_K_NUM: usize = 4;
const AXIAL_K_DEN: usize = 3;

/// The axial test above samples every this-many-th row (5 000 of 80 000).
const AXIAL_SAMPLE: usize = 16;

/// Certificate searches made on the auction's potentials, each followed by more
/// auction on the enlarged graph (see `Bed::certify_on_auction`).
const AUCTION_ROUNDS: usize = 2;

/// With the certificate, the first auction pauses at its initial ε divided by this for
/// the certificate searches on its potentials.
const AUCTION_REFINE: i64 = 16;

/// The auctions that follow those certificate searches start at the initial ε divided by
/// this (2¹² units, 0.004 diameters, on the long kiln and the pilot drum), below the
/// pause: the rows a new edge undercuts by more than that are freed and bid in finer
/// phases, where resuming at the pause ε re-ran its coarse phase over the whole bed. On
/// the long kiln 6.2·10⁶ bids instead of 8.2·10⁶, on the pilot drum 3.5·10⁶ instead of
/// 4.3·10⁶ and 2 exact rounds instead of 3; the same pairings
/// (docs/benchmarks.md#what-each-accepted-change-bought).
const AUCTION_RESUME: i64 = 256;

/// The certificate searches on the auction's potentials return up to this many
/// violating pairs per row (the exact repair rounds: `certificate::MAX_ADDED_PER_ROW`,
/// 8). The auction absorbs them cheaply, and on the long kiln the rows it leaves
/// violated otherwise surface again, one round at a time, in the exact phase: with 8
/// its solves scanned 1.04·10⁶ columns in 6 rounds, with 32 0.37·10⁶ in 5 (with 32 in
/// every pass too: 4 rounds, no faster). The pilot drum's counts do not change
/// (docs/benchmarks.md#what-each-accepted-change-bought).
const AUCTION_PAIRS_PER_ROW: usize = 32;

/// `TDEX_PAIR_TRACE` set: phase timings and counters of the sparse solver on stderr
/// (diagnostics only; the result does not depend on it).
fn trace_on() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("TDEX_PAIR_TRACE").is_some())
}

macro_rules! trace {
    ($t:expr, $($arg:tt)*) => {
        if trace_on() {
            eprintln!("[pair {:8.3} s] {}", $t.elapsed().as_secs_f64(), format!($($arg)*));
        }
    };
}

/// Summary of a list of added pairs for the trace: rows, mean and max cost (in units of
/// 10⁶ cost units, one diameter at the default unit), y quantiles of the rows.
fn describe(
    pairs: &[(u32, u32)],
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    scale: &cost::CostScale,
) -> String {
    if pairs.is_empty() {
        return "none".into();
    }
    let mut rows: Vec<u32> = pairs.iter().map(|e| e.0).collect();
    rows.dedup();
    let costs: Vec<i64> = pairs
        .iter()
        .map(|&(p, q)| scale.cost(&x1[p as usize], &x0[q as usize]))
        .collect();
    let mean = costs.iter().sum::<i64>() as f64 / costs.len() as f64 * 1e-6;
    let max = *costs.iter().max().unwrap() as f64 * 1e-6;
    let mut ys: Vec<f64> = rows.iter().map(|&p| x1[p as usize][1]).collect();
    ys.sort_by(f64::total_cmp);
    let qy = |f: f64| ys[((ys.len() - 1) as f64 * f) as usize];
    let dy: f64 = pairs
        .iter()
        .map(|&(p, q)| (x1[p as usize][1] - x0[q as usize][1]).abs())
        .sum::<f64>()
        / pairs.len() as f64
        / (scale.unit() * 1e6);
    format!(
        "{} pairs on {} rows, cost mean {mean:.2} max {max:.2} (1e6 units), mean |dy| \
         {dy:.2}, row y q0/10/50/90/100 {:.3} {:.3} {:.3} {:.3} {:.3}",
        pairs.len(),
        rows.len(),
        qy(0.0),
        qy(0.1),
        qy(0.5),
        qy(0.9),
        qy(1.0)
    )
}

/// The sparse solver: renumber, build the kNN graph, warm-start with an auction (on
/// axial slabs if `allow_slabs` and the bed calls for them), solve (adding exit edges if
/// the graph has no perfect matching), certify, repair, repeat. Also returns the number
/// of slabs used (1: none).
pub(super) fn solve(
    x0_in: &[[f64; 3]],
    x1_in: &[[f64; 3]],
    opts: &PairingOptions,
    scale: &cost::CostScale,
    allow_slabs: bool,
) -> (Pairing, usize) {
    let bed = Bed::of(x0_in, x1_in, opts, scale);
    let (mut solve, slab_count) = bed.warm_start(allow_slabs);
    bed.certify_on_auction(&mut solve);
    let (rounds, certified) = bed.solve_exact(&mut solve);
    (
        bed.pairing(solve, rounds, certified, x0_in, x1_in),
        slab_count,
    )
}

/// The bed as every stage reads it: the points in Morton order (cache locality; mapped
/// back at the end), the candidates' grid, the transport along the bed's long axis.
struct Bed<'a> {
    x0: Vec<[f64; 3]>,
    x1: Vec<[f64; 3]>,
    perm0: Vec<u32>,
    perm1: Vec<u32>,
    /// On a periodic section the candidate search and the certificate's radius queries
    /// run on the t0 points and their images one period away
    /// (docs/pairing.md#periodic-sections).
    images: Option<candidates::Images>,
    grid: candidates::Grid,
    /// Candidates and warm-start potentials follow the transport along the bed's long
    /// axis (`candidates::Axial`; docs/pairing.md#long-drums).
    axial: candidates::Axial,
    centres: Vec<[f64; 3]>,
    opts: &'a PairingOptions,
    scale: &'a cost::CostScale,
    /// The solve's start, for the trace.
    t: Instant,
}

/// The candidate graph and what the warm start reads off it.
struct Candidates {
    graph: candidates::Graph,
    k0: usize,
    /// The mean axial transport and the mean cheapest pair cost (sampled, then on the
    /// whole graph), in length units.
    shift: f64,
    rho_sampled: f64,
    rho: f64,
    /// The auction's first ε.
    eps0: i64,
}

/// The solve in progress: the candidate graph, the assignment with its potentials, the
/// certificate's tree once built, and the work done.
struct Solve {
    graph: candidates::Graph,
    lap: sparse_lap::Lap,
    k0: usize,
    eps0: i64,
    tree: Option<certificate::WeightedTree>,
    bids: u64,
    /// Pairs the certificate added to the graph.
    added: usize,
    /// Exit edges added where the graph had no perfect matching.
    grown: usize,
    examined: u64,
}

impl<'a> Bed<'a> {
    fn of(
        x0_in: &[[f64; 3]],
        x1_in: &[[f64; 3]],
        opts: &'a PairingOptions,
        scale: &'a cost::CostScale,
    ) -> Bed<'a> {
        let t = Instant::now();
        let (lo, hi) = order::bounds(x0_in, x1_in);
        let perm0 = order::morton_order(x0_in, lo, hi);
        let perm1 = order::morton_order(x1_in, lo, hi);
        let x0: Vec<[f64; 3]> = perm0.iter().map(|&i| x0_in[i as usize]).collect();
        let x1: Vec<[f64; 3]> = perm1.iter().map(|&i| x1_in[i as usize]).collect();
        let images = scale
            .period()
            .map(|length| candidates::Images::of(&x0, length));
        let grid = match &images {
            None => candidates::Grid::new(&x0),
            Some(images) => candidates::Grid::with_images(images),
        };
        trace!(t, "morton order + grid, n {}", x0.len());
        let axial = candidates::Axial::new(&x0, &x1);
        let centres = axial.centres(&x1);
        trace!(t, "axial transport and centres");
        Bed {
            x0,
            x1,
            perm0,
            perm1,
            images,
            grid,
            axial,
            centres,
            opts,
            scale,
            t,
        }
    }

    fn n(&self) -> usize {
        self.x0.len()
    }

    /// The k-nearest candidate graph.
    fn knn_graph(&self, k: usize) -> candidates::Graph {
        let (x0, x1) = (&self.x0[..], &self.x1[..]);
        if self.images.is_some() {
            candidates::knn_images(&self.grid, x0, x1, &self.centres, k, self.scale)
        } else {
            let (kc, kw) = candidates::knn(&self.grid, x0, x1, &self.centres, k, self.scale);
            candidates::Graph::from_knn(k, kc, kw)
        }
    }

    /// The certificate's tree: it depends on the t0 points alone.
    fn new_tree(&self) -> certificate::WeightedTree {
        match &self.images {
            None => certificate::WeightedTree::new(&self.x0),
            Some(images) => certificate::WeightedTree::with_images(images),
        }
    }

    /// With the certificate, the auction pauses at ε0 / AUCTION_REFINE for the
    /// certificate searches and resumes from there.
    fn eps_pause(&self, eps0: i64) -> i64 {
        if self.opts.certify {
            (eps0 / AUCTION_REFINE).max(1)
        } else {
            1
        }
    }

    fn budget(&self) -> u64 {
        AUCTION_BIDS_PER_ROW * self.n() as u64
    }

    /// The candidate graph, with k raised for a bed with a large axial transport, and what
    /// the warm start reads off it.
    fn candidate_graph(&self) -> Candidates {
        let (t, n, opts, scale) = (self.t, self.n(), self.opts, self.scale);
        let (x0, x1) = (&self.x0[..], &self.x1[..]);
        let shift = self.axial.mean_abs_shift();
        // A bed with a large axial transport needs more candidates: the long kiln has no
        // perfect matching at k = 24, and finding that out costs the auction's whole budget
        // (docs/pairing.md#long-drums). The test is `shift > ρ`, ρ the mean cheapest
        // candidate cost of the k-graph, estimated on every `AXIAL_SAMPLE`-th row so that
        // the graph is built once, with the k it needs (building the k = 24 graph only to
        // throw it away cost 0.3 s on the long kiln). ρ itself is then taken on the whole
        // graph, as before.
        let k_axial = (opts.k_initial * AXIAL_K_NUM / AXIAL_K_DEN).clamp(1, n);
        let k_plain = opts.k_initial.min(n);
        let rho_sampled = candidates::mean_cheapest_sampled(
            &self.grid,
            x0,
            x1,
            &self.centres,
            k_plain,
            AXIAL_SAMPLE,
            scale,
        ) * scale.unit();
        let k0 = if shift > rho_sampled {
            k_axial
        } else {
            k_plain
        };
        trace!(t, "sampled mean cheapest pair");
        let graph = self.knn_graph(k0);
        trace!(t, "knn k {k0}");
        if trace_on() {
            // A pass over the graph (a few milliseconds on 80 000 rows, in the stamps that
            // follow): only with the trace on.
            let (span, lines) = graph.locality();
            trace!(
                t,
                "locality: a row's columns span {span:.0} indices on {lines:.1} cache lines"
            );
        }
        let cheapest = sparse_lap::Cheapest::of(&graph);
        let rho = cheapest.mean() * scale.unit();
        trace!(
            t,
            "axial transport (mean |shift| {shift:.3e}, mean cheapest pair {rho:.3e}, sampled \
             {rho_sampled:.3e}) + knn k {k0} + graph"
        );
        Candidates {
            eps0: cheapest.initial_eps(),
            graph,
            k0,
            shift,
            rho_sampled,
            rho,
        }
    }

    /// The warm start on the candidate graph: the row reduction, then an ε-scaling
    /// auction (on axial slabs when `allow_slabs` and the bed calls for them); k doubled
    /// once if the auction stopped on a graph without a perfect matching. Returns the
    /// solve and the number of slabs (1: none).
    fn warm_start(&self, allow_slabs: bool) -> (Solve, usize) {
        let (t, n, scale, x0) = (self.t, self.n(), self.scale, &self.x0[..]);
        let Candidates {
            mut graph,
            mut k0,
            shift,
            rho_sampled,
            rho,
            mut eps0,
        } = self.candidate_graph();
        let v_axial = self.axial.potentials(x0, rho, scale.unit());
        let budget = self.budget();
        // Warm start: the row reduction, then an ε-scaling auction. The auction moves the
        // holes left by the row reduction (the long-range part of the transport) far more
        // cheaply than one Dijkstra search per hole, which scans the whole region between
        // the hole and a free column. While its potentials are near optimal, the
        // certificate's search also runs on them, and the pairs it finds join the graph
        // before the exact phase (`AUCTION_ROUNDS`). Only the auction's potentials and the
        // matched pairs that satisfy the exact invariant are kept; the exact solver below
        // does not depend on anything else the auction did.
        //
        // On a long bed with an axial transport the auction runs first on axial slabs, in
        // parallel (`slabs`): the global price war grows with the bed's length.
        let cut = if allow_slabs && shift > rho_sampled {
            slabs::Slabs::for_bed(n, self.axial.length(x0), rho)
        } else {
            None
        };
        let slab_count = cut.as_ref().map_or(1, slabs::Slabs::count);
        // The certificate's tree is built on the second core while the first runs the
        // sequential auction before the first search.
        let (mut lap, mut bids, tree) = match &cut {
            Some(cut) => self.auction_on_slabs(cut, &graph, &v_axial, eps0),
            None => self.auction_on_the_bed(&graph, &v_axial, eps0),
        };
        // An auction that stops on its budget may be bidding on a graph without a perfect
        // matching. If Hopcroft–Karp confirms that, k doubles once and the warm start is
        // redone: exit edges (the growth step below) are long, and their potentials make
        // the certificate expensive. A real bed whose t1 shape differs slightly from t0's
        // has no perfect matching at k = 12 or 16, the long kiln none at k = 24
        // (docs/pairing.md). Checking up front instead costs 1.1–1.3 s of Hopcroft–Karp
        // on the long kiln, feasible or not (its augmenting paths are long).
        if lap.col_of_row.contains(&sparse_lap::NONE) && k0 < n {
            let mut m = feasibility::Matching::from_partial(&lap.col_of_row, &lap.row_of_col_vec());
            if !m.deficient_rows(&graph).is_empty() {
                k0 = (2 * k0).min(n);
                graph = self.knn_graph(k0);
                lap = sparse_lap::Lap::new(n);
                lap.set_potentials(&v_axial);
                lap.greedy_init(&graph);
                eps0 = sparse_lap::Cheapest::of(&graph).initial_eps();
                bids += lap.auction(&graph, eps0, AUCTION_THETA, self.eps_pause(eps0), budget);
                trace!(t, "k doubled to {k0}, auction again: {bids} bids in all");
            } else {
                trace!(t, "Hopcroft-Karp: the graph has a perfect matching");
            }
        }
        let solve = Solve {
            graph,
            lap,
            k0,
            eps0,
            tree,
            bids,
            added: 0,
            grown: 0,
            examined: 0,
        };
        (solve, slab_count)
    }

    /// The warm start's auction on axial slabs of the bed, in parallel, from `eps0` to where
    /// the certified path pauses (the global auction then repairs the seams at that ε);
    /// returns the assignment, the bids and, when certifying, the certificate's tree (built
    /// on the second core meanwhile).
    fn auction_on_slabs(
        &self,
        cut: &slabs::Slabs,
        graph: &candidates::Graph,
        v_axial: &[i64],
        eps0: i64,
    ) -> (sparse_lap::Lap, u64, Option<certificate::WeightedTree>) {
        let t = self.t;
        let eps_slabs = (eps0 / AUCTION_REFINE).max(1);
        let (mut lap, slab_bids) = slabs::warm_start(
            cut,
            &self.axial,
            graph,
            &self.x0,
            &self.x1,
            self.scale,
            v_axial,
            [eps0, AUCTION_THETA, eps_slabs],
            AUCTION_BIDS_PER_ROW,
        );
        trace!(
            t,
            "{} slabs: auction eps0 {eps0} -> {eps_slabs}: {slab_bids} bids, {} rows free",
            cut.count(),
            lap.free_rows()
        );
        let (seam_bids, tree) = rayon::join(
            || {
                lap.auction(
                    graph,
                    eps_slabs,
                    AUCTION_THETA,
                    self.eps_pause(eps0),
                    self.budget(),
                )
            },
            || self.opts.certify.then(|| self.new_tree()),
        );
        trace!(
            t,
            "seams: auction {eps_slabs} -> {}: {seam_bids} bids, {} rows free",
            self.eps_pause(eps0),
            lap.free_rows()
        );
        (lap, slab_bids + seam_bids, tree)
    }

    /// The warm start's auction on the whole bed: the axial potentials and the row
    /// reduction, then the auction from `eps0`; as [`Self::auction_on_slabs`] returns.
    fn auction_on_the_bed(
        &self,
        graph: &candidates::Graph,
        v_axial: &[i64],
        eps0: i64,
    ) -> (sparse_lap::Lap, u64, Option<certificate::WeightedTree>) {
        let t = self.t;
        let mut lap = sparse_lap::Lap::new(self.n());
        lap.set_potentials(v_axial);
        lap.greedy_init(graph);
        trace!(
            t,
            "axial potentials + row reduction: {} rows free",
            lap.free_rows()
        );
        let (bids, tree) = rayon::join(
            || {
                lap.auction(
                    graph,
                    eps0,
                    AUCTION_THETA,
                    self.eps_pause(eps0),
                    self.budget(),
                )
            },
            || self.opts.certify.then(|| self.new_tree()),
        );
        trace!(
            t,
            "auction eps0 {eps0} -> {}: {bids} bids, {} rows free",
            self.eps_pause(eps0),
            lap.free_rows()
        );
        (lap, bids, tree)
    }

    /// Certificate searches on the auction's near-optimal potentials (`AUCTION_ROUNDS`),
    /// their pairs joining the graph and the auction carried on over them; then the
    /// auction finished and the exact invariant restored.
    fn certify_on_auction(&self, s: &mut Solve) {
        let (t, x0, x1, scale) = (self.t, &self.x0[..], &self.x1[..], self.scale);
        let (eps0, budget) = (s.eps0, self.budget());
        let mut paused = self.eps_pause(eps0) > 1;
        for _ in 0..AUCTION_ROUNDS {
            if !self.opts.certify || s.lap.col_of_row.contains(&sparse_lap::NONE) {
                break; // nothing to certify, or the auction stopped on its budget
            }
            let wtree = s.tree.get_or_insert_with(|| self.new_tree());
            // A throwaway memo: these potentials satisfy ε-CS only, so a pass may also
            // return candidate edges (dropped by the merge). Its bounds would hold later too,
            // but carried over with the slack they made these passes search further while
            // round 1 still re-examined every row (docs/benchmarks.md).
            let check = certificate::check(
                wtree,
                x0,
                x1,
                &s.lap,
                &s.graph,
                scale,
                &mut certificate::Memo::new(0, AUCTION_PAIRS_PER_ROW),
            );
            s.examined += check.examined;
            trace!(
                t,
                "auction certificate search: {} examined, {}",
                check.examined,
                describe(&check.violations, x0, x1, scale)
            );
            if check.violations.is_empty() {
                break;
            }
            s.added += s.graph.insert(&check.violations, x0, x1, scale);
            // The auction frees the rows undercut by more than ε by a new edge.
            let resume = (eps0 / AUCTION_RESUME).clamp(1, self.eps_pause(eps0));
            s.bids += s.lap.auction(&s.graph, resume, AUCTION_THETA, 1, budget);
            trace!(t, "auction to 1: {} bids in all", s.bids);
            paused = false;
        }
        if paused && !s.lap.col_of_row.contains(&sparse_lap::NONE) {
            let pause = self.eps_pause(eps0);
            s.bids += s.lap.auction(&s.graph, pause, AUCTION_THETA, 1, budget);
            trace!(t, "auction to 1: {} bids in all", s.bids);
        }
        let freed = s.lap.restore_invariant(&s.graph);
        trace!(t, "restore invariant: {freed} rows freed");
    }

    /// Optimal on the candidate graph, then the certificate; repair until it holds.
    /// If a search finds no augmenting path, the graph has no perfect matching: add exit
    /// edges on Hall-violating sets until Hopcroft–Karp finds a perfect matching, and
    /// carry on from the same state. Returns the rounds and whether the pairing is
    /// certified.
    fn solve_exact(&self, s: &mut Solve) -> (u32, bool) {
        let (t, x0, x1, scale) = (self.t, &self.x0[..], &self.x1[..], self.scale);
        // The repair passes search a little beyond the violations (`Memo`): the auction's
        // pause ε (1/16 of the mean cheapest pair cost times two). On the long kiln this
        // spares rows whose `u` a repair solve raised by less: 7 % of the certificate's
        // time (slack 0: 0.78 s, 2^14 or 2^16 units: 0.72 s).
        let mut memo =
            certificate::Memo::new(s.eps0 / AUCTION_REFINE, certificate::MAX_ADDED_PER_ROW);
        let mut rounds = 0u32;
        let certified = loop {
            rounds += 1;
            let work0 = s.lap.work;
            while let Err(failed) = s.lap.solve(&s.graph) {
                trace!(t, "solve failed at row {}: growth", failed.row);
                let before = s.grown;
                let mut m =
                    feasibility::Matching::from_partial(&s.lap.col_of_row, &s.lap.row_of_col_vec());
                loop {
                    let deficient = m.deficient_rows(&s.graph);
                    if deficient.is_empty() {
                        break;
                    }
                    let more = feasibility::exit_edges(&s.graph, x0, x1, &deficient);
                    s.grown += more.len();
                    s.graph.insert(&more, x0, x1, scale);
                }
                // A failed search proves there is no perfect matching (the symmetric
                // difference with one would hold an augmenting path), so growth happened.
                assert!(
                    s.grown > before,
                    "internal error: search from row {} failed on a feasible graph",
                    failed.row
                );
                s.lap.restore_invariant(&s.graph);
                trace!(t, "growth: {} exit edges in all", s.grown);
            }
            trace!(
                t,
                "round {rounds}: solve scanned {} columns",
                s.lap.work - work0
            );
            if !self.opts.certify {
                break false;
            }
            let wtree = s.tree.get_or_insert_with(|| self.new_tree());
            let check = certificate::check(wtree, x0, x1, &s.lap, &s.graph, scale, &mut memo);
            s.examined += check.examined;
            trace!(
                t,
                "round {rounds}: certificate {} examined, {}; {} close pairs",
                check.examined,
                describe(&check.violations, x0, x1, scale),
                check.close.len()
            );
            if check.violations.is_empty() {
                break true;
            }
            // Only the rows with a violation can break the invariant (sorted by row).
            let mut touched: Vec<usize> = check.violations.iter().map(|e| e.0 as usize).collect();
            touched.dedup();
            // Every violation is a new edge (candidate edges cannot violate), so the graph
            // grows strictly each round and the loop ends, at worst with all n² pairs. The
            // close pairs are new edges too; they join the graph before a solve can make
            // them violate.
            let mut pairs = check.violations;
            pairs.extend(check.close);
            pairs.sort_unstable();
            s.added += s.graph.insert(&pairs, x0, x1, scale);
            let freed = s.lap.restore_invariant_on(&s.graph, touched);
            trace!(t, "round {rounds}: {freed} rows freed");
        };
        (rounds, certified)
    }

    /// The solve's pairing in the caller's numbering, with its counters.
    fn pairing(
        &self,
        s: Solve,
        rounds: u32,
        certified: bool,
        x0_in: &[[f64; 3]],
        x1_in: &[[f64; 3]],
    ) -> Pairing {
        let total_cost = s.lap.mcost.iter().sum();
        trace!(
            self.t,
            "total cost {total_cost}, {} bids, {} columns scanned, {} examined",
            s.bids,
            s.lap.work,
            s.examined
        );
        let mut g = vec![0u32; self.n()];
        for (p, &q) in s.lap.col_of_row.iter().enumerate() {
            g[self.perm1[p] as usize] = self.perm0[q as usize];
        }
        Pairing {
            total_cost,
            total_distance: total_distance(x0_in, x1_in, &g, self.scale.period()),
            g,
            k_used: s.k0,
            certified,
            rounds,
            added_pairs: s.added,
            growth_pairs: s.grown,
            edges: s.graph.edges(),
            certificate_examined: s.examined,
            auction_bids: s.bids,
            seconds: 0.0,
        }
    }
}
