//! The batched pair law alone, in each build this CPU can run (`recorder::simd`): nanoseconds
//! per contact for the same random contacts (unequal spheres, sliding and sticking, capped and
//! free rolling springs), and a check that every build gives them the same bits.
//!
//! Run: `cargo bench -p recorder --bench pair_law` (`TDEX_CONTACTS`, default 4096 contacts;
//! `TDEX_REPEAT`, default 400 passes over them; each build timed in turn, three rounds).

use recorder::case::{ContactArea, RollingModel};
use recorder::contact::pair_batch::{PairBatch, PairConstants};
use recorder::contact::pair_sample::{sample_heat, sample_law, PairSample};
use recorder::contact::ContactHistory;
use recorder::simd::Simd;
use std::time::Instant;

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Every contact once through batches of `simd`; the advanced histories and the summed
/// responses' bits (so that nothing is optimised away and builds can be compared).
fn pass(simd: Simd, constants: &PairConstants, c: &PairSample, out: &mut [ContactHistory]) -> u64 {
    let spheres = c.spheres();
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
    // the unit test's sample and constants (`recorder::contact::pair_sample`)
    let c = PairSample::random(3, count);
    let law = sample_law(RollingModel::Epsd2);
    let heat = sample_heat(ContactArea::Overlap);
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
