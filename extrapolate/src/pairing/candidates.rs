//! The sparse candidate graph: for every t1 point (row), its k nearest t0 points
//! (columns, found with a kiddo k-d tree), plus the exit edges and certificate pairs
//! added since. Stored as compressed rows with the integer cost of each edge. The graph
//! only ever grows, so a warm-started solver never loses the edges it stands on.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use super::cost::CostScale;

/// k-d tree over the t0 positions; items are t0 indices.
pub(crate) type Tree = ImmutableKdTree<f64, 3>;

/// Builds the tree over the t0 points. Serial construction (kiddo's threading is off),
/// so the tree, and with it the order of equal-distance results, never depends on the
/// number of threads.
pub(crate) fn build_tree(x0: &[[f64; 3]]) -> Tree {
    // Item indices are u32; the caller has checked that n fits.
    Tree::new_from_slice(x0).expect("n fits in u32, checked by the caller")
}

/// The k nearest t0 points of every t1 point, as a flat row-major array (`k` entries per
/// row) of column indices and the matching integer costs. Within a row, entries are
/// ordered by (cost, column) so that the result is the same whatever the traversal order
/// inside the tree or the number of threads.
pub(crate) fn knn(
    tree: &Tree,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    k: usize,
    scale: &CostScale,
) -> (Vec<u32>, Vec<i64>) {
    let n = x1.len();
    let k = k.clamp(1, x0.len());
    let kk = NonZeroUsize::new(k).expect("k >= 1");
    let mut cols = vec![0u32; n * k];
    let mut costs = vec![0i64; n * k];
    // Each row writes only its own k-slot chunk: embarrassingly parallel and
    // deterministic (no collection order to worry about).
    cols.par_chunks_mut(k)
        .zip(costs.par_chunks_mut(k))
        .enumerate()
        .with_min_len(256)
        .for_each(|(p, (cc, cs))| {
            let found = tree
                .query(&x1[p])
                .nearest_n::<SquaredEuclidean<f64>>(kk)
                .execute();
            let mut row: Vec<(i64, u32)> = found
                .iter()
                .map(|r| (scale.cost(&x1[p], &x0[r.item as usize]), r.item))
                .collect();
            row.sort_unstable();
            debug_assert_eq!(row.len(), k);
            for (s, (c, q)) in row.into_iter().enumerate() {
                cc[s] = q;
                cs[s] = c;
            }
        });
    (cols, costs)
}

/// Compressed sparse rows: row `p`'s edges are `cols[offsets[p]..offsets[p + 1]]` with
/// costs `costs[..]` at the same positions.
#[derive(Debug, Default)]
pub(crate) struct Graph {
    pub(crate) offsets: Vec<usize>,
    pub(crate) cols: Vec<u32>,
    pub(crate) costs: Vec<i64>,
}

impl Graph {
    /// Number of rows.
    pub(crate) fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of edges.
    pub(crate) fn edges(&self) -> usize {
        self.cols.len()
    }

    /// The edges of row `p`: columns and costs.
    #[inline]
    pub(crate) fn row(&self, p: usize) -> (&[u32], &[i64]) {
        let (a, b) = (self.offsets[p], self.offsets[p + 1]);
        (&self.cols[a..b], &self.costs[a..b])
    }

    /// Merges the kNN lists and the extra edges (sorted by row then column; they may
    /// repeat kNN entries, which are dropped) into one graph without duplicate edges.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        k: usize,
        knn_cols: &[u32],
        knn_costs: &[i64],
        extras: &[(u32, u32)],
        x0: &[[f64; 3]],
        x1: &[[f64; 3]],
        scale: &CostScale,
    ) -> Graph {
        let n = x1.len();
        let mut g = Graph {
            offsets: Vec::with_capacity(n + 1),
            cols: Vec::with_capacity(knn_cols.len() + extras.len()),
            costs: Vec::with_capacity(knn_cols.len() + extras.len()),
        };
        g.offsets.push(0);
        let mut e = 0usize;
        for p in 0..n {
            let start = g.cols.len();
            g.cols.extend_from_slice(&knn_cols[p * k..(p + 1) * k]);
            g.costs.extend_from_slice(&knn_costs[p * k..(p + 1) * k]);
            while e < extras.len() && extras[e].0 as usize == p {
                let q = extras[e].1;
                // Extras of a row are few: a linear scan beats any set structure.
                if !g.cols[start..].contains(&q) {
                    g.cols.push(q);
                    g.costs.push(scale.cost(&x1[p], &x0[q as usize]));
                }
                e += 1;
            }
            g.offsets.push(g.cols.len());
        }
        debug_assert_eq!(e, extras.len());
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knn_rows_are_sorted_and_exact() {
        let x0: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 0.0, 0.0]).collect();
        let x1 = vec![[10.2, 0.0, 0.0], [-3.0, 0.0, 0.0]];
        let scale = CostScale::new(&x0, &x1, 1e-3).unwrap();
        let tree = build_tree(&x0);
        let (c, w) = knn(&tree, &x0, &x1, 3, &scale);
        assert_eq!(&c[..3], &[10, 11, 9]);
        assert_eq!(&w[..3], &[200, 800, 1200]);
        assert_eq!(&c[3..], &[0, 1, 2]);
        let g = Graph::build(3, &c, &w, &[(1, 2), (1, 30), (1, 40)], &x0, &x1, &scale);
        assert_eq!(g.row(0).0, &[10, 11, 9]);
        assert_eq!(g.row(1).0, &[0, 1, 2, 30, 40]);
        assert_eq!(g.row(1).1[4], 43000);
        assert_eq!(g.edges(), 8);
        assert_eq!(g.rows(), 2);
    }
}
