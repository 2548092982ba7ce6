//! One DEM step: integrate, broad phase, pair and wall interactions, integrate. The pipeline
//! owns only scratch data; every set is passed to `step` explicitly.

use crate::contact::contact_sphere_sphere::SphereState;
use crate::contact::narrow_phase::{self, ListEntries};
use crate::contact::pair_batch::{PairBatch, PairConstants, SphereArrays};
use crate::contact::{contact_sphere_wall as sphere_wall, hertz_mindlin, ContactHistory, PairLaw};
use crate::counters::{timed, Counters};
use crate::heat::ConductionLaw;
use crate::integrate;
use crate::math::*;
use crate::neighbor::{CellGrid, ListPieces, NeighborList};
use crate::particles::ParticleSet;
use crate::periodic::AxialPeriod;
use crate::prefetch::{self, ArrayAddress, Prefetch};
use crate::slices::{for_each_task, pieces_at, slices_indexed_alike};
use crate::wall::WallSet;
use std::cell::RefCell;
use std::ops::Range;

/// Particles per chunk of the contact stage's layers: a chunk's state and lists stay in the
/// cache between its two phases.
const CHUNK: u32 = 16384;

thread_local! {
    /// A pair task's histories from the last step, read from this copy while the new ones
    /// are written over them (packed, a task may have more contacts than before).
    static OLD_HISTORIES: RefCell<Vec<ContactHistory>> = const { RefCell::new(Vec::new()) };
}

/// Everything constant during a step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepParams {
    pub dt: f64,
    pub gravity: Vec3,
    pub particle_particle: PairLaw,
    pub particle_wall: PairLaw,
    pub conduction: ConductionLaw,
    /// The section's period along the axis when the drum is periodic (no end caps).
    pub axial_period: Option<AxialPeriod>,
}

/// Contacts counted during the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ContactCount {
    /// Particle–particle contacts seen from both sides (twice the number of pairs).
    pub pair_entries: u64,
    pub wall: u64,
}

impl std::ops::Add for ContactCount {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        Self {
            pair_entries: self.pair_entries + other.pair_entries,
            wall: self.wall + other.wall,
        }
    }
}

/// The step driver; holds the cell grid of the broad phase.
#[derive(Debug, Clone)]
pub struct Pipeline {
    pub grid: CellGrid,
}

impl Pipeline {
    pub fn new(grid: CellGrid) -> Self {
        Self { grid }
    }

    /// Advances the state by one `dt`.
    pub fn step(
        &mut self,
        params: &StepParams,
        particles: &mut ParticleSet,
        neighbors: &mut NeighborList,
        walls: &WallSet,
        counters: &mut Counters,
    ) -> ContactCount {
        // the drift also measures how far the particles have moved since the list was built
        let moved_far = timed(&mut counters.integrate, || {
            integrate::initial_integrate(
                particles,
                params.dt,
                params.gravity,
                &neighbors.pos_at_build,
                0.5 * neighbors.skin,
                params.axial_period,
            )
        });
        timed(&mut counters.neighbor, || {
            if moved_far {
                neighbors.rebuild(particles, &self.grid, walls);
            }
        });
        let contacts = timed(&mut counters.contact, || {
            contact_interactions(params, particles, neighbors, walls)
        });
        timed(&mut counters.integrate, || {
            integrate::final_integrate(
                particles,
                params.dt,
                params.gravity,
                params.conduction.heat_capacity,
            );
        });
        counters.steps += 1;
        counters.particle_steps += particles.len() as u64;
        contacts
    }
}

/// Sphere–sphere and sphere–wall forces, torques and conduction: each pair evaluated once
/// from the half list, each wall candidate by the particle it belongs to.
///
/// Layer `l` of the cell grid owns the pairs of its particles, whose partners lie in layer
/// `l` or `l + 1`, so it writes only those two layers. Even layers run in parallel, then
/// the odd ones (chunk by chunk, below): no two tasks write the same particle, and every
/// particle receives its contributions in an order fixed by the list alone, so the sums do
/// not depend on the thread count. The task that writes a layer last then adds its
/// particles' wall contacts, while their state is still in the cache. Returns the touching
/// pairs counted from both sides and the touching wall candidates.
pub fn contact_interactions(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
    walls: &WallSet,
) -> ContactCount {
    let cache = prefetch::last_level_cache_bytes();
    contact_interactions_in_chunks(params, particles, neighbors, walls, CHUNK, cache)
}

