//! Contact kinematics of two spheres (LIGGGHTS `surface_model_default`).

use super::hertz_mindlin::ContactKinematics;
use crate::math::*;

/// One side of a sphere–sphere pair.
#[derive(Debug, Clone, Copy)]
pub struct SphereState {
    pub pos: Vec3,
    pub vel: Vec3,
    pub omega: Vec3,
    pub radius: f64,
    pub mass: f64,
}

/// Kinematics of `i` against `j` and their centre distance, or `None` if they do not touch.
#[inline(always)]
pub fn kinematics(i: &SphereState, j: &SphereState) -> Option<(ContactKinematics, f64)> {
    let delta = sub(i.pos, j.pos);
    let r2 = norm2(delta);
    let radsum = i.radius + j.radius;
    if r2 >= radsum * radsum {
        return None;
    }
    let r = r2.sqrt();
    let overlap = radsum - r;
    let normal = scale(delta, 1.0 / r);
    let lever_i = i.radius - 0.5 * overlap;
    let lever_j = j.radius - 0.5 * overlap;
    Some((
        ContactKinematics {
            overlap,
            normal,
            rel_vel: sub(i.vel, j.vel),
            lever_omega: add(scale(i.omega, lever_i), scale(j.omega, lever_j)),
            roll_omega: sub(i.omega, j.omega),
            lever_i,
            r_eff: i.radius * j.radius / radsum,
            m_eff: i.mass * j.mass / (i.mass + j.mass),
        },
        r,
    ))
}
