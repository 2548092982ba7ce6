//! The pairing of a bed of several particle sizes (`pair_by_size`): never across size classes,
//! optimal within each class (against the dense oracle), `pair` itself on a bed of one size,
//! its refusals; and its callers: the stored pairing (a sidecar that ignored the sizes is
//! stale), the extrapolation (heat kept across the jumps), the fresh boundary pools.

mod common;

use common::{fresh_maps, is_permutation, Rng};
use extrapolate::boundary;
use extrapolate::pairing::{
    pair, pair_by_size, pair_dense, respects_classes, Pairing, PairingError, PairingOptions,
};
use extrapolate::sidecar::StoredPairing;
use extrapolate::{cache, extrapolate_recording, ExtrapolationRequest, MemoryLimit};
use proptest::prelude::*;
use std::path::Path;
use tdex_format::{CollisionRow, RecordingInfo, RecordingReader, RecordingWriter, Snapshot};

/// The radii of the size classes the random beds draw from (a 1 mm to 2.8 mm spread).
const RADII: [f64; 4] = [0.5e-3, 0.8e-3, 1.1e-3, 1.4e-3];

/// Integer cost of a pair, as the solver defines it: `round(|a − b| / unit)`, halves away
/// from zero.
fn cost(a: &[f64; 3], b: &[f64; 3], unit: f64) -> i64 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    let x = (dx * dx + dy * dy + dz * dz).sqrt() / unit;
    let whole = x as i64;
    whole + i64::from(x - whole as f64 >= 0.5)
}

/// A random bed of `classes` sizes: `per_class[c]` particles of radius `RADII[c]` at
/// positions drawn in a box of a few millimetres (from a coarse grid or continuous, so that
/// ties and coincident points occur), the same counts at t1 dealt to other indices.
#[allow(clippy::type_complexity)]
fn sized_bed() -> impl Strategy<Value = (Vec<[f64; 3]>, Vec<f64>, Vec<[f64; 3]>, Vec<f64>)> {
    (
        prop::collection::vec(1usize..60, 2..=4),
        any::<u64>(),
        any::<bool>(),
    )
        .prop_map(|(per_class, seed, on_grid)| {
            let mut rng = Rng::new(seed);
            let point = |rng: &mut Rng| {
                if on_grid {
                    [0; 3].map(|_| rng.below(4) as f64 * 1e-3)
                } else {
                    [0; 3].map(|_| rng.range(0.0, 6e-3))
                }
            };
            let r0: Vec<f64> = per_class
                .iter()
                .enumerate()
                .flat_map(|(c, &count)| std::iter::repeat_n(RADII[c], count))
                .collect();
            let mut r1 = r0.clone();
            rng.shuffle(&mut r1);
            let mut r0 = r0;
            rng.shuffle(&mut r0);
            let x0 = (0..r0.len()).map(|_| point(&mut rng)).collect();
            let x1 = (0..r1.len()).map(|_| point(&mut rng)).collect();
            (x0, r0, x1, r1)
        })
}

/// The positions of the particles of radius `radius`, in index order, and their indices.
fn of_radius(x: &[[f64; 3]], r: &[f64], radius: f64) -> (Vec<[f64; 3]>, Vec<usize>) {
    let members: Vec<usize> = (0..r.len()).filter(|&i| r[i] == radius).collect();
    (members.iter().map(|&i| x[i]).collect(), members)
}