/// [`contact_interactions`] with the layers taken in chunks of about `chunk` particles, and
/// the next task's data prefetched when the state and lists take more than `prefetch_above`
/// bytes (the results depend on neither).
pub fn contact_interactions_in_chunks(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
    walls: &WallSet,
    chunk: u32,
    prefetch_above: usize,
) -> ContactCount {
    let ParticleSet {
        pos,
        vel,
        omega,
        force,
        torque,
        radius,
        mass,
        temp,
        heat_flow,
        ..
    } = particles;
    let (pos, vel, omega, radius, mass, temp) = (&*pos, &*vel, &*omega, &*radius, &*mass, &*temp);
    let NeighborList {
        offsets,
        neighbors: partners,
        history,
        touching,
        layer_start,
        uniform_pair,
        wall_offsets,
        wall_index,
        wall_history,
        wall_touching,
        ..
    } = neighbors;
    if layer_start.len() < 2 {
        // no list yet: no contacts, and no task to start the sums below
        force.fill([0.0; 3]);
        torque.fill([0.0; 3]);
        heat_flow.fill(0.0);
        return ContactCount::default();
    }
    // past the cache size, each task prefetches what the next task of its phase on the same
    // thread will read, spread over its own work
    let task_arrays = TaskArrays {
        per_slot: [
            ArrayAddress::of(pos),
            ArrayAddress::of(vel),
            ArrayAddress::of(omega),
            ArrayAddress::of(radius),
            ArrayAddress::of(mass),
            ArrayAddress::of(temp),
            ArrayAddress::of(force),
            ArrayAddress::of(torque),
            ArrayAddress::of(heat_flow),
            ArrayAddress::of(offsets),
        ],
        partners: ArrayAddress::of(partners),
        touching: ArrayAddress::of(touching),
        histories: ArrayAddress::of(history),
    };
    let tasks = LayerTasks {
        spheres: SphereArrays {
            pos,
            vel,
            omega,
            radius,
            mass,
            temp,
        },
        constants: PairConstants {
            law: &params.particle_particle,
            heat: &params.conduction,
            dt: params.dt,
            uniform_pair: *uniform_pair,
        },
        walls: WallContacts {
            walls,
            law: &params.particle_wall,
            heat: &params.conduction,
            dt: params.dt,
            offsets: wall_offsets,
            index: wall_index,
        },
        ahead: (task_arrays.bytes() > prefetch_above).then_some(task_arrays),
        layer_start,
        offsets,
        partners,
        axial_period: params.axial_period,
    };
    let run = |phase: usize, range: Range<usize>| {
        let pieces = TaskPieces {
            sums: Sums {
                force: &mut force[..],
                torque: &mut torque[..],
                heat_flow: &mut heat_flow[..],
            },
            pairs: ListPieces {
                histories: &mut history[..],
                touching: &mut touching[..],
            },
            walls: ListPieces {
                histories: &mut wall_history[..],
                touching: &mut wall_touching[..],
            },
        };
        tasks.run_phase(phase, range, pieces)
    };
    in_chunks(layer_start, chunk, run)
}

/// The odd task of layer l must follow the even tasks of l - 1 and l + 1 (it writes a layer
/// of each, and each particle's sums keep that order). Rather than all even tasks, then all
/// odd ones, which reads every layer from memory twice once the state outgrows the cache,
/// the layers go in chunks of about `chunk` particles: a chunk's even tasks, then the odd
/// tasks whose two even neighbours are done; the chunk's last odd layer waits for the next
/// chunk's first even one. Same tasks, same order of every sum. `run(phase, tasks)` runs
/// the tasks `tasks` of a phase (task k of a phase owns layer `phase + 2k`).
fn in_chunks(
    layer_start: &[u32],
    chunk: u32,
    mut run: impl FnMut(usize, Range<usize>) -> ContactCount,
) -> ContactCount {
    let layers = layer_start.len() - 1;
    let odd_tasks = layers.saturating_sub(1).div_ceil(2);
    let (mut count, mut first, mut odd_done) = (ContactCount::default(), 0, 0);
    while first < layers {
        let mut end = first + 2;
        while end < layers && (layer_start[end] - layer_start[first]) < chunk {
            end += 2;
        }
        let end = end.min(layers);
        count = count + run(0, first / 2..end.div_ceil(2));
        let odd_ready = if end == layers {
            odd_tasks
        } else {
            end / 2 - 1
        };
        count = count + run(1, odd_done..odd_ready);
        odd_done = odd_ready;
        first = end;
    }
    count
}

