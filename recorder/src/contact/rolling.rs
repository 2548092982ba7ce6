//! Rolling resistance as LIGGGHTS defines it: `epsd2` (spring with a Coulomb-like cap, no
//! dashpot) and `cdt` (constant directional torque).

use super::hertz_mindlin::{ContactKinematics, PairLaw};
use crate::case::RollingModel;
use crate::math::*;

/// The rolling torque `M` (applied as `−M` on `i`); updates the `epsd2` spring. The model
/// is passed apart from the law so that a caller fixing it at compile time loses the match;
/// both outcomes of each cap are computed and one kept (no branch, see `pair_batch`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn torque<T: Real>(
    model: RollingModel,
    law: &PairLaw,
    k: &ContactKinematics<T>,
    kn: T,
    kt: T,
    fn_mag: T,
    spring: &mut [T; 3],
    dt: f64,
) -> [T; 3] {
    match model {
        RollingModel::Off => [T::splat(0.0); 3],
        RollingModel::Epsd2 => {
            let wr_t = tangential(k.roll_omega, k.normal);
            let kr = kt * k.r_eff * k.r_eff;
            let m = add(*spring, scale(wr_t, T::splat(dt) * kr));
            let m_max = fn_mag.abs() * k.r_eff * T::splat(law.rolling_friction);
            let m_mag2 = norm2(m);
            let capped = scale(m, m_max / m_mag2.sqrt());
            let m = select(m_mag2.gt(m_max * m_max), capped, m);
            *spring = m;
            m
        }
        RollingModel::Cdt => {
            let w = k.roll_omega;
            let w_mag = norm2(w).sqrt();
            let m = scale(
                w,
                T::splat(law.rolling_friction) * kn * k.overlap * k.r_eff / w_mag,
            );
            select(
                w_mag.gt(T::splat(0.0)),
                tangential(m, k.normal),
                [T::splat(0.0); 3],
            )
        }
    }
}