/// The same pairing but for its wall time.
fn timeless(mut p: Pairing) -> Pairing {
    p.seconds = 0.0;
    p
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 120, ..ProptestConfig::default() })]

    /// On random beds of 2–4 sizes, up to 59 particles each: a permutation that maps every
    /// particle onto a role of its own radius, certified, and within every class exactly
    /// as long, in integer cost, as the dense oracle's optimum of that class alone.
    #[test]
    fn the_pairing_keeps_each_class_and_is_optimal_within_it(
        (x0, r0, x1, r1) in sized_bed(),
        k in 1usize..6,
    ) {
        let d = 2.0 * r0.iter().sum::<f64>() / r0.len() as f64;
        let opts = PairingOptions { k_initial: k, ..PairingOptions::for_bed(d, &x0, &x1) };
        let s = pair_by_size(&x0, &r0, &x1, &r1, &opts).unwrap();
        prop_assert!(is_permutation(&s.g));
        prop_assert_eq!(s.g.len(), x0.len());
        for (p, &q) in s.g.iter().enumerate() {
            prop_assert_eq!(r0[q as usize], r1[p], "particle {} onto role {}", p, q);
        }
        prop_assert!(s.certified);
        let mut total = 0;
        for radius in tdex_format::size_classes(&r0) {
            let (x0c, members0) = of_radius(&x0, &r0, radius);
            let (x1c, members1) = of_radius(&x1, &r1, radius);
            let oracle = pair_dense(&x0c, &x1c, opts.unit).unwrap();
            let ours: i64 = members1
                .iter()
                .map(|&p| cost(&x1[p], &x0[s.g[p] as usize], opts.unit))
                .sum();
            prop_assert_eq!(ours, oracle.total_cost, "class of radius {}", radius);
            prop_assert!(members0.iter().all(|&q| r0[q] == radius));
            total += oracle.total_cost;
        }
        prop_assert_eq!(s.total_cost, total);
        let distance: f64 = s
            .g
            .iter()
            .enumerate()
            .map(|(p, &q)| {
                let (a, b) = (x1[p], x0[q as usize]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .sum();
        prop_assert!((s.total_distance - distance).abs() <= 1e-12 * distance.max(1.0));
    }

    /// A bed of one size is paired by `pair` itself: the same result, field for field.
    #[test]
    fn a_bed_of_one_size_is_paired_as_pair_pairs_it(
        n in 1usize..80,
        seed: u64,
        k in 1usize..6,
        radius in 1e-4f64..1e-2,
    ) {
        let mut rng = Rng::new(seed);
        let x0: Vec<[f64; 3]> = (0..n).map(|_| [0; 3].map(|_| rng.range(0.0, 0.05))).collect();
        let x1: Vec<[f64; 3]> = (0..n).map(|_| [0; 3].map(|_| rng.range(0.0, 0.05))).collect();
        let r = vec![radius; n];
        let opts = PairingOptions { k_initial: k, ..PairingOptions::for_bed(2.0 * radius, &x0, &x1) };
        let sized = timeless(pair_by_size(&x0, &r, &x1, &r, &opts).unwrap());
        let plain = timeless(pair(&x0, &x1, &opts).unwrap());
        prop_assert_eq!(sized.total_distance.to_bits(), plain.total_distance.to_bits());
        prop_assert_eq!(sized, plain);
    }
}

#[test]
fn classes_of_different_counts_are_refused_naming_the_radius_and_the_counts() {
    let x = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let opts = PairingOptions::for_diameter(1.0);
    let e = pair_by_size(&x, &[0.5, 0.5, 0.7], &x, &[0.5, 0.7, 0.7], &opts).unwrap_err();
    assert!(
        matches!(
            e,
            PairingError::ClassMismatch {
                radius: 0.5,
                n0: 2,
                n1: 1
            }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .starts_with("particles of radius 0.5: 2 at t0, 1 at t1"),
        "{e}"
    );
    // a radius found at t1 only: none of it at t0
    let e = pair_by_size(&x, &[0.7, 0.7, 0.9], &x, &[0.7, 0.7, 0.3], &opts).unwrap_err();
    assert!(
        matches!(
            e,
            PairingError::ClassMismatch {
                radius: 0.3,
                n0: 0,
                n1: 1
            }
        ),
        "{e:?}"
    );
    // one size at t0, two at t1: not one bed of one size
    let e = pair_by_size(&x, &[0.5; 3], &x, &[0.5, 0.5, 0.6], &opts).unwrap_err();
    assert!(matches!(e, PairingError::ClassMismatch { .. }), "{e:?}");
}

#[test]
fn radii_that_do_not_match_the_positions_are_refused() {
    let x = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let opts = PairingOptions::for_diameter(1.0);
    let e = pair_by_size(&x, &[0.5, 0.5], &x, &[0.5], &opts).unwrap_err();
    assert!(
        matches!(
            e,
            PairingError::RadiusCount {
                snapshot: "t1",
                radii: 1,
                positions: 2
            }
        ),
        "{e:?}"
    );
    assert_eq!(e.to_string(), "the t1 snapshot has 1 radii for 2 positions");
    // the whole bed's checks come first on a bed of several sizes too
    let e = pair_by_size(&x, &[0.5, 0.6], &x[..1], &[0.5], &opts).unwrap_err();
    assert!(matches!(e, PairingError::LengthMismatch { n0: 2, n1: 1 }));
    let e = pair_by_size(&[], &[], &[], &[], &opts).unwrap_err();
    assert!(matches!(e, PairingError::Empty));
}

/// A bed of three sizes, 3 000 particles whose t1 positions are t0's dealt to other
/// particles of the same size and jittered: the same result on 1, 2 and 3 threads.
#[test]
fn the_result_does_not_depend_on_the_thread_count() {
    let mut rng = Rng::new(31);
    let n = 3000;
    let x0: Vec<[f64; 3]> = (0..n)
        .map(|_| [0; 3].map(|_| rng.range(0.0, 0.15)))
        .collect();
    let r: Vec<f64> = (0..n).map(|_| RADII[rng.below(3)]).collect();
    let x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| p.map(|c| c + rng.range(-4e-3, 4e-3)))
        .collect();
    let opts = PairingOptions {
        k_initial: 4,
        ..PairingOptions::for_bed(2e-3, &x0, &x1)
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| pair_by_size(&x0, &r, &x1, &r, &opts).unwrap())
    };
    let one = run(1);
    assert!(one.certified && respects_classes(&one.g, &r, &r));
    for other in [run(2), run(3)] {
        assert_eq!(other.total_distance.to_bits(), one.total_distance.to_bits());
        assert_eq!(timeless(other), timeless(one.clone()));
    }
}

// --- the callers ---

/// Particles of the recorded bed: a 4 × 4 × 4 lattice, half of them of radius 4 mm and half
/// of 6 mm (by id, alternately).
const N: usize = 64;
const TAU: u64 = 1000;

fn radius_of(id: usize) -> f64 {
    if id.is_multiple_of(2) {
        0.004
    } else {
        0.006
    }
}

fn info() -> RecordingInfo {
    common::recording_info(N, TAU, 1, serde_json::json!({ "seed": 5 }))
}

/// Snapshot `t_index`: the lattice's sites dealt to the particles in a shuffled order and
/// jittered, so that the unconstrained pairing maps many particles onto roles of the other
/// size.
fn snapshot(index: u32, rng: &mut Rng) -> Snapshot {
    let mut sites: Vec<usize> = (0..N).collect();
    rng.shuffle(&mut sites);
    let pos = sites
        .iter()
        .map(|&s| {
            let (x, y, z) = (s % 4, (s / 4) % 4, s / 16);
            [x, y, z].map(|c| 0.013 * c as f64 + rng.range(-1e-3, 1e-3))
        })
        .collect();
    Snapshot {
        index,
        time: (u64::from(index) * TAU) as f64 * 1e-5,
        id: (0..N as u32).collect(),
        pos,
        radius: (0..N).map(radius_of).collect(),
        vel: vec![[0.0; 3]; N],
        temp: (0..N).map(|_| rng.range(300.0, 400.0)).collect(),
    }
}

/// A recording of one period of the two-size bed, with rows between random particles.
fn write_recording(path: &Path) -> (Snapshot, Snapshot) {
    let mut rng = Rng::new(11);
    let (t0, t1) = (snapshot(0, &mut rng), snapshot(1, &mut rng));
    let mut writer = RecordingWriter::create(path, info()).unwrap();
    writer.write_snapshot(&t0).unwrap();
    writer.write_snapshot(&t1).unwrap();
    let rows: Vec<CollisionRow> = (0..200)
        .map(|r| {
            let i = rng.below(N - 1);
            CollisionRow {
                i: i as u32,
                j: (i + 1 + rng.below(N - 1 - i)) as u32,
                start_step: r as u64 * 4,
                duration_steps: 1 + rng.below(10) as u32,
                sqrt_area: 1e-3 * rng.range(0.5, 1.5),
            }
        })
        .collect();
    writer.push_rows(rows).unwrap();
    writer.finish(vec![0; 4], None).unwrap();
    (t0, t1)
}

/// The stored pairing keeps the classes and says how many; a sidecar written without them
/// (no class count, or the unconstrained pairing) is stale: not reused, and an extrapolation
/// computes the pairing again, stores it, and keeps `Σ C T` across the jumps.
#[test]
fn a_sidecar_that_ignored_the_sizes_is_stale_and_the_extrapolation_keeps_the_heat() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    let (t0, t1) = write_recording(&rec);
    let reader = RecordingReader::open(&rec).unwrap();

    let stored = cache::compute(&t0, &t1, None).unwrap();
    assert_eq!(stored.summary.size_classes, Some(2));
    assert!(respects_classes(&stored.g, &t0.radius, &t1.radius));
    let free = pair(
        &t0.pos,
        &t1.pos,
        &PairingOptions::for_bed(t0.mean_diameter(), &t0.pos, &t1.pos),
    )
    .unwrap();
    assert!(
        !respects_classes(&free.g, &t0.radius, &t1.radius),
        "the bed must tempt the unconstrained pairing across the sizes"
    );
    let classless = |g: Vec<u32>| StoredPairing {
        snapshots_fingerprint: stored.snapshots_fingerprint,
        summary: tdex_format::PairingSummary {
            size_classes: None,
            ..stored.summary.clone()
        },
        g,
    };
    for stale in [classless(free.g.clone()), classless(stored.g.clone())] {
        cache::store(&reader, 1, 0, &stale).unwrap();
        assert!(cache::load(&reader, &t0, &t1).is_none());
    }
    let mut crossing = classless(free.g.clone());
    crossing.summary.size_classes = Some(2);
    cache::store(&reader, 1, 0, &crossing).unwrap();
    assert!(cache::load(&reader, &t0, &t1).is_none());

    // the stale file left in place: the extrapolation pairs again and stores the pairing
    let out = dir.path().join("x.mcap");
    let mut request = ExtrapolationRequest::new(
        rec.clone(),
        5,
        out,
        MemoryLimit {
            bytes: u64::MAX,
            source: "test".into(),
        },
    );
    request.reproducible = true;
    let outcome = extrapolate_recording(&request, |_| {}).unwrap();
    assert!(!outcome.costs.pairing_reused);
    let reused = cache::load(&reader, &t0, &t1).expect("stored with its classes");
    assert_eq!(reused.g, stored.g);
    assert_eq!(reused.summary.size_classes, Some(2));
    let heat = (outcome.total_heat_t1, outcome.total_heat_end);
    assert!(
        (heat.1 - heat.0).abs() <= 1e-12 * heat.0,
        "Σ C T at t1 {} and after 5 periods {}",
        heat.0,
        heat.1
    );
}

