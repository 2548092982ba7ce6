//! Pairing of the t0 and t1 snapshots (docs/method.md §5; Haydar et al. 2023 §2.1.2,
//! Bednarek et al. 2019): the bijection `g` that minimises `Σ_p |x1[p] − x0[g(p)]|`
//! (Euclidean distance, not squared). At t1 particle `p` stands where `g(p)` stood at
//! t0, so in the next period `p` plays the role of `g(p)`.
//!
//! Costs are integers, `round(|x1[p] − x0[q]| / unit)` (see [`PairingOptions::unit`]),
//! so the sparse solver and the dense oracle minimise exactly the same objective.
//!
//! * [`pair_dense`] — Kuhn–Munkres on the full matrix; the oracle, small n only.
//! * [`pair`] — the solver for real beds: on the k nearest t0 neighbours of each t1
//!   point (queried where the transport along the bed's long axis sends it), an
//!   ε-scaling auction as a warm start (potentials started from that transport),
//!   then shortest augmenting paths (Jonker–Volgenant, Dijkstra on reduced costs);
//!   exit edges added on
//!   Hall-violating sets while the candidate graph has no perfect matching; then an
//!   optimality certificate against every excluded pair, through the dual potentials
//!   (pairs it finds are added and the solve repeated, warm-started, until it holds).
//!
//! * [`pair_by_size`] — [`pair`] on each size class of a bed of several particle sizes, so
//!   that a particle only takes the role of one of its own radius.
//!
//! Module map: `cost` (integer objective), `order` (Morton renumbering), `candidates`
//! (kNN graph), `sparse_lap` (the solver), `feasibility` (Hopcroft–Karp, exit edges),
//! `certificate` (weighted k-d tree search), `dense` (the oracle), `classes` (size
//! classes). The method and its
//! soundness argument are written up in `docs/pairing.md`.

mod candidates;
mod certificate;
mod classes;
mod cost;
pub mod cycles;
mod dense;
mod feasibility;
mod order;
mod slabs;
mod sparse_lap;

use std::time::Instant;

pub use classes::{pair_by_size, respects_classes};
pub(crate) use cost::{nearest_image, wrap};
pub use cycles::{cycle_structure, CycleStructure, SHORT_CYCLE};
pub use dense::DENSE_LIMIT;

/// Options of [`pair`].
#[derive(Clone, Debug, PartialEq)]
pub struct PairingOptions {
    /// Length of one integer cost unit, in the units of the coordinates. Pair costs are
    /// `round(distance / unit)`: `unit = diameter · 1e-6` resolves distances to a
    /// millionth of a particle diameter, far below any physical meaning, while keeping
    /// costs small integers (≈ 6·10⁸ for the length of the long kiln).
    pub unit: f64,
    /// Number of nearest t0 candidates per t1 point (≥ 1); multiplied by 4/3 on a bed
    /// with a large transport along its long axis (docs/pairing.md). If they admit no perfect
    /// matching (detected when the auction warm start runs out of bids), k doubles
    /// once; if that is still not enough, exit edges are added on the Hall-violating
    /// sets (`growth_pairs`).
    pub k_initial: usize,
    /// Use the dense oracle when `n <= dense_max` (0: never). At most [`DENSE_LIMIT`].
    pub dense_max: usize,
    /// Run the optimality certificate (and repair until it holds). Without it the
    /// result is optimal on the candidate graph only and `certified` is false.
    pub certify: bool,
    /// The period `L` along y of a section periodic along its axis (`None`: a drum with end
    /// caps). A pair's distance is then taken across the seam, its y part to the nearest
    /// image (`Δy − L · round(Δy / L)`), and positions are wrapped into `[−L/2, L/2)`
    /// first; the result is exact and certified for that distance
    /// (docs/pairing.md#periodic-sections). Finite and positive.
    pub axial_period: Option<f64>,
}

