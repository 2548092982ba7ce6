//! Contact kinematics of two spheres (LIGGGHTS `surface_model_default`), evaluated once per pair.

use super::hertz_mindlin::ContactKinematics;
use crate::math::*;

/// One side of a sphere–sphere pair (`T`: one pair, or several in a vector register).
#[derive(Debug, Clone, Copy)]
pub struct SphereState<T = f64> {
    pub pos: [T; 3],
    pub vel: [T; 3],
    pub omega: [T; 3],
    pub radius: T,
    pub mass: T,
}

/// A touching pair seen from `i`: the law's kinematics, the centre distance and both
/// contact lever arms `R − δ/2`.
#[derive(Debug, Clone, Copy)]
pub struct PairContact<T = f64> {
    pub kinematics: ContactKinematics<T>,
    pub distance: T,
    pub lever_i: T,
    pub lever_j: T,
}

/// Whether spheres of radii `ri`, `rj` whose centres are `delta` apart overlap; the squared
/// distance alongside (the broad test, before any other field of `j` is read).
#[inline(always)]
pub fn overlapping(delta: Vec3, ri: f64, rj: f64) -> Option<f64> {
    let r2 = norm2(delta);
    let radsum = ri + rj;
    (r2 < radsum * radsum).then_some(r2)
}

/// Effective radius and mass `(R*, m*)` of a pair.
#[inline(always)]
pub fn effective(ri: f64, rj: f64, mi: f64, mj: f64) -> (f64, f64) {
    (ri * rj / (ri + rj), mi * mj / (mi + mj))
}

/// Kinematics of `i` against `j`, given `delta = x_i − x_j` and its squared length `r2`
/// from [`overlapping`], and the pair's `(R*, m*)` from [`effective`] (passed in so that
/// equal spheres compute it once).
#[inline(always)]
pub fn kinematics<T: Real>(
    i: &SphereState<T>,
    j: &SphereState<T>,
    delta: [T; 3],
    r2: T,
    (r_eff, m_eff): (T, T),
) -> PairContact<T> {
    let radsum = i.radius + j.radius;
    let r = r2.sqrt();
    let overlap = radsum - r;
    let normal = scale(delta, T::splat(1.0) / r);
    let lever_i = i.radius - T::splat(0.5) * overlap;
    let lever_j = j.radius - T::splat(0.5) * overlap;
    PairContact {
        kinematics: ContactKinematics {
            overlap,
            normal,
            rel_vel: sub(i.vel, j.vel),
            lever_omega: add(scale(i.omega, lever_i), scale(j.omega, lever_j)),
            roll_omega: sub(i.omega, j.omega),
            r_eff,
            m_eff,
        },
        distance: r,
        lever_i,
        lever_j,
    }
}
