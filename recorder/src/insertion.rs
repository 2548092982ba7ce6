//! Seeded insertion without overlap: random sites of a loose cubic lattice inside the drum
//! (one size), or random sequential placement, largest first (several sizes).

use crate::case::SizeClasses;
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

/// Largest share of the drum's volume the spheres of several sizes may fill at insertion:
/// random sequential placement jams near 0.38 for equal spheres and higher for mixed ones,
/// so 0.30 is reached in a few attempts per sphere.
pub const MAX_RANDOM_FILL: f64 = 0.30;
/// Attempts per sphere before random placement gives up.
const ATTEMPTS: usize = 100_000;

/// Places the spheres of `sizes` at rest, drum at rest. One size: randomly chosen sites of a
/// lattice, each jittered inside its gap, ids in lattice order (the bed every one-size case
/// has always had). Several sizes: [`insert_mixed`]. `None` if they do not fit.
pub fn insert(
    sizes: &SizeClasses,
    density: f64,
    temp: f64,
    drum_radius: f64,
    drum_length: f64,
    seed: u64,
) -> Option<ParticleSet> {
    if sizes.radius.len() > 1 {
        return insert_mixed(sizes, density, temp, drum_radius, drum_length, seed);
    }
    let count: usize = sizes.count.iter().sum();
    let radius = sizes.largest();
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

/// Spheres of several sizes placed one by one, largest first, each at uniformly random
/// points of the drum until one overlaps no sphere placed before (LIGGGHTS `insert/pack`
/// works the same way), with a gap of [`GAP`] of the smaller radius. A lattice spaced for
/// the largest sphere would leave the small ones far apart and hold too few. The ids are
/// then dealt in a seeded random order, so no id range belongs to one size. `None` if a
/// sphere finds no room in [`ATTEMPTS`] tries.
pub fn insert_mixed(
    sizes: &SizeClasses,
    density: f64,
    temp: f64,
    drum_radius: f64,
    drum_length: f64,
    seed: u64,
) -> Option<ParticleSet> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let largest = sizes.largest();
    let cell = 2.0 * largest * (1.0 + GAP);
    let per_side = ((2.0 * drum_radius / cell).ceil() as usize).max(1);
    let along = ((drum_length / cell).ceil() as usize).max(1);
    let cell_of = |p: &[f64; 3]| {
        let index =
            |x: f64, lo: f64, n: usize| (((x - lo) / cell).floor().max(0.0) as usize).min(n - 1);
        (
            index(p[0], -drum_radius, per_side),
            index(p[1], -0.5 * drum_length, along),
            index(p[2], -drum_radius, per_side),
        )
    };
    let flat = |(i, j, k): (usize, usize, usize)| (j * per_side + k) * per_side + i;
    let mut occupants: Vec<Vec<u32>> = vec![Vec::new(); per_side * per_side * along];
    let mut placed: Vec<([f64; 3], f64)> = Vec::with_capacity(sizes.count.iter().sum());
    for (&radius, &count) in sizes.radius.iter().zip(&sizes.count).rev() {
        let reach = drum_radius - radius * (1.0 + GAP);
        let half = 0.5 * drum_length - radius * (1.0 + GAP);
        if reach <= 0.0 || half < 0.0 {
            return None;
        }
        for _ in 0..count {
            let mut found = None;
            for _ in 0..ATTEMPTS {
                // uniform in the disc (ρ ∝ sqrt u) and along the axis
                let rho = reach * uniform(&mut rng).sqrt();
                let theta = 2.0 * std::f64::consts::PI * uniform(&mut rng);
                let y = half * (2.0 * uniform(&mut rng) - 1.0);
                let p = [rho * theta.cos(), y, rho * theta.sin()];
                let (ci, cj, ck) = cell_of(&p);
                let clear = (ci.saturating_sub(1)..=(ci + 1).min(per_side - 1)).all(|i| {
                    (cj.saturating_sub(1)..=(cj + 1).min(along - 1)).all(|j| {
                        (ck.saturating_sub(1)..=(ck + 1).min(per_side - 1)).all(|k| {
                            occupants[flat((i, j, k))].iter().all(|&o| {
                                let (q, r) = placed[o as usize];
                                let d2: f64 = (0..3).map(|a| (p[a] - q[a]).powi(2)).sum();
                                let gap = (radius + r) + GAP * radius.min(r);
                                d2 >= gap * gap
                            })
                        })
                    })
                });
                if clear {
                    found = Some(p);
                    break;
                }
            }
            let p = found?;
            occupants[flat(cell_of(&p))].push(placed.len() as u32);
            placed.push((p, radius));
        }
    }
    for k in (1..placed.len()).rev() {
        let pick = (rng.next_u64() % (k as u64 + 1)) as usize;
        placed.swap(k, pick);
    }
    let mut particles = ParticleSet::default();
    for (id, (p, r)) in placed.into_iter().enumerate() {
        particles.push(id as u32, p, r, density, temp);
    }
    Some(particles)
}