impl PairingOptions {
    /// Defaults for particles of the given diameter: `unit = diameter · 1e-6`,
    /// `k_initial = 24`, never dense, certified. A pair cost must fit 32 bits, so with
    /// this unit the bed may span at most 4 294 diameters; [`PairingOptions::for_bed`]
    /// coarsens the unit beyond that.
    #[must_use]
    pub fn for_diameter(diameter: f64) -> Self {
        Self {
            unit: diameter * 1e-6,
            k_initial: 24,
            dense_max: 0,
            certify: true,
            axial_period: None,
        }
    }

    /// [`PairingOptions::for_diameter`] for these snapshots: the unit is a millionth of a
    /// diameter, or, on a bed whose joint bounding box is more than 4 294 diameters
    /// across, that diagonal over `0.999 · (2³² − 1)`, so that every pair cost fits the
    /// solver's 32-bit edge costs (docs/pairing.md#integer-costs). Non-finite
    /// coordinates leave the unit as it is; [`pair`] reports them.
    #[must_use]
    pub fn for_bed(diameter: f64, x0: &[[f64; 3]], x1: &[[f64; 3]]) -> Self {
        let opts = Self::for_diameter(diameter);
        Self {
            // f64::max ignores a NaN diagonal: the unit stays a millionth of a diameter
            unit: opts
                .unit
                .max(cost::diagonal(x0, x1) / (0.999 * cost::MAX_PAIR_UNITS)),
            ..opts
        }
    }
}

/// The optimal pairing and how it was obtained.
#[derive(Clone, Debug, PartialEq)]
pub struct Pairing {
    /// `g[p]`: the t0 index whose position particle `p` occupies at t1 (a permutation
    /// of `0..n`).
    pub g: Vec<u32>,
    /// The minimised objective: `Σ_p round(|x1[p] − x0[g[p]]| / unit)`.
    pub total_cost: i64,
    /// `Σ_p |x1[p] − x0[g[p]]|`, in the units of the coordinates (summed in row order);
    /// with an axial period, the distances across the seam.
    pub total_distance: f64,
    /// Nearest t0 candidates per row in the kNN lists: `k_initial` (times 4/3 on a bed
    /// with a large axial transport), or twice that if the first kNN graph had no
    /// perfect matching, capped at n; `n` for the dense
    /// oracle. Growth adds individual edges, counted in `growth_pairs`.
    pub k_used: usize,
    /// True if the result is proven optimal for the complete problem (the dense oracle,
    /// or the sparse solver with its certificate).
    pub certified: bool,
    /// Number of optimal solves on the candidate graph: 1 if the first solution was
    /// certified at once; each certificate repair adds one.
    pub rounds: u32,
    /// Pairs added to the candidate graph by the certificate.
    pub added_pairs: usize,
    /// Exit edges added because the candidate graph had no perfect matching.
    pub growth_pairs: usize,
    /// Edges of the final candidate graph (`n²` for the dense oracle).
    pub edges: usize,
    /// Points returned by the certificate's radius queries, all passes together.
    pub certificate_examined: u64,
    /// Bids of the auction warm start (0 for the dense oracle).
    pub auction_bids: u64,
    /// Wall-clock time of the call, in seconds.
    pub seconds: f64,
}

impl Pairing {
    /// Mean pair distance, in particle diameters.
    #[must_use]
    pub fn mean_distance_in_diameters(&self, diameter: f64) -> f64 {
        self.total_distance / self.g.len() as f64 / diameter
    }
}

