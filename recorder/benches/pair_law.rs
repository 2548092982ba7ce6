//! The batched pair law alone, in each build this CPU can run (`recorder::simd`): nanoseconds
//! per contact for the same random contacts (unequal spheres, sliding and sticking, capped and
//! free rolling springs), and a check that every build gives them the same bits.
//!
//! Run: `cargo bench -p recorder --bench pair_law` (`TDEX_CONTACTS`, default 4096 contacts;
//! `TDEX_REPEAT`, default 400 passes over them; each build timed in turn, three rounds).

use rand_xoshiro::rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use recorder::case::{ConductionSpec, ContactArea, PairCoefficients, RollingModel};
use recorder::contact::pair_batch::{PairBatch, PairConstants, SphereArrays};
use recorder::contact::{ContactHistory, PairLaw};
use recorder::heat::ConductionLaw;
use recorder::simd::Simd;
use std::time::Instant;

type Vec3 = [f64; 3];

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Touching pairs `2p, 2p + 1` with overlaps up to 5 % of a radius (as the unit test's).
struct Contacts {
    pos: Vec<Vec3>,
    vel: Vec<Vec3>,
    omega: Vec<Vec3>,
    radius: Vec<f64>,
    mass: Vec<f64>,
    temp: Vec<f64>,
    history: Vec<ContactHistory>,
}

fn contacts(count: usize) -> Contacts {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut u = move || 2.0 * ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64) - 1.0;
    let mut c = Contacts {
        pos: vec![],
        vel: vec![],
        omega: vec![],
        radius: vec![],
        mass: vec![],
        temp: vec![],
        history: vec![],
    };
    for _ in 0..count {
        let (ri, rj) = (0.005 * (1.0 + 0.2 * u()), 0.004 * (1.0 + 0.2 * u()));
        let dir = [u(), u(), u()];
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        let gap = (ri + rj) * (1.0 - 0.025 * (1.0 + u()));
        c.pos.extend([
            [0.0; 3],
            [gap * dir[0] / len, gap * dir[1] / len, gap * dir[2] / len],
        ]);
        c.vel.extend([
            [0.5 * u(), 0.5 * u(), 0.5 * u()],
            [0.5 * u(), 0.5 * u(), 0.5 * u()],
        ]);
        c.omega.extend([
            [50.0 * u(), 50.0 * u(), 50.0 * u()],
            [50.0 * u(), 50.0 * u(), 50.0 * u()],
        ]);
        c.radius.extend([ri, rj]);
        c.mass
            .extend([2500.0 * 4.19 * ri * ri * ri, 2500.0 * 4.19 * rj * rj * rj]);
        c.temp.extend([20.0 + 10.0 * u(), 20.0 + 10.0 * u()]);
        c.history.push(ContactHistory {
            shear: [2e-4 * u(), 2e-4 * u(), 2e-4 * u()],
            roll: [6e-6 * u(), 6e-6 * u(), 6e-6 * u()],
        });
    }
    c
}

/// Every contact once through batches of `simd`; the advanced histories and the summed
/// responses' bits (so that nothing is optimised away and builds can be compared).
fn pass(simd: Simd, constants: &PairConstants, c: &Contacts, out: &mut [ContactHistory]) -> u64 {
    let spheres = SphereArrays {
        pos: &c.pos,
        vel: &c.vel,
        omega: &c.omega,
        radius: &c.radius,
        mass: &c.mass,
        temp: &c.temp,
    };
    let mut batch = PairBatch::with_simd(simd);
    let mut digest = 0u64;
    let mut evaluate = |batch: &mut PairBatch| {
        batch.evaluate(constants, &spheres, &c.history, out);
        for l in 0..batch.ready() {
            let (_, _, r) = batch.response(l);
            digest = digest.rotate_left(7) ^ r.force[0].to_bits() ^ r.heat_flow.to_bits();
        }
        batch.consume();
    };
    for p in 0..c.history.len() {
        let (a, b) = (c.pos[2 * p], c.pos[2 * p + 1]);
        let delta = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let r2 = delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2];
        if batch.push(2 * p, 2 * p + 1, p, delta, r2) {
            evaluate(&mut batch);
        }
    }
    evaluate(&mut batch);
    digest
}

fn main() {
    let count = env_usize("TDEX_CONTACTS", 4096);
    let repeat = env_usize("TDEX_REPEAT", 400);
    let c = contacts(count);
    let coefficients = PairCoefficients {
        restitution: 0.2,
        friction: 0.3,
        rolling_friction: 0.002,
    };
    let law = PairLaw::new(1e7, 0.3, &coefficients, RollingModel::Epsd2);
    let spec = ConductionSpec {
        contact_area: ContactArea::Overlap,
        youngs_modulus_real: Some(7e10),
    };
    let heat = ConductionLaw::new(&spec, 100.0, 100.0, 840.0, 1e7);
    let constants = PairConstants {
        law: &law,
        heat: &heat,
        dt: 1e-5,
        uniform_pair: None,
    };
    let builds: Vec<Simd> = Simd::available().collect();
    println!(
        "pair law (epsd2 rolling, lens area): {count} contacts × {repeat} passes, builds this CPU has"
    );
    let mut reference: Option<(u64, Vec<ContactHistory>)> = None;
    let mut best = vec![f64::INFINITY; builds.len()];
    for _round in 0..3 {
        for (b, &simd) in builds.iter().enumerate() {
            let mut out = vec![ContactHistory::default(); count];
            let start = Instant::now();
            let mut digest = 0;
            for _ in 0..repeat {
                digest = pass(simd, &constants, &c, &mut out);
            }
            let ns = start.elapsed().as_secs_f64() * 1e9 / (count * repeat) as f64;
            best[b] = best[b].min(ns);
            match &reference {
                None => reference = Some((digest, out)),
                Some((d, h)) => assert!(
                    *d == digest && *h == out,
                    "{simd:?} gives other bits than {:?}",
                    builds[0]
                ),
            }
        }
    }
    for (b, simd) in builds.iter().enumerate() {
        println!(
            "{:<8} {:>6.1} ns per contact (best of 3), {:.2}× the scalar build",
            simd.name(),
            best[b],
            best[0] / best[b]
        );
    }
}
