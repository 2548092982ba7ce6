//! Velocity Verlet for spheres (LIGGGHTS `fix nve/sphere`) and the explicit temperature update.

use crate::math::*;
use crate::particles::ParticleSet;
use rayon::prelude::*;

/// Moment of inertia of a solid sphere is `INERTIA · m R²`.
const INERTIA: f64 = 0.4;

/// First half kick and drift: `v += dt/2 (F/m + g)`, `x += dt v`, `ω += dt/2 T/I`.
pub fn initial_integrate(p: &mut ParticleSet, dt: f64, gravity: Vec3) {
    let half = 0.5 * dt;
    let ParticleSet {
        pos,
        vel,
        omega,
        force,
        torque,
        radius,
        mass,
        ..
    } = p;
    (pos, vel, omega)
        .into_par_iter()
        .zip((
            force.par_iter(),
            torque.par_iter(),
            radius.par_iter(),
            mass.par_iter(),
        ))
        .with_min_len(4096)
        .for_each(|((x, v, w), (f, t, r, m))| {
            *v = add(*v, scale(add(scale(*f, 1.0 / m), gravity), half));
            *x = add(*x, scale(*v, dt));
            *w = add(*w, scale(*t, half / (INERTIA * m * r * r)));
        });
}

/// Second half kick: `v += dt/2 (F/m + g)`, `ω += dt/2 T/I`.
pub fn final_integrate(p: &mut ParticleSet, dt: f64, gravity: Vec3) {
    let half = 0.5 * dt;
    let ParticleSet {
        vel,
        omega,
        force,
        torque,
        radius,
        mass,
        ..
    } = p;
    (vel, omega)
        .into_par_iter()
        .zip((
            force.par_iter(),
            torque.par_iter(),
            radius.par_iter(),
            mass.par_iter(),
        ))
        .with_min_len(4096)
        .for_each(|((v, w), (f, t, r, m))| {
            *v = add(*v, scale(add(scale(*f, 1.0 / m), gravity), half));
            *w = add(*w, scale(*t, half / (INERTIA * m * r * r)));
        });
}

/// Forward Euler on the heat flows of this step: `T += dt Q / (m c)`.
pub fn update_temperatures(p: &mut ParticleSet, dt: f64, heat_capacity: f64) {
    let ParticleSet {
        temp,
        heat_flow,
        mass,
        ..
    } = p;
    (temp, heat_flow.par_iter(), mass.par_iter())
        .into_par_iter()
        .with_min_len(4096)
        .for_each(|(t, q, m)| *t += dt * q / (m * heat_capacity));
}
