//! Pairing benchmark on a bed the size of the paper's drum (Haydar et al. 2023: 80 000
//! spheres of radius 5 mm; drum radius 0.10 m, length 6.349 m, 35 % fill).
//!
//! Run: `cargo bench -p extrapolate --bench pairing` (threads: `TDEX_THREADS`, default 2;
//! particles: `TDEX_N`, default 80000, the drum length scaled to keep the fill; initial
//! k: `TDEX_K`, default the library's).
//!
//! Two t1 snapshots against the same t0 packing:
//! * `independent`: a second packing of the same region generated independently (other
//!   lattice orientation and offset, other jitter): no correlation at all, the worst case;
//! * `circulation`: t0 carried by a smooth incompressible circulation confined to the bed
//!   (up to 3 diameters) plus 1 diameter of random jitter.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{circulation, fill_fraction, is_permutation, packing, surface_height, Drum, Rng};
use extrapolate::pairing::{pair, Pairing, PairingOptions};

const D: f64 = 0.01;

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Lattice spacing that puts `n` particles at `fill` of the drum (bisection on the
/// fill of an unjittered packing).
fn spacing_for_fill(drum: &Drum, n: usize, fill: f64) -> f64 {
    let (mut lo, mut hi) = (0.9 * D, 1.3 * D);
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        let x = packing(drum, n, mid, 0.0, &mut Rng::new(7));
        if fill_fraction(drum, surface_height(&x, D)) < fill {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn report(name: &str, r: &Pairing) {
    println!(
        "{name:12} n {:6} | k {:3} rounds {:2} certified {:5} | total cost {:13} | mean {:.4} d | \
         edges {:8} growth {:5} added {:6} cert. examined {:9} | {:.3} s",
        r.g.len(),
        r.k_used,
        r.rounds,
        r.certified,
        r.total_cost,
        r.mean_distance_in_diameters(D),
        r.edges,
        r.growth_pairs,
        r.added_pairs,
        r.certificate_examined,
        r.seconds
    );
}

fn main() {
    let threads = env_usize("TDEX_THREADS", 2);
    let n = env_usize("TDEX_N", 80_000);
    // The paper's drum holds 80 000 at 35 %; other n keep the fill by scaling the length.
    let drum = Drum {
        radius: 0.10,
        length: 6.349 * n as f64 / 80_000.0,
        diameter: D,
    };
    let t = Instant::now();
    let spacing = spacing_for_fill(&drum, n, 0.35);
    let mut rng = Rng::new(20261121);
    let x0 = packing(&drum, n, spacing, 0.05 * D, &mut rng);
    let h = surface_height(&x0, D);
    println!(
        "bed: {n} spheres d = {D} m, drum R = {} m L = {} m; FCC spacing {:.4} d, jitter 0.05 d; \
         fill {:.1} % (surface at y = {:.4} m); generated in {:.2} s; {threads} threads",
        drum.radius,
        drum.length,
        spacing / D,
        100.0 * fill_fraction(&drum, h),
        h,
        t.elapsed().as_secs_f64()
    );
    let independent = packing(&drum, n, spacing, 0.05 * D, &mut rng);
    let circ = circulation(&drum, &x0, h, 3.0 * D, 1.0 * D, &mut rng);

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let defaults = PairingOptions::for_diameter(D);
    let opts = PairingOptions {
        k_initial: env_usize("TDEX_K", defaults.k_initial),
        ..defaults
    };
    for (name, x1) in [("independent", &independent), ("circulation", &circ)] {
        let r = pool.install(|| pair(&x0, x1, &opts)).unwrap();
        assert!(is_permutation(&r.g));
        report(name, &r);
        let u = pool
            .install(|| {
                pair(
                    &x0,
                    x1,
                    &PairingOptions {
                        certify: false,
                        ..opts.clone()
                    },
                )
            })
            .unwrap();
        report(&format!("{name}/nocert"), &u);
        let s = one.install(|| pair(&x0, x1, &opts)).unwrap();
        report(&format!("{name}/1thr"), &s);
        assert_eq!(s.g, r.g, "result depends on the thread count");
        assert_eq!(s.total_cost, r.total_cost);
    }
}
