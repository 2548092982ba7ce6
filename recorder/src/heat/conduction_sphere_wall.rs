//! Conductance between a sphere and the heated mantle: the same `H = k sqrt(A)` law with the
//! disc where the sphere cuts the wall, `A = π (R² − (R − δ)²)`.

use super::ConductionLaw;

impl ConductionLaw {
    /// `sqrt(A)` of the disc where a sphere of `radius` overlapping a wall by `overlap` cuts it.
    #[inline(always)]
    pub fn wall_sqrt_area(&self, overlap: f64, radius: f64) -> f64 {
        let overlap = overlap * self.overlap_correction;
        let d = radius - overlap;
        (std::f64::consts::PI * (radius * radius - d * d)).sqrt()
    }

    /// Conductance H (W/K) of a sphere of `radius` overlapping a heated wall by `overlap`.
    #[inline(always)]
    pub fn wall_conductance(&self, overlap: f64, radius: f64) -> f64 {
        self.wall_conductivity * self.wall_sqrt_area(overlap, radius)
    }
}
