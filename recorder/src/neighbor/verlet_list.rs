//! The half Verlet list in CSR form (each pair once, partner after the particle in slot
//! order) and the wall candidates, with the open contacts' histories beside them.
//! On rebuild the particles are re-sorted in cell order (memory order is worth several times
//! in the force loop) and every open contact's history follows its pair into the new list.
//! The lists are counted, then filled in place: a rebuild allocates nothing once the arrays
//! have grown to size, and never holds two lists at once.

use super::CellGrid;
use crate::contact::contact_sphere_sphere::{effective, overlapping};
use crate::contact::ContactHistory;
use crate::math::*;
use crate::particles::{ParticleSet, PermuteScratch};
use crate::periodic::AxialPeriod;
use crate::slices::{for_each_task, pieces_at, slices_indexed_alike};
use crate::wall::WallSet;
use rayon::prelude::*;
use std::ops::Range;

/// Particles per parallel task when the list entries are counted (the fill goes by layer).
const BLOCK: usize = 512;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct NeighborList {
    /// Entries of slot `i` are `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<u32>,
    /// Partner slots, each greater than the holder's slot and in its layer or the next.
    pub neighbors: Vec<u32>,
    /// Histories of the touching entries, seen from the holder, packed layer by layer: layer
    /// `l`'s in entry order from its first entry `offsets[layer_start[l]]` on (the rest of
    /// its range is unused). Most entries lie within the skin without touching, so the pair
    /// stage streams the contacts' histories, not one per entry.
    pub history: Vec<ContactHistory>,
    /// Whether each entry touched at the last step.
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
    /// Scratch of the cell sort and the re-sort (not part of a checkpoint).
    #[serde(skip)]
    cell_of: Vec<u32>,
    #[serde(skip)]
    cell_start: Vec<u32>,
    #[serde(skip)]
    order: Vec<u32>,
    #[serde(skip)]
    permute_scratch: PermuteScratch,
    #[serde(skip)]
    carried: Carried,
}

/// Open contacts carried through a rebuild, grouped by the permanent id of their holder.
#[derive(Debug, Clone, Default)]
struct Carried {
    /// Contacts of id `a` are `start[a]..start[a + 1]`.
    start: Vec<u32>,
    /// Where the next contact of each id goes while they are collected.
    next: Vec<u32>,
    /// Partner id (walls: particle count + wall index) and history seen from the holder.
    contacts: Vec<(u32, ContactHistory)>,
}