/// Why a pairing could not be computed. Bad input is reported, never a panic.
#[derive(Debug, thiserror::Error)]
pub enum PairingError {
    /// The snapshots hold different numbers of particles.
    #[error("the snapshots differ in size: {n0} particles at t0, {n1} at t1")]
    LengthMismatch { n0: usize, n1: usize },
    /// Nothing to pair.
    #[error("the snapshots are empty: nothing to pair")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error(
        "non-finite coordinate in the {snapshot} snapshot: particle {index}, axis {axis} \
         is {value}"
    )]
    NonFinite {
        snapshot: &'static str,
        index: usize,
        axis: usize,
        value: f64,
    },
    /// An option is out of range.
    #[error("invalid pairing option `{name}`: {reason}")]
    InvalidOption { name: &'static str, reason: String },
    /// More particles than u32 indices can address.
    #[error("{n} particles: at most {max} can be paired")]
    TooMany { n: usize, max: usize },
    /// `unit` is too small for the extent of the bed: costs would overflow.
    #[error(
        "the bed spans {extent} but the cost unit is {unit}: {units:.3e} units per pair, \
         more than the {max_units:.3e} the solver can hold; use a larger unit"
    )]
    CostOverflow {
        extent: f64,
        unit: f64,
        units: f64,
        max_units: f64,
    },
    /// The dense oracle was asked for more than [`DENSE_LIMIT`] particles.
    #[error("the dense oracle takes at most {max} particles, got {n}; use `pair`")]
    TooLargeForDense { n: usize, max: usize },
    /// A snapshot does not hold one radius per position ([`pair_by_size`]).
    #[error("the {snapshot} snapshot has {radii} radii for {positions} positions")]
    RadiusCount {
        snapshot: &'static str,
        radii: usize,
        positions: usize,
    },
    /// A size class has not as many particles at t0 as at t1 ([`pair_by_size`]): no
    /// bijection keeps every particle in its class.
    #[error(
        "particles of radius {radius}: {n0} at t0, {n1} at t1; a particle can only take the \
         role of one of its own radius"
    )]
    ClassMismatch { radius: f64, n0: usize, n1: usize },
}

/// Checks sizes and coordinates; returns n.
fn validate(x0: &[[f64; 3]], x1: &[[f64; 3]]) -> Result<usize, PairingError> {
    if x0.len() != x1.len() {
        return Err(PairingError::LengthMismatch {
            n0: x0.len(),
            n1: x1.len(),
        });
    }
    if x0.is_empty() {
        return Err(PairingError::Empty);
    }
    if x0.len() > u32::MAX as usize {
        return Err(PairingError::TooMany {
            n: x0.len(),
            max: u32::MAX as usize,
        });
    }
    for (snapshot, xs) in [("t0", x0), ("t1", x1)] {
        for (index, p) in xs.iter().enumerate() {
            if let Some(axis) = p.iter().position(|c| !c.is_finite()) {
                return Err(PairingError::NonFinite {
                    snapshot,
                    index,
                    axis,
                    value: p[axis],
                });
            }
        }
    }
    Ok(x0.len())
}

/// `Σ_p |x1[p] − x0[g[p]]|` in row order, across the seam of `period` if given.
fn total_distance(x0: &[[f64; 3]], x1: &[[f64; 3]], g: &[u32], period: Option<f64>) -> f64 {
    match period {
        None => g
            .iter()
            .enumerate()
            .map(|(p, &q)| cost::distance(&x1[p], &x0[q as usize]))
            .sum(),
        Some(length) => g
            .iter()
            .enumerate()
            .map(|(p, &q)| cost::periodic_distance(&x1[p], &x0[q as usize], length))
            .sum(),
    }
}

/// Checks an axial period: finite and positive.
fn check_period(period: Option<f64>) -> Result<(), PairingError> {
    match period {
        Some(length) if !(length.is_finite() && length > 0.0) => Err(PairingError::InvalidOption {
            name: "axial_period",
            reason: format!("must be finite and > 0, got {length}"),
        }),
        _ => Ok(()),
    }
}

/// The positions with y wrapped into `[−L/2, L/2)` (those already inside keep their bits).
fn wrapped(x: &[[f64; 3]], length: f64) -> Vec<[f64; 3]> {
    x.iter()
        .map(|&[a, y, z]| [a, cost::wrap(y, length), z])
        .collect()
}