/// What every pair task of a step reads: the state, the laws, the list's layout, and where
/// to prefetch the next task's data (when it pays).
struct LayerTasks<'a> {
    spheres: SphereArrays<'a>,
    constants: PairConstants<'a>,
    walls: WallContacts<'a>,
    ahead: Option<TaskArrays>,
    layer_start: &'a [u32],
    offsets: &'a [u32],
    partners: &'a [u32],
    axial_period: Option<AxialPeriod>,
}

impl LayerTasks<'_> {
    fn layers(&self) -> usize {
        self.layer_start.len() - 1
    }

    /// Runs the tasks `tasks` of a phase (0 even, 1 odd), in parallel, each on its pieces of
    /// the arrays (task k owns layer `phase + 2k`; its pieces reach the next task's start).
    fn run_phase(&self, phase: usize, tasks: Range<usize>, pieces: TaskPieces) -> ContactCount {
        let layer = |k: usize| phase + 2 * k;
        for_each_task(
            pieces,
            TaskStart::default(),
            tasks,
            &|k| self.start(layer(k)),
            &|k, pieces| self.run_layer(layer(k), pieces),
        )
    }

    /// Where the pieces of the task of layer `l` start: it writes the slots of `l` and
    /// `l + 1`, the entries of `l` and the wall candidates of the layers it finishes (below).
    fn start(&self, l: usize) -> TaskStart {
        let slot = self.layer_start[l] as usize;
        TaskStart {
            slot,
            pair_entry: self.offsets[slot] as usize,
            wall_candidate: self.walls.offsets[slot] as usize,
        }
    }

    /// The task of layer `l`: its pairs, then the wall contacts of the slots it finishes.
    fn run_layer(&self, l: usize, pieces: TaskPieces) -> ContactCount {
        let TaskPieces {
            mut sums,
            pairs,
            walls: wall_pieces,
        } = pieces;
        let first_slot = self.layer_start[l] as usize;
        if l.is_multiple_of(2) {
            // an even task is the first to write its two layers: their sums start from
            // zero here, where the task is about to use them, not in a pass of their own
            // over memory
            let written = self.layer_start[(l + 2).min(self.layers())] as usize - first_slot;
            sums.force[..written].fill([0.0; 3]);
            sums.torque[..written].fill([0.0; 3]);
            sums.heat_flow[..written].fill(0.0);
        }
        let pair_entries = self.pairs(l, &mut sums, pairs);
        let finished = finished_slots(l, self.layer_start);
        let wall = self
            .walls
            .add(&self.spheres, finished, first_slot, &mut sums, wall_pieces);
        ContactCount {
            pair_entries: 2 * pair_entries,
            wall,
        }
    }

    /// The pair contacts of layer `l` added to `sums`; returns the touching pairs.
    fn pairs(&self, l: usize, sums: &mut Sums, pieces: ListPieces) -> u64 {
        let ListPieces {
            histories: h,
            touching: touch,
        } = pieces;
        let first_slot = self.layer_start[l] as usize;
        let first_entry = self.offsets[first_slot] as usize;
        let slots = first_slot..self.layer_start[l + 1] as usize;
        let layer_entries = self.offsets[slots.end] as usize - first_entry;
        // the layer's histories are packed: those of its touching entries, in entry
        // order, from its first entry on (the stream the stage reads is the contacts',
        // not the list's)
        let touched = touch[..layer_entries]
            .iter()
            .map(|&t| usize::from(t))
            .sum::<usize>();
        let mut next = match &self.ahead {
            Some(arrays) if l + 2 < self.layers() => {
                let share = touched as f64 / layer_entries.max(1) as f64;
                arrays.prefetch(l + 2, self.layer_start, self.offsets, share)
            }
            _ => Prefetch::default(),
        };
        let holders = slots.len().max(1) as f64;
        OLD_HISTORIES.with_borrow_mut(|old| {
            old.clear();
            old.extend_from_slice(&h[..touched]);
            old.push(ContactHistory::default());
            let mut batch = PairBatch::default();
            // the holder's sums are kept apart and added once its contacts are done, as
            // each pair's partner sums are added in pair order: the order of every sum
            // is fixed by the list alone
            let mut holder = Holder::default();
            let entries = ListEntries {
                slots,
                offsets: self.offsets,
                partners: self.partners,
                first_entry,
                fresh: touched as u32,
            };
            let mut evaluate = |batch: &mut PairBatch| {
                batch.evaluate(&self.constants, &self.spheres, old, h);
                holder.scatter(batch, sums, first_slot);
                next.advance(holder.slots_done(first_slot) as f64 / holders);
            };
            let touching_pairs = narrow_phase::scan(
                &entries,
                self.spheres.pos,
                self.spheres.radius,
                self.axial_period,
                touch,
                &mut batch,
                &mut evaluate,
            );
            // the batch holds fewer than a full batch's contacts now: one evaluation
            evaluate(&mut batch);
            holder.add_to(sums, first_slot);
            touching_pairs
        })
    }
}

