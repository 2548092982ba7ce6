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
use crate::neighbor::{CellGrid, NeighborList};
use crate::particles::ParticleSet;
use crate::slices::for_each_task;
use crate::wall::WallSet;
use std::cell::RefCell;
use std::ops::Range;

/// Particles per parallel task in the wall stage.
const BLOCK: usize = 1024;
/// Particles per chunk of the pair stage's layers: a chunk's state and lists stay in the
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
}

/// Contacts counted during the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ContactCount {
    /// Particle–particle contacts seen from both sides (twice the number of pairs).
    pub pair_entries: u64,
    pub wall: u64,
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
            )
        });
        timed(&mut counters.neighbor, || {
            if moved_far {
                neighbors.rebuild(particles, &self.grid, walls);
            }
        });
        let pair_entries = timed(&mut counters.pair, || {
            pair_interactions(params, particles, neighbors)
        });
        let wall = timed(&mut counters.wall, || {
            wall_interactions(params, particles, neighbors, walls)
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
        ContactCount { pair_entries, wall }
    }
}

/// Sphere–sphere forces, torques and conduction, each pair evaluated once from the half list.
///
/// Layer `l` of the cell grid owns the pairs of its particles, whose partners lie in layer
/// `l` or `l + 1`, so it writes only those two layers. Even layers run in parallel, then
/// the odd ones (chunk by chunk, below): no two tasks write the same particle, and every
/// particle receives its contributions in an order fixed by the list alone, so the sums do
/// not depend on the thread count. Returns the touching pairs counted from both sides.
pub fn pair_interactions(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
) -> u64 {
    pair_interactions_in_chunks(params, particles, neighbors, CHUNK)
}

/// [`pair_interactions`] with the layers taken in chunks of about `chunk` particles (the
/// results do not depend on it).
pub fn pair_interactions_in_chunks(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
    chunk: u32,
) -> u64 {
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
        ..
    } = neighbors;
    let layers = layer_start.len().saturating_sub(1);
    if layers == 0 {
        // no list yet: no pairs, and no task to start the sums below
        force.fill([0.0; 3]);
        torque.fill([0.0; 3]);
        heat_flow.fill(0.0);
        return 0;
    }
    let spheres = SphereArrays {
        pos,
        vel,
        omega,
        radius,
        mass,
        temp,
    };
    let constants = PairConstants {
        law: &params.particle_particle,
        heat: &params.conduction,
        dt: params.dt,
        uniform_pair: *uniform_pair,
    };
    // the task of layer l writes the slots of l and l + 1 and the entries of l, from the
    // start of its pieces (which reach the next task's start; it touches only those)
    let start = |l: usize| {
        let s = layer_start[l] as usize;
        let e = offsets[s] as usize;
        ((s, s), (s, (e, e)))
    };
    let layer_task = |l: usize, ((f, t), (q, (h, touch))): Accumulators| {
        let first_slot = layer_start[l] as usize;
        let first_entry = offsets[first_slot] as usize;
        if l.is_multiple_of(2) {
            // an even task is the first to write its two layers: their sums start from
            // zero here, where the task is about to use them, not in a pass of their own
            // over memory
            let written = layer_start[(l + 2).min(layers)] as usize - first_slot;
            f[..written].fill([0.0; 3]);
            t[..written].fill([0.0; 3]);
            q[..written].fill(0.0);
        }
        let slots = first_slot..layer_start[l + 1] as usize;
        let layer_entries = offsets[slots.end] as usize - first_entry;
        // the layer's histories are packed: those of its touching entries, in entry
        // order, from its first entry on (the stream the stage reads is the contacts',
        // not the list's)
        let touched = touch[..layer_entries]
            .iter()
            .map(|&t| usize::from(t))
            .sum::<usize>();
        OLD_HISTORIES.with_borrow_mut(|old| {
            old.clear();
            old.extend_from_slice(&h[..touched]);
            old.push(ContactHistory::default());
            let mut batch = PairBatch::default();
            // the owner's sums are kept apart and added once its contacts are done, as
            // each pair's partner sums are added in pair order: the order of every sum
            // is fixed by the list alone
            let mut owner = Owner::default();
            let entries = ListEntries {
                slots,
                offsets,
                partners,
                first_entry,
                fresh: touched as u32,
            };
            let mut evaluate = |batch: &mut PairBatch| {
                batch.evaluate(&constants, &spheres, old, h);
                owner.scatter(batch, (&mut *f, &mut *t, &mut *q), first_slot);
            };
            let touching_pairs =
                narrow_phase::scan(&entries, pos, radius, touch, &mut batch, &mut evaluate);
            // the batch holds fewer than a full batch's contacts now: one evaluation
            evaluate(&mut batch);
            owner.add_to((f, t, q), first_slot);
            touching_pairs
        })
    };
    // task k of a phase owns layer l = phase + 2k (its pieces reach the next task's start)
    let mut run = |phase: usize, tasks: Range<usize>| {
        let arrays = (
            (&mut force[..], &mut torque[..]),
            (&mut heat_flow[..], (&mut history[..], &mut touching[..])),
        );
        let origin = ((0, 0), (0, (0, 0)));
        let layer = |k: usize| phase + 2 * k;
        let work = |k: usize, pieces: Accumulators| layer_task(layer(k), pieces);
        for_each_task(arrays, origin, tasks, &|k| start(layer(k)), &work)
    };
    // The odd task of layer l must follow the even tasks of l - 1 and l + 1 (it writes a
    // layer of each, and each particle's sums keep that order). Rather than all even
    // tasks, then all odd ones, which reads every layer from memory twice once the state
    // outgrows the cache, the layers go in chunks of about `chunk` particles: a chunk's even
    // tasks, then the odd tasks whose two even neighbours are done; the chunk's last odd
    // layer waits for the next chunk's first even one. Same tasks, same order of every sum.
    let odd_tasks = layers.saturating_sub(1).div_ceil(2);
    let (mut pairs, mut first, mut odd_done) = (0, 0, 0);
    while first < layers {
        let mut end = first + 2;
        while end < layers && (layer_start[end] - layer_start[first]) < chunk {
            end += 2;
        }
        let end = end.min(layers);
        pairs += run(0, first / 2..end.div_ceil(2));
        let odd_ready = if end == layers {
            odd_tasks
        } else {
            end / 2 - 1
        };
        pairs += run(1, odd_done..odd_ready);
        odd_done = odd_ready;
        first = end;
    }
    2 * pairs
}

