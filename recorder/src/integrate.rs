//! Velocity Verlet for spheres (LIGGGHTS `fix nve/sphere`) and the explicit temperature update.

use crate::math::*;
use crate::particles::ParticleSet;
use crate::periodic::{nearest_image, AxialPeriod};
use rayon::prelude::*;

/// Moment of inertia of a solid sphere is `INERTIA · m R²`.
const INERTIA: f64 = 0.4;
/// Particles per parallel task: enough work to pay for the dispatch.
const MIN_TASK: usize = 4096;

/// First half kick and drift: `v += dt/2 (F/m + g)`, `x += dt v`, `ω += dt/2 T/I`; in a
/// periodic drum a sphere that crossed an end face is moved to the other. Returns
/// whether a particle now lies farther than `limit` from its place in `reference` (or the
/// reference is missing): the Verlet list's rebuild test, done in the same pass.
pub fn initial_integrate(
    p: &mut ParticleSet,
    dt: f64,
    gravity: Vec3,
    reference: &[Vec3],
    limit: f64,
    period: Option<AxialPeriod>,
) -> bool {
    let half = 0.5 * dt;
    let n = p.len();
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
    let kick = |(x, v, w): (&mut Vec3, &mut Vec3, &mut Vec3),
                (f, t, r, m): (&Vec3, &Vec3, &f64, &f64)| {
        *v = add(*v, scale(add(scale(*f, 1.0 / m), gravity), half));
        *x = add(*x, scale(*v, dt));
        if let Some(period) = period {
            x[1] = period.wrap(x[1]);
        }
        *w = add(*w, scale(*t, half / (INERTIA * m * r * r)));
    };
    let kicked = (pos, vel, omega).into_par_iter().zip((
        force.par_iter(),
        torque.par_iter(),
        radius.par_iter(),
        mass.par_iter(),
    ));
    if reference.len() != n {
        kicked.with_min_len(MIN_TASK).for_each(|(a, b)| kick(a, b));
        return true;
    }
    let limit2 = limit * limit;
    kicked
        .zip(reference.par_iter())
        .with_min_len(MIN_TASK)
        .map(|((a, b), x0)| {
            kick((&mut *a.0, a.1, a.2), b);
            // a NaN displacement also forces a rebuild (and the out-of-drum check then reports it)
            // across the seam the displacement is the short way round
            let d2 = norm2(nearest_image(sub(*a.0, *x0), period));
            d2.is_nan() || d2 > limit2
        })
        .reduce(|| false, |a, b| a || b)
}

/// Second half kick `v += dt/2 (F/m + g)`, `ω += dt/2 T/I`, and forward Euler on the heat
/// flows of this step, `T += dt Q / (m c)`.
pub fn final_integrate(p: &mut ParticleSet, dt: f64, gravity: Vec3, heat_capacity: f64) {
    let half = 0.5 * dt;
    let ParticleSet {
        vel,
        omega,
        force,
        torque,
        radius,
        mass,
        temp,
        heat_flow,
        ..
    } = p;
    (vel, omega, temp)
        .into_par_iter()
        .zip((
            force.par_iter(),
            torque.par_iter(),
            radius.par_iter(),
            mass.par_iter(),
            heat_flow.par_iter(),
        ))
        .with_min_len(MIN_TASK)
        .for_each(|((v, w, temp), (f, t, r, m, q))| {
            *v = add(*v, scale(add(scale(*f, 1.0 / m), gravity), half));
            *w = add(*w, scale(*t, half / (INERTIA * m * r * r)));
            *temp += dt * q / (m * heat_capacity);
        });
}

/// Forward Euler on the heat flows alone (tests of conduction without motion).
pub fn update_temperatures(p: &mut ParticleSet, dt: f64, heat_capacity: f64) {
    let ParticleSet {
        temp,
        heat_flow,
        mass,
        ..
    } = p;
    (temp, heat_flow.par_iter(), mass.par_iter())
        .into_par_iter()
        .with_min_len(MIN_TASK)
        .for_each(|(t, q, m)| *t += dt * q / (m * heat_capacity));
}
