//! Seeded insertion without overlap: random sites of a loose cubic lattice inside the drum.

use crate::particles::ParticleSet;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Lattice spacing is `2R(1 + GAP)`: the gap leaves room for a jitter that never overlaps.
const GAP: f64 = 0.05;

/// Site centres of the insertion lattice, in a fixed order (x fastest, then z, then y).
fn lattice_sites(radius: f64, drum_radius: f64, drum_length: f64) -> Vec<[f64; 3]> {
    let spacing = 2.0 * radius * (1.0 + GAP);
    // keep a half-gap from every wall so that the jitter cannot reach it either
    let clearance = radius * (1.0 + GAP);
    let rho_max = drum_radius - clearance;
    let half_len = 0.5 * drum_length - clearance;
    if rho_max <= 0.0 || half_len < 0.0 {
        return Vec::new();
    }
    let ny = (2.0 * half_len / spacing).floor() as i64 + 1;
    let y0 = -0.5 * (ny - 1) as f64 * spacing;
    let nr = (rho_max / spacing).floor() as i64;
    let mut sites = Vec::new();
    for iy in 0..ny {
        let y = y0 + iy as f64 * spacing;
        for iz in -nr..=nr {
            let z = iz as f64 * spacing;
            for ix in -nr..=nr {
                let x = ix as f64 * spacing;
                if x * x + z * z <= rho_max * rho_max {
                    sites.push([x, y, z]);
                }
            }
        }
    }
    sites
}

/// How many particles the insertion lattice can hold, counted up to `limit`: the sites are
/// counted row by row from the axis outwards without being listed, so a drum millions of
/// radii wide costs no memory and at most about `sqrt(limit)` rows.
pub fn lattice_site_count(radius: f64, drum_radius: f64, drum_length: f64, limit: usize) -> usize {
    let spacing = 2.0 * radius * (1.0 + GAP);
    let clearance = radius * (1.0 + GAP);
    let rho_max = drum_radius - clearance;
    let half_len = 0.5 * drum_length - clearance;
    if !(rho_max > 0.0 && half_len >= 0.0 && spacing > 0.0) {
        return 0;
    }
    // as in `lattice_sites` (float-to-int casts saturate)
    let ny = ((2.0 * half_len / spacing).floor() as i64).saturating_add(1) as u128;
    let nr = (rho_max / spacing).floor() as i64;
    let inside = |ix: i64, iz: i64| {
        let (x, z) = (ix as f64 * spacing, iz as f64 * spacing);
        x * x + z * z <= rho_max * rho_max
    };
    let limit = limit as u128;
    let mut total: u128 = 0;
    for step in 0..=nr.saturating_mul(2) {
        // rows iz = 0, 1, -1, 2, -2, ...
        let iz = if step % 2 == 1 {
            step / 2 + 1
        } else {
            -(step / 2)
        };
        if iz.abs() > nr {
            break;
        }
        // the largest ix ≥ 0 inside the row: from the circle, then corrected by the lattice's
        // own test (rounding moves it by one at most; a bounded loop even if rho² overflows)
        let z = iz as f64 * spacing;
        let mut k = ((rho_max * rho_max - z * z).max(0.0).sqrt() / spacing).floor() as i64;
        k = k.min(nr);
        for _ in 0..2 {
            if k < nr && inside(k + 1, iz) {
                k += 1;
            }
        }
        for _ in 0..3 {
            if k >= 0 && !inside(k, iz) {
                k -= 1;
            }
        }
        if k >= 0 {
            total += (2 * k as u128 + 1) * ny;
        }
        if total >= limit {
            return limit as usize;
        }
    }
    total as usize
}

/// Uniform in [0, 1) from the top 53 bits.
pub(crate) fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Places `count` spheres at rest on randomly chosen lattice sites, each jittered inside
/// its gap; ids follow the lattice order. `None` if the lattice is too small.
pub fn insert(
    count: usize,
    radius: f64,
    density: f64,
    temp: f64,
    drum_radius: f64,
    drum_length: f64,
    seed: u64,
) -> Option<ParticleSet> {
    let sites = lattice_sites(radius, drum_radius, drum_length);
    if sites.len() < count {
        return None;
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    // partial Fisher–Yates: the first `count` entries are a uniform random subset
    let mut order: Vec<u32> = (0..sites.len() as u32).collect();
    for k in 0..count {
        let pick = k + (rng.next_u64() % (sites.len() - k) as u64) as usize;
        order.swap(k, pick);
    }
    let mut chosen = order[..count].to_vec();
    chosen.sort_unstable();
    let jitter = radius * GAP;
    let mut particles = ParticleSet::default();
    for (id, &s) in chosen.iter().enumerate() {
        let c = sites[s as usize];
        let mut p = [0.0; 3];
        for (k, pk) in p.iter_mut().enumerate() {
            *pk = c[k] + jitter * (2.0 * uniform(&mut rng) - 1.0);
        }
        particles.push(id as u32, p, radius, density, temp);
    }
    Some(particles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_site_count_is_the_lattice_size_up_to_its_limit() {
        for (r, rd, l) in [
            (0.005, 0.05, 0.06),
            (0.0013, 0.1, 0.02),
            (0.004, 0.0421, 0.1),
            (0.01, 0.011, 0.05),
            (0.01, 0.005, 0.05),
        ] {
            let n = lattice_sites(r, rd, l).len();
            assert_eq!(lattice_site_count(r, rd, l, usize::MAX), n, "{r} {rd} {l}");
            assert_eq!(lattice_site_count(r, rd, l, n / 2), n / 2);
        }
        // a drum 10^12 radii wide: counted to the limit, instantly
        assert_eq!(lattice_site_count(1e-12, 1.0, 1.0, 1 << 31), 1 << 31);
        assert_eq!(lattice_site_count(1e-3, 1e300, 1e-2, 1000), 1000);
    }

    #[test]
    fn inserted_spheres_never_overlap_and_stay_inside() {
        let (r, rd, len) = (0.005, 0.05, 0.06);
        let n = lattice_site_count(r, rd, len, usize::MAX) * 9 / 10;
        let p = insert(n, r, 2500.0, 300.0, rd, len, 3).unwrap();
        assert_eq!(p.len(), n);
        for i in 0..n {
            let [x, y, z] = p.pos[i];
            assert!((x * x + z * z).sqrt() + r <= rd);
            assert!(y.abs() + r <= 0.5 * len);
            for j in 0..i {
                let d: f64 = (0..3)
                    .map(|k| (p.pos[i][k] - p.pos[j][k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(d >= 2.0 * r, "{i} and {j} overlap: {d}");
            }
        }
    }

    #[test]
    fn same_seed_same_positions_other_seed_differs() {
        let a = insert(100, 0.005, 2500.0, 300.0, 0.05, 0.06, 1).unwrap();
        let b = insert(100, 0.005, 2500.0, 300.0, 0.05, 0.06, 1).unwrap();
        let c = insert(100, 0.005, 2500.0, 300.0, 0.05, 0.06, 2).unwrap();
        assert_eq!(a, b);
        assert_ne!(a.pos, c.pos);
    }

    #[test]
    fn too_many_particles_is_refused() {
        let n = lattice_site_count(0.005, 0.05, 0.06, usize::MAX);
        assert!(insert(n + 1, 0.005, 2500.0, 300.0, 0.05, 0.06, 1).is_none());
    }
}