/// The sums of the particle whose contacts the pair stage is handing out.
struct Owner {
    slot: usize,
    force: Vec3,
    torque: Vec3,
    heat_flow: f64,
}

impl Default for Owner {
    fn default() -> Self {
        Self::new(usize::MAX)
    }
}

impl Owner {
    fn new(slot: usize) -> Self {
        Self {
            slot,
            force: [0.0; 3],
            torque: [0.0; 3],
            heat_flow: 0.0,
        }
    }

    /// Adds an evaluated batch's responses to the owners' and partners' sums of a task's
    /// pieces starting at `first_slot`, and empties the batch.
    #[inline(always)]
    fn scatter(
        &mut self,
        batch: &mut PairBatch,
        (f, t, q): (&mut [Vec3], &mut [Vec3], &mut [f64]),
        first_slot: usize,
    ) {
        for l in 0..batch.ready() {
            let (i, j, r) = batch.response(l);
            if i != self.slot {
                self.add_to((&mut *f, &mut *t, &mut *q), first_slot);
                *self = Owner::new(i);
            }
            self.force = add(self.force, r.force);
            self.torque = add(self.torque, r.torque_owner);
            self.heat_flow += r.heat_flow;
            let jl = j - first_slot;
            f[jl] = sub(f[jl], r.force);
            t[jl] = add(t[jl], r.torque_partner);
            q[jl] -= r.heat_flow;
        }
        batch.consume();
    }

    /// Adds the sums to the owner's slot of a task's pieces starting at `first_slot`.
    fn add_to(&self, (f, t, q): (&mut [Vec3], &mut [Vec3], &mut [f64]), first_slot: usize) {
        if self.slot == usize::MAX {
            return;
        }
        let il = self.slot - first_slot;
        f[il] = add(f[il], self.force);
        t[il] = add(t[il], self.torque);
        q[il] += self.heat_flow;
    }
}

/// A task's force, torque, heat-flow, history and touching pieces.
type Accumulators<'a> = (
    (&'a mut [Vec3], &'a mut [Vec3]),
    (&'a mut [f64], (&'a mut [ContactHistory], &'a mut [bool])),
);

/// Sphere–wall forces and heated-wall conduction over the wall candidates of the list,
/// added to the pair results (each particle writes only its own sums).
pub fn wall_interactions(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
    walls: &WallSet,
) -> u64 {
    let n = particles.len();
    if walls.is_empty() || n == 0 {
        return 0;
    }
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
        wall_offsets,
        wall_index,
        wall_history,
        wall_touching,
        ..
    } = neighbors;
    let wall_offsets = &*wall_offsets;
    let wall_index = &*wall_index;
    let dt = params.dt;
    let (law, heat) = (&params.particle_wall, &params.conduction);
    // task b owns the slots of block b and their wall candidates
    let start = |b: usize| {
        let first = b * BLOCK;
        let w = wall_offsets[first] as usize;
        ((first, first), (first, (w, w)))
    };
    let arrays = (
        (&mut force[..], &mut torque[..]),
        (
            &mut heat_flow[..],
            (&mut wall_history[..], &mut wall_touching[..]),
        ),
    );
    let work = |b: usize, ((f, t), (q, (h, touch))): Accumulators| {
        let first_slot = b * BLOCK;
        let first_entry = wall_offsets[first_slot] as usize;
        let mut touching = 0;
        for il in 0..f.len() {
            let i = first_slot + il;
            for e in wall_offsets[i] as usize..wall_offsets[i + 1] as usize {
                let (w, local) = (wall_index[e] as usize, e - first_entry);
                let Some(c) = walls.contact(w, pos[i], radius[i]) else {
                    if touch[local] {
                        h[local] = ContactHistory::default();
                        touch[local] = false;
                    }
                    continue;
                };
                let si = SphereState {
                    pos: pos[i],
                    vel: vel[i],
                    omega: omega[i],
                    radius: radius[i],
                    mass: mass[i],
                };
                let (kin, lever) = sphere_wall::kinematics(&si, &c);
                let resp = hertz_mindlin::respond(law, &kin, &mut h[local], dt);
                touch[local] = true;
                f[il] = add(f[il], resp.force);
                t[il] = add(t[il], resp.torque_on_i(lever));
                if let Some(tw) = walls.temperature(w) {
                    q[il] += heat.wall_conductance(c.overlap, si.radius) * (tw - temp[i]);
                }
                touching += 1;
            }
        }
        touching
    };
    let tasks = 0..n.div_ceil(BLOCK);
    for_each_task(arrays, ((0, 0), (0, (0, 0))), tasks, &start, &work)
}
