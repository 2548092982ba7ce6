//! Whole-drum invariants: heat conservation over a revolution, thread-count independence.

use crate::util::*;
use recorder::Simulation;

fn small_drum() -> recorder::Case {
    recorder::case::load(&repo().join("cases/small_drum.toml")).expect("small_drum.toml is valid")
}

#[test]
fn drum_heating_for_one_revolution_conserves_heat_and_mixes() {
    let case = small_drum();
    let mut sim = Simulation::new(&case).unwrap();
    let mut quiet = |_| {};
    sim.run(case.steps_in(case.time.settle), 1000, &mut quiet)
        .unwrap();
    sim.start_rotation();
    sim.run(case.steps_in(case.time.spin_up), 1000, &mut quiet)
        .unwrap();
    sim.assign_temperatures();
    let start = sim.heat_summary();
    assert_eq!(
        sim.groups.hot.iter().filter(|&&h| h).count(),
        case.particles.count / 2
    );
    assert_eq!(start.hot_mean, Some(30.0));
    assert_eq!(start.cold_mean, Some(10.0));
    // one revolution
    sim.run(case.steps_in(case.drum.rotation_period), 1000, &mut quiet)
        .unwrap();
    let end = sim.heat_summary();
    let drift = ((end.total_heat - start.total_heat) / start.total_heat).abs();
    eprintln!(
        "one revolution: heat drift {drift:.3e}, hot {:.4} K, cold {:.4} K, {:.2} contacts/particle",
        end.hot_mean.unwrap(),
        end.cold_mean.unwrap(),
        sim.contacts_per_particle()
    );
    assert!(drift < 1e-12, "sum m c T drifted by {drift:.3e}");
    let (hot, cold) = (end.hot_mean.unwrap(), end.cold_mean.unwrap());
    assert!(hot < 30.0 - 0.1, "hot group mean {hot}");
    assert!(cold > 10.0 + 0.1, "cold group mean {cold}");
    assert!(
        sim.contacts_per_particle() > 2.0,
        "a bed at rest in a turning drum is in contact"
    );
}

/// 1 000 steps of falling, then the drum turns and conducts for 1 000 more.
fn two_thousand_steps(threads: usize) -> Simulation {
    with_threads(threads, || {
        let case = small_drum();
        let mut sim = Simulation::new(&case).unwrap();
        sim.run(1000, 1000, &mut |_| {}).unwrap();
        sim.start_rotation();
        sim.assign_temperatures();
        sim.run(1000, 1000, &mut |_| {}).unwrap();
        sim
    })
}

fn bits(v: &[[f64; 3]]) -> Vec<[u64; 3]> {
    v.iter().map(|x| x.map(f64::to_bits)).collect()
}

#[test]
fn results_are_bit_identical_with_one_and_two_threads() {
    let (a, b) = (two_thousand_steps(1), two_thousand_steps(2));
    let (pa, pb) = (&a.particles, &b.particles);
    assert_eq!(pa.id, pb.id);
    assert_eq!(bits(&pa.pos), bits(&pb.pos));
    assert_eq!(bits(&pa.vel), bits(&pb.vel));
    assert_eq!(bits(&pa.omega), bits(&pb.omega));
    assert_eq!(bits(&pa.force), bits(&pb.force));
    let tb = |p: &recorder::particles::ParticleSet| {
        p.temp.iter().map(|t| t.to_bits()).collect::<Vec<_>>()
    };
    assert_eq!(tb(pa), tb(pb));
    let hist = |s: &Simulation| {
        s.neighbors
            .history
            .iter()
            .map(|h| bits(&[h.shear, h.roll]))
            .collect::<Vec<_>>()
    };
    assert_eq!(hist(&a), hist(&b));
    // the comparison means something: particles touched and heat moved
    assert!(a.contacts_per_particle() > 1.0);
    assert!(pa.temp.iter().any(|&t| t != 30.0 && t != 10.0));
}