/// Share of the drum's volume the spheres of `sizes` take ([`MAX_RANDOM_FILL`]).
pub fn random_fill(sizes: &SizeClasses, drum_radius: f64, drum_length: f64) -> f64 {
    let drum = std::f64::consts::PI * drum_radius * drum_radius * drum_length;
    sizes.solid_volume() / drum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(count: usize, radius: f64) -> SizeClasses {
        SizeClasses {
            radius: vec![radius],
            count: vec![count],
        }
    }

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
        let p = insert(&one(n, r), 2500.0, 300.0, rd, len, 3).unwrap();
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
        let a = insert(&one(100, 0.005), 2500.0, 300.0, 0.05, 0.06, 1).unwrap();
        let b = insert(&one(100, 0.005), 2500.0, 300.0, 0.05, 0.06, 1).unwrap();
        let c = insert(&one(100, 0.005), 2500.0, 300.0, 0.05, 0.06, 2).unwrap();
        assert_eq!(a, b);
        assert_ne!(a.pos, c.pos);
    }

    #[test]
    fn too_many_particles_is_refused() {
        let n = lattice_site_count(0.005, 0.05, 0.06, usize::MAX);
        assert!(insert(&one(n + 1, 0.005), 2500.0, 300.0, 0.05, 0.06, 1).is_none());
    }

    #[test]
    fn spheres_of_several_sizes_never_overlap_and_each_class_is_spread_through_the_drum() {
        let (rd, len) = (0.05, 0.06);
        let sizes = SizeClasses {
            radius: vec![0.002, 0.003, 0.005],
            count: vec![60, 50, 40],
        };
        let p = insert(&sizes, 2500.0, 300.0, rd, len, 7).unwrap();
        assert_eq!(p.len(), 150);
        for (c, &r) in sizes.radius.iter().enumerate() {
            let members: Vec<usize> = (0..p.len()).filter(|&i| p.radius[i] == r).collect();
            assert_eq!(members.len(), sizes.count[c]);
            // not dealt in id order: each class reaches both halves of the drum
            assert!(members.iter().any(|&i| p.pos[i][1] < 0.0));
            assert!(members.iter().any(|&i| p.pos[i][1] > 0.0));
        }
        for i in 0..p.len() {
            let [x, y, z] = p.pos[i];
            assert!((x * x + z * z).sqrt() + p.radius[i] <= rd);
            assert!(y.abs() + p.radius[i] <= 0.5 * len);
            for j in 0..i {
                let d: f64 = (0..3)
                    .map(|k| (p.pos[i][k] - p.pos[j][k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(d >= p.radius[i] + p.radius[j], "{i} and {j} overlap: {d}");
            }
        }
        let again = insert(&sizes, 2500.0, 300.0, rd, len, 7).unwrap();
        assert_eq!(p, again);
    }
}