/// A bed of one size stores no class count: its sidecar's bytes are those written before
/// sizes were kept apart.
#[test]
fn a_bed_of_one_size_stores_no_class_count() {
    let mut rng = Rng::new(12);
    let (mut t0, mut t1) = (snapshot(0, &mut rng), snapshot(1, &mut rng));
    t0.radius = vec![0.005; N];
    t1.radius = vec![0.005; N];
    let stored = cache::compute(&t0, &t1, None).unwrap();
    assert_eq!(stored.summary.size_classes, None);
    let json = serde_json::to_string(&stored.summary).unwrap();
    assert!(!json.contains("size_classes"), "{json}");
}

/// Every map of a fresh boundary pool keeps each particle in its class.
#[test]
fn the_fresh_pools_keep_the_classes() {
    let mut rng = Rng::new(13);
    let (before, end) = (snapshot(0, &mut rng), snapshot(1, &mut rng));
    for maps in fresh_maps(4, 2.0) {
        let redraws = boundary::Redraws::of(maps, boundary::AxialEnds::Caps)
            .unwrap()
            .unwrap();
        let pool = boundary::fresh_pool(redraws, &before, &end, &before, 3).unwrap();
        assert_eq!(pool.maps.len(), 4);
        for g in &pool.maps {
            assert!(is_permutation(g));
            assert!(respects_classes(g, &before.radius, &end.radius), "{maps:?}");
        }
    }
}
