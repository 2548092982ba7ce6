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
    /// `damping_factor · sqrt(2 E*)`: γn = this · sqrt(s m*) with `s = sqrt(R* δ)`.
    normal_damping: f64,
    /// `damping_factor · sqrt(8 G*)`: γt = this · sqrt(s m*).
    tangential_damping: f64,
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
        let (e_star, g_star) = (1.0 / inv_e_star, 1.0 / inv_g_star);
        let damping_factor = -2.0 * (5.0f64 / 6.0).sqrt() * beta;
        Self {
            e_star,
            g_star,
            damping_factor,
            friction: c.friction,
            rolling_friction: c.rolling_friction,
            rolling_model,
            normal_damping: damping_factor * (2.0 * e_star).sqrt(),
            tangential_damping: damping_factor * (8.0 * g_star).sqrt(),
        }
    }
}

/// Geometry and motion of one contact, seen from particle `i` (`T`: one contact, or several
/// in a vector register, see [`Real`]).
#[derive(Debug, Clone, Copy)]
pub struct ContactKinematics<T = f64> {
    /// Overlap δ > 0.
    pub overlap: T,
    /// Unit normal from the partner (or wall) towards `i`.
    pub normal: [T; 3],
    /// `v_i − v_partner` (the wall's velocity at the contact point).
    pub rel_vel: [T; 3],
    /// `cr_i ω_i + cr_j ω_j` (walls: `cr_i ω_i`), the lever-arm angular term of the slip velocity.
    pub lever_omega: [T; 3],
    /// Relative angular velocity for rolling resistance.
    pub roll_omega: [T; 3],
    /// R* (walls: R_i).
    pub r_eff: T,
    /// m* (walls: m_i).
    pub m_eff: T,
}

/// Tangential and rolling springs carried from step to step; zero while the contact is open.
/// Seen from the partner the same springs are the negated ones.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactHistory<T = f64> {
    pub shear: [T; 3],
    pub roll: [T; 3],
}

impl ContactHistory {
    /// The same springs seen from the other body of the pair.
    pub fn reversed(self) -> Self {
        Self {
            shear: scale(self.shear, -1.0),
            roll: scale(self.roll, -1.0),
        }
    }
}

/// Force on `i` and the two parts of the torques; the partner gets `−force`.
#[derive(Debug, Clone, Copy)]
pub struct ContactResponse<T = f64> {
    pub force: [T; 3],
    /// `n × Ft`: a body whose contact lever arm is `c` gets `−c (n × Ft)` from it (the
    /// partner sees `−n` and `−Ft`, so the same product).
    pub moment_arm_torque: [T; 3],
    /// The rolling-resistance torque `M`: `−M` on `i`, `+M` on the partner.
    pub rolling_torque: [T; 3],
}

impl<T: Real> ContactResponse<T> {
    /// Torque on `i`, whose lever arm is `lever_i = R_i − δ/2`.
    #[inline(always)]
    pub fn torque_on_i(&self, lever_i: T) -> [T; 3] {
        sub(scale(self.moment_arm_torque, -lever_i), self.rolling_torque)
    }

    /// Torque on the partner sphere, whose lever arm is `lever_j = R_j − δ/2`.
    #[inline(always)]
    pub fn torque_on_partner(&self, lever_j: T) -> [T; 3] {
        add(scale(self.moment_arm_torque, -lever_j), self.rolling_torque)
    }
}

/// Evaluates the law for `i`, advancing the history by `dt`. Each pair is evaluated once;
/// the partner gets the opposite force and history.
#[inline(always)]
pub fn respond(
    law: &PairLaw,
    k: &ContactKinematics,
    history: &mut ContactHistory,
    dt: f64,
) -> ContactResponse {
    respond_with(law.rolling_model, law, k, history, dt)
}

/// [`respond`] with the rolling model passed apart (a constant there removes its match), for
/// one contact or several at once (`T`). The law's constants are combined in `f64` in the
/// order one contact combines them, then spread over the lanes.
#[inline(always)]
pub fn respond_with<T: Real>(
    rolling_model: RollingModel,
    law: &PairLaw,
    k: &ContactKinematics<T>,
    history: &mut ContactHistory<T>,
    dt: f64,
) -> ContactResponse<T> {
    let en = k.normal;
    let vn = dot(k.rel_vel, en);
    let vt = sub(k.rel_vel, scale(en, vn));
    let slip = add(vt, cross(en, k.lever_omega));

    let s = (k.r_eff * k.overlap).sqrt();
    let kn = T::splat(4.0 / 3.0 * law.e_star) * s;
    let kt = T::splat(8.0 * law.g_star) * s;
    // γn = d sqrt(2 E* s m*) and γt = d sqrt(kt m*) share the root sqrt(s m*)
    let root_sm = (s * k.m_eff).sqrt();
    let gamma_n = T::splat(law.normal_damping) * root_sm;
    let gamma_t = T::splat(law.tangential_damping) * root_sm;
    // LIGGGHTS leaves limitForce off: the force may turn slightly attractive as the pair separates
    let fn_mag = kn * k.overlap - gamma_n * vn;

    let shear = tangential(add(history.shear, scale(slip, T::splat(dt))), en);
    let ft_spring = scale(shear, -kt);
    let ft_spring2 = kt * kt * norm2(shear);
    let ft_max = T::splat(law.friction) * fn_mag.abs();
    // both outcomes are computed and one is kept: without a branch the pair stage evaluates
    // several contacts per instruction (`pair_batch`)
    let sliding = ft_spring2.gt(ft_max * ft_max);
    let ft_slide = scale(ft_spring, ft_max / ft_spring2.sqrt());
    let ft_stick = sub(ft_spring, scale(slip, gamma_t));
    let ft = select(sliding, ft_slide, ft_stick);
    history.shear = select(sliding, scale(ft_slide, T::splat(-1.0) / kt), shear);

    let rolling_torque =
        rolling::torque(rolling_model, law, k, kn, kt, fn_mag, &mut history.roll, dt);
    ContactResponse {
        force: add(scale(en, fn_mag), ft),
        moment_arm_torque: cross(en, ft),
        rolling_torque,
    }
}
