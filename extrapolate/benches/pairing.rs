//! Pairing benchmark on a bed the size of the paper's drum (Haydar et al. 2023: 80 000
//! spheres of radius 5 mm; drum radius 0.10 m, length 6.349 m, 35 % fill).
//!
//! Run: `cargo bench -p extrapolate --bench pairing` (threads: `TDEX_THREADS`, default 2;
//! particles: `TDEX_N`, default 80000, the drum length scaled to keep the fill; initial
//! k: `TDEX_K`, default the library's).
//!
//! Real recordings: `TDEX_RECORDING=/path.mcap` pairs the recording's t0 and t1
//! snapshots instead (diameter: the mean of t0's), `TDEX_TILE=m` (default 1) first tiles
//! the bed m times along the drum axis (y), each copy shifted by the bed's y extent plus
//! one diameter, so that 4 × 20 000 gives an 80 000 instance with the structure of real
//! data. `TDEX_REPEAT` (default 3) runs, certified, 2 threads (`TDEX_THREADS`); all runs
//! must give the same result, which `TDEX_DUMP_G=file` writes out (g, one index a line).
//!
//! `TDEX_STRETCH=A:L` displaces the recording's t1 along y by A·d·sin(2π y / (L·d)), a
//! stand-in for the axial transport of a long drum.
//!
//! Two t1 snapshots against the same t0 packing:
//! * `independent`: a second packing of the same region generated independently (other
//!   lattice orientation and offset, other jitter): no correlation at all, the worst case;
//! * `circulation`: t0 carried by a smooth incompressible circulation confined to the bed
//!   (up to 3 diameters) plus 1 diameter of random jitter.
//!
//! and `sizes`: a circulation of the same t0 (its own draw) on a bed of three size classes
//! (radii 1, 1.25 and 1.5 times d/2 in number fractions 0.3, 0.4 and 0.3, dealt to the
//! particles at random from a fixed seed, each particle keeping its radius at t1), paired
//! within the classes (`pair_by_size`) and, alternately in the same run, as one size
//! (`pair`) on the same positions; `TDEX_REPEAT` (default 3) pairs of runs.
//!
//! and `periodic`: the same t0 as a section periodic along its axis (the axis turned to y,
//! the period the drum's length), t1 the `circulation` draw carried 2 diameters along the
//! axis, so that the particles near one end cross the seam; paired across the seam
//! (`axial_period`, t1 wrapped into the section) and, alternately in the same run, without
//! a period on the same t1 left unwrapped (the same displacements, no seam);
//! `TDEX_REPEAT` (default 3) pairs of runs.
//!
//! A filter after `--` runs only the cases whose name contains it:
//! `cargo bench -p extrapolate --bench pairing -- sizes`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{circulation, fill_fraction, is_permutation, packing, surface_height, Drum, Rng};
use extrapolate::pairing::{pair, pair_by_size, Pairing, PairingOptions};

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
    report_d(name, r, D);
}

fn report_d(name: &str, r: &Pairing, d: f64) {
    println!(
        "{name:12} n {:6} | k {:3} rounds {:2} certified {:5} | total cost {:13} | mean {:.4} d | \
         edges {:8} growth {:5} added {:6} cert. examined {:9} bids {:9} | {:.3} s",
        r.g.len(),
        r.k_used,
        r.rounds,
        r.certified,
        r.total_cost,
        r.mean_distance_in_diameters(d),
        r.edges,
        r.growth_pairs,
        r.added_pairs,
        r.certificate_examined,
        r.auction_bids,
        r.seconds
    );
}

