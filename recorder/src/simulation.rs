//! A drum case brought to life: insertion, settling, spin-up, temperatures at `t0`, heating.
//! Owns the sets and the pipeline, and reports heat totals and group means.

use crate::case::{Case, TemperatureSpec};
use crate::contact::PairLaw;
use crate::counters::Counters;
use crate::heat::ConductionLaw;
use crate::insertion;
use crate::math::{norm2, sub};
use crate::neighbor::{CellGrid, NeighborList};
use crate::particles::ParticleSet;
use crate::periodic::nearest_image;
use crate::pipeline::{ContactCount, Pipeline, StepParams};
use crate::wall::WallSet;
use tdex_format::Snapshot;

/// Standard gravity along −z (m/s²).
pub const GRAVITY: f64 = 9.81;
/// Verlet skin as a fraction of the particle diameter (0.4: fewer rebuilds for more list
/// entries; since the batched pair law an entry costs less than a rebuild's share, measured
/// on bench_drum with a short spin-up: docs/benchmarks.md).
const SKIN_PER_DIAMETER: f64 = 0.4;

#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    #[error("cannot insert {count} particles: the drum has no room for them without overlaps")]
    Insertion { count: usize },
    #[error("the simulation became unstable at step {step} (t = {time:.6} s): particle {id} is at {pos:?}, outside the drum; reduce time.dt")]
    Unstable {
        step: u64,
        time: f64,
        id: u32,
        pos: [f64; 3],
    },
}

impl tdex_format::Classify for SimulationError {
    /// A run that cannot insert its particles or blows up fails as a run (exit code 1),
    /// though the case's parameters are the cause: the message names them.
    fn fault(&self) -> tdex_format::Fault {
        tdex_format::Fault::Run
    }
}

/// Initial-temperature groups: the hot and cold halves of a split, by particle id.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Groups {
    /// `hot[id]`: whether particle `id` started hot; empty for a uniform start.
    pub hot: Vec<bool>,
    /// The split-plane coordinate (midway between the last hot and the first cold particle).
    pub split_at: Option<f64>,
}

/// Sums over the bed at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatSummary {
    /// `Σ m c T` (J).
    pub total_heat: f64,
    pub mean_temperature: f64,
    pub hot_mean: Option<f64>,
    pub cold_mean: Option<f64>,
}

#[derive(Clone)]
pub struct Simulation {
    pub case: Case,
    pub params: StepParams,
    pub particles: ParticleSet,
    pub neighbors: NeighborList,
    pub walls: WallSet,
    pub pipeline: Pipeline,
    pub counters: Counters,
    pub groups: Groups,
    pub time: f64,
    pub step: u64,
    pub last_contacts: ContactCount,
}

impl Simulation {
    /// Inserts the particles of a validated case, drum at rest, all at the initial temperature.
    pub fn new(case: &Case) -> Result<Self, SimulationError> {
        let p = &case.particles;
        let m = &case.material;
        let start_temp = case.temperature.before_t0();
        let sizes = p.size_classes();
        let particles = insertion::insert(
            &sizes,
            m.density,
            start_temp,
            case.drum.radius,
            case.drum.length,
            case.seed,
        )
        .ok_or(SimulationError::Insertion { count: p.count })?;
        let rolling = case.contact.rolling_model;
        let params = StepParams {
            dt: case.time.dt,
            gravity: [0.0, 0.0, -GRAVITY],
            particle_particle: PairLaw::new(
                m.youngs_modulus,
                m.poisson_ratio,
                &case.contact.particle_particle,
                rolling,
            ),
            particle_wall: PairLaw::new(
                m.youngs_modulus,
                m.poisson_ratio,
                &case.contact.particle_wall,
                rolling,
            ),
            conduction: ConductionLaw::new(
                &case.conduction,
                m.conductivity,
                case.drum.wall_conductivity.unwrap_or(m.conductivity),
                m.heat_capacity,
                m.youngs_modulus,
            ),
            axial_period: case.drum.axial_period(),
        };
        let walls = WallSet::of_drum(&case.drum);
        // the largest spheres set the cells: a pair of them must be found within one
        let skin = SKIN_PER_DIAMETER * 2.0 * sizes.largest();
        let cell = 2.0 * sizes.largest() + skin;
        let rd = case.drum.radius + cell;
        let grid = match case.drum.axial_period() {
            // the grid spans exactly one period along the axis, the positions' range
            Some(period) => {
                let half = 0.5 * period.length;
                CellGrid::periodic_along_y([-rd, -half, -rd], [rd, half, rd], cell)
            }
            None => {
                let half = 0.5 * case.drum.length + cell;
                CellGrid::new([-rd, -half, -rd], [rd, half, rd], cell)
            }
        };
        Ok(Self {
            case: case.clone(),
            params,
            neighbors: NeighborList::new(skin),
            particles,
            walls,
            pipeline: Pipeline::new(grid),
            counters: Counters::default(),
            groups: Groups {
                hot: Vec::new(),
                split_at: None,
            },
            time: 0.0,
            step: 0,
            last_contacts: ContactCount::default(),
        })
    }

