//! Whole-drum invariants: heat conservation over a revolution, thread-count independence.

use crate::util::*;
use recorder::Simulation;

fn small_drum() -> recorder::Case {
    recorder::case::load(&repo().join("cases/small_drum.toml")).expect("small_drum.toml is valid")
}

/// The small drum settled, then turning for `spin_steps` (temperatures assigned at the start
/// of the turning when `heated`).
fn turning_small_drum(spin_steps: u64, heated: bool) -> Simulation {
    let case = small_drum();
    let mut sim = Simulation::new(&case).unwrap();
    let mut quiet = |_| {};
    sim.run(case.steps_in(case.time.settle), 1000, &mut quiet)
        .unwrap();
    sim.start_rotation();
    if heated {
        sim.assign_temperatures();
    }
    sim.run(spin_steps, 1000, &mut quiet).unwrap();
    sim
}

#[test]
fn drum_heating_for_one_revolution_conserves_heat_and_mixes() {
    let case = small_drum();
    let mut sim = turning_small_drum(case.steps_in(case.time.spin_up), false);
    let mut quiet = |_| {};
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
            .histories_by_entry()
            .iter()
            .map(|h| bits(&[h.shear, h.roll]))
            .collect::<Vec<_>>()
    };
    assert_eq!(hist(&a), hist(&b));
    // the comparison means something: particles touched and heat moved
    assert!(a.contacts_per_particle() > 1.0);
    assert!(pa.temp.iter().any(|&t| t != 30.0 && t != 10.0));
}

/// The pair stage evaluates each pair once and hands `j` the opposite force, its own
/// lever-arm torque and the opposite heat flow. Checked against the definition: every
/// particle evaluates the law from its own side over all its touching partners (what a
/// full-list engine does), with histories taken from the list (reversed for the partner).
#[test]
fn each_pair_once_equals_each_particle_summing_its_own_contacts() {
    use recorder::contact::contact_sphere_sphere::{self as ss, SphereState};
    use recorder::contact::{contact_sphere_wall as sw, hertz_mindlin};
    use recorder::math::*;
    use recorder::pipeline::contact_interactions;

    let before = turning_small_drum(2000, true);
    let (p, list, params) = (&before.particles, &before.neighbors, &before.params);
    let n = p.len();
    let state = |i: usize| SphereState {
        pos: p.pos[i],
        vel: p.vel[i],
        omega: p.omega[i],
        radius: p.radius[i],
        mass: p.mass[i],
    };
    let (mut force, mut torque, mut heat) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n], vec![0.0; n]);
    let mut from_side = |i: usize, j: usize, history: recorder::contact::ContactHistory| {
        let delta = sub(p.pos[i], p.pos[j]);
        let Some(r2) = ss::overlapping(delta, p.radius[i], p.radius[j]) else {
            return;
        };
        let eff = ss::effective(p.radius[i], p.radius[j], p.mass[i], p.mass[j]);
        let c = ss::kinematics(&state(i), &state(j), delta, r2, eff);
        let mut h = history;
        let resp =
            hertz_mindlin::respond(&params.particle_particle, &c.kinematics, &mut h, params.dt);
        force[i] = add(force[i], resp.force);
        torque[i] = add(torque[i], resp.torque_on_i(c.lever_i));
        let conductance = params
            .conduction
            .pair_conductance(c.distance, p.radius[i], p.radius[j]);
        heat[i] += conductance * (p.temp[j] - p.temp[i]);
    };
    let mut pairs = 0;
    let history = list.histories_by_entry();
    for i in 0..n {
        for e in list.range(i) {
            let j = list.neighbors[e] as usize;
            from_side(i, j, history[e]);
            from_side(j, i, history[e].reversed());
            pairs += list.touching[e] as usize;
        }
    }
    let mut wall_contacts = 0;
    for i in 0..n {
        for e in list.wall_range(i) {
            let w = list.wall_index[e] as usize;
            if let Some(c) = before.walls.contact(w, p.pos[i], p.radius[i]) {
                wall_contacts += 1;
                let (kin, lever) = sw::kinematics(&state(i), &c);
                let mut h = list.wall_history[e];
                let resp = hertz_mindlin::respond(&params.particle_wall, &kin, &mut h, params.dt);
                force[i] = add(force[i], resp.force);
                torque[i] = add(torque[i], resp.torque_on_i(lever));
            }
        }
    }
    assert!(
        pairs > n,
        "the bed should be in contact: {pairs} touching pairs"
    );

    assert!(wall_contacts > 0, "the bed should touch the drum");
    let mut after = before.clone();
    let count = contact_interactions(
        &after.params,
        &mut after.particles,
        &mut after.neighbors,
        &after.walls,
    );
    assert_eq!(count.pair_entries, 2 * pairs as u64);
    assert_eq!(count.wall, wall_contacts);
    let scale_f = force.iter().map(|f| norm2(*f).sqrt()).fold(0.0, f64::max);
    let scale_t = torque.iter().map(|t| norm2(*t).sqrt()).fold(0.0, f64::max);
    let scale_q = heat.iter().map(|q| q.abs()).fold(0.0, f64::max);
    for i in 0..n {
        let q = &after.particles;
        let df = norm2(sub(q.force[i], force[i])).sqrt() / scale_f;
        let dt = norm2(sub(q.torque[i], torque[i])).sqrt() / scale_t;
        let dq = (q.heat_flow[i] - heat[i]).abs() / scale_q;
        assert!(
            df < 1e-12 && dt < 1e-12 && dq < 1e-12,
            "slot {i}: force {:?} vs {:?}, torque {:?} vs {:?}, heat {} vs {}",
            q.force[i],
            force[i],
            q.torque[i],
            torque[i],
            q.heat_flow[i],
            heat[i]
        );
    }
}

