//! Contact kinematics of a sphere against an analytic wall (drum mantle or end cap).

use super::contact_sphere_sphere::SphereState;
use super::hertz_mindlin::ContactKinematics;
use crate::math::*;
use crate::wall::WallContact;

/// Kinematics of sphere `i` against a wall contact found by the wall geometry. As in
/// LIGGGHTS a wall has R* = R_i and m* = m_i, and its angular velocity does not enter the
/// slip or rolling terms (only its surface velocity at the contact point does). Returns the
/// kinematics and the sphere's lever arm `R − δ/2`.
#[inline(always)]
pub fn kinematics(i: &SphereState, wall: &WallContact) -> (ContactKinematics, f64) {
    let overlap = wall.overlap;
    let lever_i = i.radius - 0.5 * overlap;
    // LIGGGHTS scales ω by cr/|d| with |d| = R − δ the centre-to-surface distance
    let roll_omega = scale(i.omega, lever_i / (i.radius - overlap));
    let kinematics = ContactKinematics {
        overlap,
        normal: wall.normal,
        rel_vel: sub(i.vel, wall.surface_velocity),
        lever_omega: scale(i.omega, lever_i),
        roll_omega,
        r_eff: i.radius,
        m_eff: i.mass,
    };
    (kinematics, lever_i)
}
