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
mod sparse;
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
    let (mut s, _) = sparse::solve(x0, x1, opts, &scale, true);
    s.seconds = start.elapsed().as_secs_f64();
    Ok(s)
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
