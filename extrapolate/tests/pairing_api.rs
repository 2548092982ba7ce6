//! Properties of `pair` on small random inputs (proptest), its error cases, and the
//! independence of the result from the number of threads.

mod common;

use common::{is_permutation, packing, rejitter, Drum, Rng};
use extrapolate::pairing::{pair, pair_dense, PairingError, PairingOptions, DENSE_LIMIT};
use proptest::prelude::*;

/// Points on a coarse grid, so that coincident and equidistant points are common.
fn grid_points(n: usize) -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec((0u8..4, 0u8..4, 0u8..3), n).prop_map(|v| {
        v.into_iter()
            .map(|(a, b, c)| [a as f64 * 0.5, b as f64 * 0.5, c as f64 * 0.5])
            .collect()
    })
}

/// Two snapshots of the same size, from the grid or continuous.
fn snapshots() -> impl Strategy<Value = (Vec<[f64; 3]>, Vec<[f64; 3]>)> {
    (1usize..40).prop_flat_map(|n| {
        prop_oneof![
            (grid_points(n), grid_points(n)),
            (
                prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), n),
                prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), n)
            ),
        ]
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Always a permutation, always certified, and always the oracle's total, whatever
    /// k and however degenerate the points (duplicates, ties, n = 1).
    #[test]
    fn pair_is_an_optimal_permutation((x0, x1) in snapshots(), k in 1usize..5) {
        let opts = PairingOptions { unit: 1e-6, k_initial: k, dense_max: 0, certify: true, axial_period: None };
        let s = pair(&x0, &x1, &opts).unwrap();
        prop_assert!(is_permutation(&s.g));
        prop_assert_eq!(s.g.len(), x0.len());
        prop_assert!(s.certified);
        let d = pair_dense(&x0, &x1, opts.unit).unwrap();
        prop_assert!(is_permutation(&d.g));
        prop_assert_eq!(s.total_cost, d.total_cost);
    }

    /// Without the certificate the result is still a permutation (optimal on the
    /// candidate graph only, so no claim on the total beyond the oracle's bound).
    #[test]
    fn uncertified_is_a_permutation((x0, x1) in snapshots(), k in 1usize..5) {
        let opts = PairingOptions { unit: 1e-6, k_initial: k, dense_max: 0, certify: false, axial_period: None };
        let s = pair(&x0, &x1, &opts).unwrap();
        prop_assert!(is_permutation(&s.g));
        prop_assert!(!s.certified);
        let d = pair_dense(&x0, &x1, opts.unit).unwrap();
        prop_assert!(s.total_cost >= d.total_cost);
    }
}

#[test]
fn rejects_mismatched_lengths() {
    let e = pair(
        &[[0.0; 3]; 3],
        &[[0.0; 3]; 2],
        &PairingOptions::for_diameter(1.0),
    )
    .unwrap_err();
    assert!(
        matches!(e, PairingError::LengthMismatch { n0: 3, n1: 2 }),
        "{e}"
    );
    assert!(e.to_string().contains("3 particles at t0, 2 at t1"), "{e}");
    let e = pair_dense(&[[0.0; 3]; 1], &[[0.0; 3]; 2], 1e-6).unwrap_err();
    assert!(matches!(e, PairingError::LengthMismatch { .. }));
}

#[test]
fn rejects_empty_snapshots() {
    let e = pair(&[], &[], &PairingOptions::for_diameter(1.0)).unwrap_err();
    assert!(matches!(e, PairingError::Empty), "{e}");
    assert!(matches!(
        pair_dense(&[], &[], 1e-6).unwrap_err(),
        PairingError::Empty
    ));
}

#[test]
fn rejects_non_finite_coordinates_naming_index_and_value() {
    let good = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let mut bad = good.clone();
    bad[2][1] = f64::NAN;
    let e = pair(&good, &bad, &PairingOptions::for_diameter(1.0)).unwrap_err();
    match &e {
        PairingError::NonFinite {
            snapshot,
            index,
            axis,
            value,
        } => {
            assert_eq!((*snapshot, *index, *axis), ("t1", 2, 1));
            assert!(value.is_nan());
        }
        other => panic!("unexpected error {other}"),
    }
    assert!(e.to_string().contains("particle 2, axis 1 is NaN"), "{e}");
    let mut inf = good.clone();
    inf[0][0] = f64::NEG_INFINITY;
    let e = pair(&inf, &good, &PairingOptions::for_diameter(1.0)).unwrap_err();
    assert!(
        e.to_string()
            .contains("t0 snapshot: particle 0, axis 0 is -inf"),
        "{e}"
    );
}