/// The slots whose pair sums are complete once the task of layer `l` has run, so their wall
/// terms can follow every pair term: the odd task of layer `l` is the last to write layers
/// `l` and `l + 1`, the even task of layer 0 the only one to write layer 0; the other even
/// tasks finish none.
fn finished_slots(l: usize, layer_start: &[u32]) -> Range<usize> {
    let layers = layer_start.len() - 1;
    let first_slot = layer_start[l] as usize;
    if !l.is_multiple_of(2) {
        first_slot..layer_start[(l + 2).min(layers)] as usize
    } else if l == 0 {
        first_slot..layer_start[1] as usize
    } else {
        first_slot..first_slot
    }
}

/// The sums of the particle whose contacts the pair stage is handing out.
struct Holder {
    slot: usize,
    force: Vec3,
    torque: Vec3,
    heat_flow: f64,
}

impl Default for Holder {
    fn default() -> Self {
        Self::new(usize::MAX)
    }
}

impl Holder {
    fn new(slot: usize) -> Self {
        Self {
            slot,
            force: [0.0; 3],
            torque: [0.0; 3],
            heat_flow: 0.0,
        }
    }

    /// Adds an evaluated batch's responses to the holders' and partners' sums of a task's
    /// pieces starting at `first_slot`, and empties the batch.
    #[inline(always)]
    fn scatter(&mut self, batch: &mut PairBatch, sums: &mut Sums, first_slot: usize) {
        for l in 0..batch.ready() {
            let (i, j, r) = batch.response(l);
            if i != self.slot {
                self.add_to(sums, first_slot);
                *self = Holder::new(i);
            }
            self.force = add(self.force, r.force);
            self.torque = add(self.torque, r.torque_holder);
            self.heat_flow += r.heat_flow;
            let jl = j - first_slot;
            sums.force[jl] = sub(sums.force[jl], r.force);
            sums.torque[jl] = add(sums.torque[jl], r.torque_partner);
            sums.heat_flow[jl] -= r.heat_flow;
        }
        batch.consume();
    }

    /// Slots of a task starting at `first_slot` that its batches have reached, the holder's
    /// included (0 before the first holder): the task's progress.
    fn slots_done(&self, first_slot: usize) -> usize {
        if self.slot == usize::MAX {
            return 0;
        }
        self.slot + 1 - first_slot
    }

    /// Adds the sums to the holder's slot of a task's pieces starting at `first_slot`.
    fn add_to(&self, sums: &mut Sums, first_slot: usize) {
        if self.slot == usize::MAX {
            return;
        }
        let il = self.slot - first_slot;
        sums.force[il] = add(sums.force[il], self.force);
        sums.torque[il] = add(sums.torque[il], self.torque);
        sums.heat_flow[il] += self.heat_flow;
    }
}

/// What a pair task writes, from where its pieces start: its particles' sums, and the
/// histories and touching flags of its pair entries and of its wall candidates.
struct TaskPieces<'a> {
    sums: Sums<'a>,
    pairs: ListPieces<'a>,
    walls: ListPieces<'a>,
}

/// Where a task's pieces start in each kind of array.
#[derive(Debug, Clone, Copy, Default)]
struct TaskStart {
    /// In the per-particle sums.
    slot: usize,
    /// In the pair entries of the list.
    pair_entry: usize,
    /// In the wall candidates of the list.
    wall_candidate: usize,
}