impl Carried {
    fn find(&self, holder: u32, partner: u32) -> Option<ContactHistory> {
        let range = self.start[holder as usize] as usize..self.start[holder as usize + 1] as usize;
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

    /// Calls `found(slot, entry, history)` for every touching entry, in entry order.
    pub fn for_each_touching(&self, mut found: impl FnMut(usize, usize, &ContactHistory)) {
        for layer in self.layer_start.windows(2) {
            let slots = layer[0] as usize..layer[1] as usize;
            let mut packed = self.offsets[slots.start] as usize;
            for i in slots {
                for e in self.range(i).filter(|&e| self.touching[e]) {
                    found(i, e, &self.history[packed]);
                    packed += 1;
                }
            }
        }
    }

    /// The history of every entry (zero for those not touching).
    pub fn histories_by_entry(&self) -> Vec<ContactHistory> {
        let mut by_entry = vec![ContactHistory::default(); self.neighbors.len()];
        self.for_each_touching(|_, e, h| by_entry[e] = *h);
        by_entry
    }

    /// Collects the open contacts (pairs and walls) by holder id into `self.carried`.
    fn carry_open_contacts(&mut self, ids: &[u32]) {
        let n = ids.len();
        let slots = self.offsets.len().saturating_sub(1);
        // taken out while the list is read, put back at the end
        let mut carried = std::mem::take(&mut self.carried);
        let Carried {
            start,
            next,
            contacts,
        } = &mut carried;
        start.clear();
        start.resize(n + 1, 0);
        for i in 0..slots {
            let pairs = self.touching[self.range(i)].iter().filter(|&&t| t).count();
            let walls = self.wall_touching[self.wall_range(i)]
                .iter()
                .filter(|&&t| t)
                .count();
            start[ids[i] as usize + 1] += (pairs + walls) as u32;
        }
        for a in 0..n {
            start[a + 1] += start[a];
        }
        contacts.clear();
        contacts.resize(start[n] as usize, (0, ContactHistory::default()));
        // each holder's pairs first, then its walls
        next.clear();
        next.extend_from_slice(start);
        self.for_each_touching(|i, e, &h| {
            let at = &mut next[ids[i] as usize];
            contacts[*at as usize] = (ids[self.neighbors[e] as usize], h);
            *at += 1;
        });
        for i in 0..slots {
            for e in self.wall_range(i).filter(|&e| self.wall_touching[e]) {
                let at = &mut next[ids[i] as usize];
                let wall = n as u32 + self.wall_index[e] as u32;
                contacts[*at as usize] = (wall, self.wall_history[e]);
                *at += 1;
            }
        }
        self.carried = carried;
    }

    /// Re-sorts `particles` into cell order and rebuilds the lists, carrying histories over.
    pub fn rebuild(&mut self, particles: &mut ParticleSet, grid: &CellGrid, walls: &WallSet) {
        let n = particles.len();
        self.carry_open_contacts(&particles.id);
        self.sort_into_cells(particles, grid);
        // count each slot's partners and wall candidates, then fill the lists in place
        let search = Search {
            grid,
            cell_start: &self.cell_start,
            pos: &particles.pos,
            radius: &particles.radius,
            skin: self.skin,
            walls,
        };
        self.offsets.clear();
        self.offsets.resize(n + 1, 0);
        self.wall_offsets.clear();
        self.wall_offsets.resize(n + 1, 0);
        self.offsets[1..]
            .par_iter_mut()
            .zip(self.wall_offsets[1..].par_iter_mut())
            .enumerate()
            .with_min_len(BLOCK)
            .for_each(|(i, (pairs, walls))| {
                search.partners(i, |_, _| *pairs += 1);
                search.walls(i, |_| *walls += 1);
            });
        for i in 0..n {
            self.offsets[i + 1] += self.offsets[i];
            self.wall_offsets[i + 1] += self.wall_offsets[i];
        }
        let (entries, wall_entries) = (self.offsets[n] as usize, self.wall_offsets[n] as usize);
        self.neighbors.resize(entries, 0);
        self.history.resize(entries, ContactHistory::default());
        self.touching.resize(entries, false);
        self.wall_index.resize(wall_entries, 0);
        self.wall_history
            .resize(wall_entries, ContactHistory::default());
        self.wall_touching.resize(wall_entries, false);

        // task l fills the entries and wall candidates of the slots of layer l (whose
        // histories are packed from the layer's first entry on)
        let (offsets, wall_offsets, layer_start) =
            (&self.offsets, &self.wall_offsets, &self.layer_start);
        let start = |l: usize| {
            let first = layer_start[l] as usize;
            ListStart {
                pair_entry: offsets[first] as usize,
                wall_candidate: wall_offsets[first] as usize,
            }
        };
        let (ids, carried) = (&particles.id, &self.carried);
        let arrays = FillPieces {
            partners: &mut self.neighbors[..],
            pairs: ListPieces {
                histories: &mut self.history[..],
                touching: &mut self.touching[..],
            },
            wall_index: &mut self.wall_index[..],
            walls: ListPieces {
                histories: &mut self.wall_history[..],
                touching: &mut self.wall_touching[..],
            },
        };
        let fill = |l: usize, pieces: FillPieces| {
            let slots = layer_start[l] as usize..layer_start[l + 1] as usize;
            fill_layer(slots, &search, ids, carried, pieces);
            0
        };
        for_each_task(
            arrays,
            ListStart::default(),
            0..grid.layers(),
            &start,
            &fill,
        );

        self.pos_at_build.clear();
        self.pos_at_build.extend_from_slice(&particles.pos);
        self.uniform_pair = uniform_pair(particles);
        self.rebuilds += 1;
    }

    /// Re-sorts `particles` into the order of `grid`'s cells (a stable counting sort: ties
    /// keep their previous order, so the order is deterministic) and notes where each cell
    /// and layer starts.
    fn sort_into_cells(&mut self, particles: &mut ParticleSet, grid: &CellGrid) {
        let n = particles.len();
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
        self.order.clear();
        self.order.resize(n, 0);
        // the cell starts advance as slots are handed out, then step back by one cell
        for (old, &c) in self.cell_of.iter().enumerate() {
            self.order[self.cell_start[c as usize] as usize] = old as u32;
            self.cell_start[c as usize] += 1;
        }
        self.cell_start.rotate_right(1);
        self.cell_start[0] = 0;
        particles.permute_state(&self.order, &mut self.permute_scratch);
        let per_layer = grid.cells_per_layer();
        self.layer_start.clear();
        self.layer_start
            .extend((0..=grid.layers()).map(|l| self.cell_start[l * per_layer]));
    }

    /// Checks a list read back from a checkpoint against `n` particles, the grid's `layers`
    /// and `walls` walls: every index the stages follow stays in range, and every partner
    /// lies after its holder in the holder's layer or the next (what the parallel pair stage
    /// relies on).
    pub fn check(&self, n: usize, layers: usize, walls: usize) -> Result<(), String> {
        if self.offsets.is_empty() && self.wall_offsets.is_empty() && self.layer_start.is_empty() {
            return if self.neighbors.is_empty() && self.pos_at_build.is_empty() {
                Ok(()) // never built: the first step builds it
            } else {
                Err("neighbour list has entries but no offsets".into())
            };
        }
        let csr = |name: &str, offsets: &[u32], entries: usize| -> Result<(), String> {
            if offsets.len() != n + 1 || offsets[0] != 0 || offsets[n] as usize != entries {
                return Err(format!(
                    "{name} offsets: {} values from {:?} to {:?} for {n} particles and {entries} entries",
                    offsets.len(),
                    offsets.first(),
                    offsets.last()
                ));
            }
            match offsets.windows(2).position(|w| w[0] > w[1]) {
                Some(i) => Err(format!("{name} offsets decrease at slot {i}")),
                None => Ok(()),
            }
        };
        let entries = self.neighbors.len();
        csr("pair", &self.offsets, entries)?;
        csr("wall", &self.wall_offsets, self.wall_index.len())?;
        if self.history.len() != entries || self.touching.len() != entries {
            return Err(format!(
                "{entries} pair entries but {} histories and {} touching flags",
                self.history.len(),
                self.touching.len()
            ));
        }
        let wall_entries = self.wall_index.len();
        if self.wall_history.len() != wall_entries || self.wall_touching.len() != wall_entries {
            return Err(format!(
                "{wall_entries} wall candidates but {} histories and {} touching flags",
                self.wall_history.len(),
                self.wall_touching.len()
            ));
        }
        if let Some(e) = self.wall_index.iter().position(|&w| w as usize >= walls) {
            return Err(format!(
                "wall candidate {e} names wall {} of {walls}",
                self.wall_index[e]
            ));
        }
        let starts = &self.layer_start;
        if starts.len() != layers + 1
            || starts[0] != 0
            || starts[layers] as usize != n
            || starts.windows(2).any(|w| w[0] > w[1])
        {
            return Err(format!(
                "layer starts {:?}..{:?} ({} values) do not split {n} particles into {layers} layers",
                starts.first(),
                starts.last(),
                starts.len()
            ));
        }
        for l in 0..layers {
            let end = starts[(l + 2).min(layers)] as usize;
            for i in starts[l] as usize..starts[l + 1] as usize {
                if let Some(e) = self.range(i).find(|&e| {
                    let j = self.neighbors[e] as usize;
                    j <= i || j >= end
                }) {
                    return Err(format!(
                        "slot {i} (layer {l}) lists partner {} outside slots {}..{end}",
                        self.neighbors[e],
                        i + 1
                    ));
                }
            }
        }
        if self.pos_at_build.len() != n {
            return Err(format!(
                "{} build positions for {n} particles",
                self.pos_at_build.len()
            ));
        }
        if !(self.skin.is_finite() && self.skin > 0.0) {
            return Err(format!("skin = {} (must be > 0)", self.skin));
        }
        Ok(())
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
}

/// Histories and touching flags of a task's list entries (pair entries or wall candidates),
/// from where its pieces start.
pub(crate) struct ListPieces<'a> {
    pub(crate) histories: &'a mut [ContactHistory],
    pub(crate) touching: &'a mut [bool],
}

slices_indexed_alike!(ListPieces {
    histories,
    touching
});

/// One list-filling task's pieces: the partner slots, histories and touching flags of its
/// pair entries, and the wall, histories and touching flags of its wall candidates.
struct FillPieces<'a> {
    partners: &'a mut [u32],
    pairs: ListPieces<'a>,
    wall_index: &'a mut [u8],
    walls: ListPieces<'a>,
}

