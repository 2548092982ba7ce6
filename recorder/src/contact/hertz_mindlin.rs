//! Hertz normal force with LIGGGHTS damping and the Mindlin tangential spring with history
//! (LIGGGHTS 3.8 `gran model hertz tangential history`), shared by sphere–sphere and sphere–wall.

use super::rolling;
use crate::case::{PairCoefficients, RollingModel};
use crate::math::*;

/// Constants of one kind of pair (particle–particle or particle–wall), resolved once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLaw {
    /// Effective Young's modulus E*.
    pub e_star: f64,
    /// Effective shear modulus G*.
    pub g_star: f64,
    /// `−2 sqrt(5/6) β` with `β = ln e / sqrt(ln²e + π²)`; positive.
    pub damping_factor: f64,
    /// Coulomb coefficient μ.
    pub friction: f64,
    /// Rolling coefficient μr.
    pub rolling_friction: f64,
    pub rolling_model: RollingModel,
}

impl PairLaw {
    /// Law between two bodies of the same material `(E, ν)` (walls share the particles' moduli).
    pub fn new(
        youngs_modulus: f64,
        poisson_ratio: f64,
        c: &PairCoefficients,
        rolling_model: RollingModel,
    ) -> Self {
        let (e, nu) = (youngs_modulus, poisson_ratio);
        let inv_e_star = 2.0 * (1.0 - nu * nu) / e;
        let inv_g_star = 2.0 * (2.0 * (2.0 - nu) * (1.0 + nu) / e);
        let ln_e = c.restitution.ln();
        let beta = ln_e / (ln_e * ln_e + std::f64::consts::PI * std::f64::consts::PI).sqrt();
        Self {
            e_star: 1.0 / inv_e_star,
            g_star: 1.0 / inv_g_star,
            damping_factor: -2.0 * (5.0f64 / 6.0).sqrt() * beta,
            friction: c.friction,
            rolling_friction: c.rolling_friction,
            rolling_model,
        }
    }
}

/// Geometry and motion of one contact, seen from particle `i`.
#[derive(Debug, Clone, Copy)]
pub struct ContactKinematics {
    /// Overlap δ > 0.
    pub overlap: f64,
    /// Unit normal from the partner (or wall) towards `i`.
    pub normal: Vec3,
    /// `v_i − v_partner` (the wall's velocity at the contact point).
    pub rel_vel: Vec3,
    /// `cr_i ω_i + cr_j ω_j` (walls: `cr_i ω_i`), the lever-arm angular term of the slip velocity.
    pub lever_omega: Vec3,
    /// Relative angular velocity for rolling resistance.
    pub roll_omega: Vec3,
    /// Contact lever arm of `i`, `R_i − δ/2`.
    pub lever_i: f64,
    /// R* (walls: R_i).
    pub r_eff: f64,
    /// m* (walls: m_i).
    pub m_eff: f64,
}

/// Tangential and rolling springs carried from step to step; zero while the contact is open.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactHistory {
    pub shear: Vec3,
    pub roll: Vec3,
}

/// Force and torque on `i`, and the normal force magnitude (for the recorder and diagnostics).
#[derive(Debug, Clone, Copy)]
pub struct ContactResponse {
    pub force: Vec3,
    pub torque: Vec3,
    pub normal_force: f64,
}

/// Evaluates the law for `i`, advancing the history by `dt`. Written so that evaluating the
/// same pair from `j` gives exactly the opposite force and history (bitwise), which keeps the
/// full-neighbour-list sums symmetric.
#[inline(always)]
pub fn respond(
    law: &PairLaw,
    k: &ContactKinematics,
    history: &mut ContactHistory,
    dt: f64,
) -> ContactResponse {
    let en = k.normal;
    let vn = dot(k.rel_vel, en);
    let vt = sub(k.rel_vel, scale(en, vn));
    let slip = add(vt, cross(en, k.lever_omega));

    let s = (k.r_eff * k.overlap).sqrt();
    let kn = 4.0 / 3.0 * law.e_star * s;
    let kt = 8.0 * law.g_star * s;
    let gamma_n = law.damping_factor * (2.0 * law.e_star * s * k.m_eff).sqrt();
    let gamma_t = law.damping_factor * (kt * k.m_eff).sqrt();
    // LIGGGHTS leaves limitForce off: the force may turn slightly attractive as the pair separates
    let fn_mag = kn * k.overlap - gamma_n * vn;

    let mut shear = add(history.shear, scale(slip, dt));
    shear = tangential(shear, en);
    let mut ft = scale(shear, -kt);
    let ft_spring = kt * norm2(shear).sqrt();
    let ft_max = law.friction * fn_mag.abs();
    if ft_spring > ft_max {
        if ft_spring > 0.0 {
            ft = scale(ft, ft_max / ft_spring);
            shear = scale(ft, -1.0 / kt);
        } else {
            ft = [0.0; 3];
        }
    } else {
        ft = sub(ft, scale(slip, gamma_t));
    }
    history.shear = shear;

    let mut torque = scale(cross(en, ft), -k.lever_i);
    let roll_torque = rolling::torque(law, k, kn, kt, fn_mag, &mut history.roll, dt);
    torque = sub(torque, roll_torque);

    ContactResponse {
        force: add(scale(en, fn_mag), ft),
        torque,
        normal_force: fn_mag,
    }
}