    /// One DEM step.
    pub fn step(&mut self) {
        self.last_contacts = self.pipeline.step(
            &self.params,
            &mut self.particles,
            &mut self.neighbors,
            &self.walls,
            &mut self.counters,
        );
        self.step += 1;
        self.time = self.step as f64 * self.params.dt;
    }

    /// Runs `steps` steps, calling `progress(done)` every `every` steps; checks that no
    /// particle has left the drum (the sign of an unstable time step) at each report.
    pub fn run(
        &mut self,
        steps: u64,
        every: u64,
        progress: &mut dyn FnMut(u64),
    ) -> Result<(), SimulationError> {
        let every = every.max(1);
        for s in 1..=steps {
            self.step();
            if s % every == 0 || s == steps {
                self.check_inside()?;
                progress(s);
            }
        }
        Ok(())
    }

    /// Fails if a particle has left the drum (the sign of an unstable time step).
    pub fn check_inside(&self) -> Result<(), SimulationError> {
        let (rd, half) = (self.case.drum.radius, 0.5 * self.case.drum.length);
        for (i, p) in self.particles.pos.iter().enumerate() {
            let rho2 = p[0] * p[0] + p[2] * p[2];
            let inside = rho2 <= rd * rd && p[1].abs() <= half;
            if !inside {
                return Err(SimulationError::Unstable {
                    step: self.step,
                    time: self.time,
                    id: self.particles.id[i],
                    pos: *p,
                });
            }
        }
        Ok(())
    }

    /// Starts the drum turning at the case's speed.
    pub fn start_rotation(&mut self) {
        self.walls.angular_velocity = self.case.angular_velocity();
    }

    /// Assigns the initial temperatures at `t0` and switches on the heated wall, if any.
    pub fn assign_temperatures(&mut self) {
        let n = self.particles.len();
        match self.case.temperature {
            TemperatureSpec::Uniform { value, .. } => {
                self.particles.temp.iter_mut().for_each(|x| *x = value);
                self.groups = Groups {
                    hot: Vec::new(),
                    split_at: None,
                };
            }
            TemperatureSpec::Split {
                hot: th,
                cold: tc,
                split_axis,
            } => {
                let axis = split_axis.index();
                // rank by coordinate, ties by id: the first ⌊N/2⌋ are hot, whatever the tilt of the bed
                let mut rank: Vec<usize> = (0..n).collect();
                let key = |i: usize| (self.particles.pos[i][axis], self.particles.id[i]);
                rank.sort_by(|&a, &b| {
                    key(a)
                        .partial_cmp(&key(b))
                        .unwrap_or(std::cmp::Ordering::Equal)
                });
                let n_hot = n / 2;
                let mut hot = vec![false; n];
                for &i in &rank[..n_hot] {
                    hot[self.particles.id[i] as usize] = true;
                }
                let split_at = 0.5
                    * (self.particles.pos[rank[n_hot.saturating_sub(1)]][axis]
                        + self.particles.pos[rank[n_hot]][axis]);
                for i in 0..n {
                    self.particles.temp[i] = if hot[self.particles.id[i] as usize] {
                        th
                    } else {
                        tc
                    };
                }
                self.groups = Groups {
                    hot,
                    split_at: Some(split_at),
                };
            }
        }
        self.walls.mantle_temperature = self.case.drum.wall_temperature;
    }