/// Where a list-filling task's pieces start in each kind of array.
#[derive(Debug, Clone, Copy, Default)]
struct ListStart {
    /// In the pair entries.
    pair_entry: usize,
    /// In the wall candidates.
    wall_candidate: usize,
}

pieces_at!(FillPieces at ListStart {
    partners: pair_entry,
    pairs: pair_entry,
    wall_index: wall_candidate,
    walls: wall_candidate
});

/// `(R*, m*)` of every pair when all spheres are equal (`None` otherwise): the pair stage
/// then skips computing them per contact.
fn uniform_pair(particles: &ParticleSet) -> Option<(f64, f64)> {
    let (r0, m0) = (particles.radius.first(), particles.mass.first());
    match (r0, m0) {
        (Some(&r), Some(&m))
            if particles.radius.iter().all(|&x| x == r)
                && particles.mass.iter().all(|&x| x == m) =>
        {
            Some(effective(r, r, m, m))
        }
        _ => None,
    }
}

/// Fills the entries and wall candidates of a layer's `slots` into its `pieces`, with the
/// histories `carried` over from the last list (`ids`: the particles' ids by slot); the
/// layer's pair histories are packed from its first entry on.
fn fill_layer(
    slots: Range<usize>,
    search: &Search,
    ids: &[u32],
    carried: &Carried,
    pieces: FillPieces,
) {
    let FillPieces {
        partners: partner,
        pairs: ListPieces {
            histories: history,
            touching: touch,
        },
        wall_index: wall,
        walls:
            ListPieces {
                histories: wall_history,
                touching: wall_touch,
            },
    } = pieces;
    let n = ids.len() as u32;
    let (mut e, mut w, mut packed) = (0, 0, 0);
    for i in slots {
        search.partners(i, |j, now_touching| {
            // a history matters only to a pair touching now (the pair stage's own test): it
            // resets the others
            let h = now_touching.then(|| carried.pair(ids[i], ids[j])).flatten();
            partner[e] = j as u32;
            touch[e] = h.is_some();
            if let Some(h) = h {
                history[packed] = h;
                packed += 1;
            }
            e += 1;
        });
        search.walls(i, |k| {
            let h = carried.find(ids[i], n + k as u32);
            wall[w] = k as u8;
            wall_history[w] = h.unwrap_or_default();
            wall_touch[w] = h.is_some();
            w += 1;
        });
    }
}

