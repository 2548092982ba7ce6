//! Random touching pairs and the law constants the batched pair law is checked and timed
//! with: one sample for the unit test (`pair_batch`) and the bench (`benches/pair_law.rs`),
//! so that what is timed is what is checked.

use super::pair_batch::SphereArrays;
use super::{ContactHistory, PairLaw};
use crate::case::{ConductionSpec, ContactArea, PairCoefficients, RollingModel};
use crate::heat::ConductionLaw;
use crate::insertion::uniform;
use crate::math::{norm2, scale};
use rand_xoshiro::rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

type Vec3 = [f64; 3];

/// Pair `p` is spheres `2p` and `2p + 1`: unequal glass-like spheres of about 4 and 5 mm
/// radius, overlapping by up to 5 % of a radius, with speeds and spins large enough that
/// some contacts slide and some rolling springs are capped, and a history already loaded.
#[derive(Default)]
pub struct PairSample {
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    pub omega: Vec<Vec3>,
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    pub temp: Vec<f64>,
    pub history: Vec<ContactHistory>,
}

impl PairSample {
    /// `count` pairs drawn from `seed`.
    pub fn random(seed: u64, count: usize) -> PairSample {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut u = move || 2.0 * uniform(&mut rng) - 1.0;
        let mut v3 = |s: f64| [s * u(), s * u(), s * u()];
        let mut sample = PairSample::default();
        for _ in 0..count {
            let (ri, rj) = (
                0.005 * (1.0 + 0.2 * v3(1.0)[0]),
                0.004 * (1.0 + 0.2 * v3(1.0)[0]),
            );
            let dir = v3(1.0);
            let n = scale(dir, 1.0 / norm2(dir).sqrt());
            let gap = (ri + rj) * (1.0 - 0.025 * (1.0 + v3(1.0)[0]));
            sample.pos.extend([[0.0; 3], scale(n, gap)]);
            sample.vel.extend([v3(0.5), v3(0.5)]);
            sample.omega.extend([v3(50.0), v3(50.0)]);
            sample.radius.extend([ri, rj]);
            let mass = |r: f64| 2500.0 * 4.19 * r * r * r;
            sample.mass.extend([mass(ri), mass(rj)]);
            sample
                .temp
                .extend([20.0 + 10.0 * v3(1.0)[0], 20.0 + 10.0 * v3(1.0)[0]]);
            sample.history.push(ContactHistory {
                shear: v3(2e-4),
                roll: v3(6e-6),
            });
        }
        sample
    }

    /// The spheres as the batch reads them.
    pub fn spheres(&self) -> SphereArrays<'_> {
        SphereArrays {
            pos: &self.pos,
            vel: &self.vel,
            omega: &self.omega,
            radius: &self.radius,
            mass: &self.mass,
            temp: &self.temp,
        }
    }
}

/// The sample's contact law: a soft Young's modulus (1e7 Pa) with restitution 0.2, friction
/// 0.3 and rolling friction 0.002, so that both outcomes of each cap occur.
pub fn sample_law(rolling: RollingModel) -> PairLaw {
    let coefficients = PairCoefficients {
        restitution: 0.2,
        friction: 0.3,
        rolling_friction: 0.002,
    };
    PairLaw::new(1e7, 0.3, &coefficients, rolling)
}

/// The sample's conduction: 100 W/m/K for spheres and wall (large, so the flows are), 840
/// J/kg/K, the contact area from `area`, corrected from the law's 1e7 Pa to a real 7e10 Pa.
pub fn sample_heat(area: ContactArea) -> ConductionLaw {
    let spec = ConductionSpec {
        contact_area: area,
        youngs_modulus_real: Some(7e10),
    };
    ConductionLaw::new(&spec, 100.0, 100.0, 840.0, 1e7)
}