/// The contact stage takes the layers chunk by chunk (even tasks, then the odd ones whose
/// even neighbours are done, each layer's wall contacts with the task that writes it last),
/// and past the cache size each task prefetches the next one's data; the chunk size and the
/// prefetching change the schedule, not a bit of the results.
#[test]
fn the_contact_stage_gives_the_same_bits_whatever_its_chunks_and_prefetching() {
    use recorder::contact::ContactHistory;
    use recorder::pipeline::contact_interactions_in_chunks;

    let before = turning_small_drum(2000, true);
    let layers = before.neighbors.layer_start.len() - 1;
    assert!(layers >= 8, "{layers} layers: too few for several chunks");
    let stage = |chunk: u32, prefetch_above: usize| {
        let mut after = before.clone();
        let count = contact_interactions_in_chunks(
            &after.params,
            &mut after.particles,
            &mut after.neighbors,
            &after.walls,
            chunk,
            prefetch_above,
        );
        let p = &after.particles;
        let bits = |v: &[[f64; 3]]| v.iter().map(|x| x.map(f64::to_bits)).collect::<Vec<_>>();
        let spring_bits = |histories: &[ContactHistory]| {
            histories
                .iter()
                .map(|h| (h.shear.map(f64::to_bits), h.roll.map(f64::to_bits)))
                .collect::<Vec<_>>()
        };
        let springs = spring_bits(&after.neighbors.histories_by_entry());
        let heat = p.heat_flow.iter().map(|q| q.to_bits()).collect::<Vec<_>>();
        let touching = after.neighbors.touching.clone();
        let wall_springs = spring_bits(&after.neighbors.wall_history);
        let wall_touching = after.neighbors.wall_touching.clone();
        (
            (count.pair_entries, count.wall),
            (bits(&p.force), bits(&p.torque), heat),
            (springs, touching),
            (wall_springs, wall_touching),
        )
    };
    // one chunk for the whole drum, about two layers per chunk, and one in between
    let whole = stage(u32::MAX, usize::MAX);
    let (pair_entries, wall) = whole.0;
    assert!(
        pair_entries > 2000 && wall > 0,
        "the bed should be in contact: {pair_entries} entries and {wall} wall candidates touch"
    );
    for (chunk, prefetch_above) in [(1, usize::MAX), (300, 0), (900, usize::MAX), (900, 0)] {
        assert!(
            stage(chunk, prefetch_above) == whole,
            "chunks of {chunk} particles, prefetching above {prefetch_above} bytes, changed \
             the contact stage"
        );
    }
}

/// A rebuild re-sorts the particles and rebuilds the lists; every open contact keeps its
/// springs, seen from whichever particle now owns the entry.
#[test]
fn a_rebuild_keeps_every_open_contact_history() {
    use recorder::contact::ContactHistory;
    use std::collections::BTreeMap;

    let sim = turning_small_drum(3000, false);
    // (smaller id, larger id or particles + wall) → springs seen from the smaller id
    let open = |sim: &Simulation| {
        let (p, list) = (&sim.particles, &sim.neighbors);
        let mut map: BTreeMap<(u32, u32), ContactHistory> = BTreeMap::new();
        list.for_each_touching(|i, e, &h| {
            let (a, b) = (p.id[i], p.id[list.neighbors[e] as usize]);
            let key = (a.min(b), a.max(b));
            map.insert(key, if a < b { h } else { h.reversed() });
        });
        for i in 0..p.len() {
            for e in list.wall_range(i).filter(|&e| list.wall_touching[e]) {
                let w = p.len() as u32 + list.wall_index[e] as u32;
                map.insert((p.id[i], w), list.wall_history[e]);
            }
        }
        map
    };
    let before = open(&sim);
    assert!(
        before.len() > sim.particles.len(),
        "{} open contacts",
        before.len()
    );
    assert!(before.values().any(|h| h.shear != [0.0; 3]));
    let mut rebuilt = sim.clone();
    let (grid, walls) = (rebuilt.pipeline.grid.clone(), rebuilt.walls.clone());
    rebuilt
        .neighbors
        .rebuild(&mut rebuilt.particles, &grid, &walls);
    assert_ne!(
        rebuilt.particles.id, sim.particles.id,
        "the re-sort moved particles"
    );
    assert_eq!(open(&rebuilt), before);
}

/// A DEM twin is a clone of the run at `t1` with one change, the drum's angular velocity:
/// the clone alone must step to the same bits as the run it was cloned from, or the twins
/// would part from the DEM for a reason other than the perturbation.
#[test]
fn a_cloned_simulation_steps_to_the_same_bits_and_a_twin_does_not() {
    let mut sim = turning_small_drum(500, true);
    let (mut clone, mut twin) = (sim.clone(), recorder::record::twin_of(&sim, 1));
    for _ in 0..1500 {
        sim.step();
        clone.step();
        twin.step();
    }
    assert!(
        bits(&sim.particles.pos) == bits(&clone.particles.pos),
        "the clone parted"
    );
    assert_eq!(sim.particles.temp, clone.particles.temp);
    assert!(
        bits(&sim.particles.pos) != bits(&twin.particles.pos),
        "the twin did not part"
    );
}