    /// Total heat and group means now.
    pub fn heat_summary(&self) -> HeatSummary {
        let p = &self.particles;
        let c = self.params.conduction.heat_capacity;
        let (mut total, mut sum_t) = (0.0, 0.0);
        let (mut hot_sum, mut hot_n, mut cold_sum, mut cold_n) = (0.0, 0usize, 0.0, 0usize);
        // slot order is fixed between rebuilds and independent of the thread count
        for i in 0..p.len() {
            total += p.mass[i] * c * p.temp[i];
            sum_t += p.temp[i];
            if let Some(&h) = self.groups.hot.get(p.id[i] as usize) {
                if h {
                    hot_sum += p.temp[i];
                    hot_n += 1;
                } else {
                    cold_sum += p.temp[i];
                    cold_n += 1;
                }
            }
        }
        let mean = |s: f64, k: usize| if k > 0 { Some(s / k as f64) } else { None };
        HeatSummary {
            total_heat: total,
            mean_temperature: sum_t / p.len() as f64,
            hot_mean: mean(hot_sum, hot_n),
            cold_mean: mean(cold_sum, cold_n),
        }
    }

    /// Pairs touching at the last step, each once, in the order the DEM lists them:
    /// `(smaller id, larger id, sqrt(contact area))` — the recorder's sample. The area is
    /// recomputed from the positions the pair stage used (the last half kick moves none), by
    /// the same expressions, so it is the conducted area to the bit.
    pub fn touching_pairs(&self) -> impl Iterator<Item = (u32, u32, f64)> + '_ {
        let (list, p) = (&self.neighbors, &self.particles);
        let heat = &self.params.conduction;
        (0..p.len()).flat_map(move |i| {
            list.range(i).filter(|&e| list.touching[e]).map(move |e| {
                let j = list.neighbors[e] as usize;
                let delta = nearest_image(sub(p.pos[i], p.pos[j]), self.params.axial_period);
                let r = norm2(delta).sqrt();
                let sqrt_area = heat.pair_area(r, p.radius[i], p.radius[j]).sqrt();
                let (a, b) = (p.id[i].min(p.id[j]), p.id[i].max(p.id[j]));
                (a, b, sqrt_area)
            })
        })
    }

    /// Particles touching a conducting wall now, each as `(id, particles + wall, sqrt(A))`:
    /// the wall rows of the recorder's sample (none when the walls are adiabatic).
    pub fn touching_walls(&self) -> impl Iterator<Item = (u32, u32, f64)> + '_ {
        let p = &self.particles;
        let n = p.len() as u32;
        let conducting = (0..self.walls.len()).filter(|&w| self.walls.temperature(w).is_some());
        // a bit per conducting wall (a drum has three walls)
        let mask: u64 = conducting.map(|w| 1u64 << w).sum();
        let particles = if mask == 0 { 0 } else { p.len() };
        (0..particles).flat_map(move |i| {
            (0..self.walls.len())
                .filter(move |&w| mask & (1 << w) != 0)
                .filter_map(move |w| {
                    self.walls.contact(w, p.pos[i], p.radius[i]).map(|c| {
                        let sqrt_area = self
                            .params
                            .conduction
                            .wall_sqrt_area(c.overlap, p.radius[i]);
                        (p.id[i], n + w as u32, sqrt_area)
                    })
                })
        })
    }

    /// The particles now, in id order, as snapshot `index` of a recording.
    pub fn snapshot(&self, index: u32) -> Snapshot {
        let p = &self.particles;
        let mut slot = vec![0usize; p.len()];
        for (i, &id) in p.id.iter().enumerate() {
            slot[id as usize] = i;
        }
        Snapshot {
            index,
            time: self.time,
            id: (0..p.len() as u32).collect(),
            pos: slot.iter().map(|&i| p.pos[i]).collect(),
            radius: slot.iter().map(|&i| p.radius[i]).collect(),
            temp: slot.iter().map(|&i| p.temp[i]).collect(),
            vel: slot.iter().map(|&i| p.vel[i]).collect(),
        }
    }

    /// Particle–particle contacts per particle in the last step (coordination number).
    pub fn contacts_per_particle(&self) -> f64 {
        self.last_contacts.pair_entries as f64 / self.particles.len() as f64
    }
}