/// The t0/t1 snapshots of a recording, tiled `tile` times along y; also the diameter.
fn load_recording(path: &str, tile: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, f64) {
    let reader = tdex_format::RecordingReader::open(std::path::Path::new(path)).unwrap();
    let s0 = reader.snapshot(0).unwrap().expect("no t0 snapshot");
    let s1 = reader.snapshot(1).unwrap().expect("no t1 snapshot");
    let d = 2.0 * s0.radius.iter().sum::<f64>() / s0.radius.len() as f64;
    let (mut ylo, mut yhi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in s0.pos.iter().chain(&s1.pos) {
        ylo = ylo.min(p[1]);
        yhi = yhi.max(p[1]);
    }
    let shift = yhi - ylo + d;
    for (name, s) in [("t0", &s0), ("t1", &s1)] {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &s.pos {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        println!(
            "{name}: {} particles, box {lo:.4?} .. {hi:.4?} m",
            s.pos.len()
        );
    }
    let tiled = |pos: &[[f64; 3]]| -> Vec<[f64; 3]> {
        (0..tile)
            .flat_map(|m| {
                pos.iter()
                    .map(move |p| [p[0], p[1] + m as f64 * shift, p[2]])
            })
            .collect()
    };
    (tiled(&s0.pos), tiled(&s1.pos), d)
}

fn recording(path: &str, threads: usize) {
    let tile = env_usize("TDEX_TILE", 1);
    let repeat = env_usize("TDEX_REPEAT", 3);
    let t = Instant::now();
    let (x0, mut x1, d) = load_recording(path, tile);
    // `TDEX_STRETCH=A:L`: a stand-in for the axial mass transport of a long drum. t1 is
    // displaced along y by `A·d·sin(2π (y − y_min) / (L·d))`, a density modulation of
    // wavelength L diameters that the pairing must undo by shifting whole slabs.
    if let Ok(spec) = std::env::var("TDEX_STRETCH") {
        let (a, l) = spec.split_once(':').expect("TDEX_STRETCH=A:L");
        let (a, l): (f64, f64) = (a.parse().unwrap(), l.parse().unwrap());
        let ymin = x1.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        for p in &mut x1 {
            p[1] += a * d * (std::f64::consts::TAU * (p[1] - ymin) / (l * d)).sin();
        }
        println!("t1 stretched along y: amplitude {a} d, wavelength {l} d");
    }
    println!(
        "recording {path}: {} particles ({tile} × {}), d = {d:.6} m, read in {:.2} s; \
         {threads} threads",
        x0.len(),
        x0.len() / tile,
        t.elapsed().as_secs_f64()
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let defaults = PairingOptions::for_diameter(d);
    let opts = PairingOptions {
        k_initial: env_usize("TDEX_K", defaults.k_initial),
        ..defaults
    };
    let mut first: Option<Pairing> = None;
    let mut times = Vec::new();
    for i in 0..repeat {
        let r = pool.install(|| pair(&x0, &x1, &opts)).unwrap();
        assert!(is_permutation(&r.g));
        report_d(&format!("real/{tile}x#{i}"), &r, d);
        times.push(r.seconds);
        if let Some(f) = &first {
            assert_eq!(f.g, r.g, "runs differ");
        } else {
            // `TDEX_DUMP_G=file`: write g, one index a line, to compare two builds.
            if let Ok(path) = std::env::var("TDEX_DUMP_G") {
                let text: String = r.g.iter().map(|q| format!("{q}\n")).collect();
                std::fs::write(path, text).unwrap();
            }
            first = Some(r);
        }
    }
    let min = times.iter().copied().fold(f64::INFINITY, f64::min);
    let max = times.iter().copied().fold(0.0, f64::max);
    println!("min {min:.3} s, range {min:.3}–{max:.3} s over {repeat} runs");
}

/// Three size classes on the circulation of `x0`: the pairing within them beside the pairing
/// of the same positions as one size, alternated `repeat` times on the same pool.
fn sizes(drum: &Drum, x0: &[[f64; 3]], h: f64, pool: &rayon::ThreadPool, k: usize) {
    let n = x0.len();
    // The circulation shuffles its output. Its draws do not depend on the points, nor its
    // flow across the axis on the axial coordinate, so the same draw on t0 with each axial
    // coordinate replaced by 1 000 m times the index moves every point alike and tells
    // which t0 particle each t1 point is (the axial drift and jitter stay below 0.1 m).
    let seed = 20261206;
    let x1 = circulation(drum, x0, h, 3.0 * D, 1.0 * D, &mut Rng::new(seed));
    let tagged: Vec<[f64; 3]> = x0
        .iter()
        .enumerate()
        .map(|(i, p)| [p[0], p[1], i as f64 * 1e3])
        .collect();
    let source: Vec<usize> = circulation(drum, &tagged, h, 3.0 * D, 1.0 * D, &mut Rng::new(seed))
        .iter()
        .map(|p| (p[2] / 1e3).round() as usize)
        .collect();
    let base = 0.5 * D;
    let (small, middle) = (n * 3 / 10, n * 4 / 10);
    let mut r0: Vec<f64> = (0..n)
        .map(|i| {
            base * if i < small {
                1.0
            } else if i < small + middle {
                1.25
            } else {
                1.5
            }
        })
        .collect();
    Rng::new(seed + 1).shuffle(&mut r0);
    let r1: Vec<f64> = source.iter().map(|&i| r0[i]).collect();
    let d = 2.0 * r0.iter().sum::<f64>() / n as f64;
    let defaults = PairingOptions::for_bed(d, x0, &x1);
    let opts = PairingOptions {
        k_initial: k,
        ..defaults
    };
    println!(
        "sizes: {small} of radius {base} m, {middle} of {}, {} of {}; mean diameter {d:.5} m, \
         unit {:.3e} m",
        1.25 * base,
        n - small - middle,
        1.5 * base,
        opts.unit
    );
    let repeat = env_usize("TDEX_REPEAT", 3);
    let (mut one_size, mut classes) = (Vec::new(), Vec::new());
    for i in 0..repeat {
        let single = pool.install(|| pair(x0, &x1, &opts)).unwrap();
        assert!(is_permutation(&single.g));
        report_d(&format!("one size#{i}"), &single, D);
        let sized = pool
            .install(|| pair_by_size(x0, &r0, &x1, &r1, &opts))
            .unwrap();
        assert!(is_permutation(&sized.g));
        assert!(sized
            .g
            .iter()
            .enumerate()
            .all(|(p, &q)| r0[q as usize] == r1[p]));
        report_d(&format!("3 sizes#{i}"), &sized, D);
        one_size.push(single.seconds);
        classes.push(sized.seconds);
    }
    let range = |t: &[f64]| {
        (
            t.iter().copied().fold(f64::INFINITY, f64::min),
            t.iter().copied().fold(0.0, f64::max),
        )
    };
    let ((a, b), (c, e)) = (range(&one_size), range(&classes));
    println!("one size {a:.3}–{b:.3} s, three sizes {c:.3}–{e:.3} s over {repeat} alternated runs");
}

/// The `periodic` case (module documentation): the bed as a periodic section, paired across
/// the seam, beside the same displacements paired without a seam.
fn periodic(
    drum: &Drum,
    x0: &[[f64; 3]],
    circ: &[[f64; 3]],
    pool: &rayon::ThreadPool,
    k_initial: usize,
) {
    let repeat = env_usize("TDEX_REPEAT", 3);
    let length = drum.length;
    // the drum's axis (z from 0 to `length`) turned to y, centred on the origin
    let section = |p: &[f64; 3], shift: f64| [p[0], p[2] - 0.5 * length + shift, p[1]];
    let wrap = |[x, y, z]: [f64; 3]| {
        let y = if y >= 0.5 * length {
            y - length
        } else if y < -0.5 * length {
            y + length
        } else {
            y
        };
        [x, y, z]
    };
    let s0: Vec<[f64; 3]> = x0.iter().map(|p| section(p, 0.0)).collect();
    let carried: Vec<[f64; 3]> = circ.iter().map(|p| section(p, 2.0 * D)).collect();
    let wrapped: Vec<[f64; 3]> = carried.iter().copied().map(wrap).collect();
    let crossed = carried
        .iter()
        .zip(&wrapped)
        .filter(|(a, b)| a[1] != b[1])
        .count();
    let plain = PairingOptions {
        k_initial,
        ..PairingOptions::for_diameter(D)
    };
    let across = PairingOptions {
        axial_period: Some(length),
        ..plain.clone()
    };
    println!("periodic: period {length} m, {crossed} particles crossed the seam");
    let (mut without, mut with) = (Vec::new(), Vec::new());
    for i in 0..repeat {
        let a = pool.install(|| pair(&s0, &carried, &plain)).unwrap();
        report(&format!("no seam#{i}"), &a);
        let b = pool.install(|| pair(&s0, &wrapped, &across)).unwrap();
        assert!(is_permutation(&b.g) && b.certified);
        report(&format!("periodic#{i}"), &b);
        without.push(a.seconds);
        with.push(b.seconds);
    }
    let range = |t: &[f64]| {
        (
            t.iter().copied().fold(f64::INFINITY, f64::min),
            t.iter().copied().fold(0.0, f64::max),
        )
    };
    let ((a, b), (c, e)) = (range(&without), range(&with));
    println!("no seam {a:.3}–{b:.3} s, periodic {c:.3}–{e:.3} s over {repeat} alternated runs");
}

fn main() {
    // `cargo bench` passes `--bench`; a word without a dash selects the cases
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let wanted = |name: &str| filter.as_deref().is_none_or(|f| name.contains(f));
    let threads = env_usize("TDEX_THREADS", 2);
    if let Ok(path) = std::env::var("TDEX_RECORDING") {
        recording(&path, threads);
        return;
    }
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
        if !wanted(name) {
            continue;
        }
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
    if wanted("sizes") {
        sizes(&drum, &x0, h, &pool, opts.k_initial);
    }
    if wanted("periodic") {
        periodic(&drum, &x0, &circ, &pool, opts.k_initial);
    }
}