pieces_at!(TaskPieces at TaskStart {
    sums: slot,
    pairs: pair_entry,
    walls: wall_candidate
});

/// The force, torque and heat flow each particle of a task's slots receives from its
/// contacts.
struct Sums<'a> {
    force: &'a mut [Vec3],
    torque: &'a mut [Vec3],
    heat_flow: &'a mut [f64],
}

slices_indexed_alike!(Sums {
    force,
    torque,
    heat_flow
});

/// Where the arrays a pair task reads lie, for prefetching the next task's part of them.
struct TaskArrays {
    /// Indexed by slot: the state, the sums and the list offsets.
    per_slot: [ArrayAddress; 10],
    partners: ArrayAddress,
    touching: ArrayAddress,
    histories: ArrayAddress,
}

impl TaskArrays {
    /// Bytes of all these arrays: what must outgrow the cache for the prefetch to pay.
    fn bytes(&self) -> usize {
        let lists = [self.partners, self.touching, self.histories];
        self.per_slot
            .iter()
            .chain(&lists)
            .map(ArrayAddress::bytes)
            .sum()
    }

    /// What the task of layer `l` reads: the slots of `l` and `l + 1` (its partners'), the
    /// entries of `l`, and their packed histories, as many as `touching_share` of the
    /// entries (their count is known only once that task has counted its flags).
    fn prefetch(
        &self,
        l: usize,
        layer_start: &[u32],
        offsets: &[u32],
        touching_share: f64,
    ) -> Prefetch {
        let layers = layer_start.len() - 1;
        let slots = layer_start[l] as usize..layer_start[(l + 2).min(layers)] as usize;
        let mut next = Prefetch::default();
        for array in self.per_slot {
            next.add(array, slots.clone());
        }
        let first = offsets[slots.start] as usize;
        let entries = offsets[layer_start[l + 1] as usize] as usize - first;
        next.add(self.partners, first..first + entries);
        next.add(self.touching, first..first + entries);
        let histories = (entries as f64 * touching_share).ceil() as usize;
        next.add(self.histories, first..first + histories);
        next
    }
}

/// Sphere–wall forces and heated-wall conduction over the wall candidates of the list.
struct WallContacts<'a> {
    walls: &'a WallSet,
    law: &'a PairLaw,
    heat: &'a ConductionLaw,
    dt: f64,
    offsets: &'a [u32],
    index: &'a [u8],
}

impl WallContacts<'_> {
    /// Adds the wall contacts of `slots` to their sums; the sum pieces start at slot
    /// `first_slot`, the wall pieces at its first candidate. Returns the touching ones.
    #[inline(always)]
    fn add(
        &self,
        spheres: &SphereArrays,
        slots: Range<usize>,
        first_slot: usize,
        sums: &mut Sums,
        ListPieces {
            histories: h,
            touching: touch,
        }: ListPieces,
    ) -> u64 {
        let first_entry = self.offsets[first_slot] as usize;
        let mut touching = 0;
        for i in slots {
            let il = i - first_slot;
            for e in self.offsets[i] as usize..self.offsets[i + 1] as usize {
                let (w, local) = (self.index[e] as usize, e - first_entry);
                let Some(c) = self.walls.contact(w, spheres.pos[i], spheres.radius[i]) else {
                    if touch[local] {
                        h[local] = ContactHistory::default();
                        touch[local] = false;
                    }
                    continue;
                };
                let si = SphereState {
                    pos: spheres.pos[i],
                    vel: spheres.vel[i],
                    omega: spheres.omega[i],
                    radius: spheres.radius[i],
                    mass: spheres.mass[i],
                };
                let (kin, lever) = sphere_wall::kinematics(&si, &c);
                let resp = hertz_mindlin::respond(self.law, &kin, &mut h[local], self.dt);
                touch[local] = true;
                sums.force[il] = add(sums.force[il], resp.force);
                sums.torque[il] = add(sums.torque[il], resp.torque_on_i(lever));
                if let Some(tw) = self.walls.temperature(w) {
                    sums.heat_flow[il] +=
                        self.heat.wall_conductance(c.overlap, si.radius) * (tw - spheres.temp[i]);
                }
                touching += 1;
            }
        }
        touching
    }
}
