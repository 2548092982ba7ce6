//! Hertz contact checks: head-on collision time and restitution, static overlap on a wall.

use crate::util::*;
use recorder::contact::PairLaw;
use recorder::particles::ParticleSet;
use recorder::wall::{Wall, WallMotion, WallSet};

const RADIUS: f64 = 0.005;

/// Contact duration of the damped Hertz oscillator `m* δ'' = −kn δ − γn δ'` integrated by RK4
/// with 200 000 steps per contact time: the theory the DEM run must reproduce.
fn theory_duration(law: &PairLaw, r_eff: f64, m_eff: f64, v0: f64) -> f64 {
    let accel = |d: f64, v: f64| {
        let s = (r_eff * d.max(0.0)).sqrt();
        let kn = 4.0 / 3.0 * law.e_star * s;
        let gn = law.damping_factor * (2.0 * law.e_star * s * m_eff).sqrt();
        -(kn * d + gn * v) / m_eff
    };
    let t_elastic = elastic_duration(law, r_eff, m_eff, v0);
    let h = t_elastic / 200_000.0;
    let (mut d, mut v, mut t) = (0.0f64, v0, 0.0);
    loop {
        let (k1d, k1v) = (v, accel(d, v));
        let (k2d, k2v) = (
            v + 0.5 * h * k1v,
            accel(d + 0.5 * h * k1d, v + 0.5 * h * k1v),
        );
        let (k3d, k3v) = (
            v + 0.5 * h * k2v,
            accel(d + 0.5 * h * k2d, v + 0.5 * h * k2v),
        );
        let (k4d, k4v) = (v + h * k3v, accel(d + h * k3d, v + h * k3v));
        let d_next = d + h / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
        let v_next = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if d_next <= 0.0 {
            // linear interpolation of the zero crossing
            return t + h * d / (d - d_next);
        }
        (d, v, t) = (d_next, v_next, t + h);
    }
}

/// Closed-form elastic Hertz duration `2.9432 δmax / v0`, `δmax = (15 m* v0² / (16 E* sqrt R*))^(2/5)`.
fn elastic_duration(law: &PairLaw, r_eff: f64, m_eff: f64, v0: f64) -> f64 {
    let d_max = (15.0 * m_eff * v0 * v0 / (16.0 * law.e_star * r_eff.sqrt())).powf(0.4);
    2.9432 * d_max / v0
}

/// Two equal spheres approaching head-on at relative speed `v0`: (duration, restitution, theory).
fn collide(restitution: f64, v0: f64) -> (f64, f64, f64) {
    let (duration, e, theory, _) = collide_spheres(restitution, v0, RADIUS, RADIUS);
    (duration, e, theory)
}

/// Spheres of radii `ri`, `rj` approaching head-on at relative speed `v0`, their centre of
/// mass at rest: (duration, restitution, theory with R* and m*, total momentum after).
fn collide_spheres(restitution: f64, v0: f64, ri: f64, rj: f64) -> (f64, f64, f64, f64) {
    let mut p = ParticleSet::default();
    p.push(0, [-ri - 1e-4, 0.0, 0.0], ri, DENSITY, 300.0);
    p.push(1, [rj + 1e-4, 0.0, 0.0], rj, DENSITY, 300.0);
    let (mi, mj) = (p.mass[0], p.mass[1]);
    p.vel[0] = [v0 * mj / (mi + mj), 0.0, 0.0];
    p.vel[1] = [-v0 * mi / (mi + mj), 0.0, 0.0];
    let law_probe = World::new(p.clone(), no_walls(), restitution, 1.0, 0.0)
        .params
        .particle_particle;
    let theory = theory_duration(&law_probe, ri * rj / (ri + rj), mi * mj / (mi + mj), v0);
    let dt = theory / 2000.0;
    let mut world = World::new(p, no_walls(), restitution, dt, 0.0);
    let (mut first, mut last) = (None, 0u64);
    for step in 1..=20_000u64 {
        let touching = world.step().pair_entries > 0;
        if touching {
            first.get_or_insert(step);
            last = step;
        } else if first.is_some() {
            break;
        }
    }
    let first = first.expect("the spheres collide");
    let duration = (last - first + 1) as f64 * dt;
    let slot0 = world.particles.id.iter().position(|&id| id == 0).unwrap();
    let slot1 = 1 - slot0;
    let v_rel_after = world.particles.vel[slot1][0] - world.particles.vel[slot0][0];
    let momentum = world.particles.mass[slot0] * world.particles.vel[slot0][0]
        + world.particles.mass[slot1] * world.particles.vel[slot1][0];
    (duration, v_rel_after / v0, theory, momentum)
}

