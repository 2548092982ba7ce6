//! The sparse solver against the dense Kuhn–Munkres oracle on DEM-like instances:
//! same integer total on every instance, including ones where the first candidate
//! graph is infeasible or the certificate has to add pairs.

mod common;

use std::time::Instant;

use common::{block_shift, flow, is_permutation, packing, rejitter, Drum, Rng};
use extrapolate::pairing::{pair, pair_dense, Pairing, PairingOptions};

const D: f64 = 0.01; // particle diameter, m (the paper's 5 mm radius)

#[derive(Clone, Copy, Debug)]
enum Variant {
    /// Same lattice sites, independent jitter of `j` diameters.
    Rejitter(f64),
    /// An independent packing of the same region (different lattice offset/rotation).
    Independent,
    /// A block of the bed translated by `s` diameters along the axis.
    Block(f64),
    /// Smooth drum-like flow of `a` diameters plus 1 diameter of jitter.
    Flow(f64),
}

#[derive(Debug)]
struct Case {
    n: usize,
    length_d: f64,
    variant: Variant,
    k: usize,
    seed: u64,
    /// The instance must exercise k growth or certificate repair.
    must_grow: bool,
}

fn instance(c: &Case) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let drum = Drum {
        radius: 6.0 * D,
        length: c.length_d * D,
        diameter: D,
    };
    let mut rng = Rng::new(c.seed);
    let x0 = packing(&drum, c.n, 1.05 * D, 0.05 * D, &mut rng);
    let x1 = match c.variant {
        Variant::Rejitter(j) => rejitter(&x0, j * D, &mut rng),
        Variant::Independent => packing(&drum, c.n, 1.05 * D, 0.05 * D, &mut rng),
        Variant::Block(s) => {
            // A slab of the bed (a quarter of its length) pushed along the axis.
            let z0 = 0.3 * drum.length;
            let z1 = z0 + 0.25 * drum.length;
            let (x1, moved) = block_shift(
                &x0,
                [-1.0, -1.0, z0],
                [1.0, 1.0, z1],
                [0.0, 0.0, s * D],
                0.1 * D,
                &mut rng,
            );
            assert!(moved > c.n / 10, "block too small: {moved}");
            x1
        }
        Variant::Flow(a) => flow(&drum, &x0, a * D, 1.0 * D, &mut rng),
    };
    (x0, x1)
}

fn integer_total(x0: &[[f64; 3]], x1: &[[f64; 3]], g: &[u32], unit: f64) -> i64 {
    g.iter()
        .enumerate()
        .map(|(p, &q)| {
            let a = x1[p];
            let b = x0[q as usize];
            let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
            (d / unit).round() as i64
        })
        .sum()
}

fn check_case(c: &Case) -> (Pairing, Pairing) {
    let (x0, x1) = instance(c);
    let opts = PairingOptions {
        k_initial: c.k,
        ..PairingOptions::for_diameter(D)
    };
    let sparse = pair(&x0, &x1, &opts).unwrap();
    let dense = pair_dense(&x0, &x1, opts.unit).unwrap();
    assert!(
        is_permutation(&sparse.g),
        "{c:?}: sparse g is not a permutation"
    );
    assert!(
        is_permutation(&dense.g),
        "{c:?}: dense g is not a permutation"
    );
    assert!(sparse.certified, "{c:?}: not certified");
    // Totals are recomputed from g independently of the solvers' own bookkeeping.
    assert_eq!(
        integer_total(&x0, &x1, &sparse.g, opts.unit),
        sparse.total_cost
    );
    assert_eq!(
        integer_total(&x0, &x1, &dense.g, opts.unit),
        dense.total_cost
    );
    assert_eq!(
        sparse.total_cost, dense.total_cost,
        "{c:?}: sparse total {} != oracle total {} (rounds {}, k {})",
        sparse.total_cost, dense.total_cost, sparse.rounds, sparse.k_used
    );
    // Same integer objective ⇒ same real total up to the rounding of n costs.
    let tol = c.n as f64 * opts.unit;
    assert!((sparse.total_distance - dense.total_distance).abs() <= tol);
    if c.must_grow {
        assert!(
            sparse.rounds > 1 || sparse.growth_pairs > 0,
            "{c:?}: expected graph growth or certificate repair, got rounds {} escape pairs {}",
            sparse.rounds,
            sparse.growth_pairs
        );
    }
    (sparse, dense)
}

fn cases() -> Vec<Case> {
    use Variant::*;
    let mut v = Vec::new();
    let mut seed = 1000;
    let mut add = |n, length_d, variant, k, must_grow| {
        seed += 1;
        v.push(Case {
            n,
            length_d,
            variant,
            k,
            seed,
            must_grow,
        });
    };
    // Near-identity and independent packings at the default k.
    add(400, 10.0, Rejitter(0.3), 8, false);
    add(800, 16.0, Rejitter(0.6), 8, false);
    add(1500, 26.0, Rejitter(1.0), 8, false);
    add(600, 12.0, Independent, 8, false);
    add(1200, 22.0, Independent, 8, false);
    add(300, 8.0, Flow(3.0), 8, false);
    add(1000, 18.0, Flow(2.0), 8, false);
    // Tiny k: the first candidate graph is very likely infeasible.
    add(500, 10.0, Rejitter(1.0), 1, true);
    add(700, 14.0, Independent, 1, true);
    add(900, 16.0, Independent, 2, true);
    add(400, 8.0, Flow(2.0), 1, true);
    add(1100, 20.0, Rejitter(1.0), 2, true);
    // A translated block: partners several diameters away, far outside the kNN lists.
    add(600, 12.0, Block(4.0), 1, true);
    add(600, 12.0, Block(4.0), 2, true);
    add(800, 16.0, Block(6.0), 2, true);
    add(1000, 20.0, Block(5.0), 4, true);
    add(1200, 24.0, Block(3.0), 8, true);
    add(1500, 26.0, Block(8.0), 8, true);
    add(500, 10.0, Block(2.5), 8, true);
    add(300, 6.0, Block(6.0), 1, true);
    add(800, 14.0, Block(4.0), 16, true);
    add(1000, 18.0, Flow(6.0), 2, true);
    v
}

#[test]
fn sparse_total_equals_kuhn_munkres_on_dem_instances() {
    let cases = cases();
    assert!(cases.len() >= 20);
    let mut grown = 0;
    for c in &cases {
        let t = Instant::now();
        let (s, d) = check_case(c);
        if s.rounds > 1 || s.growth_pairs > 0 {
            grown += 1;
        }
        eprintln!(
            "n {:5} {:?} k0 {:2}: total {} | sparse {:.3}s growth {} rounds {} added {} | dense {:.3}s | {:.2}s",
            c.n,
            c.variant,
            c.k,
            s.total_cost,
            s.seconds,
            s.growth_pairs,
            s.rounds,
            s.added_pairs,
            d.seconds,
            t.elapsed().as_secs_f64()
        );
    }
    assert!(grown >= 10, "only {grown} instances exercised growth");
}
