//! DEM-like point sets for the pairing tests and benchmark: jittered FCC packings of the
//! lower part of a horizontal cylinder (drum axis = z, gravity = −y), and t1 variants
//! (re-jittered, independently packed, block-translated, displaced by a smooth flow).
#![allow(dead_code)] // each test binary uses a different subset

use std::f64::consts::PI;

use extrapolate::boundary::BoundaryMaps;
use rand_xoshiro::rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use tdex_format::{AreaEncoding, RecordingInfo, FORMAT_VERSION};

/// Both kinds of fresh boundary maps, pools of `pool` pairings, cells of 3 diameters, the
/// drift's bins `bin_diameters` long.
pub fn fresh_maps(pool: u32, bin_diameters: f64) -> [BoundaryMaps; 2] {
    [
        BoundaryMaps::FreshSteps {
            pool,
            cell_diameters: 3.0,
        },
        BoundaryMaps::FreshDrift {
            pool,
            bin_diameters,
            cell_diameters: 3.0,
            cap_zone_diameters: 0.0,
        },
    ]
}

/// Small seeded generator with the few draws we need.
pub struct Rng(Xoshiro256PlusPlus);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(Xoshiro256PlusPlus::seed_from_u64(seed))
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    /// Uniform integer in 0..n.
    pub fn below(&mut self, n: usize) -> usize {
        (self.0.next_u64() % n as u64) as usize
    }
    /// Uniform in the ball of radius r.
    pub fn in_ball(&mut self, r: f64) -> [f64; 3] {
        loop {
            let p = [
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            ];
            if p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= 1.0 {
                return [p[0] * r, p[1] * r, p[2] * r];
            }
        }
    }
    /// Fisher–Yates shuffle.
    pub fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            let j = self.below(i + 1);
            v.swap(i, j);
        }
    }
}

/// A horizontal drum: axis along z from 0 to `length`, radius `radius`.
#[derive(Clone, Copy, Debug)]
pub struct Drum {
    pub radius: f64,
    pub length: f64,
    pub diameter: f64,
}

impl Drum {
    /// True if a sphere centred at `p` fits inside the drum.
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        let r = 0.5 * self.diameter;
        (p[0] * p[0] + p[1] * p[1]).sqrt() <= self.radius - r
            && p[2] >= r
            && p[2] <= self.length - r
    }
}

/// `n` sites of an FCC lattice (nearest-neighbour distance `spacing`) with a random
/// rotation about the drum axis and a random offset, restricted to the drum and taken
/// from the bottom up (the lowest `n` by height), each jittered uniformly in a ball of
/// radius `jitter`. Returned in a random order.
pub fn packing(drum: &Drum, n: usize, spacing: f64, jitter: f64, rng: &mut Rng) -> Vec<[f64; 3]> {
    let theta = rng.range(0.0, 2.0 * PI);
    let (s, c) = theta.sin_cos();
    let ac = spacing * 2f64.sqrt(); // cubic cell side
    let off = [rng.range(0.0, ac), rng.range(0.0, ac), rng.range(0.0, ac)];
    let basis = [
        [0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ];
    let m = (drum.radius / ac).ceil() as i64 + 2;
    let mz = (drum.length / ac).ceil() as i64 + 2;
    let mut sites = Vec::new();
    for i in -m..=m {
        for j in -m..=m {
            for l in -2..=mz {
                for b in &basis {
                    // Lattice frame, then rotate about z and offset.
                    let lx = (i as f64 + b[0]) * ac + off[0];
                    let ly = (j as f64 + b[1]) * ac + off[1];
                    let z = (l as f64 + b[2]) * ac + off[2];
                    let p = [c * lx - s * ly, s * lx + c * ly, z];
                    if drum.contains(&p) {
                        sites.push(p);
                    }
                }
            }
        }
    }
    assert!(
        sites.len() >= n,
        "drum holds only {} sites, asked for {n}",
        sites.len()
    );
    sites.sort_by(|a, b| {
        a[1].total_cmp(&b[1])
            .then(a[2].total_cmp(&b[2]))
            .then(a[0].total_cmp(&b[0]))
    });
    sites.truncate(n);
    for p in &mut sites {
        let d = rng.in_ball(jitter);
        for a in 0..3 {
            p[a] += d[a];
        }
    }
    rng.shuffle(&mut sites);
    sites
}

/// Copy of `x0`, each point jittered in a ball of radius `jitter`, then shuffled.
pub fn rejitter(x0: &[[f64; 3]], jitter: f64, rng: &mut Rng) -> Vec<[f64; 3]> {
    let mut x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            let d = rng.in_ball(jitter);
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        })
        .collect();
    rng.shuffle(&mut x1);
    x1
}

/// `x0` with every point inside the axis-aligned box `[lo, hi]` translated by `shift`,
/// the rest jittered by `jitter`, then shuffled.
pub fn block_shift(
    x0: &[[f64; 3]],
    lo: [f64; 3],
    hi: [f64; 3],
    shift: [f64; 3],
    jitter: f64,
    rng: &mut Rng,
) -> (Vec<[f64; 3]>, usize) {
    let mut moved = 0;
    let mut x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            let inside = (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a]);
            let d = rng.in_ball(jitter);
            if inside {
                moved += 1;
                [
                    p[0] + shift[0] + d[0],
                    p[1] + shift[1] + d[1],
                    p[2] + shift[2] + d[2],
                ]
            } else {
                [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
            }
        })
        .collect();
    rng.shuffle(&mut x1);
    (x1, moved)
}