#[test]
fn unequal_spheres_collide_as_hertz_with_the_effective_radius_and_mass() {
    // a sphere of 5 mm against one of 2.5 mm (an eighth of its mass)
    for e in [0.2, 0.9] {
        let (duration, e_measured, theory, momentum) =
            collide_spheres(e, 0.5, RADIUS, 0.5 * RADIUS);
        eprintln!(
            "unequal, e = {e}: duration {duration:.5e} s, theory {theory:.5e} s ({:+.3} %), restitution {e_measured:.5}",
            100.0 * (duration / theory - 1.0)
        );
        assert!(
            (duration - theory).abs() / theory < 0.02,
            "e = {e}: duration {duration:.6e} s vs theory {theory:.6e} s"
        );
        assert!((e_measured - e).abs() / e < 0.02, "e = {e}: {e_measured}");
        // momentum started at zero: what one sphere gains the other loses
        let scale = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3) * 0.5;
        assert!(momentum.abs() < 1e-12 * scale, "momentum {momentum:e}");
    }
}

#[test]
fn head_on_collision_matches_hertz_duration_and_restitution() {
    for e in [0.2, 0.5, 0.9] {
        let (duration, e_measured, theory) = collide(e, 0.5);
        let dur_err = (duration - theory).abs() / theory;
        let e_err = (e_measured - e).abs() / e;
        eprintln!(
            "e = {e}: duration {duration:.5e} s, theory {theory:.5e} s ({:+.3} %), restitution {e_measured:.5} ({:+.3} %)",
            100.0 * (duration / theory - 1.0),
            100.0 * (e_measured / e - 1.0)
        );
        assert!(
            dur_err < 0.02,
            "e = {e}: duration {duration:.6e} s vs theory {theory:.6e} s ({:.3} %)",
            100.0 * dur_err
        );
        assert!(
            e_err < 0.02,
            "e = {e}: restitution {e_measured:.5} ({:.3} %)",
            100.0 * e_err
        );
    }
}

#[test]
fn elastic_collision_matches_closed_form_hertz_time() {
    // e = 1: no damping, the duration is the classical Hertz time
    let (duration, e_measured, theory) = collide(1.0, 0.5);
    let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3);
    let law = World::new(ParticleSet::default(), no_walls(), 1.0, 1.0, 0.0)
        .params
        .particle_particle;
    let closed = elastic_duration(&law, 0.5 * RADIUS, 0.5 * mass, 0.5);
    assert!(
        (theory - closed).abs() / closed < 1e-4,
        "RK4 {theory} vs closed form {closed}"
    );
    eprintln!("elastic: duration {duration:.5e} s, closed form {closed:.5e} s, restitution {e_measured:.5}");
    assert!(
        (duration - closed).abs() / closed < 0.02,
        "{duration} vs {closed}"
    );
    assert!((e_measured - 1.0).abs() < 0.02, "{e_measured}");
}

#[test]
fn sphere_resting_on_a_flat_wall_has_the_hertz_static_overlap() {
    let mut p = ParticleSet::default();
    p.push(0, [0.0, 0.0, RADIUS], RADIUS, DENSITY, 300.0);
    let walls = WallSet {
        walls: vec![(
            Wall::Plane {
                point: [0.0; 3],
                normal: [0.0, 0.0, 1.0],
            },
            WallMotion::Fixed,
        )],
        angular_velocity: 0.0,
        mantle_temperature: None,
    };
    let g = 9.81;
    let mut world = World::new(p, walls, 0.2, 1e-5, g);
    for _ in 0..50_000 {
        world.step();
    }
    let overlap = RADIUS - world.particles.pos[0][2];
    // m g = 4/3 E* sqrt(R) δ^(3/2), wall of the same material: 1/E* = 2(1 − ν²)/E
    let e_star = YOUNG / (2.0 * (1.0 - POISSON * POISSON));
    let mass = world.particles.mass[0];
    let theory = (3.0 * mass * g / (4.0 * e_star * RADIUS.sqrt())).powf(2.0 / 3.0);
    let err = (overlap - theory).abs() / theory;
    eprintln!(
        "static overlap {overlap:.6e} m, Hertz {theory:.6e} m ({:+.4} %)",
        100.0 * (overlap / theory - 1.0)
    );
    assert!(
        err < 0.01,
        "overlap {overlap:.6e} m vs Hertz {theory:.6e} m ({:.3} %)",
        100.0 * err
    );
    assert!(
        world.particles.vel[0][2].abs() < 1e-6,
        "still moving: {:?}",
        world.particles.vel[0]
    );
}
