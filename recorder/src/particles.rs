//! The particle set: one array per field (LAMMPS style), permuted together into cell order.

use rayon::prelude::*;

/// Spheres of the simulation. Index `i` is the memory slot (changes at every re-sort);
/// `id[i]` is the particle's permanent id.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParticleSet {
    pub id: Vec<u32>,
    pub pos: Vec<[f64; 3]>,
    pub vel: Vec<[f64; 3]>,
    pub omega: Vec<[f64; 3]>,
    pub force: Vec<[f64; 3]>,
    pub torque: Vec<[f64; 3]>,
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    /// Temperature (K).
    pub temp: Vec<f64>,
    /// Heat flowing into the particle this step (W).
    pub heat_flow: Vec<f64>,
}

impl ParticleSet {
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// Adds a sphere at rest.
    pub fn push(&mut self, id: u32, pos: [f64; 3], radius: f64, density: f64, temp: f64) {
        self.id.push(id);
        self.pos.push(pos);
        self.vel.push([0.0; 3]);
        self.omega.push([0.0; 3]);
        self.force.push([0.0; 3]);
        self.torque.push([0.0; 3]);
        self.radius.push(radius);
        self.mass
            .push(density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3));
        self.temp.push(temp);
        self.heat_flow.push(0.0);
    }

    /// Reorders the state fields so that new slot `i` holds what old slot `order[i]` held.
    /// The per-step outputs (`force`, `torque`, `heat_flow`) are left in the old order: the
    /// pair stage zeroes and refills them after every re-sort.
    pub fn permute_state(&mut self, order: &[u32], scratch: &mut PermuteScratch) {
        permute_field(&mut self.id, order, &mut scratch.ids);
        for field in [&mut self.pos, &mut self.vel, &mut self.omega] {
            permute_field(field, order, &mut scratch.vectors);
        }
        for field in [&mut self.radius, &mut self.mass, &mut self.temp] {
            permute_field(field, order, &mut scratch.scalars);
        }
    }

    /// Checks a set read back from a checkpoint: every field holds `n` values and the ids
    /// are a permutation of `0..n` (the engine indexes by both).
    pub fn check(&self, n: usize) -> Result<(), String> {
        let lengths = [
            ("id", self.id.len()),
            ("pos", self.pos.len()),
            ("vel", self.vel.len()),
            ("omega", self.omega.len()),
            ("force", self.force.len()),
            ("torque", self.torque.len()),
            ("radius", self.radius.len()),
            ("mass", self.mass.len()),
            ("temp", self.temp.len()),
            ("heat_flow", self.heat_flow.len()),
        ];
        if let Some((field, len)) = lengths.iter().find(|(_, len)| *len != n) {
            return Err(format!(
                "particle field {field} has {len} values, the case has {n} particles"
            ));
        }
        let mut seen = vec![false; n];
        for (slot, &id) in self.id.iter().enumerate() {
            match seen.get_mut(id as usize) {
                Some(s) if !*s => *s = true,
                _ => {
                    return Err(format!(
                        "particle slot {slot} has id {id}: ids must be 0..{n}, each once"
                    ))
                }
            }
        }
        Ok(())
    }

    /// Slot of every id: `slot_of()[id] = i`.
    pub fn slot_of(&self) -> Vec<u32> {
        let mut slot = vec![u32::MAX; self.len()];
        for (i, &id) in self.id.iter().enumerate() {
            slot[id as usize] = i as u32;
        }
        slot
    }
}

/// Buffers reused by every re-sort (one per field type), so that a rebuild allocates nothing.
#[derive(Debug, Clone, Default)]
pub struct PermuteScratch {
    ids: Vec<u32>,
    vectors: Vec<[f64; 3]>,
    scalars: Vec<f64>,
}

/// `field[i] = old[order[i]]`, through `scratch` (which then holds the old order).
pub fn permute_field<T: Copy + Send + Sync>(
    field: &mut Vec<T>,
    order: &[u32],
    scratch: &mut Vec<T>,
) {
    order
        .par_iter()
        .with_min_len(4096)
        .map(|&o| field[o as usize])
        .collect_into_vec(scratch);
    std::mem::swap(field, scratch);
}