#[test]
fn rejects_bad_options() {
    let x = vec![[0.0; 3], [1.0, 0.0, 0.0]];
    let base = PairingOptions::for_diameter(1.0);
    for (opts, name) in [
        (
            PairingOptions {
                k_initial: 0,
                ..base.clone()
            },
            "k_initial",
        ),
        (
            PairingOptions {
                dense_max: DENSE_LIMIT + 1,
                ..base.clone()
            },
            "dense_max",
        ),
        (
            PairingOptions {
                unit: 0.0,
                ..base.clone()
            },
            "unit",
        ),
        (
            PairingOptions {
                unit: f64::NAN,
                ..base.clone()
            },
            "unit",
        ),
    ] {
        match pair(&x, &x, &opts) {
            Err(PairingError::InvalidOption { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{name}: unexpected {other:?}"),
        }
    }
    // A unit so small that costs would overflow is refused, not wrapped.
    let e = pair(
        &[[0.0; 3], [1e6, 0.0, 0.0]],
        &x,
        &PairingOptions {
            unit: 1e-12,
            ..base
        },
    )
    .unwrap_err();
    assert!(matches!(e, PairingError::CostOverflow { .. }), "{e}");
    let big = vec![[0.0; 3]; DENSE_LIMIT + 1];
    assert!(matches!(
        pair_dense(&big, &big, 1.0).unwrap_err(),
        PairingError::TooLargeForDense { .. }
    ));
}

#[test]
fn dense_max_switches_to_the_oracle() {
    let mut rng = Rng::new(5);
    let drum = Drum {
        radius: 0.06,
        length: 0.08,
        diameter: 0.01,
    };
    let x0 = packing(&drum, 200, 0.0105, 0.0005, &mut rng);
    let x1 = rejitter(&x0, 0.006, &mut rng);
    let dense = pair(
        &x0,
        &x1,
        &PairingOptions {
            dense_max: 200,
            ..PairingOptions::for_diameter(0.01)
        },
    )
    .unwrap();
    let sparse = pair(&x0, &x1, &PairingOptions::for_diameter(0.01)).unwrap();
    assert_eq!(dense.k_used, 200); // the oracle's signature
    assert_eq!(dense.total_cost, sparse.total_cost);
    let mean = sparse.mean_distance_in_diameters(0.01);
    assert!((mean - sparse.total_distance / 200.0 / 0.01).abs() < 1e-12);
    assert!(mean > 0.0 && mean < 1.0, "{mean}");
}

/// A bed 10 000 diameters long: a millionth of a diameter would give pair costs beyond 32
/// bits, which `pair` refuses; `for_bed` coarsens the unit just enough, and the sparse
/// solver then reaches the dense oracle's optimum at that unit.
#[test]
fn a_bed_too_long_for_a_millionth_of_a_diameter_gets_a_coarser_unit() {
    let mut rng = Rng::new(11);
    let n = 240;
    // a line of clusters along x, 10 000 diameters of 0.01 from end to end
    let x0: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let x = (i / 8) as f64 * 100.0 / (n / 8 - 1) as f64;
            [x + 0.01 * rng.f64(), 0.02 * rng.f64(), 0.02 * rng.f64()]
        })
        .collect();
    let x1 = rejitter(&x0, 0.008, &mut rng);
    let fine = PairingOptions::for_diameter(0.01);
    assert!(matches!(
        pair(&x0, &x1, &fine).unwrap_err(),
        PairingError::CostOverflow { .. }
    ));
    let opts = PairingOptions::for_bed(0.01, &x0, &x1);
    assert!(
        opts.unit > fine.unit && opts.unit < 3.0 * fine.unit,
        "{}",
        opts.unit
    );
    let sparse = pair(&x0, &x1, &opts).unwrap();
    assert!(sparse.certified);
    let dense = pair_dense(&x0, &x1, opts.unit).unwrap();
    assert_eq!(sparse.total_cost, dense.total_cost);
    // on a short bed `for_bed` is `for_diameter`
    let short: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] * 1e-3, p[1], p[2]]).collect();
    assert_eq!(PairingOptions::for_bed(0.01, &short, &short), fine);
}

/// Same bytes whatever the number of threads (the parallel parts collect in row order).
#[test]
fn result_does_not_depend_on_thread_count() {
    let mut rng = Rng::new(77);
    let drum = Drum {
        radius: 0.08,
        length: 0.6,
        diameter: 0.01,
    };
    let x0 = packing(&drum, 6000, 0.0105, 0.0005, &mut rng);
    let x1 = packing(&drum, 6000, 0.0105, 0.0005, &mut rng);
    let opts = PairingOptions {
        k_initial: 4,
        ..PairingOptions::for_diameter(0.01)
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| pair(&x0, &x1, &opts).unwrap())
    };
    let a = run(1);
    let b = run(2);
    let c = run(3);
    assert!(
        a.certified && a.rounds > 1,
        "instance too easy: rounds {}",
        a.rounds
    );
    for r in [&b, &c] {
        assert_eq!(r.g, a.g);
        assert_eq!(r.total_cost, a.total_cost);
        assert_eq!(r.total_distance.to_bits(), a.total_distance.to_bits());
        assert_eq!(
            (r.rounds, r.edges, r.added_pairs, r.growth_pairs),
            (a.rounds, a.edges, a.added_pairs, a.growth_pairs)
        );
    }
}