/// The broad-phase search over particles already in cell order.
struct Search<'a> {
    grid: &'a CellGrid,
    cell_start: &'a [u32],
    pos: &'a [Vec3],
    radius: &'a [f64],
    skin: f64,
    walls: &'a WallSet,
}

impl Search<'_> {
    /// Calls `found(j, touching_now)` for every `j > i` within the skin, scanning `i`'s own
    /// cell and the 13 after it in a fixed order (earlier cells hold only slots below `i`).
    #[inline(always)]
    fn partners(&self, i: usize, mut found: impl FnMut(usize, bool)) {
        if let Some(period) = self.grid.period {
            return self.partners_across_seam(i, period, found);
        }
        let (grid, pos, radius) = (self.grid, self.pos, self.radius);
        let ci = grid.coords(pos[i]);
        for d in &grid.forward {
            let c = [
                ci[0] as i64 + d[0],
                ci[1] as i64 + d[1],
                ci[2] as i64 + d[2],
            ];
            if (0..3).any(|k| c[k] < 0 || c[k] >= grid.dims[k] as i64) {
                continue;
            }
            let cell = grid.index([c[0] as usize, c[1] as usize, c[2] as usize]);
            let first = (self.cell_start[cell] as usize).max(i + 1);
            for j in first..self.cell_start[cell + 1] as usize {
                let cut = radius[i] + radius[j] + self.skin;
                let delta = sub(pos[i], pos[j]);
                if norm2(delta) < cut * cut {
                    found(j, overlapping(delta, radius[i], radius[j]).is_some());
                }
            }
        }
    }

    /// [`Search::partners`] in a grid that wraps along y: the half stencil's "cells ahead"
    /// wrap to cells behind, so every distinct cell of the 27 around `i`'s is scanned for
    /// partners `j > i`, each pair once, from its lower slot, with the centre vector taken to
    /// the nearest image. A section one or two cells long reaches the same cell from both
    /// sides: it is scanned once. The partners stay in `i`'s layer or the next, as the
    /// pair stage needs, since y is not the layer axis.
    #[inline(always)]
    fn partners_across_seam(
        &self,
        i: usize,
        period: AxialPeriod,
        mut found: impl FnMut(usize, bool),
    ) {
        let (grid, pos, radius) = (self.grid, self.pos, self.radius);
        let ci = grid.coords(pos[i]);
        let mut scanned = [usize::MAX; 27];
        let mut n_scanned = 0;
        for dz in -1..=1i64 {
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let (x, z) = (ci[0] as i64 + dx, ci[2] as i64 + dz);
                    if x < 0 || z < 0 || x >= grid.dims[0] as i64 || z >= grid.dims[2] as i64 {
                        continue;
                    }
                    let y = (ci[1] as i64 + dy).rem_euclid(grid.dims[1] as i64);
                    let cell = grid.index([x as usize, y as usize, z as usize]);
                    if scanned[..n_scanned].contains(&cell) {
                        continue;
                    }
                    scanned[n_scanned] = cell;
                    n_scanned += 1;
                    let first = (self.cell_start[cell] as usize).max(i + 1);
                    for j in first..self.cell_start[cell + 1] as usize {
                        let cut = radius[i] + radius[j] + self.skin;
                        let delta = period.nearest_image(sub(pos[i], pos[j]));
                        if norm2(delta) < cut * cut {
                            found(j, overlapping(delta, radius[i], radius[j]).is_some());
                        }
                    }
                }
            }
        }
    }

    /// Calls `found(w)` for every wall within the skin of sphere `i`.
    #[inline(always)]
    fn walls(&self, i: usize, mut found: impl FnMut(usize)) {
        for w in 0..self.walls.len() {
            if self.walls.gap(w, self.pos[i], self.radius[i]) < self.skin {
                found(w);
            }
        }
    }
}
