//! The boundary maps: how the roles are handed over at each jump of the replay, through one
//! optimal pairing (the paper's method) or through a pool of fresh pairings in which the
//! recorded period's displacement along the drum's axis is drawn again (docs/method.md §6).
//!
//! Why fresh maps: one recorded period replayed again and again applies the same particle map
//! every period. Its random part (what this period's flow did beyond the mean flow) is then
//! repeated, so its errors add up like the number of periods, where the DEM draws a new one
//! each period and its own differences grow like the square root. Along the drum's axis the
//! flow is the same everywhere (away from the end caps), so what the recorded period did at
//! one place of the axis is as likely at another: moving it along the axis gives another
//! period of the same flow. Two ways are kept, because they mend different things (measured
//! in docs/validation.md#fresh-boundary-maps):
//!
//! - [`BoundaryMaps::FreshSteps`] redraws each particle's own axial step among the particles
//!   ending in the same cell of the cross-section. The particles' axial dispersion stays the
//!   recording's, and a particle no longer meets the same contacts (the hot mantle) on the
//!   same short cycle of the pairing for ever; but neighbours part by about a step each
//!   period, which mixes heat along the axis faster than the DEM does.
//! - [`BoundaryMaps::FreshDrift`] keeps each particle's step and moves only the period's
//!   coarse axial drift (the mean step of each bin of the axis in each cell of the
//!   cross-section, beyond the cell's mean over the axis) by a random offset along the axis:
//!   the drift the exact map repeats becomes a random walk, and neighbours stay neighbours.
//!   A cap zone keeps the drift near the end caps, where the caps' own circulation drives
//!   much the same drift every period, and moves only the middle's (for a drum short for its
//!   radius; docs/method.md, "The drift at the end caps").
//!
//! Between end caps a redrawn step stops at the bed's extent; in a section periodic along
//! its axis ([`AxialEnds::Periodic`]) steps are taken across the seam to the nearest image
//! and positions wrap, so the drift's bins tile the period and a moved drift is an exact
//! translation of the recorded one.

use crate::pairing::{self, PairingOptions};
use crate::ExtrapolateError;
use rand_xoshiro::rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::BTreeMap;
use std::ops::Range;
use tdex_format::extrapolation::FreshPool;
use tdex_format::Snapshot;

pub use tdex_format::extrapolation::Boundary;

/// Pairings per start in a pool: 8 and 128 give the same mean median as 32 within 0.01 on
/// eight beds of `heated_drum` over 100 periods (docs/validation.md#fresh-boundary-maps).
pub const DEFAULT_POOL: u32 = 32;
/// Width of the cross-section cells, in particle diameters: cells of 2 and 100 diameters
/// move the redrawn steps' mean median by at most 0.04 on the same beds.
pub const DEFAULT_CELL_DIAMETERS: f64 = 3.0;
/// Length of the axial bins of the drift, in particle diameters: bins of 1 and 4 diameters
/// move the mean median by at most 0.02 on eight beds of `axial_drum` over 100 periods.
pub const DEFAULT_BIN_DIAMETERS: f64 = 2.0;
/// How near an end cap the drift is kept rather than moved, in particle diameters: none by
/// default, since a long drum's caps' drift is half fresh and keeping it repeats that half
/// (docs/method.md#6-the-replay, "The drift at the end caps").
pub const DEFAULT_CAP_ZONE_DIAMETERS: f64 = 0.0;

/// The boundary maps an extrapolation asks for; the seed is the recurrence path's (the
/// case's unless given), so that one seed names the whole extrapolation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoundaryMaps {
    /// One optimal pairing per start, the same at every jump: the paper's method.
    Exact,
    /// A pool of `pool` pairings per start, each particle's axial step redrawn among the
    /// particles ending in its `cell_diameters`-wide cell of the cross-section.
    FreshSteps { pool: u32, cell_diameters: f64 },
    /// A pool of `pool` pairings per start, the coarse axial drift (bins of `bin_diameters`
    /// along the axis, cells of `cell_diameters` across) moved along the axis; the drift of
    /// the bins within `cap_zone_diameters` of an end cap is kept (0: every bin's is moved).
    FreshDrift {
        pool: u32,
        bin_diameters: f64,
        cell_diameters: f64,
        cap_zone_diameters: f64,
    },
}

impl BoundaryMaps {
    /// The boundary as the extrapolation file records it, with the seed it was drawn from.
    pub fn with_seed(self, seed: u64) -> Boundary {
        match self {
            BoundaryMaps::Exact => Boundary::Exact,
            BoundaryMaps::FreshSteps {
                pool,
                cell_diameters,
            } => Boundary::FreshSteps {
                pool,
                cell_diameters,
                seed,
            },
            BoundaryMaps::FreshDrift {
                pool,
                bin_diameters,
                cell_diameters,
                cap_zone_diameters,
            } => Boundary::FreshDrift {
                pool,
                bin_diameters,
                cell_diameters,
                cap_zone_diameters,
                seed,
            },
        }
    }
}

