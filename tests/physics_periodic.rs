//! The seam of a periodic section: a contact across it, and a pair whose centres cross it
//! while they touch, behave as the same pair away from the seam (momentum, heat, and the
//! contact's tangential history kept).

use crate::util::*;
use recorder::particles::ParticleSet;

const RADIUS: f64 = 0.005;
/// Four diameters: the shortest section the case file allows is two.
const SECTION: f64 = 0.04;

/// Two spheres of 5 and 4 mm drifting together along the axis at 1 m/s and meeting
/// obliquely (their centres 0.5 mm apart along y, sliding past each other along z), one
/// at 30 K and one at 10 K; `y0` is the first sphere's axial position.
fn drifting_pair(y0: f64) -> ParticleSet {
    let mut p = ParticleSet::default();
    p.push(0, [-RADIUS - 1e-5, y0, 0.0], RADIUS, DENSITY, 30.0);
    p.push(
        1,
        [0.8 * RADIUS + 1e-5, y0 + 0.0005, 0.0],
        0.8 * RADIUS,
        DENSITY,
        10.0,
    );
    p.vel[0] = [0.3, 1.0, 0.05];
    p.vel[1] = [-0.3, 1.0, -0.05];
    p
}

/// What a run leaves: per id, velocity, angular velocity, temperature and y; the steps
/// the pair touched; the total momentum and heat.
struct Outcome {
    vel: [[f64; 3]; 2],
    omega: [[f64; 3]; 2],
    temp: [f64; 2],
    y: [f64; 2],
    touching_steps: u32,
    momentum: [f64; 3],
    heat: f64,
}

/// Steps the pair 4 000 times of 1 µs (4 mm of drift), rebuilding the neighbour list
/// every 50 steps so that the contact is carried over while it crosses the seam.
fn run(world: &mut World) -> Outcome {
    let mut touching_steps = 0;
    for step in 0..4000 {
        if step % 50 == 0 {
            world
                .neighbors
                .rebuild(&mut world.particles, &world.pipeline.grid, &world.walls);
        }
        touching_steps += u32::from(world.step().pair_entries > 0);
    }
    let p = &world.particles;
    let slot = |id: u32| p.id.iter().position(|&i| i == id).unwrap();
    let (a, b) = (slot(0), slot(1));
    let momentum = [0, 1, 2].map(|k| p.mass[a] * p.vel[a][k] + p.mass[b] * p.vel[b][k]);
    Outcome {
        vel: [p.vel[a], p.vel[b]],
        omega: [p.omega[a], p.omega[b]],
        temp: [p.temp[a], p.temp[b]],
        y: [p.pos[a][1], p.pos[b][1]],
        touching_steps,
        momentum,
        heat: HEAT_CAPACITY * (p.mass[a] * p.temp[a] + p.mass[b] * p.temp[b]),
    }
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-9 * scale
}

#[test]
fn a_pair_crossing_the_seam_while_touching_keeps_its_contact_and_conserves_momentum_and_heat() {
    let dt = 1e-6;
    // away from the seam: the same pair in the middle of the section
    let mut away = World::new(drifting_pair(-0.0004), no_walls(), 0.5, dt, 0.0).periodic(SECTION);
    let reference = run(&mut away);
    assert!(
        reference.touching_steps > 500,
        "the pair must touch for a good part of the run: {} steps",
        reference.touching_steps
    );
    // no seam crossed, no image taken: the periodic section computes what a closed drum does
    let mut closed = World::new(drifting_pair(-0.0004), no_walls(), 0.5, dt, 0.0);
    let plain = run(&mut closed);
    assert_eq!(plain.vel, reference.vel);
    assert_eq!(plain.temp, reference.temp);

    // at the seam: the second sphere crosses it after 0.5 mm and the first after 1 mm,
    // while they touch (from about step 60 to step 1 000)
    let at_seam = 0.5 * SECTION - 0.001;
    let mut seam = World::new(drifting_pair(at_seam), no_walls(), 0.5, dt, 0.0).periodic(SECTION);
    let start = seam.particles.clone();
    let crossed = run(&mut seam);
    for s in 0..2 {
        assert!(
            crossed.y[s] < 0.0 && start.pos[s][1] > 0.0,
            "sphere {s} crossed the seam (y {} → {})",
            start.pos[s][1],
            crossed.y[s]
        );
    }
    assert_eq!(crossed.touching_steps, reference.touching_steps);
    let speed = 1.0;
    for s in 0..2 {
        for k in 0..3 {
            assert!(
                close(crossed.vel[s][k], reference.vel[s][k], speed),
                "velocity {s}.{k}: {} across the seam, {} away from it",
                crossed.vel[s][k],
                reference.vel[s][k]
            );
            assert!(
                close(crossed.omega[s][k], reference.omega[s][k], 100.0),
                "angular velocity {s}.{k}: {} vs {}",
                crossed.omega[s][k],
                reference.omega[s][k]
            );
        }
        assert!(
            close(crossed.temp[s], reference.temp[s], 30.0),
            "temperature {s}: {} vs {}",
            crossed.temp[s],
            reference.temp[s]
        );
    }
    // heat went from the hot sphere to the cold one, and none was made or lost
    assert!(crossed.temp[1] > 10.0 + 1e-6, "{}", crossed.temp[1]);
    let mass_scale = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let heat0 = HEAT_CAPACITY * (start.mass[0] * 30.0 + start.mass[1] * 10.0);
    assert!(((crossed.heat - heat0) / heat0).abs() < 1e-12);
    let momentum0 =
        [0, 1, 2].map(|k| start.mass[0] * start.vel[0][k] + start.mass[1] * start.vel[1][k]);
    for (k, (after, before)) in crossed.momentum.iter().zip(momentum0).enumerate() {
        assert!(
            (after - before).abs() < 1e-12 * mass_scale,
            "momentum {k}: {before} → {after}"
        );
    }
}
