//! The half Verlet list in CSR form (each pair once, partner after the particle in slot
//! order) and the wall candidates, with every contact's history stored next to its entry.
//! On rebuild the particles are re-sorted in cell order (memory order is worth several times
//! in the force loop) and every open contact's history follows its pair into the new list.

use super::CellGrid;
use crate::contact::contact_sphere_sphere::{effective, overlapping};
use crate::contact::ContactHistory;
use crate::math::*;
use crate::particles::ParticleSet;
use crate::wall::WallSet;
use rayon::prelude::*;

/// Particles per parallel task in the list build.
const BLOCK: usize = 512;

#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    /// Entries of slot `i` are `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<u32>,
    /// Partner slots, each greater than the owner's slot and in its layer or the next.
    pub neighbors: Vec<u32>,
    /// History of each entry's contact, seen from the owner (zero while open).
    pub history: Vec<ContactHistory>,
    /// Whether each entry touched at the last step (its history is non-zero only then).
    pub touching: Vec<bool>,
    /// First slot of each layer of the cell grid, and the particle count at the end.
    pub layer_start: Vec<u32>,
    /// Wall candidates of slot `i` are `wall_offsets[i]..wall_offsets[i + 1]`.
    pub wall_offsets: Vec<u32>,
    /// The wall of each candidate.
    pub wall_index: Vec<u8>,
    pub wall_history: Vec<ContactHistory>,
    pub wall_touching: Vec<bool>,
    /// Extra distance beyond contact kept in the list.
    pub skin: f64,
    /// Positions at the last build; a rebuild is due when one has moved half the skin (the
    /// drift of `integrate::initial_integrate` tests it).
    pub pos_at_build: Vec<Vec3>,
    pub rebuilds: u64,
    /// `(R*, m*)` of every pair when all spheres have one radius and one mass (the pair
    /// stage then skips two divisions per pair).
    pub uniform_pair: Option<(f64, f64)>,
    /// Scratch of the cell sort.
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
    order: Vec<u32>,
}

/// Open contacts carried through a rebuild, grouped by the permanent id of their owner.
struct Carried {
    /// Contacts of id `a` are `start[a]..start[a + 1]`.
    start: Vec<u32>,
    /// Partner id (walls: particle count + wall index) and history seen from the owner.
    contacts: Vec<(u32, ContactHistory)>,
}

impl Carried {
    fn find(&self, owner: u32, partner: u32) -> Option<ContactHistory> {
        let range = self.start[owner as usize] as usize..self.start[owner as usize + 1] as usize;
        self.contacts[range]
            .iter()
            .find(|(p, _)| *p == partner)
            .map(|&(_, h)| h)
    }

    /// The history of the pair `(a, b)` seen from `a`, wherever it was stored.
    fn pair(&self, a: u32, b: u32) -> Option<ContactHistory> {
        self.find(a, b)
            .or_else(|| self.find(b, a).map(ContactHistory::reversed))
    }
}

impl NeighborList {
    pub fn new(skin: f64) -> Self {
        Self {
            skin,
            ..Default::default()
        }
    }

    /// The open contacts (pairs and walls) by owner id; the old lists are released.
    fn take_open_contacts(&mut self, ids: &[u32]) -> Carried {
        let n = ids.len();
        let mut start = vec![0u32; n + 1];
        let owners = (0..self.offsets.len().saturating_sub(1)).flat_map(|i| {
            let pairs = self.offsets[i] as usize..self.offsets[i + 1] as usize;
            let walls = self.wall_offsets[i] as usize..self.wall_offsets[i + 1] as usize;
            pairs
                .filter(|&e| self.touching[e])
                .chain(walls.filter(|&e| self.wall_touching[e]))
                .map(move |_| ids[i])
        });
        for owner in owners {
            start[owner as usize + 1] += 1;
        }
        for a in 0..n {
            start[a + 1] += start[a];
        }
        let mut fill = start.clone();
        let mut contacts = vec![(0u32, ContactHistory::default()); start[n] as usize];
        for i in 0..self.offsets.len().saturating_sub(1) {
            let owner = ids[i] as usize;
            let mut put = |partner: u32, h: ContactHistory| {
                contacts[fill[owner] as usize] = (partner, h);
                fill[owner] += 1;
            };
            for e in self.offsets[i] as usize..self.offsets[i + 1] as usize {
                if self.touching[e] {
                    put(ids[self.neighbors[e] as usize], self.history[e]);
                }
            }
            for e in self.wall_offsets[i] as usize..self.wall_offsets[i + 1] as usize {
                if self.wall_touching[e] {
                    put(n as u32 + self.wall_index[e] as u32, self.wall_history[e]);
                }
            }
        }
        for list in [&mut self.history, &mut self.wall_history] {
            *list = Vec::new();
        }
        self.neighbors = Vec::new();
        self.touching = Vec::new();
        self.wall_index = Vec::new();
        self.wall_touching = Vec::new();
        Carried { start, contacts }
    }

