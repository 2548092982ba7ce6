//! One DEM step: integrate, broad phase, pair and wall interactions, integrate. The pipeline
//! owns only scratch data; every set is passed to `step` explicitly.

use crate::contact::contact_sphere_sphere::{self as sphere_sphere, SphereState};
use crate::contact::{contact_sphere_wall as sphere_wall, hertz_mindlin, ContactHistory, PairLaw};
use crate::counters::{timed, Counters};
use crate::heat::ConductionLaw;
use crate::integrate;
use crate::math::*;
use crate::neighbor::{CellGrid, NeighborList};
use crate::particles::ParticleSet;
use crate::wall::WallSet;
use rayon::prelude::*;

/// Particles per parallel task in the interaction stages.
const BLOCK: usize = 256;

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
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
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
        timed(&mut counters.integrate, || {
            integrate::initial_integrate(particles, params.dt, params.gravity)
        });
        timed(&mut counters.neighbor, || {
            if neighbors.needs_rebuild(particles) {
                neighbors.rebuild(particles, &self.grid);
            }
        });
        let pair_entries = timed(&mut counters.pair, || {
            pair_interactions(params, particles, neighbors)
        });
        let wall = timed(&mut counters.wall, || {
            wall_interactions(params, particles, neighbors, walls)
        });
        timed(&mut counters.integrate, || {
            integrate::final_integrate(particles, params.dt, params.gravity);
            integrate::update_temperatures(particles, params.dt, params.conduction.heat_capacity);
        });
        counters.steps += 1;
        counters.particle_steps += particles.len() as u64;
        ContactCount { pair_entries, wall }
    }
}

/// Splits `items` into consecutive mutable pieces, piece `b` covering `bounds[b]..bounds[b+1]`.
fn split_by<T>(mut items: &mut [T], bounds: impl Iterator<Item = (usize, usize)>) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    let mut at = 0;
    for (lo, hi) in bounds {
        let (_, rest) = std::mem::take(&mut items).split_at_mut(lo - at);
        let (piece, rest) = rest.split_at_mut(hi - lo);
        pieces.push(piece);
        items = rest;
        at = hi;
    }
    pieces
}

/// Runs `work` on every block, in parallel when there is more than one.
fn for_each_block<T: Send>(blocks: Vec<T>, work: impl Fn(T) -> u64 + Sync + Send) -> u64 {
    if blocks.len() == 1 {
        blocks.into_iter().map(work).sum()
    } else {
        blocks.into_par_iter().map(work).sum()
    }
}

/// Sphere–sphere forces, torques and conduction. Every particle sums over its own full
/// neighbour list and writes only its own entries: no write conflicts, thread-count
/// independent. Returns the number of touching entries.
pub fn pair_interactions(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
) -> u64 {
    let n = particles.len();
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
    let offsets = &neighbors.offsets;
    let nbrs = &neighbors.neighbors;
    let block_bounds = (0..n.div_ceil(BLOCK)).map(|b| (b * BLOCK, ((b + 1) * BLOCK).min(n)));
    let entry_bounds = || {
        block_bounds
            .clone()
            .map(|(lo, hi)| (offsets[lo] as usize, offsets[hi] as usize))
    };
    let history = split_by(&mut neighbors.history, entry_bounds());
    let areas = split_by(&mut neighbors.sqrt_area, entry_bounds());
    let blocks: Vec<_> = force
        .chunks_mut(BLOCK)
        .zip(torque.chunks_mut(BLOCK))
        .zip(heat_flow.chunks_mut(BLOCK))
        .zip(history.into_iter().zip(areas))
        .enumerate()
        .collect();
    let state = |i: usize| SphereState {
        pos: pos[i],
        vel: vel[i],
        omega: omega[i],
        radius: radius[i],
        mass: mass[i],
    };
    let dt = params.dt;
    let (law, heat) = (&params.particle_particle, &params.conduction);
    for_each_block(
        blocks,
        |(b, (((f_block, t_block), q_block), (h_block, a_block)))| {
            let lo = b * BLOCK;
            let base = offsets[lo] as usize;
            let mut touching = 0;
            for (k, ((f_out, t_out), q_out)) in f_block
                .iter_mut()
                .zip(t_block.iter_mut())
                .zip(q_block.iter_mut())
                .enumerate()
            {
                let i = lo + k;
                let si = state(i);
                let (mut f, mut t, mut q) = ([0.0; 3], [0.0; 3], 0.0);
                for e in offsets[i] as usize..offsets[i + 1] as usize {
                    let j = nbrs[e] as usize;
                    let h: &mut ContactHistory = &mut h_block[e - base];
                    match sphere_sphere::kinematics(&si, &state(j)) {
                        Some((kin, r)) => {
                            let resp = hertz_mindlin::respond(law, &kin, h, dt);
                            f = add(f, resp.force);
                            t = add(t, resp.torque);
                            let sqrt_area = heat.pair_area(r, si.radius, radius[j]).sqrt();
                            q += heat.pair_conductivity * sqrt_area * (temp[j] - temp[i]);
                            a_block[e - base] = sqrt_area;
                            touching += 1;
                        }
                        None => {
                            *h = ContactHistory::default();
                            a_block[e - base] = 0.0;
                        }
                    }
                }
                *f_out = f;
                *t_out = t;
                *q_out = q;
            }
            touching
        },
    )
}

/// Sphere–wall forces and heated-wall conduction, added to the pair results.
pub fn wall_interactions(
    params: &StepParams,
    particles: &mut ParticleSet,
    neighbors: &mut NeighborList,
    walls: &WallSet,
) -> u64 {
    let nw = walls.len();
    if nw == 0 {
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
    let blocks: Vec<_> = force
        .chunks_mut(BLOCK)
        .zip(torque.chunks_mut(BLOCK))
        .zip(heat_flow.chunks_mut(BLOCK))
        .zip(neighbors.wall_history.chunks_mut(BLOCK * nw))
        .enumerate()
        .collect();
    let dt = params.dt;
    let (law, heat) = (&params.particle_wall, &params.conduction);
    for_each_block(blocks, |(b, (((f_block, t_block), q_block), h_block))| {
        let mut touching = 0;
        for k in 0..f_block.len() {
            let i = b * BLOCK + k;
            let si = SphereState {
                pos: pos[i],
                vel: vel[i],
                omega: omega[i],
                radius: radius[i],
                mass: mass[i],
            };
            for w in 0..nw {
                let h = &mut h_block[k * nw + w];
                match walls.contact(w, si.pos, si.radius) {
                    Some(c) => {
                        let kin = sphere_wall::kinematics(&si, &c);
                        let resp = hertz_mindlin::respond(law, &kin, h, dt);
                        f_block[k] = add(f_block[k], resp.force);
                        t_block[k] = add(t_block[k], resp.torque);
                        if let Some(tw) = walls.temperature(w) {
                            q_block[k] +=
                                heat.wall_conductance(c.overlap, si.radius) * (tw - temp[i]);
                        }
                        touching += 1;
                    }
                    None => *h = ContactHistory::default(),
                }
            }
        }
        touching
    })
}
