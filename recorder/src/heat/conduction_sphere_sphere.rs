//! Conductance of a sphere–sphere contact: `H = 4KiKj/(Ki+Kj)·sqrt(A)`, with A the lens
//! (intersection disc) area or the Hertz circle, optionally with the Young's-modulus correction.

use crate::case::{ConductionSpec, ContactArea};
use crate::math::Real;

/// Resolved conduction constants (one particle material).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConductionLaw {
    /// `4 Ki Kj / (Ki + Kj)` for particle pairs.
    pub pair_conductivity: f64,
    /// `4 Ki Kw / (Ki + Kw)` for the heated mantle.
    pub wall_conductivity: f64,
    /// Specific heat capacity c (J/(kg K)).
    pub heat_capacity: f64,
    pub area: ContactArea,
    /// `(E*/E*_real)^(2/3)`, 1 without correction.
    pub overlap_correction: f64,
}

impl ConductionLaw {
    pub fn new(
        spec: &ConductionSpec,
        conductivity: f64,
        wall_conductivity: f64,
        heat_capacity: f64,
        youngs_modulus: f64,
    ) -> Self {
        let harmonic = |a: f64, b: f64| 4.0 * a * b / (a + b);
        // E* ∝ E for equal Poisson ratios, so the modulus ratio is the E* ratio
        let overlap_correction = spec
            .youngs_modulus_real
            .map_or(1.0, |e_real| (youngs_modulus / e_real).powf(2.0 / 3.0));
        Self {
            pair_conductivity: harmonic(conductivity, conductivity),
            wall_conductivity: harmonic(conductivity, wall_conductivity),
            heat_capacity,
            area: spec.contact_area,
            overlap_correction,
        }
    }

    /// Contact area of two spheres whose centres are `r` apart (of one pair, or of several
    /// in a vector register). Symmetric in (Ri, Rj) to the bit.
    #[inline(always)]
    pub fn pair_area<T: Real>(&self, r: T, ri: T, rj: T) -> T {
        let radsum = ri + rj;
        let overlap = (radsum - r) * T::splat(self.overlap_correction);
        let r = radsum - overlap;
        let raddiff = ri - rj;
        let r2 = r * r;
        let lens = T::splat(-std::f64::consts::FRAC_PI_4)
            * (r2 - radsum * radsum)
            * (r2 - raddiff * raddiff)
            / r2;
        let hertz = T::splat(std::f64::consts::PI) * (ri * rj / radsum) * overlap;
        // both computed, one kept: a select, which the batched pair law needs (`pair_batch`)
        if self.area == ContactArea::Overlap {
            lens
        } else {
            hertz
        }
    }

    /// Conductance H (W/K) of a sphere–sphere contact.
    #[inline(always)]
    pub fn pair_conductance(&self, r: f64, ri: f64, rj: f64) -> f64 {
        self.pair_conductivity * self.pair_area(r, ri, rj).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(area: ContactArea) -> ConductionLaw {
        ConductionLaw::new(
            &ConductionSpec {
                contact_area: area,
                youngs_modulus_real: None,
            },
            100.0,
            100.0,
            840.0,
            1e7,
        )
    }

    #[test]
    fn lens_area_matches_the_four_factor_formula() {
        let (r, ri, rj) = (0.0088, 0.005, 0.004);
        let four = -std::f64::consts::PI / 4.0
            * (r - ri - rj)
            * (r + ri - rj)
            * (r - ri + rj)
            * (r + ri + rj)
            / (r * r);
        let a = law(ContactArea::Overlap).pair_area(r, ri, rj);
        assert!((a - four).abs() < 1e-12 * four, "{a} vs {four}");
        // bit-identical from either side
        assert_eq!(
            a.to_bits(),
            law(ContactArea::Overlap).pair_area(r, rj, ri).to_bits()
        );
    }

    #[test]
    fn equal_spheres_conductance_is_2k_sqrt_area() {
        let l = law(ContactArea::Overlap);
        let (r, rp) = (0.0099, 0.005);
        let h = l.pair_conductance(r, rp, rp);
        assert!((h - 200.0 * l.pair_area(r, rp, rp).sqrt()).abs() < 1e-15);
        // equal spheres: lens radius² = Rδ − δ²/4, Hertz R*δ = Rδ/2, ratio 2 − δ/(2R) (≈ 2)
        let ratio = l.pair_area(r, rp, rp) / law(ContactArea::Hertz).pair_area(r, rp, rp);
        let overlap = 2.0 * rp - r;
        assert!(
            (ratio - (2.0 - overlap / (2.0 * rp))).abs() < 1e-12,
            "{ratio}"
        );
    }
}
