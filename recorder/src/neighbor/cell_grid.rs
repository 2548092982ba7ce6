//! A uniform grid of cubic cells over a fixed box; positions outside are clamped to the edge
//! cells, which keeps every pair closer than a cell size in adjacent cells.

use crate::math::Vec3;

#[derive(Debug, Clone, PartialEq)]
pub struct CellGrid {
    pub origin: Vec3,
    pub cell_size: f64,
    pub dims: [usize; 3],
}

impl CellGrid {
    /// A grid covering `[lo, hi]` with cells at least `min_cell` wide.
    pub fn new(lo: Vec3, hi: Vec3, min_cell: f64) -> Self {
        let mut dims = [1usize; 3];
        for k in 0..3 {
            dims[k] = (((hi[k] - lo[k]) / min_cell).floor() as usize).max(1);
        }
        // cells stay ≥ min_cell: the box is widened to a whole number of them
        Self {
            origin: lo,
            cell_size: min_cell,
            dims,
        }
    }

    pub fn cell_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Integer cell coordinates of a position, clamped to the grid.
    #[inline(always)]
    pub fn coords(&self, p: Vec3) -> [usize; 3] {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let f = ((p[k] - self.origin[k]) / self.cell_size).floor();
            // NaN and −∞ clamp to 0 through the `as` conversion of a negative/NaN float
            c[k] = (f.max(0.0) as usize).min(self.dims[k] - 1);
        }
        c
    }

    /// Linear cell index, x fastest.
    #[inline(always)]
    pub fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }
}
