//! Dense exact oracle: Kuhn–Munkres (`pathfinding::kuhn_munkres::kuhn_munkres_min`) on
//! the full n × n integer cost matrix. O(n²) memory and O(n³) time: for tests and
//! small beds only.

use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;
use rayon::prelude::*;

use super::cost::CostScale;

/// Largest `n` the dense oracle accepts (the matrix alone is 8 n² bytes).
pub const DENSE_LIMIT: usize = 4096;

/// Solves the complete problem; returns `g` (row → column) and the integer total.
pub(crate) fn solve(x0: &[[f64; 3]], x1: &[[f64; 3]], scale: &CostScale) -> (Vec<u32>, i64) {
    let n = x1.len();
    let mut data = vec![0i64; n * n];
    data.par_chunks_mut(n).enumerate().for_each(|(p, row)| {
        for (q, c) in row.iter_mut().enumerate() {
            *c = scale.cost(&x1[p], &x0[q]);
        }
    });
    let m = Matrix::from_vec(n, n, data).expect("n × n data");
    let (total, assign) = kuhn_munkres_min(&m);
    (assign.into_iter().map(|q| q as u32).collect(), total)
}