    /// Re-sorts `particles` into cell order and rebuilds the lists, carrying histories over.
    pub fn rebuild(&mut self, particles: &mut ParticleSet, grid: &CellGrid, walls: &WallSet) {
        let n = particles.len();
        let carried = self.take_open_contacts(&particles.id);

        // 1. stable counting sort by cell: ties keep their previous order (deterministic)
        particles
            .pos
            .par_iter()
            .map(|&p| grid.index(grid.coords(p)) as u32)
            .collect_into_vec(&mut self.cell_of);
        self.cell_start.clear();
        self.cell_start.resize(grid.cell_count() + 1, 0);
        for &c in &self.cell_of {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..grid.cell_count() {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        let mut fill = self.cell_start.clone();
        self.order.clear();
        self.order.resize(n, 0);
        for (old, &c) in self.cell_of.iter().enumerate() {
            self.order[fill[c as usize] as usize] = old as u32;
            fill[c as usize] += 1;
        }
        particles.permute(&self.order);
        let per_layer = grid.cells_per_layer();
        self.layer_start.clear();
        self.layer_start
            .extend((0..=grid.layers()).map(|l| self.cell_start[l * per_layer]));

        // 2. half list: slot i scans the cells around its own, in a fixed order, for j > i
        let skin = self.skin;
        let (pos, radius, ids) = (&particles.pos, &particles.radius, &particles.id);
        let cell_start = &self.cell_start;
        let carried = &carried;
        let blocks: Vec<ListBlock> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut block = ListBlock::default();
                for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                    let before = block.neighbors.len();
                    let ci = grid.coords(pos[i]);
                    let own_cell = grid.index(ci);
                    for dz in -1i64..=1 {
                        for dy in -1i64..=1 {
                            for dx in -1i64..=1 {
                                let c = [ci[0] as i64 + dx, ci[1] as i64 + dy, ci[2] as i64 + dz];
                                if (0..3).any(|k| c[k] < 0 || c[k] >= grid.dims[k] as i64) {
                                    continue;
                                }
                                let cell =
                                    grid.index([c[0] as usize, c[1] as usize, c[2] as usize]);
                                if cell < own_cell {
                                    continue;
                                }
                                let first = (cell_start[cell] as usize).max(i + 1);
                                for j in first..cell_start[cell + 1] as usize {
                                    let cut = radius[i] + radius[j] + skin;
                                    let delta = sub(pos[i], pos[j]);
                                    if norm2(delta) < cut * cut {
                                        // a history matters only to a pair touching now (the
                                        // pair stage's own test): it resets the others
                                        let h = overlapping(delta, radius[i], radius[j])
                                            .and_then(|_| carried.pair(ids[i], ids[j]));
                                        block.neighbors.push(j as u32);
                                        block.history.push(h.unwrap_or_default());
                                        block.touching.push(h.is_some());
                                    }
                                }
                            }
                        }
                    }
                    block.counts.push((block.neighbors.len() - before) as u32);
                    let walls_before = block.wall_index.len();
                    for w in 0..walls.len() {
                        if walls.gap(w, pos[i], radius[i]) < skin {
                            let h = carried.find(ids[i], n as u32 + w as u32);
                            block.wall_index.push(w as u8);
                            block.wall_history.push(h.unwrap_or_default());
                            block.wall_touching.push(h.is_some());
                        }
                    }
                    block
                        .wall_counts
                        .push((block.wall_index.len() - walls_before) as u32);
                }
                block
            })
            .collect();

        self.offsets.clear();
        self.offsets.push(0);
        self.wall_offsets.clear();
        self.wall_offsets.push(0);
        let entries: usize = blocks.iter().map(|b| b.neighbors.len()).sum();
        let wall_entries: usize = blocks.iter().map(|b| b.wall_index.len()).sum();
        self.neighbors.reserve_exact(entries);
        self.history.reserve_exact(entries);
        self.touching.reserve_exact(entries);
        self.wall_index.reserve_exact(wall_entries);
        self.wall_history.reserve_exact(wall_entries);
        self.wall_touching.reserve_exact(wall_entries);
        for block in blocks {
            for c in block.counts {
                let last = *self.offsets.last().expect("starts with 0");
                self.offsets.push(last + c);
            }
            for c in block.wall_counts {
                let last = *self.wall_offsets.last().expect("starts with 0");
                self.wall_offsets.push(last + c);
            }
            self.neighbors.extend_from_slice(&block.neighbors);
            self.history.extend_from_slice(&block.history);
            self.touching.extend_from_slice(&block.touching);
            self.wall_index.extend_from_slice(&block.wall_index);
            self.wall_history.extend_from_slice(&block.wall_history);
            self.wall_touching.extend_from_slice(&block.wall_touching);
        }
        self.pos_at_build.clear();
        self.pos_at_build.extend_from_slice(&particles.pos);
        let (r0, m0) = (particles.radius.first(), particles.mass.first());
        self.uniform_pair = match (r0, m0) {
            (Some(&r), Some(&m))
                if particles.radius.iter().all(|&x| x == r)
                    && particles.mass.iter().all(|&x| x == m) =>
            {
                Some(effective(r, r, m, m))
            }
            _ => None,
        };
        self.rebuilds += 1;
    }

    /// Entry range of slot `i`.
    #[inline(always)]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Wall-candidate range of slot `i`.
    #[inline(always)]
    pub fn wall_range(&self, i: usize) -> std::ops::Range<usize> {
        self.wall_offsets[i] as usize..self.wall_offsets[i + 1] as usize
    }

    /// The list entries in use (pairs, walls), for the memory figures.
    pub fn entries(&self) -> (usize, usize) {
        (self.neighbors.len(), self.wall_index.len())
    }
}

/// One parallel task's share of a list build.
#[derive(Default)]
struct ListBlock {
    counts: Vec<u32>,
    neighbors: Vec<u32>,
    history: Vec<ContactHistory>,
    touching: Vec<bool>,
    wall_counts: Vec<u32>,
    wall_index: Vec<u8>,
    wall_history: Vec<ContactHistory>,
    wall_touching: Vec<bool>,
}
