//! The full (both-direction) Verlet list in CSR form. On rebuild the particles are re-sorted
//! in cell order (memory order is worth several times in the force loop) and every open
//! contact's history follows its pair into the new list.

use super::CellGrid;
use crate::contact::ContactHistory;
use crate::math::*;
use crate::particles::{permute_field, ParticleSet};
use rayon::prelude::*;

/// Particles per parallel task in the list build.
const BLOCK: usize = 512;

#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    /// Entries of slot `i` are `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<u32>,
    /// Neighbour slots.
    pub neighbors: Vec<u32>,
    /// History of each entry's contact (zero while open).
    pub history: Vec<ContactHistory>,
    /// `sqrt(contact area)` of each entry at the last step, 0 when not touching (the
    /// recorder's per-sample input).
    pub sqrt_area: Vec<f64>,
    /// Wall-contact histories, `walls` per particle, in slot order.
    pub wall_history: Vec<ContactHistory>,
    pub walls: usize,
    /// Extra distance beyond contact kept in the list.
    pub skin: f64,
    /// Positions at the last build; a rebuild is due when one has moved half the skin.
    pub pos_at_build: Vec<Vec3>,
    pub rebuilds: u64,
    /// Scratch of the cell sort.
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
}

impl NeighborList {
    pub fn new(particle_count: usize, walls: usize, skin: f64) -> Self {
        Self {
            wall_history: vec![ContactHistory::default(); particle_count * walls],
            walls,
            skin,
            ..Default::default()
        }
    }

    /// Whether any particle has moved more than half the skin since the last build.
    pub fn needs_rebuild(&self, particles: &ParticleSet) -> bool {
        if self.pos_at_build.len() != particles.len() {
            return true;
        }
        let limit = 0.25 * self.skin * self.skin;
        particles
            .pos
            .par_iter()
            .zip(self.pos_at_build.par_iter())
            .any(|(p, q)| {
                // a NaN displacement also forces a rebuild (and the out-of-drum check then reports it)
                let d2 = norm2(sub(*p, *q));
                d2.is_nan() || d2 > limit
            })
    }

    /// Re-sorts `particles` into cell order and rebuilds the list, carrying histories over.
    pub fn rebuild(&mut self, particles: &mut ParticleSet, grid: &CellGrid) {
        let n = particles.len();
        // 1. stable counting sort by cell: ties keep their previous order (deterministic)
        self.cell_of.clear();
        self.cell_of.extend(
            particles
                .pos
                .iter()
                .map(|&p| grid.index(grid.coords(p)) as u32),
        );
        self.cell_start.clear();
        self.cell_start.resize(grid.cell_count() + 1, 0);
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..grid.cell_count() {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let mut fill = self.cell_start.clone();
        let mut order = vec![0u32; n];
        for (old, &c) in self.cell_of.iter().enumerate() {
            order[fill[c as usize] as usize] = old as u32;
            fill[c as usize] += 1;
        }

        // 2. keep the old open contacts keyed by the partner's permanent id
        let old_offsets = std::mem::take(&mut self.offsets);
        let old_history = std::mem::take(&mut self.history);
        let old_partner_id: Vec<u32> = self
            .neighbors
            .iter()
            .map(|&j| particles.id[j as usize])
            .collect();

        // 3. move every per-particle array into cell order
        particles.permute(&order);
        if self.walls > 0 {
            let w = self.walls;
            let old = std::mem::take(&mut self.wall_history);
            self.wall_history = order
                .iter()
                .flat_map(|&o| old[o as usize * w..(o as usize + 1) * w].iter().copied())
                .collect();
        }
        let mut cell_sorted = std::mem::take(&mut self.cell_of);
        permute_field(&mut cell_sorted, &order);
        self.cell_of = cell_sorted;

        // 4. full list: slot i scans the 27 cells around its own, in a fixed order
        let skin = self.skin;
        let (pos, radius, ids) = (&particles.pos, &particles.radius, &particles.id);
        let cell_start = &self.cell_start;
        let blocks: Vec<(Vec<u32>, Vec<u32>, Vec<ContactHistory>)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let mut counts = Vec::with_capacity(hi - lo);
                let mut nbrs = Vec::new();
                let mut hist = Vec::new();
                for i in lo..hi {
                    let before = nbrs.len();
                    let ci = grid.coords(pos[i]);
                    let old_i = order[i] as usize;
                    let old_range = if old_offsets.is_empty() {
                        0..0
                    } else {
                        old_offsets[old_i] as usize..old_offsets[old_i + 1] as usize
                    };
                    for dz in -1i64..=1 {
                        for dy in -1i64..=1 {
                            for dx in -1i64..=1 {
                                let c = [ci[0] as i64 + dx, ci[1] as i64 + dy, ci[2] as i64 + dz];
                                if (0..3).any(|k| c[k] < 0 || c[k] >= grid.dims[k] as i64) {
                                    continue;
                                }
                                let cell =
                                    grid.index([c[0] as usize, c[1] as usize, c[2] as usize]);
                                for j in cell_start[cell] as usize..cell_start[cell + 1] as usize {
                                    if j == i {
                                        continue;
                                    }
                                    let cut = radius[i] + radius[j] + skin;
                                    if norm2(sub(pos[i], pos[j])) < cut * cut {
                                        nbrs.push(j as u32);
                                        let h = old_range
                                            .clone()
                                            .find(|&e| old_partner_id[e] == ids[j])
                                            .map_or(ContactHistory::default(), |e| old_history[e]);
                                        hist.push(h);
                                    }
                                }
                            }
                        }
                    }
                    counts.push((nbrs.len() - before) as u32);
                }
                (counts, nbrs, hist)
            })
            .collect();

        self.offsets = Vec::with_capacity(n + 1);
        self.offsets.push(0);
        self.neighbors.clear();
        for (counts, nbrs, hist) in blocks {
            for c in counts {
                let last = *self.offsets.last().unwrap();
                self.offsets.push(last + c);
            }
            self.neighbors.extend_from_slice(&nbrs);
            self.history.extend_from_slice(&hist);
        }
        self.sqrt_area.clear();
        self.sqrt_area.resize(self.neighbors.len(), 0.0);
        self.pos_at_build.clear();
        self.pos_at_build.extend_from_slice(&particles.pos);
        self.rebuilds += 1;
    }

    /// Entry range of slot `i`.
    #[inline(always)]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }
}