impl From<Boundary> for BoundaryMaps {
    /// The maps a file's boundary records, without the seed they were drawn from.
    fn from(boundary: Boundary) -> Self {
        match boundary {
            Boundary::Exact => BoundaryMaps::Exact,
            Boundary::FreshSteps {
                pool,
                cell_diameters,
                ..
            } => BoundaryMaps::FreshSteps {
                pool,
                cell_diameters,
            },
            Boundary::FreshDrift {
                pool,
                bin_diameters,
                cell_diameters,
                cap_zone_diameters,
                ..
            } => BoundaryMaps::FreshDrift {
                pool,
                bin_diameters,
                cell_diameters,
                cap_zone_diameters,
            },
        }
    }
}

/// The fresh maps asked of one recording, checked against how its axis ends: what each
/// start's pool redraws (lengths in particle diameters). A cap zone exists only between
/// end caps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Redraws {
    Steps {
        pool: u32,
        cell_diameters: f64,
        axis: AxialEnds,
    },
    Drift {
        pool: u32,
        grid_diameters: DriftGrid,
        ends: DriftEnds,
    },
}

/// A cap zone (in diameters) asked of a section periodic along its axis, which has no caps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapZoneWithoutCaps {
    pub cap_zone_diameters: f64,
}

impl Redraws {
    /// What `maps` redraws in a recording whose axis ends as `axis`: `Ok(None)` for the
    /// exact map; a cap zone in a section periodic along the axis is refused.
    pub fn of(maps: BoundaryMaps, axis: AxialEnds) -> Result<Option<Self>, CapZoneWithoutCaps> {
        Ok(match maps {
            BoundaryMaps::Exact => None,
            BoundaryMaps::FreshSteps {
                pool,
                cell_diameters,
            } => Some(Self::Steps {
                pool,
                cell_diameters,
                axis,
            }),
            BoundaryMaps::FreshDrift {
                pool,
                bin_diameters,
                cell_diameters,
                cap_zone_diameters,
            } => Some(Self::Drift {
                pool,
                grid_diameters: DriftGrid {
                    bin: bin_diameters,
                    cell: cell_diameters,
                },
                ends: match axis {
                    AxialEnds::Caps => DriftEnds::Caps {
                        kept_zone: cap_zone_diameters,
                    },
                    AxialEnds::Periodic { length } if cap_zone_diameters == 0.0 => {
                        DriftEnds::Periodic { length }
                    }
                    AxialEnds::Periodic { .. } => {
                        return Err(CapZoneWithoutCaps { cap_zone_diameters })
                    }
                },
            }),
        })
    }
}

/// The drift's grid: bins of `bin` along the axis, squares of `cell` across it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftGrid {
    pub bin: f64,
    pub cell: f64,
}

impl DriftGrid {
    fn scaled(self, by: f64) -> Self {
        Self {
            bin: self.bin * by,
            cell: self.cell * by,
        }
    }
}

/// How the drift's axis ends: between caps, where the drift of the bins whose centre is
/// within `kept_zone` of an end of the bed is kept (0: none is), or periodic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DriftEnds {
    Caps { kept_zone: f64 },
    Periodic { length: f64 },
}

impl DriftEnds {
    fn axis(self) -> AxialEnds {
        match self {
            Self::Caps { .. } => AxialEnds::Caps,
            Self::Periodic { length } => AxialEnds::Periodic { length },
        }
    }

    /// The ends with the cap zone (a length in diameters) in metres, for diameter `d`.
    fn scaled(self, d: f64) -> Self {
        match self {
            Self::Caps { kept_zone } => Self::Caps {
                kept_zone: kept_zone * d,
            },
            periodic => periodic,
        }
    }
}

/// How the drum's axis ends, which decides what a redrawn axial step does at an end: stop
/// there (end caps), or cross the seam and come back through the other face (a section
/// periodic along the axis, [`crate::axial_period`] of the recording).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxialEnds {
    Caps,
    Periodic { length: f64 },
}

impl AxialEnds {
    /// The ends of a recording whose section is periodic with `period` (or capped: `None`).
    pub fn of(period: Option<f64>) -> Self {
        period.map_or(Self::Caps, |length| Self::Periodic { length })
    }

    /// The span a redrawn position must stay in: the bed's extent between caps (from `pos`),
    /// the section `[−L/2, L/2)` when periodic.
    fn span(self, pos: &[[f64; 3]]) -> (f64, f64) {
        match self {
            Self::Caps => axial_extent(pos),
            Self::Periodic { length } => (-0.5 * length, 0.5 * length),
        }
    }

    /// The axial step from `from` to `to`: across the seam, the nearest image's (a recorded
    /// particle that crossed it moved by a fraction of a diameter, not by a period).
    fn step(self, from: f64, to: f64) -> f64 {
        match self {
            Self::Caps => to - from,
            Self::Periodic { length } => pairing::nearest_image(to - from, length),
        }
    }

    /// `y` brought back into `span`: stopped at a cap, or wrapped by whole periods.
    fn place(self, y: f64, span: (f64, f64)) -> f64 {
        match self {
            Self::Caps => y.clamp(span.0, span.1),
            Self::Periodic { length } => pairing::wrap(y, length),
        }
    }

    fn period(self) -> Option<f64> {
        match self {
            Self::Caps => None,
            Self::Periodic { length } => Some(length),
        }
    }
}

/// The extent of the bed along the axis, `(lowest, highest)` `y`.
fn axial_extent(pos: &[[f64; 3]]) -> (f64, f64) {
    pos.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        })
}

