//! Two spheres held at a fixed overlap relax towards each other's temperature exponentially.

use crate::util::*;
use recorder::integrate::update_temperatures;
use recorder::particles::ParticleSet;
use recorder::pipeline::contact_interactions;

#[test]
fn pair_temperature_difference_decays_exponentially() {
    let (ri, rj) = (0.005, 0.004);
    let r = ri + rj - 2e-4; // centre distance: 0.2 mm overlap
    let mut p = ParticleSet::default();
    p.push(0, [0.0, 0.0, 0.0], ri, DENSITY, 30.0);
    p.push(1, [r, 0.0, 0.0], rj, DENSITY, 10.0);
    let (ci, cj) = (p.mass[0] * HEAT_CAPACITY, p.mass[1] * HEAT_CAPACITY);
    // independent of the engine: the four-factor lens area and 2K sqrt(A)
    let area =
        -std::f64::consts::PI / 4.0 * (r - ri - rj) * (r + ri - rj) * (r - ri + rj) * (r + ri + rj)
            / (r * r);
    let h = 2.0 * CONDUCTIVITY * area.sqrt();
    let rate = h * (1.0 / ci + 1.0 / cj);
    // explicit Euler is (1 − c)^n against e^(−cn): 5 time constants cost 5c/2 relative
    let dt = 2e-7 / rate;
    let steps_per_tau = (1.0 / (rate * dt)).round() as u64;
    let mut world = World::new(p, no_walls(), 0.5, dt, 0.0);
    world
        .neighbors
        .rebuild(&mut world.particles, &world.pipeline.grid, &world.walls);
    let (a, b) = if world.particles.id[0] == 0 {
        (0, 1)
    } else {
        (1, 0)
    };
    let dt0 = 20.0;
    let mut worst: f64 = 0.0;
    with_threads(1, || {
        for step in 1..=5 * steps_per_tau {
            let touching = contact_interactions(
                &world.params,
                &mut world.particles,
                &mut world.neighbors,
                &world.walls,
            );
            assert_eq!(touching.pair_entries, 2);
            update_temperatures(&mut world.particles, dt, HEAT_CAPACITY);
            if step % (steps_per_tau / 10) == 0 {
                let t = step as f64 * dt;
                let diff = world.particles.temp[a] - world.particles.temp[b];
                let theory = dt0 * (-h * t * (1.0 / ci + 1.0 / cj)).exp();
                worst = worst.max((diff / theory - 1.0).abs());
            }
        }
    });
    eprintln!("conduction pair: largest relative deviation over 5 time constants {worst:.3e}");
    assert!(
        worst < 1e-6,
        "largest relative deviation from exp(-H t (1/Ci + 1/Cj)): {worst:.3e}"
    );
    // heat is exchanged, not created
    let total = ci * world.particles.temp[a] + cj * world.particles.temp[b];
    let start = ci * 30.0 + cj * 10.0;
    assert!(((total - start) / start).abs() < 1e-12);
}

#[test]
fn sphere_on_a_heated_mantle_relaxes_towards_the_wall_temperature() {
    use recorder::wall::{WallMotion, WallSet};
    let radius = 0.005;
    let mut p = ParticleSet::default();
    p.push(0, [0.0, 0.0, -0.05 + radius], radius, DENSITY, 300.0);
    let walls = WallSet::drum(0.05, 0.04, WallMotion::Fixed);
    let dt = 1e-5;
    let mut world = World::new(p, walls, 0.2, dt, 9.81);
    with_threads(1, || {
        for _ in 0..50_000 {
            world.step(); // settle on the adiabatic mantle
        }
        assert_eq!(world.particles.temp[0], 300.0);
        let (tw, t0) = (400.0, 300.0);
        world.walls.mantle_temperature = Some(tw);
        // independent of the engine: the disc where the sphere cuts the wall, H = 2K sqrt(A)
        let [x, _, z] = world.particles.pos[0];
        let overlap = (x * x + z * z).sqrt() + radius - 0.05;
        let area = std::f64::consts::PI * (radius * radius - (radius - overlap).powi(2));
        let h = 2.0 * CONDUCTIVITY * area.sqrt();
        let c = world.particles.mass[0] * HEAT_CAPACITY;
        let steps = 100_000;
        for _ in 0..steps {
            world.step();
        }
        let t = steps as f64 * dt;
        let measured = (tw - world.particles.temp[0]) / (tw - t0);
        let theory = (-h * t / c).exp();
        eprintln!(
            "heated mantle: (Tw − T)/(Tw − T0) = {measured:.9} vs exp(−H t / C) = {theory:.9}"
        );
        assert!(
            (measured / theory - 1.0).abs() < 1e-6,
            "{measured} vs {theory}"
        );
        assert!(
            measured < 0.99,
            "the wall must heat the sphere noticeably: {measured}"
        );
    });
}