/// The exact pairing by the dense oracle (Kuhn–Munkres on all n² integer costs).
/// For tests and n ≤ [`DENSE_LIMIT`]; `unit` as in [`PairingOptions::unit`].
///
/// # Errors
///
/// [`PairingError`] for snapshots of different or zero length, non-finite
/// coordinates, a `unit` that is not positive or too small for the bed's extent, or
/// more than [`DENSE_LIMIT`] particles.
pub fn pair_dense(x0: &[[f64; 3]], x1: &[[f64; 3]], unit: f64) -> Result<Pairing, PairingError> {
    dense_pairing(x0, x1, unit, None)
}

/// [`pair_dense`] on a section periodic along y with period `period`: the full matrix of
/// periodic integer costs (`PairingOptions::axial_period`), positions wrapped into
/// `[−L/2, L/2)` first. The oracle of the periodic sparse solver.
///
/// # Errors
///
/// As [`pair_dense`], and [`PairingError::InvalidOption`] for a period that is not finite
/// and positive.
pub fn pair_dense_periodic(
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    unit: f64,
    period: f64,
) -> Result<Pairing, PairingError> {
    dense_pairing(x0, x1, unit, Some(period))
}

fn dense_pairing(
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    unit: f64,
    period: Option<f64>,
) -> Result<Pairing, PairingError> {
    let start = Instant::now();
    let n = validate(x0, x1)?;
    check_period(period)?;
    if n > DENSE_LIMIT {
        return Err(PairingError::TooLargeForDense {
            n,
            max: DENSE_LIMIT,
        });
    }
    let wrapped_positions;
    let (x0, x1) = match period {
        None => (x0, x1),
        Some(length) => {
            wrapped_positions = (wrapped(x0, length), wrapped(x1, length));
            (&wrapped_positions.0[..], &wrapped_positions.1[..])
        }
    };
    let scale = cost::CostScale::new(x0, x1, unit)?.with_period(period);
    let (g, total_cost) = dense::solve(x0, x1, &scale);
    Ok(Pairing {
        total_distance: total_distance(x0, x1, &g, period),
        g,
        total_cost,
        k_used: n,
        certified: true,
        rounds: 1,
        added_pairs: 0,
        growth_pairs: 0,
        edges: n * n,
        certificate_examined: 0,
        auction_bids: 0,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The exact pairing: minimises `Σ_p round(|x1[p] − x0[g[p]]| / unit)` over all
/// bijections. Uses the dense oracle when `n <= opts.dense_max`, otherwise the sparse
/// solver (see the module documentation). The parallel parts run on the current rayon
/// pool; the result does not depend on the number of threads.
///
/// # Errors
///
/// [`PairingError`] for snapshots of different or zero length (or more than
/// `u32::MAX` particles), non-finite coordinates, and out-of-range options
/// (`k_initial = 0`, `dense_max > DENSE_LIMIT`, a `unit` that is not positive or too
/// small for the bed's extent, an `axial_period` that is not finite and positive). Valid
/// input never panics.
pub fn pair(
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    opts: &PairingOptions,
) -> Result<Pairing, PairingError> {
    let start = Instant::now();
    let n = validate(x0, x1)?;
    if opts.k_initial == 0 {
        return Err(PairingError::InvalidOption {
            name: "k_initial",
            reason: "must be at least 1".into(),
        });
    }
    if opts.dense_max > DENSE_LIMIT {
        return Err(PairingError::InvalidOption {
            name: "dense_max",
            reason: format!("at most {DENSE_LIMIT}, got {}", opts.dense_max),
        });
    }
    check_period(opts.axial_period)?;
    if n <= opts.dense_max {
        return dense_pairing(x0, x1, opts.unit, opts.axial_period);
    }
    let wrapped_positions;
    let (x0, x1) = match opts.axial_period {
        None => (x0, x1),
        Some(length) => {
            wrapped_positions = (wrapped(x0, length), wrapped(x1, length));
            (&wrapped_positions.0[..], &wrapped_positions.1[..])
        }
    };
    let scale = cost::CostScale::new(x0, x1, opts.unit)?.with_period(opts.axial_period);
    let (mut s, _) = sparse(x0, x1, opts, &scale, true);
    s.seconds = start.elapsed().as_secs_f64();
    Ok(s)
}

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
/// auction on the enlarged graph (see `sparse`).
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
fn sparse(
    x0_in: &[[f64; 3]],
    x1_in: &[[f64; 3]],
    opts: &PairingOptions,
    scale: &cost::CostScale,
    allow_slabs: bool,
) -> (Pairing, usize) {
    let n = x0_in.len();
    let t = Instant::now();
    // Work on a Morton-ordered copy (cache locality); map back at the end.
    let (lo, hi) = order::bounds(x0_in, x1_in);
    let perm0 = order::morton_order(x0_in, lo, hi);
    let perm1 = order::morton_order(x1_in, lo, hi);
    let x0: Vec<[f64; 3]> = perm0.iter().map(|&i| x0_in[i as usize]).collect();
    let x1: Vec<[f64; 3]> = perm1.iter().map(|&i| x1_in[i as usize]).collect();
    let (x0, x1) = (&x0[..], &x1[..]);
    // On a periodic section the candidate search and the certificate's radius queries run
    // on the t0 points and their images one period away (docs/pairing.md#periodic-sections).
    let images = scale
        .period()
        .map(|length| candidates::Images::of(x0, length));
    let grid = match &images {
        None => candidates::Grid::new(x0),
        Some(images) => candidates::Grid::with_images(images),
    };
    trace!(t, "morton order + grid, n {n}");

    // Candidates and warm-start potentials follow the transport along the bed's long
    // axis (`candidates::Axial`; docs/pairing.md#long-drums).
    let axial = candidates::Axial::new(x0, x1);
    let centres = axial.centres(x1);
    let shift = axial.mean_abs_shift();
    trace!(t, "axial transport and centres");
    let knn_graph = |k: usize| {
        if images.is_some() {
            candidates::knn_images(&grid, x0, x1, &centres, k, scale)
        } else {
            let (kc, kw) = candidates::knn(&grid, x0, x1, &centres, k, scale);
            candidates::Graph::from_knn(k, kc, kw)
        }
    };
    // A bed with a large axial transport needs more candidates: the long kiln has no
    // perfect matching at k = 24, and finding that out costs the auction's whole budget
    // (docs/pairing.md#long-drums). The test is `shift > ρ`, ρ the mean cheapest
    // candidate cost of the k-graph, estimated on every `AXIAL_SAMPLE`-th row so that
    // the graph is built once, with the k it needs (building the k = 24 graph only to
    // throw it away cost 0.3 s on the long kiln). ρ itself is then taken on the whole
    // graph, as before.
    let k_axial = (opts.k_initial * AXIAL_K_NUM / AXIAL_K_DEN).clamp(1, n);
    let k_plain = opts.k_initial.min(n);
    let rho_sampled =
        candidates::mean_cheapest_sampled(&grid, x0, x1, &centres, k_plain, AXIAL_SAMPLE, scale)
            * scale.unit();
    let mut k0 = if shift > rho_sampled {
        k_axial
    } else {
        k_plain
    };
    trace!(t, "sampled mean cheapest pair");
    let mut graph = knn_graph(k0);
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
    let v_axial = axial.potentials(x0, rho, scale.unit());
    let mut eps0 = cheapest.initial_eps();
    let budget = AUCTION_BIDS_PER_ROW * n as u64;
    // With the certificate, the auction pauses at ε0 / AUCTION_REFINE for the
    // certificate searches below and resumes from there.
    let eps_pause = |eps0: i64| {
        if opts.certify {
            (eps0 / AUCTION_REFINE).max(1)
        } else {
            1
        }
    };
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
        slabs::Slabs::for_bed(n, axial.length(x0), rho)
    } else {
        None
    };
    let slab_count = cut.as_ref().map_or(1, slabs::Slabs::count);
    // The certificate's tree depends on the t0 points alone: it is built on the second
    // core while the first runs the sequential auction before the first search.
    let new_tree = || match &images {
        None => certificate::WeightedTree::new(x0),
        Some(images) => certificate::WeightedTree::with_images(images),
    };
    let build_tree = || opts.certify.then(new_tree);
    let (mut lap, mut bids, tree) = if let Some(cut) = cut {
        // The slabs stop where the certified path pauses (the global auction repairs
        // the seams at that ε, then carries on as below).
        let eps_slabs = (eps0 / AUCTION_REFINE).max(1);
        let (mut lap, slab_bids) = slabs::warm_start(
            &cut,
            &axial,
            &graph,
            x0,
            x1,
            scale,
            &v_axial,
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
            || lap.auction(&graph, eps_slabs, AUCTION_THETA, eps_pause(eps0), budget),
            build_tree,
        );
        trace!(
            t,
            "seams: auction {eps_slabs} -> {}: {seam_bids} bids, {} rows free",
            eps_pause(eps0),
            lap.free_rows()
        );
        (lap, slab_bids + seam_bids, tree)
    } else {
        let mut lap = sparse_lap::Lap::new(n);
        lap.set_potentials(&v_axial);
        lap.greedy_init(&graph);
        trace!(
            t,
            "axial potentials + row reduction: {} rows free",
            lap.free_rows()
        );
        let (bids, tree) = rayon::join(
            || lap.auction(&graph, eps0, AUCTION_THETA, eps_pause(eps0), budget),
            build_tree,
        );
        trace!(
            t,
            "auction eps0 {eps0} -> {}: {bids} bids, {} rows free",
            eps_pause(eps0),
            lap.free_rows()
        );
        (lap, bids, tree)
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
            graph = knn_graph(k0);
            lap = sparse_lap::Lap::new(n);
            lap.set_potentials(&v_axial);
            lap.greedy_init(&graph);
            eps0 = sparse_lap::Cheapest::of(&graph).initial_eps();
            bids += lap.auction(&graph, eps0, AUCTION_THETA, eps_pause(eps0), budget);
            trace!(t, "k doubled to {k0}, auction again: {bids} bids in all");
        } else {
            trace!(t, "Hopcroft-Karp: the graph has a perfect matching");
        }
    }
    let mut wtree = tree;
    let mut added = 0usize;
    let mut examined = 0u64;
    let mut paused = eps_pause(eps0) > 1;
    for _ in 0..AUCTION_ROUNDS {
        if !opts.certify || lap.col_of_row.contains(&sparse_lap::NONE) {
            break; // nothing to certify, or the auction stopped on its budget
        }
        let wtree = wtree.get_or_insert_with(new_tree);
        // A throwaway memo: these potentials satisfy ε-CS only, so a pass may also
        // return candidate edges (dropped by the merge). Its bounds would hold later too,
        // but carried over with the slack they made these passes search further while
        // round 1 still re-examined every row (docs/benchmarks.md).
        let check = certificate::check(
            wtree,
            x0,
            x1,
            &lap,
            &graph,
            scale,
            &mut certificate::Memo::new(0, AUCTION_PAIRS_PER_ROW),
        );
        examined += check.examined;
        trace!(
            t,
            "auction certificate search: {} examined, {}",
            check.examined,
            describe(&check.violations, x0, x1, scale)
        );
        if check.violations.is_empty() {
            break;
        }
        added += graph.insert(&check.violations, x0, x1, scale);
        // The auction frees the rows undercut by more than ε by a new edge.
        let resume = (eps0 / AUCTION_RESUME).clamp(1, eps_pause(eps0));
        bids += lap.auction(&graph, resume, AUCTION_THETA, 1, budget);
        trace!(t, "auction to 1: {bids} bids in all");
        paused = false;
    }
    if paused && !lap.col_of_row.contains(&sparse_lap::NONE) {
        bids += lap.auction(&graph, eps_pause(eps0), AUCTION_THETA, 1, budget);
        trace!(t, "auction to 1: {bids} bids in all");
    }
    let freed = lap.restore_invariant(&graph);
    trace!(t, "restore invariant: {freed} rows freed");

    // Optimal on the candidate graph, then the certificate; repair until it holds.
    // If a search finds no augmenting path, the graph has no perfect matching: add exit
    // edges on Hall-violating sets until Hopcroft–Karp finds a perfect matching, and
    // carry on from the same state.
    // The repair passes search a little beyond the violations (`Memo`): the auction's
    // pause ε (1/16 of the mean cheapest pair cost times two). On the long kiln this
    // spares rows whose `u` a repair solve raised by less: 7 % of the certificate's
    // time (slack 0: 0.78 s, 2^14 or 2^16 units: 0.72 s).
    let mut memo = certificate::Memo::new(eps0 / AUCTION_REFINE, certificate::MAX_ADDED_PER_ROW);
    let mut rounds = 0u32;
    let mut grown = 0usize;
    let certified = loop {
        rounds += 1;
        let work0 = lap.work;
        while let Err(failed) = lap.solve(&graph) {
            trace!(t, "solve failed at row {}: growth", failed.row);
            let before = grown;
            let mut m = feasibility::Matching::from_partial(&lap.col_of_row, &lap.row_of_col_vec());
            loop {
                let deficient = m.deficient_rows(&graph);
                if deficient.is_empty() {
                    break;
                }
                let more = feasibility::exit_edges(&graph, x0, x1, &deficient);
                grown += more.len();
                graph.insert(&more, x0, x1, scale);
            }
            // A failed search proves there is no perfect matching (the symmetric
            // difference with one would hold an augmenting path), so growth happened.
            assert!(
                grown > before,
                "internal error: search from row {} failed on a feasible graph",
                failed.row
            );
            lap.restore_invariant(&graph);
            trace!(t, "growth: {} exit edges in all", grown);
        }
        trace!(
            t,
            "round {rounds}: solve scanned {} columns",
            lap.work - work0
        );
        if !opts.certify {
            break false;
        }
        let wtree = wtree.get_or_insert_with(new_tree);
        let check = certificate::check(wtree, x0, x1, &lap, &graph, scale, &mut memo);
        examined += check.examined;
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
        added += graph.insert(&pairs, x0, x1, scale);
        let freed = lap.restore_invariant_on(&graph, touched);
        trace!(t, "round {rounds}: {freed} rows freed");
    };

    let total_cost = lap.mcost.iter().sum();
    trace!(
        t,
        "total cost {total_cost}, {bids} bids, {} columns scanned, {examined} examined",
        lap.work
    );
    // Back to the caller's numbering.
    let mut g = vec![0u32; n];
    for (p, &q) in lap.col_of_row.iter().enumerate() {
        g[perm1[p] as usize] = perm0[q as usize];
    }
    let pairing = Pairing {
        total_cost,
        total_distance: total_distance(x0_in, x1_in, &g, scale.period()),
        g,
        k_used: k0,
        certified,
        rounds,
        added_pairs: added,
        growth_pairs: grown,
        edges: graph.edges(),
        certificate_examined: examined,
        auction_bids: bids,
        seconds: 0.0,
    };
    (pairing, slab_count)
}

/// The tests' random beds: a xorshift64 stream of uniform numbers in [0, 1) from a fixed
/// seed, so that every run builds the same bed.
#[cfg(test)]
fn test_uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}
