//! Rolling resistance as LIGGGHTS defines it: `epsd2` (spring with a Coulomb-like cap, no
//! dashpot) and `cdt` (constant directional torque).

use super::hertz_mindlin::{ContactKinematics, PairLaw};
use crate::case::RollingModel;
use crate::math::*;

/// The rolling torque `M` (applied as `−M` on `i`); updates the `epsd2` spring.
#[inline(always)]
pub fn torque(
    law: &PairLaw,
    k: &ContactKinematics,
    kn: f64,
    kt: f64,
    fn_mag: f64,
    spring: &mut Vec3,
    dt: f64,
) -> Vec3 {
    match law.rolling_model {
        RollingModel::Off => [0.0; 3],
        RollingModel::Epsd2 => {
            let wr_t = tangential(k.roll_omega, k.normal);
            let kr = kt * k.r_eff * k.r_eff;
            let mut m = add(*spring, scale(wr_t, dt * kr));
            let m_max = fn_mag.abs() * k.r_eff * law.rolling_friction;
            let m_mag2 = norm2(m);
            // squares compared: the root is only needed when the spring is capped
            if m_mag2 > m_max * m_max {
                m = scale(m, m_max / m_mag2.sqrt());
            }
            *spring = m;
            m
        }
        RollingModel::Cdt => {
            let w = k.roll_omega;
            let w_mag = norm2(w).sqrt();
            if w_mag > 0.0 {
                let m = scale(w, law.rolling_friction * kn * k.overlap * k.r_eff / w_mag);
                tangential(m, k.normal)
            } else {
                [0.0; 3]
            }
        }
    }
}