/// A uniform number in `[0, 1)` from one 64-bit draw.
fn unit(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// The end positions of one map with fresh steps, for the period from `start` (`t_{p−1}`) to
/// `end` (`t_p`): each particle keeps its recorded position across the drum (`x`, `z` at
/// `t_p`); along the axis it takes its position at `t_{p−1}` plus the step of another
/// particle, drawn without replacement among those ending in the same `cell`-wide square of
/// the cross-section. Between end caps the axial position stays within the bed's extent at
/// `t_{p−1}` (a step drawn near an end cap that would cross it stops at the cap); in a
/// periodic section steps are taken across the seam and positions wrap.
pub fn fresh_step_ends(
    start: &Snapshot,
    end: &Snapshot,
    cell: f64,
    axis: AxialEnds,
    rng: &mut Xoshiro256PlusPlus,
) -> Vec<[f64; 3]> {
    step_ends(start, end, &cross_section_cells(&end.pos, cell), axis, rng)
}

/// [`fresh_step_ends`] with the cross-section's cells found once for the whole pool.
fn step_ends(
    start: &Snapshot,
    end: &Snapshot,
    cells: &BTreeMap<(i64, i64), Vec<usize>>,
    axis: AxialEnds,
    rng: &mut Xoshiro256PlusPlus,
) -> Vec<[f64; 3]> {
    let span = axis.span(&start.pos);
    let mut ends = end.pos.clone();
    for members in cells.values() {
        let mut donors = members.clone();
        shuffle(&mut donors, rng);
        for (&a, &b) in members.iter().zip(&donors) {
            let step = axis.step(start.pos[b][1], end.pos[b][1]);
            ends[a][1] = axis.place(start.pos[a][1] + step, span);
        }
    }
    ends
}

/// The coarse axial drift of the period from `start` to `end`: for each `cell`-wide square
/// of the cross-section (keyed as [`cross_section_cells`]), the mean axial step of the
/// particles ending in each `bin`-long bin of the axis (from the lowest end), less the
/// square's mean over the axis (0 in an empty bin). What the exact map repeats at every
/// period. In a periodic section the bins tile the period (their length the nearest to
/// `bin` that divides it) and the steps are taken across the seam.
#[derive(Debug, Clone)]
pub struct AxialDrift {
    /// The span the bins cover, `(lowest, highest)` `y`: the bed's extent at the end between
    /// caps, the section in a periodic one.
    extent: (f64, f64),
    bin: f64,
    bins: usize,
    cell: f64,
    axis: AxialEnds,
    /// The bins whose drift is moved, among themselves: every bin, or those beyond the cap
    /// zone (the drift within it, the caps' own circulation, is kept).
    moved: Range<usize>,
    pub by_cell: BTreeMap<(i64, i64), Vec<f64>>,
}

impl AxialDrift {
    /// The drift of the period `start` → `end` on `grid`; between caps, the drift of the
    /// bins in the cap zone is kept.
    pub fn of(start: &Snapshot, end: &Snapshot, grid: DriftGrid, ends: DriftEnds) -> Self {
        let (axis, cell) = (ends.axis(), grid.cell);
        let extent = axis.span(&end.pos);
        let (bin, bins) = match axis {
            AxialEnds::Caps => (
                grid.bin,
                (((extent.1 - extent.0) / grid.bin).floor() as usize + 1).max(1),
            ),
            AxialEnds::Periodic { length } => {
                // whole bins around the seam, so that moving the drift by some of them is a
                // translation of the section onto itself
                let bins = ((length / grid.bin).round() as usize).max(1);
                (length / bins as f64, bins)
            }
        };
        let moved = match ends {
            DriftEnds::Caps {
                kept_zone: cap_zone,
            } if cap_zone > 0.0 => {
                let centre = |b: usize| extent.0 + (b as f64 + 0.5) * bin;
                let first = (0..bins).find(|&b| centre(b) >= extent.0 + cap_zone);
                let last = (0..bins).rev().find(|&b| centre(b) <= extent.1 - cap_zone);
                match (first, last) {
                    (Some(first), Some(last)) if last >= first => first..last + 1,
                    // the zones meet: the whole drift is the caps'
                    _ => 0..0,
                }
            }
            _ => 0..bins,
        };
        let mut drift = Self {
            extent,
            bin,
            bins,
            cell,
            axis,
            moved,
            by_cell: BTreeMap::new(),
        };
        for (key, members) in cross_section_cells(&end.pos, cell) {
            let mut sums = vec![(0.0, 0.0); bins];
            let mut total = 0.0;
            for &a in &members {
                let step = axis.step(start.pos[a][1], end.pos[a][1]);
                let b = drift.bin_of(end.pos[a][1]);
                sums[b].0 += step;
                sums[b].1 += 1.0;
                total += step;
            }
            let mean = total / members.len() as f64;
            let by_bin = sums
                .iter()
                .map(|&(sum, count)| if count > 0.0 { sum / count - mean } else { 0.0 })
                .collect();
            drift.by_cell.insert(key, by_bin);
        }
        drift
    }

    /// The bin of the axis `y` falls in (the last one for the highest particle).
    fn bin_of(&self, y: f64) -> usize {
        (((y - self.extent.0) / self.bin).floor() as usize).min(self.bins - 1)
    }

    /// The end positions of one map with a fresh drift: each particle keeps its recorded end
    /// position but for its bin's drift, which becomes the drift of the bin a random offset
    /// further along the axis (the same offset for the whole bed, wrapped around the moved
    /// bins), so that the drift's pattern, and every particle's place among its neighbours,
    /// is the recording's. A bin in a cap zone keeps its own drift. Positions stay within the
    /// bed's extent at the end between caps, and wrap in a periodic section.
    pub fn moved_ends(&self, end: &Snapshot, rng: &mut Xoshiro256PlusPlus) -> Vec<[f64; 3]> {
        let Range {
            start: first,
            end: past,
        } = self.moved;
        let span = (past - first).max(1);
        // one draw per map, whether or not any bin is moved: the later maps' draws stay put
        let offset = ((unit(rng) * span as f64) as usize).min(span - 1);
        end.pos
            .iter()
            .map(|&[x, y, z]| {
                let cell_drift = &self.by_cell[&cell_key(&[x, y, z], self.cell)];
                let b = self.bin_of(y);
                let source = if self.moved.contains(&b) {
                    first + (b - first + offset) % span
                } else {
                    b
                };
                let moved = y + cell_drift[source] - cell_drift[b];
                [x, self.axis.place(moved, self.extent), z]
            })
            .collect()
    }
}

/// The square of the cross-section, `cell` wide, that `p` falls in.
fn cell_key(p: &[f64; 3], cell: f64) -> (i64, i64) {
    ((p[0] / cell).floor() as i64, (p[2] / cell).floor() as i64)
}

/// The particles ending in each `cell`-wide square of the cross-section (`x`, `z`), in
/// index order within a square and squares in a fixed order: the shuffles, and so the maps,
/// are a function of the seed alone.
fn cross_section_cells(pos: &[[f64; 3]], cell: f64) -> BTreeMap<(i64, i64), Vec<usize>> {
    let mut cells: BTreeMap<(i64, i64), Vec<usize>> = BTreeMap::new();
    for (a, p) in pos.iter().enumerate() {
        cells.entry(cell_key(p, cell)).or_default().push(a);
    }
    cells
}

/// Fisher–Yates with Lemire's multiply-shift draw (as the recurrence path draws its starts):
/// one 64-bit draw per element, whatever the values.
fn shuffle(items: &mut [usize], rng: &mut Xoshiro256PlusPlus) {
    for i in (1..items.len()).rev() {
        let j = ((u128::from(rng.next_u64()) * (i as u128 + 1)) >> 64) as usize;
        items.swap(i, j);
    }
}

/// A pool of fresh pairings of one period's end to one start.
#[derive(Debug, Clone)]
pub struct Pool {
    /// `maps[m][a]`: the role at the start that particle `a` takes, in pairing `m`.
    pub maps: Vec<Vec<u32>>,
    pub summary: FreshPool,
}

/// The pool of fresh pairings `redraws` asks for, of the period from `before` (`t_{p−1}`)
/// to `end` (`t_p`) into `start` (the snapshot, or its image, a jump enters), drawn from
/// `seed`; in a periodic section the pairings take their distances across the seam, as the
/// exact one does.
pub fn fresh_pool(
    redraws: Redraws,
    before: &Snapshot,
    end: &Snapshot,
    start: &Snapshot,
    seed: u64,
) -> Result<Pool, ExtrapolateError> {
    let d = start.mean_diameter();
    // what the pool's maps share, found once: the cells whose steps are redrawn, or the drift
    enum Redraw {
        Steps(BTreeMap<(i64, i64), Vec<usize>>),
        Drift(AxialDrift),
    }
    let (pool, axis, redraw) = match redraws {
        Redraws::Steps {
            pool,
            cell_diameters,
            axis,
        } => (
            pool,
            axis,
            Redraw::Steps(cross_section_cells(&end.pos, cell_diameters * d)),
        ),
        Redraws::Drift {
            pool,
            grid_diameters,
            ends,
        } => (
            pool,
            ends.axis(),
            Redraw::Drift(AxialDrift::of(
                before,
                end,
                grid_diameters.scaled(d),
                ends.scaled(d),
            )),
        ),
    };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut pairings = Vec::with_capacity(pool as usize);
    let mut means = Vec::with_capacity(pool as usize);
    for _ in 0..pool {
        let ends = match &redraw {
            Redraw::Steps(cells) => step_ends(before, end, cells, axis, &mut rng),
            Redraw::Drift(drift) => drift.moved_ends(end, &mut rng),
        };
        // the moved ends are `end`'s particles: each keeps its radius, and its role's
        let opts = PairingOptions {
            axial_period: axis.period(),
            ..PairingOptions::for_bed(d, &start.pos, &ends)
        };
        let p = pairing::pair_by_size(&start.pos, &start.radius, &ends, &end.radius, &opts)?;
        means.push(p.mean_distance_in_diameters(d));
        pairings.push(p.g);
    }
    let mean = means.iter().sum::<f64>() / means.len().max(1) as f64;
    Ok(Pool {
        maps: pairings,
        summary: FreshPool {
            end: end.index,
            start: start.index,
            pairings: pool,
            mean_distance_diameters: mean,
            min_mean_distance_diameters: means.iter().copied().fold(f64::INFINITY, f64::min),
            max_mean_distance_diameters: means.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        },
    })
}

/// Which pairing of a pool each jump uses: a stream of its own, seeded from the boundary's
/// seed, so that the recurrence path's draws (from the path seed) are the same with either
/// boundary.
#[derive(Debug, Clone)]
pub struct PoolDraws {
    rng: Xoshiro256PlusPlus,
}

impl PoolDraws {
    pub fn new(seed: u64) -> Self {
        // a stream 2^192 draws away from the pools' own, which start at seeds near `seed`
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        rng.long_jump();
        Self { rng }
    }

    /// One of `0..pool`, uniformly (Lemire's multiply-shift, as [`shuffle`]).
    pub fn next(&mut self, pool: usize) -> usize {
        ((u128::from(self.rng.next_u64()) * pool as u128) >> 64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn redraws(maps: BoundaryMaps) -> Redraws {
        Redraws::of(maps, AxialEnds::Caps).unwrap().unwrap()
    }

    fn grid(bin: f64, cell: f64) -> DriftGrid {
        DriftGrid { bin, cell }
    }

    fn caps(kept_zone: f64) -> DriftEnds {
        DriftEnds::Caps { kept_zone }
    }

    fn snapshot(index: u32, pos: Vec<[f64; 3]>) -> Snapshot {
        let n = pos.len();
        Snapshot {
            index,
            time: f64::from(index),
            id: (0..n as u32).collect(),
            pos,
            radius: vec![0.5; n],
            vel: vec![[0.0; 3]; n],
            temp: vec![300.0; n],
        }
    }

    /// A uniform number in `[-0.5, 0.5)`.
    fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
        (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    /// A random bed of unit spheres' centres, one per unit volume, in a box `wx × wy × wz`.
    fn random_bed(n: usize, (wx, wy, wz): (f64, f64, f64), seed: u64) -> Vec<[f64; 3]> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                [
                    wx * (uniform(&mut rng) + 0.5),
                    wy * (uniform(&mut rng) + 0.5),
                    wz * (uniform(&mut rng) + 0.5),
                ]
            })
            .collect()
    }

    /// `start` a period later: a drift along the axis that changes sign every 6 (±0.8), and
    /// a step of each particle's own besides, the end position brought back by `place`.
    fn banded_drift(
        start: &Snapshot,
        rng: &mut Xoshiro256PlusPlus,
        place: impl Fn(f64) -> f64,
    ) -> Snapshot {
        let mut end_pos = start.pos.clone();
        for p in end_pos.iter_mut() {
            let drift = if (p[1] / 6.0).floor() as i64 % 2 == 0 {
                0.8
            } else {
                -0.8
            };
            p[1] = place(p[1] + drift + uniform(rng));
        }
        snapshot(1, end_pos)
    }

    #[test]
    fn fresh_steps_keep_the_cross_section_and_redraw_each_cells_axial_steps() {
        let mut start_pos = random_bed(2000, (10.0, 50.0, 4.0), 1);
        // two particles far along the axis, alone in their cell, so that no step is clamped
        start_pos.push([100.0, -100.0, 100.0]);
        start_pos.push([100.0, 200.0, 100.0]);
        let start = snapshot(0, start_pos);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
        let mut end_pos = start.pos.clone();
        for p in end_pos.iter_mut().take(2000) {
            p[0] += uniform(&mut rng);
            p[1] += 3.0 * uniform(&mut rng);
            p[2] += uniform(&mut rng);
        }
        let end = snapshot(1, end_pos);
        let ends = fresh_step_ends(&start, &end, 2.0, AxialEnds::Caps, &mut rng);
        let mut redrawn = 0;
        for members in cross_section_cells(&end.pos, 2.0).values() {
            let sorted = |mut steps: Vec<f64>| {
                steps.sort_by(f64::total_cmp);
                steps
            };
            let recorded = sorted(
                members
                    .iter()
                    .map(|&a| end.pos[a][1] - start.pos[a][1])
                    .collect(),
            );
            let drawn = sorted(
                members
                    .iter()
                    .map(|&a| ends[a][1] - start.pos[a][1])
                    .collect(),
            );
            for (r, d) in recorded.iter().zip(&drawn) {
                assert!((r - d).abs() < 1e-9, "steps {r} and {d}");
            }
            for &a in members {
                assert_eq!([ends[a][0], ends[a][2]], [end.pos[a][0], end.pos[a][2]]);
                redrawn += usize::from(ends[a][1] != end.pos[a][1]);
            }
        }
        assert!(redrawn > 1500, "only {redrawn} of 2000 steps redrawn");
    }

    #[test]
    fn a_step_that_would_cross_an_end_cap_stops_at_it() {
        let start = snapshot(0, vec![[0.0, 0.0, 0.0], [0.0, 10.0, 0.0]]);
        let end = snapshot(1, vec![[0.0, -5.0, 0.0], [0.0, 15.0, 0.0]]);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        for _ in 0..8 {
            let ends = fresh_step_ends(&start, &end, 3.0, AxialEnds::Caps, &mut rng);
            assert!(
                ends.iter().all(|p| (0.0..=10.0).contains(&p[1])),
                "{ends:?}"
            );
        }
    }

    /// The calibration: on a synthetic bed whose recorded period moves one half of the
    /// cross-section (`x < 4`) along the axis by +1.5 and the other by −1.5, each particle with
    /// an independent step of its own besides, the exact pairing repeated carries that
    /// counterflow again every period (its mean square displacement grows like k²). Redrawn
    /// across the whole cross-section, the fresh maps make it a random walk at the recorded
    /// steps' own mean square (it grows like k); redrawn within cells that separate the two
    /// halves, they keep it, as they keep the flow's mean at every place of the cross-section.
    #[test]
    fn fresh_maps_recover_the_recorded_axial_dispersion_where_the_exact_map_drifts() {
        let start = snapshot(0, random_bed(3000, (8.0, 120.0, 3.0), 3));
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        let mut end_pos = start.pos.clone();
        for p in end_pos.iter_mut() {
            let drift = if p[0] < 4.0 { 1.5 } else { -1.5 };
            p[1] += drift + 4.0 * uniform(&mut rng);
        }
        let end = snapshot(1, end_pos);
        let y0: Vec<f64> = start.pos.iter().map(|p| p[1]).collect();
        let recorded = (0..y0.len())
            .map(|a| (end.pos[a][1] - y0[a]).powi(2))
            .sum::<f64>()
            / y0.len() as f64;
        // the axial mean square displacement of the heat after `k` periods, over the parcels
        // starting in the middle (the ends, 40 away, confine none of them): a parcel starting
        // at role a is at role map_k(…map_1(a)) of the start
        let msd_after = |map: &mut dyn FnMut() -> Vec<u32>, k: usize| {
            let mid: Vec<usize> = (0..y0.len())
                .filter(|&a| (40.0..80.0).contains(&y0[a]))
                .collect();
            let mut role = mid.clone();
            for _ in 0..k {
                let g = map();
                for r in role.iter_mut() {
                    *r = g[*r] as usize;
                }
            }
            mid.iter()
                .zip(&role)
                .map(|(&a, &r)| (y0[r] - y0[a]).powi(2))
                .sum::<f64>()
                / mid.len() as f64
        };
        let d = start.mean_diameter();
        let exact = pairing::pair(
            &start.pos,
            &end.pos,
            &PairingOptions::for_bed(d, &start.pos, &end.pos),
        )
        .unwrap()
        .g;
        let k = 10;
        let fresh_msd = |cell: f64| {
            let steps = BoundaryMaps::FreshSteps {
                pool: 16,
                cell_diameters: cell / d,
            };
            let pool = fresh_pool(redraws(steps), &start, &end, &start, 3).unwrap();
            let mut draws = PoolDraws::new(3);
            msd_after(&mut || pool.maps[draws.next(16)].clone(), k)
        };
        let exact_msd = msd_after(&mut || exact.clone(), k);
        let across = fresh_msd(100.0);
        let within_halves = fresh_msd(4.0);
        let random_walk = k as f64 * recorded;
        assert!(
            (0.8..1.25).contains(&(across / random_walk)),
            "fresh {across}, a random walk at the recorded rate {random_walk}"
        );
        // the counterflow alone moves a parcel 15 in 10 periods: 225 beside the walk's 36
        assert!(
            exact_msd > 4.0 * across,
            "exact {exact_msd}, fresh {across}"
        );
        assert!(
            within_halves > 4.0 * across,
            "fresh within the halves {within_halves}, across {across}"
        );
    }

    /// In a periodic section a step is taken across the seam (a particle that left through
    /// one face and came back through the other moved by its step, not by a period), and a
    /// redrawn position wraps into the section instead of stopping at an end.
    #[test]
    fn in_a_periodic_section_steps_cross_the_seam_and_positions_wrap() {
        let axis = AxialEnds::Periodic { length: 10.0 };
        // one cell of the cross-section: the first crosses the seam (4.5 → −4.5, a step of
        // +1), the second moves 0.5 in the middle
        let start = snapshot(0, vec![[0.0, 4.5, 0.0], [0.0, 0.0, 0.0]]);
        let end = snapshot(1, vec![[0.0, -4.5, 0.0], [0.0, 0.5, 0.0]]);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let mut swapped = false;
        for _ in 0..16 {
            let ends = fresh_step_ends(&start, &end, 3.0, axis, &mut rng);
            assert!(ends.iter().all(|p| (-5.0..5.0).contains(&p[1])), "{ends:?}");
            let mut steps: Vec<f64> = (0..2)
                .map(|a| axis.step(start.pos[a][1], ends[a][1]))
                .collect();
            swapped |= (steps[0] - 0.5).abs() < 1e-12;
            steps.sort_by(f64::total_cmp);
            assert!((steps[0] - 0.5).abs() < 1e-12 && (steps[1] - 1.0).abs() < 1e-12);
        }
        assert!(swapped, "the steps are redrawn");
        // between end caps the same recording's crossing is a step of −9 and stops at a cap
        let capped = fresh_step_ends(&start, &end, 3.0, AxialEnds::Caps, &mut rng);
        assert!(
            capped.iter().all(|p| (0.0..=4.5).contains(&p[1])),
            "{capped:?}"
        );
    }

    /// In a periodic section the drift's bins tile the period, so a fresh drift is the
    /// recorded one moved round the section: every bin of a cell moves as one, by the drift
    /// of the bin one offset further less its own, and the ends stay in the section.
    #[test]
    fn a_periodic_drift_tiles_the_section_and_moves_round_it() {
        let length = 60.0;
        let axis = AxialEnds::Periodic { length };
        let bed = random_bed(3000, (8.0, length, 3.0), 11);
        let start = snapshot(0, bed.iter().map(|&[x, y, z]| [x, y - 30.0, z]).collect());
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let end = banded_drift(&start, &mut rng, |y| pairing::wrap(y, length));
        let periodic = DriftEnds::Periodic { length };
        let odd = AxialDrift::of(&start, &end, grid(7.0, 4.0), periodic);
        assert_eq!((odd.bins, odd.bin), (9, length / 9.0));
        let recorded = AxialDrift::of(&start, &end, grid(2.0, 4.0), periodic);
        assert_eq!(recorded.bins, 30);
        // the recorded drift carries the ±0.8 pattern
        let cell0 = &recorded.by_cell[&(0, 0)];
        let spread = cell0.iter().map(|d| d * d).sum::<f64>() / cell0.len() as f64;
        assert!(spread > 0.3, "{cell0:?}");
        let mut offsets_seen = std::collections::BTreeSet::new();
        for _ in 0..6 {
            let ends = recorded.moved_ends(&end, &mut rng);
            assert!(ends.iter().all(|p| (-30.0..30.0).contains(&p[1])));
            let offset = (0..recorded.bins)
                .find(|&o| {
                    end.pos.iter().zip(&ends).all(|(e, m)| {
                        let drift = &recorded.by_cell[&cell_key(e, 4.0)];
                        let b = recorded.bin_of(e[1]);
                        let by = axis.step(e[1], m[1]);
                        (drift[(b + o) % recorded.bins] - drift[b] - by).abs() < 1e-9
                    })
                })
                .expect("one offset explains every particle's move");
            offsets_seen.insert(offset);
        }
        assert!(offsets_seen.len() > 1, "{offsets_seen:?}");
    }

    /// A section periodic along its axis has no caps: a cap zone there is refused when the
    /// maps are planned, and a drift without one keeps the section's period.
    #[test]
    fn a_cap_zone_is_planned_only_between_caps() {
        let drift = |cap_zone_diameters| BoundaryMaps::FreshDrift {
            pool: 4,
            bin_diameters: 2.0,
            cell_diameters: 3.0,
            cap_zone_diameters,
        };
        let periodic = AxialEnds::Periodic { length: 30.0 };
        assert_eq!(
            Redraws::of(drift(2.5), periodic),
            Err(CapZoneWithoutCaps {
                cap_zone_diameters: 2.5
            })
        );
        let planned = |maps, axis| match Redraws::of(maps, axis) {
            Ok(Some(Redraws::Drift { ends, .. })) => ends,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            planned(drift(0.0), periodic),
            DriftEnds::Periodic { length: 30.0 }
        );
        assert_eq!(
            planned(drift(2.5), AxialEnds::Caps),
            DriftEnds::Caps { kept_zone: 2.5 }
        );
    }

    #[test]
    fn the_drift_is_each_bins_mean_step_beyond_its_cells_mean() {
        // one cell of the cross-section; bins of 2 along the axis from the lowest end, y = 0
        let at = |ys: [f64; 4]| ys.iter().map(|&y| [0.5, y, 0.5]).collect::<Vec<_>>();
        let start = snapshot(0, at([-1.0, 0.5, 3.0, 5.0]));
        let end = snapshot(1, at([0.0, 1.5, 2.5, 5.0]));
        // steps 1, 1, −0.5, 0 (mean 0.375); ends in bins 0, 0, 1, 2
        let drift = AxialDrift::of(&start, &end, grid(2.0, 3.0), caps(0.0)).by_cell;
        assert_eq!(drift.len(), 1);
        let bins = &drift[&(0, 0)];
        let expected = [1.0 - 0.375, -0.5 - 0.375, 0.0 - 0.375];
        assert_eq!(bins.len(), 3);
        for (b, e) in bins.iter().zip(expected) {
            assert!((b - e).abs() < 1e-12, "{bins:?}");
        }
    }

    /// A fresh drift moves every particle of a bin (in one cell of the cross-section) by the
    /// same amount, the drift of the bin one offset further less its own: the drift's
    /// pattern is the recording's, moved along the axis, and neighbours stay neighbours.
    #[test]
    fn a_fresh_drift_moves_each_bin_as_one_by_the_drift_of_another() {
        let start = snapshot(0, random_bed(3000, (8.0, 60.0, 3.0), 7));
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
        let end = banded_drift(&start, &mut rng, |y| y.clamp(0.0, 60.0));
        let (bin, cell) = (2.0, 4.0);
        let recorded = AxialDrift::of(&start, &end, grid(bin, cell), caps(0.0));
        let drift = &recorded.by_cell;
        let spread = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
        let mut offsets_seen = std::collections::BTreeSet::new();
        for _ in 0..6 {
            let ends = recorded.moved_ends(&end, &mut rng);
            let (lowest, highest) = axial_extent(&end.pos);
            let bins = ((highest - lowest) / bin).floor() as usize + 1;
            let mut moved_by: BTreeMap<((i64, i64), usize), f64> = BTreeMap::new();
            for (a, e) in end.pos.iter().enumerate() {
                assert_eq!([ends[a][0], ends[a][2]], [e[0], e[2]]);
                let key = cell_key(e, cell);
                let b = (((e[1] - lowest) / bin).floor() as usize).min(bins - 1);
                let by = ends[a][1] - e[1];
                let unclamped = (lowest..=highest).contains(&(e[1] + by))
                    && ends[a][1] > lowest
                    && ends[a][1] < highest;
                if unclamped {
                    let first = *moved_by.entry((key, b)).or_insert(by);
                    assert!((first - by).abs() < 1e-12, "a bin moved apart");
                }
            }
            // the one offset: every cell's bins moved by drift[b + o] − drift[b]
            let cell0 = &drift[&(0, 0)];
            let offset = (0..bins)
                .find(|&o| {
                    moved_by
                        .iter()
                        .filter(|((k, _), _)| *k == (0, 0))
                        .all(|((_, b), by)| (cell0[(b + o) % bins] - cell0[*b] - by).abs() < 1e-9)
                })
                .expect("one offset explains every bin's move");
            offsets_seen.insert(offset);
        }
        assert!(
            offsets_seen.len() > 1,
            "the offset is drawn: {offsets_seen:?}"
        );
        // the recorded drift carries the ±0.8 pattern: each bin's drift is far from 0
        assert!(spread(&drift[&(0, 0)]) > 0.3, "{:?}", drift[&(0, 0)]);
    }

    #[test]
    fn a_cap_zone_keeps_the_drift_near_the_caps_and_moves_the_middles_among_its_bins() {
        let start = snapshot(0, random_bed(3000, (8.0, 60.0, 3.0), 7));
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
        let end = banded_drift(&start, &mut rng, |y| y.clamp(0.0, 60.0));
        let (bin, cell, zone) = (2.0, 4.0, 8.0);
        let drift = AxialDrift::of(&start, &end, grid(bin, cell), caps(zone));
        let (lowest, highest) = axial_extent(&end.pos);
        // the moved bins are those whose centre is at least `zone` from both ends of the bed
        let centre = |b: usize| lowest + (b as f64 + 0.5) * bin;
        for b in 0..drift.bins {
            let inside = centre(b) >= lowest + zone && centre(b) <= highest - zone;
            assert_eq!(drift.moved.contains(&b), inside, "bin {b}");
        }
        let mut middle_moved = false;
        for _ in 0..6 {
            let ends = drift.moved_ends(&end, &mut rng);
            for (a, e) in end.pos.iter().enumerate() {
                let b = drift.bin_of(e[1]);
                let by = ends[a][1] - e[1];
                if !drift.moved.contains(&b) {
                    // y + drift[b] − drift[b]: the recorded end, to rounding
                    assert_eq!([ends[a][0], ends[a][2]], [e[0], e[2]]);
                    assert!(
                        by.abs() < 1e-12,
                        "a particle in a cap zone keeps its end: {by}"
                    );
                } else {
                    // the drift it takes is a middle bin's: within the moved bins' range
                    let cell_drift = &drift.by_cell[&cell_key(e, cell)];
                    let taken = cell_drift[b] + by;
                    let clamped = ends[a][1] <= lowest || ends[a][1] >= highest;
                    assert!(
                        clamped
                            || drift
                                .moved
                                .clone()
                                .any(|m| (cell_drift[m] - taken).abs() < 1e-9),
                        "particle {a} took a drift no middle bin has"
                    );
                    middle_moved |= by.abs() > 1e-9;
                }
            }
        }
        assert!(middle_moved, "the middle's drift is moved");
        // a zone reaching the middle from both caps keeps the whole drift: the recorded ends
        let kept = AxialDrift::of(&start, &end, grid(bin, cell), caps(31.0));
        assert!(kept.moved.is_empty());
        let kept_ends = kept.moved_ends(&end, &mut rng);
        for (moved, recorded) in kept_ends.iter().zip(&end.pos) {
            assert!((moved[1] - recorded[1]).abs() < 1e-12);
        }
        // no zone moves every bin, as before there was one
        let all = AxialDrift::of(&start, &end, grid(bin, cell), caps(0.0));
        assert_eq!(all.moved, 0..all.bins);
    }

    #[test]
    fn the_pool_is_a_function_of_the_seed_and_its_maps_are_permutations() {
        let start = snapshot(0, random_bed(500, (6.0, 30.0, 3.0), 5));
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(6);
        let mut end_pos = start.pos.clone();
        for p in end_pos.iter_mut() {
            p[1] += 3.0 * uniform(&mut rng);
        }
        let end = snapshot(1, end_pos);
        let steps = BoundaryMaps::FreshSteps {
            pool: 4,
            cell_diameters: 3.0,
        };
        let pool = |seed| fresh_pool(redraws(steps), &start, &end, &start, seed).unwrap();
        let (one, again, other) = (pool(9), pool(9), pool(10));
        assert_eq!(Redraws::of(BoundaryMaps::Exact, AxialEnds::Caps), Ok(None));
        assert_eq!(one.maps, again.maps);
        assert_ne!(one.maps, other.maps);
        assert_ne!(one.maps[0], one.maps[1]);
        for g in &one.maps {
            let mut seen = vec![false; g.len()];
            for &r in g {
                assert!(!std::mem::replace(&mut seen[r as usize], true));
            }
        }
        let mut a = PoolDraws::new(9);
        let mut b = PoolDraws::new(9);
        let drawn: Vec<usize> = (0..50).map(|_| a.next(4)).collect();
        assert_eq!(drawn, (0..50).map(|_| b.next(4)).collect::<Vec<_>>());
        assert!((0..4).all(|m| drawn.contains(&m)));
    }
}
