//! The pairing of a section periodic along its axis y (`PairingOptions::axial_period`):
//! exact against the dense oracle on the periodic cost matrix, across the seam where the
//! particles crossed it, the same as without a period when the period is far longer than the
//! bed, optimal within each size class; and its callers: the recording's period, a sidecar
//! computed without it is stale, fresh boundary maps across the seam.

mod common;

use common::{fresh_maps, is_permutation, Rng};
use extrapolate::boundary::{fresh_pool, AxialEnds, Redraws};
use extrapolate::pairing::{
    pair, pair_by_size, pair_dense_periodic, respects_classes, Pairing, PairingError,
    PairingOptions,
};
use extrapolate::sidecar::StoredPairing;
use extrapolate::{axial_period, cache, extrapolate_recording, ExtrapolationRequest, MemoryLimit};
use proptest::prelude::*;
use std::path::Path;
use tdex_format::{CollisionRow, RecordingInfo, RecordingReader, RecordingWriter, Snapshot};

/// Integer cost of a pair across the seam of period `length`, as the solver defines it:
/// `Δy` to its nearest image, then `round(|Δ| / unit)`, halves away from zero.
fn periodic_cost(a: &[f64; 3], b: &[f64; 3], unit: f64, length: f64) -> i64 {
    let (dx, mut dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dy -= length * (dy / length).round();
    let x = (dx * dx + dy * dy + dz * dz).sqrt() / unit;
    let whole = x as i64;
    whole + i64::from(x - whole as f64 >= 0.5)
}

fn total(x0: &[[f64; 3]], x1: &[[f64; 3]], g: &[u32], unit: f64, length: f64) -> i64 {
    g.iter()
        .enumerate()
        .map(|(p, &q)| periodic_cost(&x1[p], &x0[q as usize], unit, length))
        .sum()
}

/// The same pairing but for its wall time.
fn timeless(mut p: Pairing) -> Pairing {
    p.seconds = 0.0;
    p
}

/// A random bed of `n` particles in a periodic box `[0, 6 mm)² × [−L/2, L/2)` along y, half
/// of them within 0.4 mm of the seam, on a coarse grid (ties, coincident points) or
/// continuous; t1 either drawn again, or t0 drifted along y by up to 2 mm (across the seam)
/// with 0.3 mm of jitter, wrapped and shuffled.
fn periodic_bed() -> impl Strategy<Value = (Vec<[f64; 3]>, Vec<[f64; 3]>, f64)> {
    (
        2usize..=150,
        any::<u64>(),
        any::<bool>(),
        any::<bool>(),
        3.0f64..12.0,
    )
        .prop_map(|(n, seed, on_grid, drifted, length_mm)| {
            let length = length_mm * 1e-3;
            let mut rng = Rng::new(seed);
            let half = 0.5 * length;
            let wrap = |y: f64| {
                if y >= half {
                    y - length
                } else if y < -half {
                    y + length
                } else {
                    y
                }
            };
            let point = |rng: &mut Rng, i: usize| {
                let across = |rng: &mut Rng| {
                    if on_grid {
                        rng.below(4) as f64 * 1.5e-3
                    } else {
                        rng.range(0.0, 6e-3)
                    }
                };
                let y = if i.is_multiple_of(2) {
                    // near the seam, on either side
                    let off = rng.range(0.0, 4e-4);
                    if rng.below(2) == 0 {
                        -half + off
                    } else {
                        wrap(half - off)
                    }
                } else if on_grid {
                    wrap(-half + rng.below(8) as f64 * length / 8.0)
                } else {
                    rng.range(-half, half)
                };
                [across(rng), y, across(rng)]
            };
            let x0: Vec<[f64; 3]> = (0..n).map(|i| point(&mut rng, i)).collect();
            let mut x1: Vec<[f64; 3]> = if drifted {
                let drift = rng.range(-2e-3, 2e-3);
                x0.iter()
                    .map(|p| {
                        [
                            p[0] + rng.range(-3e-4, 3e-4),
                            wrap(p[1] + drift + rng.range(-3e-4, 3e-4)),
                            p[2] + rng.range(-3e-4, 3e-4),
                        ]
                    })
                    .collect()
            } else {
                (0..n).map(|i| point(&mut rng, i)).collect()
            };
            rng.shuffle(&mut x1);
            (x0, x1, length)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// On random periodic beds of up to 150 particles, many near the seam: the sparse
    /// pairing is a certified permutation whose integer cost is the dense oracle's on the
    /// periodic cost matrix, and its totals are the periodic ones recomputed from `g`.
    #[test]
    fn the_periodic_pairing_is_the_oracles(
        (x0, x1, length) in periodic_bed(),
        k in 1usize..6,
    ) {
        let opts = PairingOptions {
            unit: 1e-6 * 1e-3,
            k_initial: k,
            dense_max: 0,
            certify: true,
            axial_period: Some(length),
        };
        let s = pair(&x0, &x1, &opts).unwrap();
        prop_assert!(is_permutation(&s.g));
        prop_assert!(s.certified);
        let d = pair_dense_periodic(&x0, &x1, opts.unit, length).unwrap();
        prop_assert!(is_permutation(&d.g));
        prop_assert_eq!(s.total_cost, d.total_cost);
        prop_assert_eq!(s.total_cost, total(&x0, &x1, &s.g, opts.unit, length));
        prop_assert_eq!(d.total_cost, total(&x0, &x1, &d.g, opts.unit, length));
        let sum: f64 = s.g.iter().enumerate().map(|(p, &q)| {
            let (a, b) = (x1[p], x0[q as usize]);
            let mut dy = a[1] - b[1];
            dy -= length * (dy / length).round();
            ((a[0] - b[0]).powi(2) + dy * dy + (a[2] - b[2]).powi(2)).sqrt()
        }).sum();
        prop_assert!((s.total_distance - sum).abs() <= 1e-9 * sum.max(1e-3));
        // `pair` through the dense switch is the oracle
        let via_dense = pair(&x0, &x1, &PairingOptions { dense_max: 4096, ..opts }).unwrap();
        prop_assert_eq!(via_dense.total_cost, d.total_cost);
    }

    /// With a period more than twice as long as the bed, no image is ever a candidate: the
    /// result is the one without a period, field for field (the float total bit for bit),
    /// but for the count of points the certificate examined.
    #[test]
    fn a_period_far_longer_than_the_bed_changes_nothing(
        (x0, x1, _) in periodic_bed(),
        k in 1usize..6,
    ) {
        let plain = PairingOptions {
            unit: 1e-6 * 1e-3,
            k_initial: k,
            dense_max: 0,
            certify: true,
            axial_period: None,
        };
        let far = PairingOptions { axial_period: Some(1.0), ..plain.clone() };
        let a = timeless(pair(&x0, &x1, &plain).unwrap());
        let mut b = timeless(pair(&x0, &x1, &far).unwrap());
        prop_assert_eq!(a.total_distance.to_bits(), b.total_distance.to_bits());
        // The certificate's radius queries also return images when a radius exceeds the
        // gap to them (after exit edges): more points examined, the same pairs found.
        prop_assert!(b.certificate_examined >= a.certificate_examined);
        b.certificate_examined = a.certificate_examined;
        prop_assert_eq!(a, b);
    }

    /// With size classes and a period together: every particle onto a role of its own
    /// radius, certified, and in every class the periodic oracle's integer cost.
    #[test]
    fn size_classes_and_a_period_together(
        (x0, x1, length) in periodic_bed(),
        seed in any::<u64>(),
        k in 1usize..6,
    ) {
        let mut rng = Rng::new(seed);
        let radii = [0.4e-3, 0.6e-3, 0.9e-3];
        let r0: Vec<f64> = (0..x0.len()).map(|_| radii[rng.below(3)]).collect();
        let mut r1 = r0.clone();
        rng.shuffle(&mut r1);
        let opts = PairingOptions {
            unit: 1e-6 * 1e-3,
            k_initial: k,
            dense_max: 0,
            certify: true,
            axial_period: Some(length),
        };
        let s = pair_by_size(&x0, &r0, &x1, &r1, &opts).unwrap();
        prop_assert!(is_permutation(&s.g));
        prop_assert!(respects_classes(&s.g, &r0, &r1));
        prop_assert!(s.certified);
        let mut sum = 0;
        for radius in radii {
            let members = |r: &[f64]| -> Vec<usize> { (0..r.len()).filter(|&i| r[i] == radius).collect() };
            let (m0, m1) = (members(&r0), members(&r1));
            if m0.is_empty() {
                continue;
            }
            let c0: Vec<[f64; 3]> = m0.iter().map(|&i| x0[i]).collect();
            let c1: Vec<[f64; 3]> = m1.iter().map(|&i| x1[i]).collect();
            let oracle = pair_dense_periodic(&c0, &c1, opts.unit, length).unwrap();
            let class_cost: i64 = m1
                .iter()
                .map(|&p| periodic_cost(&x1[p], &x0[s.g[p] as usize], opts.unit, length))
                .sum();
            prop_assert_eq!(class_cost, oracle.total_cost, "radius {}", radius);
            sum += class_cost;
        }
        prop_assert_eq!(s.total_cost, sum);
    }
}

/// A lattice of 160 particles in a section 10 spacings long, carried 0.3 spacings along y:
/// the 16 at the top end cross the seam and enter at the bottom. Each t1 point's own t0
/// point is its unique nearest across the seam, so the periodic optimum is the identity,
/// across the seam for the 16; without the period those must pair far away instead.
#[test]
fn particles_that_crossed_the_seam_are_paired_across_it() {
    let (a, length) = (1e-2, 0.1);
    let mut rng = Rng::new(3);
    let x0: Vec<[f64; 3]> = (0..160)
        .map(|s| {
            let (x, y, z) = (s % 4, (s / 4) % 10, s / 40);
            [
                x as f64 * a,
                -0.5 * length + (y as f64 + 0.8) * a,
                z as f64 * a,
            ]
        })
        .collect();
    let mut order: Vec<usize> = (0..160).collect();
    rng.shuffle(&mut order);
    // t1 particle p stands where t0 particle order[p] moved to
    let moved = |q: usize| {
        let [x, y, z] = x0[q];
        let y = y + 0.3 * a;
        [x, if y >= 0.5 * length { y - length } else { y }, z]
    };
    let x1: Vec<[f64; 3]> = order.iter().map(|&q| moved(q)).collect();
    let crossed: Vec<usize> = (0..160).filter(|&p| x1[p][1] < x0[order[p]][1]).collect();
    assert_eq!(crossed.len(), 16);
    let opts = PairingOptions {
        k_initial: 4,
        axial_period: Some(length),
        ..PairingOptions::for_diameter(a)
    };
    let periodic = pair(&x0, &x1, &opts).unwrap();
    assert!(periodic.certified);
    for (p, &q) in periodic.g.iter().enumerate() {
        assert_eq!(q as usize, order[p], "particle {p}");
    }
    assert!((periodic.total_distance - 160.0 * 0.3 * a).abs() < 1e-12);
    let dense = pair_dense_periodic(&x0, &x1, opts.unit, length).unwrap();
    assert_eq!(dense.g, periodic.g);
    let plain = pair(
        &x0,
        &x1,
        &PairingOptions {
            axial_period: None,
            ..opts
        },
    )
    .unwrap();
    assert!(plain.total_distance > periodic.total_distance + 1.0 * a);
    assert!(crossed.iter().any(|&p| plain.g[p] as usize != order[p]));
    for &p in &crossed {
        // across the seam: 0.3 spacings away, not the section's length
        let (y1, y0) = (x1[p][1], x0[periodic.g[p] as usize][1]);
        assert!((y0 - y1 - (length - 0.3 * a)).abs() < 1e-12, "{y0} {y1}");
    }
}

/// Positions outside the section are wrapped first (the same pairing as of the wrapped
/// positions); a period that is not finite and positive is refused.
#[test]
fn positions_are_wrapped_and_bad_periods_refused() {
    let length = 0.1;
    let x0 = vec![[0.0, 0.049, 0.0], [0.0, 0.0, 0.0], [0.01, -0.02, 0.0]];
    let x1 = vec![
        [0.0, -0.049 + 3.0 * length, 0.0],
        [0.0, 0.001 - length, 0.0],
        [0.01, -0.019, 0.0],
    ];
    let wrapped = vec![[0.0, -0.049, 0.0], [0.0, 0.001, 0.0], [0.01, -0.019, 0.0]];
    let opts = PairingOptions {
        axial_period: Some(length),
        ..PairingOptions::for_diameter(0.01)
    };
    let a = pair(&x0, &x1, &opts).unwrap();
    let b = pair(&x0, &wrapped, &opts).unwrap();
    assert_eq!(a.g, [0, 1, 2]);
    assert_eq!(a.g, b.g);
    assert_eq!(a.total_cost, b.total_cost);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = pair(
            &x0,
            &x1,
            &PairingOptions {
                axial_period: Some(bad),
                ..opts.clone()
            },
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                PairingError::InvalidOption {
                    name: "axial_period",
                    ..
                }
            ),
            "{e}"
        );
        assert!(pair_dense_periodic(&x0, &x1, opts.unit, bad).is_err());
    }
}

// --- the callers ---

const N: usize = 48;
const TAU: u64 = 1000;
const LENGTH: f64 = 0.06;

fn info(case_resolved: serde_json::Value) -> RecordingInfo {
    common::recording_info(N, TAU, 1, case_resolved)
}

fn periodic_case() -> serde_json::Value {
    serde_json::json!({
        "seed": 5,
        "drum": { "radius": 0.05, "length": LENGTH, "rotation_period": 1.0,
                  "end_caps": "periodic" }
    })
}

/// A 4 × 4 × 3 lattice across a section `LENGTH` long, carried 5 mm along y at t1 (the
/// top layer across the seam) with 1 mm of jitter, in shuffled order.
fn snapshots(rng: &mut Rng) -> (Snapshot, Snapshot) {
    let site = |s: usize| {
        let (x, y, z) = (s % 4, (s / 4) % 4, s / 16);
        [
            x as f64 * 0.012,
            -0.5 * LENGTH + 0.012 + y as f64 * 0.015,
            z as f64 * 0.012,
        ]
    };
    let snap = |index: u32, pos: Vec<[f64; 3]>, rng: &mut Rng| Snapshot {
        index,
        time: (u64::from(index) * TAU) as f64 * 1e-5,
        id: (0..N as u32).collect(),
        pos,
        radius: vec![0.004; N],
        vel: vec![[0.0; 3]; N],
        temp: (0..N).map(|_| rng.range(300.0, 400.0)).collect(),
    };
    let x0: Vec<[f64; 3]> = (0..N).map(site).collect();
    let mut order: Vec<usize> = (0..N).collect();
    rng.shuffle(&mut order);
    let x1 = order
        .iter()
        .map(|&q| {
            let [x, y, z] = x0[q];
            let y = y + 0.005 + rng.range(-1e-3, 1e-3);
            [x, if y >= 0.5 * LENGTH { y - LENGTH } else { y }, z]
        })
        .collect();
    (snap(0, x0, rng), snap(1, x1, rng))
}

fn write_recording(path: &Path, case_resolved: serde_json::Value) -> (Snapshot, Snapshot) {
    let mut rng = Rng::new(21);
    let (t0, t1) = snapshots(&mut rng);
    write_snapshots(path, case_resolved, (t0, t1), &mut rng)
}

/// A recording of `t0`, `t1` and a table of 100 random rows.
fn write_snapshots(
    path: &Path,
    case_resolved: serde_json::Value,
    (t0, t1): (Snapshot, Snapshot),
    rng: &mut Rng,
) -> (Snapshot, Snapshot) {
    let mut writer = RecordingWriter::create(path, info(case_resolved)).unwrap();
    writer.write_snapshot(&t0).unwrap();
    writer.write_snapshot(&t1).unwrap();
    let rows: Vec<CollisionRow> = (0..100)
        .map(|r| {
            let i = rng.below(N - 1);
            CollisionRow {
                i: i as u32,
                j: (i + 1 + rng.below(N - 1 - i)) as u32,
                start_step: r as u64 * 8,
                duration_steps: 1 + rng.below(10) as u32,
                sqrt_area: 1e-3 * rng.range(0.5, 1.5),
            }
        })
        .collect();
    writer.push_rows(rows).unwrap();
    writer.finish(vec![0; 4], None).unwrap();
    (t0, t1)
}

fn request(rec: &Path, out: &Path) -> ExtrapolationRequest {
    let mut request = ExtrapolationRequest::new(
        rec.to_path_buf(),
        3,
        out.to_path_buf(),
        MemoryLimit {
            bytes: u64::MAX,
            source: "test".into(),
        },
    );
    request.reproducible = true;
    request
}

/// The recording's period is its drum's length when the drum is periodic, none otherwise.
#[test]
fn the_period_is_the_periodic_drums_length() {
    assert_eq!(axial_period(&info(periodic_case())), Some(LENGTH));
    for case in [
        serde_json::json!({ "seed": 5 }),
        serde_json::json!({ "drum": { "length": LENGTH, "end_caps": "rotating" } }),
        serde_json::json!({ "drum": { "length": LENGTH } }),
    ] {
        assert_eq!(axial_period(&info(case)), None);
    }
}

/// The stored pairing of a periodic recording is computed across the seam and says so; a
/// sidecar computed without the period is stale: not reused, and the extrapolation pairs
/// again across the seam and stores that. A drum with end caps stores no period.
#[test]
fn a_sidecar_without_the_period_is_stale_for_a_periodic_recording() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    let (t0, t1) = write_recording(&rec, periodic_case());
    let reader = RecordingReader::open(&rec).unwrap();

    let stored = cache::compute(&t0, &t1, Some(LENGTH)).unwrap();
    assert_eq!(stored.summary.axial_period, Some(LENGTH));
    let plain = cache::compute(&t0, &t1, None).unwrap();
    assert_eq!(plain.summary.axial_period, None);
    assert_ne!(plain.g, stored.g, "the bed must cross the seam");
    assert!(stored.summary.total_distance_diameters < plain.summary.total_distance_diameters);
    let json = serde_json::to_string(&plain.summary).unwrap();
    assert!(!json.contains("axial_period"), "{json}");

    let without_period = StoredPairing {
        snapshots_fingerprint: plain.snapshots_fingerprint,
        summary: plain.summary.clone(),
        g: plain.g.clone(),
    };
    cache::store(&reader, 1, 0, &without_period).unwrap();
    assert!(cache::load(&reader, &t0, &t1).is_none());

    let outcome =
        extrapolate_recording(&request(&rec, &dir.path().join("x.mcap")), |_| {}).unwrap();
    assert!(!outcome.costs.pairing_reused);
    let reused = cache::load(&reader, &t0, &t1).expect("stored with its period");
    assert_eq!(reused.g, stored.g);
    assert_eq!(reused.summary.axial_period, Some(LENGTH));

    // with end caps, the pairing without a period is the one reused
    let capped = dir.path().join("capped.mcap");
    write_recording(
        &capped,
        serde_json::json!({ "seed": 5, "drum": { "radius": 0.05,
        "length": LENGTH, "rotation_period": 1.0 } }),
    );
    let capped_reader = RecordingReader::open(&capped).unwrap();
    cache::store(&capped_reader, 1, 0, &without_period).unwrap();
    assert!(cache::load(&capped_reader, &t0, &t1).is_some());
}

