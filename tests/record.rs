//! The sampled collision table against the DEM's own contact list.

use crate::util::*;
use recorder::record::ContactSampler;
use recorder::Simulation;

#[test]
fn with_n_1_the_table_holds_exactly_the_dem_contact_time() {
    with_threads(2, || {
        let case = recorder::case::load(&repo().join("cases/small_drum.toml")).unwrap();
        let mut sim = Simulation::new(&case).unwrap();
        sim.run(case.steps_in(case.time.settle), 1000, &mut |_| {})
            .unwrap();
        sim.start_rotation();
        sim.run(case.steps_in(case.time.spin_up), 1000, &mut |_| {})
            .unwrap();
        sim.assign_temperatures();
        // a quarter revolution recorded with n = 1, Δt_c^max = 100 steps
        let period = case.steps_in(0.25 * case.drum.rotation_period);
        let mut sampler = ContactSampler::new(1, 100).unwrap();
        let (mut rows, mut dem_pair_steps) = (Vec::new(), 0u64);
        for k in 0..period {
            // the contact list of DEM step k (t0 + k dt → t0 + (k+1) dt), as the recorder samples it
            sim.step();
            let pairs: Vec<_> = sim.touching_pairs().collect();
            assert_eq!(2 * pairs.len() as u64, sim.last_contacts.pair_entries);
            dem_pair_steps += pairs.len() as u64;
            sampler.sample(k, pairs);
            rows.extend(sampler.drain_ready());
        }
        rows.extend(sampler.finish());
        let table_steps: u64 = rows.iter().map(|r| r.duration_steps as u64).sum();
        assert_eq!(
            table_steps, dem_pair_steps,
            "table and DEM contact time differ"
        );
        assert!(
            rows.windows(2).all(|w| w[0].start_step <= w[1].start_step),
            "rows out of apparition order"
        );
        assert!(rows
            .iter()
            .all(|r| r.duration_steps <= 100 && r.i < r.j && r.sqrt_area > 0.0));
        assert!(
            rows.len() > 1000,
            "a turning bed has many collisions: {}",
            rows.len()
        );
        eprintln!(
            "n = 1 over {period} steps: {} rows, {table_steps} pair-steps in both table and DEM; {} contacts open at the end",
            rows.len(),
            sampler.open_contacts()
        );
    })
}
