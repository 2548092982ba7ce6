//! A uniform grid of cubic cells over a fixed box; positions outside are clamped to the edge
//! cells, which keeps every pair closer than a cell size in adjacent cells. Cells are numbered
//! layer by layer along the axis with the most cells, so that slot order (cells in index
//! order) puts every half-list partner in the particle's own layer or the next one. In a
//! drum periodic along its axis the grid wraps along y, which is then never the layer axis.

use crate::math::Vec3;
use crate::periodic::AxialPeriod;

#[derive(Debug, Clone, PartialEq)]
pub struct CellGrid {
    pub origin: Vec3,
    pub cell_size: f64,
    pub dims: [usize; 3],
    /// Axes from the fastest-varying index to the slowest (the layer axis).
    axes: [usize; 3],
    /// Offsets `[dx, dy, dz]` of the cells at or after a cell in index order: its own and
    /// the 13 ahead of it, the half stencil of a half list.
    pub forward: [[i64; 3]; 14],
    /// The period along y when the grid wraps there (its box then spans exactly one).
    pub period: Option<AxialPeriod>,
}

impl CellGrid {
    /// A grid covering `[lo, hi]` with cells at least `min_cell` wide.
    pub fn new(lo: Vec3, hi: Vec3, min_cell: f64) -> Self {
        Self::build(lo, hi, min_cell, None)
    }

    /// A grid covering `[lo, hi]` that wraps along y, with period `hi[1] − lo[1]`. The
    /// positions along y must lie in `[lo[1], hi[1])`; a remainder of the period shorter
    /// than a cell joins the last cell, which keeps every pair closer than a cell in
    /// adjacent cells, the seam included.
    pub fn periodic_along_y(lo: Vec3, hi: Vec3, min_cell: f64) -> Self {
        let period = AxialPeriod {
            length: hi[1] - lo[1],
        };
        Self::build(lo, hi, min_cell, Some(period))
    }

    fn build(lo: Vec3, hi: Vec3, min_cell: f64, period: Option<AxialPeriod>) -> Self {
        let mut dims = [1usize; 3];
        for k in 0..3 {
            dims[k] = (((hi[k] - lo[k]) / min_cell).floor() as usize).max(1);
        }
        // the longest axis is the layer axis: the most layers, the most parallel tasks; of
        // equal ones the first, so that a drum (axis y, gravity −z) is not cut into
        // horizontal layers its bed only half fills. A wrapping axis is never the layer
        // axis: a pair across the seam would join the last layer to the first, which the
        // even/odd layer tasks of the pair stage could then write at the same time.
        let mut axes = [0, 1, 2];
        axes.sort_by_key(|&k| (period.is_none() || k != 1, dims[k], std::cmp::Reverse(k)));
        let [a, b, l] = axes;
        let mut forward = [[0i64; 3]; 14];
        let mut k = 0;
        // (slow, mid, fast) offsets in index order: the own cell, then the next along the
        // fast axis, the next row, the next layer
        for (dl, db_range, da_range) in [
            (0i64, 0..=0i64, 0..=1i64),
            (0, 1..=1, -1..=1),
            (1, -1..=1, -1..=1),
        ] {
            for db in db_range {
                for da in da_range.clone() {
                    forward[k][a] = da;
                    forward[k][b] = db;
                    forward[k][l] = dl;
                    k += 1;
                }
            }
        }
        // cells stay ≥ min_cell: the box is widened to a whole number of them
        Self {
            origin: lo,
            cell_size: min_cell,
            dims,
            axes,
            forward,
            period,
        }
    }

    pub fn cell_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Number of layers (cells along the layer axis).
    pub fn layers(&self) -> usize {
        self.dims[self.axes[2]]
    }

    /// Cells in one layer: layer `l` holds cells `l * cells_per_layer ..`.
    pub fn cells_per_layer(&self) -> usize {
        self.dims[self.axes[0]] * self.dims[self.axes[1]]
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

    /// Linear cell index, layer axis slowest.
    #[inline(always)]
    pub fn index(&self, c: [usize; 3]) -> usize {
        let [a, b, l] = self.axes;
        (c[l] * self.dims[b] + c[b]) * self.dims[a] + c[a]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_forward_stencil_is_every_cell_ahead_within_one() {
        let grid = CellGrid::new([0.0; 3], [5.0, 7.0, 4.0], 1.0);
        let centre = [2usize, 3, 2];
        let own = grid.index(centre) as i64;
        let mut ahead: Vec<[i64; 3]> = Vec::new();
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let c = [
                        centre[0] as i64 + dx,
                        centre[1] as i64 + dy,
                        centre[2] as i64 + dz,
                    ];
                    let i = grid.index([c[0] as usize, c[1] as usize, c[2] as usize]) as i64;
                    if i >= own {
                        ahead.push([dx, dy, dz]);
                    }
                }
            }
        }
        let mut forward = grid.forward.to_vec();
        forward.sort();
        ahead.sort();
        assert_eq!(forward, ahead);
    }

    #[test]
    fn of_equal_axes_the_first_is_the_layer_axis() {
        let grid = CellGrid::new([0.0; 3], [4.0, 3.0, 4.0], 1.0);
        assert_eq!(grid.layers(), 4);
        assert!(grid.index([1, 0, 0]) >= grid.cells_per_layer());
    }

    #[test]
    fn the_longest_axis_is_the_layer_axis() {
        let grid = CellGrid::new([0.0; 3], [2.0, 10.0, 3.0], 1.0);
        assert_eq!(grid.dims, [2, 10, 3]);
        assert_eq!(grid.layers(), 10);
        assert_eq!(grid.cells_per_layer(), 6);
        // every cell of layer y = 4 lies in 24..30
        for x in 0..2 {
            for z in 0..3 {
                let i = grid.index([x, 4, z]);
                assert!((24..30).contains(&i), "{i}");
            }
        }
    }
}