/// Fresh boundary maps of a periodic section take the recorded steps across the seam and
/// pair across it. The bed moved 5 mm (± 1 mm) along the axis, a part of it across the seam,
/// with 15 mm between lattice planes: whatever steps are redrawn, each particle's nearest
/// role is the one the exact pairing gives it, so every map of the pool is that pairing;
/// maps blind to the seam stop the particles that crossed it at the far end of the bed and
/// hand them other roles. Heat is conserved and the output is the seed's.
#[test]
fn fresh_boundary_maps_of_a_periodic_section_cross_the_seam() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("run.mcap");
    // each particle keeps its index, as in a recording, and moves 5 mm (± 1 mm) along the
    // axis: the top layer of the lattice crosses the seam
    let mut rng = Rng::new(22);
    let (t0, _) = snapshots(&mut rng);
    let mut t1 = t0.clone();
    t1.index = 1;
    t1.time = TAU as f64 * 1e-5;
    for p in &mut t1.pos {
        let y = p[1] + 0.005 + rng.range(-1e-3, 1e-3);
        p[1] = if y >= 0.5 * LENGTH { y - LENGTH } else { y };
    }
    let (t0, t1) = write_snapshots(&rec, periodic_case(), (t0, t1), &mut rng);
    let exact = cache::compute(&t0, &t1, Some(LENGTH)).unwrap();
    for maps in fresh_maps(4, 1.0) {
        let run = |name: &str| {
            let mut req = request(&rec, &dir.path().join(name));
            req.boundary = maps;
            extrapolate_recording(&req, |_| {}).unwrap()
        };
        let outcome = run("a.mcap");
        assert_eq!(outcome.fresh_pools.len(), 1);
        let pool = &outcome.fresh_pools[0];
        assert!(
            (pool.mean_distance_diameters - exact.summary.mean_distance_diameters).abs() < 0.05,
            "{maps:?}: pool {pool:?}, exact {:?}",
            exact.summary
        );
        let periodic = AxialEnds::Periodic { length: LENGTH };
        let pool_in = |axis| {
            let redraws = Redraws::of(maps, axis).unwrap().unwrap();
            fresh_pool(redraws, &t0, &t1, &t0, 5).unwrap()
        };
        let across = pool_in(periodic);
        assert!(across.maps.iter().all(|g| *g == exact.g), "{maps:?}");
        let seam_blind = pool_in(AxialEnds::Caps);
        assert!(seam_blind.maps.iter().all(|g| *g != exact.g), "{maps:?}");
        let heat = (outcome.total_heat_end - outcome.total_heat_t1).abs() / outcome.total_heat_t1;
        assert!(heat < 1e-12, "{maps:?}: heat changed by {heat:e}");
        assert_eq!(
            std::fs::read(dir.path().join("a.mcap")).unwrap(),
            {
                run("b.mcap");
                std::fs::read(dir.path().join("b.mcap")).unwrap()
            },
            "{maps:?}: the same seed gives the same bytes"
        );
    }
}