/// `x0` carried by a smooth drum-like flow, then jittered by `jitter` and shuffled: a
/// rotation about the axis (the bed rides up with the wall) whose angle varies smoothly
/// with depth and along the axis, up to about `amplitude` of arc length, plus a small
/// axial wave.
pub fn flow(
    drum: &Drum,
    x0: &[[f64; 3]],
    amplitude: f64,
    jitter: f64,
    rng: &mut Rng,
) -> Vec<[f64; 3]> {
    let phase = rng.range(0.0, 2.0 * PI);
    let mut x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt().max(1e-12);
            let zeta = p[2] / drum.length;
            // Arc length of the rotation: largest near the wall, varying along the axis.
            let arc =
                amplitude * (r / drum.radius) * (1.0 + 0.3 * (2.0 * PI * 3.0 * zeta + phase).sin());
            let ang = arc / r;
            let (s, c) = ang.sin_cos();
            let axial = 0.3 * amplitude * (2.0 * PI * 5.0 * zeta + phase).sin() * (r / drum.radius);
            let d = rng.in_ball(jitter);
            [
                c * p[0] - s * p[1] + d[0],
                s * p[0] + c * p[1] + d[1],
                p[2] + axial + d[2],
            ]
        })
        .collect();
    rng.shuffle(&mut x1);
    x1
}

/// True if `g` is a permutation of `0..n`.
pub fn is_permutation(g: &[u32]) -> bool {
    let mut seen = vec![false; g.len()];
    g.iter().all(|&q| {
        let q = q as usize;
        q < seen.len() && !std::mem::replace(&mut seen[q], true)
    })
}

/// Height (y) of the free surface of the bed `x` (the highest centre plus a radius).
pub fn surface_height(x: &[[f64; 3]], diameter: f64) -> f64 {
    x.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max) + 0.5 * diameter
}

/// Fraction of the drum's cross-section below height `h` (circular segment area).
pub fn fill_fraction(drum: &Drum, h: f64) -> f64 {
    let r = drum.radius;
    let h = h.clamp(-r, r);
    // Area of the segment {y <= h} of the disc of radius r.
    let a = r * r * (h / r).acos();
    let seg = PI * r * r - (a - h * (r * r - h * h).sqrt());
    seg / (PI * r * r)
}

/// `x0` carried by an incompressible circulation confined to the bed, then jittered by
/// `jitter` and shuffled. The stream function `ψ = (Rc² − x² − y²)(hc − y)` vanishes on
/// the circle `Rc = R − d/2` that bounds the particle centres and on the plane
/// `hc = h − d/2` of the top layer's centres, so the flow runs along the wall and the
/// surface and maps the bed of centres onto itself, as the bed of a rotating drum does
/// over a period. Scaled so that the largest displacement is about `amplitude`; an axial
/// drift of up to a fifth of it, varying across the bed, is added.
pub fn circulation(
    drum: &Drum,
    x0: &[[f64; 3]],
    h: f64,
    amplitude: f64,
    jitter: f64,
    rng: &mut Rng,
) -> Vec<[f64; 3]> {
    let rc = drum.radius - 0.5 * drum.diameter;
    let r2 = rc * rc;
    let h = h - 0.5 * drum.diameter;
    let vel = |x: f64, y: f64| {
        // u = ∂ψ/∂y, v = −∂ψ/∂x.
        let ux = -2.0 * y * (h - y) - (r2 - x * x - y * y);
        let uy = 2.0 * x * (h - y);
        (ux, uy)
    };
    // Scale: the largest speed over the bed's points.
    let vmax = x0
        .iter()
        .map(|p| {
            let (a, b) = vel(p[0], p[1]);
            (a * a + b * b).sqrt()
        })
        .fold(0.0, f64::max)
        .max(1e-300);
    let steps = 32;
    let dt = amplitude / vmax / steps as f64;
    let phase = rng.range(0.0, 2.0 * PI);
    let mut x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            let (mut x, mut y) = (p[0], p[1]);
            for _ in 0..steps {
                // Midpoint rule: stays on the streamline to good accuracy.
                let (a, b) = vel(x, y);
                let (a2, b2) = vel(x + 0.5 * dt * a, y + 0.5 * dt * b);
                x += dt * a2;
                y += dt * b2;
            }
            // Axial drift varying across the bed (a shear: divergence-free).
            let z = p[2] + 0.2 * amplitude * (PI * p[0] / rc + phase).sin();
            let d = rng.in_ball(jitter);
            [x + d[0], y + d[1], z + d[2]]
        })
        .collect();
    rng.shuffle(&mut x1);
    x1
}

/// The info of a synthetic recording of `particles` particles and no walls: `recorded_periods`
/// periods of `period_steps` steps of 10 µs from t = 0, exact contact areas, conductances of
/// 1e5 W/(K m) (with contacts of about 1 mm and 1e-4 s, c ≈ 0.02 on particles of 1 J/K), and
/// `case_resolved` as its case.
pub fn recording_info(
    particles: usize,
    period_steps: u64,
    recorded_periods: u32,
    case_resolved: serde_json::Value,
) -> RecordingInfo {
    RecordingInfo {
        format_version: FORMAT_VERSION,
        tool_version: "test".into(),
        case_toml: String::new(),
        case_path: String::new(),
        case_resolved,
        particles: particles as u32,
        walls: Vec::new(),
        dt: 1e-5,
        sample_every: 1,
        dtc_max_steps: 10,
        period_steps,
        tau: period_steps as f64 * 1e-5,
        t0: 0.0,
        step_t0: 0,
        reference_periods: 0,
        twins: 0,
        recorded_periods,
        twins_from: 1,
        area_encoding: AreaEncoding::Exact,
        sqrt_area_unit: 0.0,
        pair_conductivity: 1e5,
        wall_conductivity: 1e5,
        density: 2500.0,
        heat_capacity: 800.0,
        conductivity: 1.0,
    }
}
