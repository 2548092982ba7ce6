//! Feasibility of the candidate graph: does it contain a perfect matching at all, and
//! if not, how to grow it.
//!
//! Hopcroft–Karp finds a maximum matching in O(E √V). If it is not perfect, the rows
//! reachable from the free rows by alternating paths form a Hall-violating set `S`:
//! every column they see (`N(S)`) is matched to a row of `S`, and `|N(S)| < |S|`.
//! Only an edge from `S` to a column outside `N(S)` can help. `S` is typically a large
//! closed region with a small deficit spread over its boundary (growing k on all of it
//! mostly adds useless edges inside `N(S)`), so we add exit edges: for every row of `S`
//! its nearest column outside `N(S)` (a kiddo nearest-one query on a tree of those
//! columns), keeping the `4·deficit + 64` shortest. At least one new edge is added
//! each time, so the loop ends.

use std::collections::VecDeque;

use kiddo::SquaredEuclidean;
use rayon::prelude::*;

use super::candidates::{Graph, Tree};
use super::sparse_lap::NONE;

const INF: u32 = u32::MAX;

/// A maximum-cardinality matching of the candidate graph, kept between calls so that
/// growing the graph only needs the few extra augmentations.
pub(crate) struct Matching {
    col_of_row: Vec<u32>,
    row_of_col: Vec<u32>,
    layer: Vec<u32>,
    /// Iterative DFS: next edge to try per row, and the explicit stack.
    next: Vec<usize>,
    stack: Vec<u32>,
}

impl Matching {
    /// Starts from an existing (partial) matching.
    pub(crate) fn from_partial(col_of_row: &[u32], row_of_col: &[u32]) -> Self {
        let n = col_of_row.len();
        Self {
            col_of_row: col_of_row.to_vec(),
            row_of_col: row_of_col.to_vec(),
            layer: vec![INF; n],
            next: vec![0; n],
            stack: Vec::new(),
        }
    }

    /// Grows the matching to maximum cardinality on `g` (edges only ever get added, so
    /// the previous matching stays valid). Returns the rows of the Hall-violating set,
    /// sorted, or an empty vector if the matching is perfect.
    pub(crate) fn deficient_rows(&mut self, g: &Graph) -> Vec<u32> {
        let n = g.rows();
        // Cheap greedy start: first free column of each free row.
        for p in 0..n {
            if self.col_of_row[p] == NONE {
                if let Some(&q) = g
                    .row(p)
                    .0
                    .iter()
                    .find(|&&q| self.row_of_col[q as usize] == NONE)
                {
                    self.col_of_row[p] = q;
                    self.row_of_col[q as usize] = p as u32;
                }
            }
        }
        let mut queue = VecDeque::new();
        loop {
            // BFS layers from all free rows.
            queue.clear();
            for p in 0..n {
                if self.col_of_row[p] == NONE {
                    self.layer[p] = 0;
                    queue.push_back(p as u32);
                } else {
                    self.layer[p] = INF;
                }
            }
            if queue.is_empty() {
                return Vec::new();
            }
            let mut found = false;
            while let Some(r) = queue.pop_front() {
                let r = r as usize;
                for &q in g.row(r).0 {
                    let r2 = self.row_of_col[q as usize];
                    if r2 == NONE {
                        found = true;
                    } else if self.layer[r2 as usize] == INF {
                        self.layer[r2 as usize] = self.layer[r] + 1;
                        queue.push_back(r2);
                    }
                }
            }
            if !found {
                // No augmenting path: the rows the BFS reached form the deficient set.
                return (0..n as u32)
                    .filter(|&p| self.layer[p as usize] != INF)
                    .collect();
            }
            // Vertex-disjoint shortest augmenting paths along the layers.
            self.next.fill(0);
            for p in 0..n {
                if self.col_of_row[p] == NONE {
                    self.augment_from(g, p);
                }
            }
        }
    }

    /// Iterative DFS along the BFS layers from the free row `p0`; flips the path found.
    fn augment_from(&mut self, g: &Graph, p0: usize) -> bool {
        self.stack.clear();
        self.stack.push(p0 as u32);
        while let Some(&r) = self.stack.last() {
            let r = r as usize;
            let (cols, _) = g.row(r);
            let mut pushed = false;
            while self.next[r] < cols.len() {
                let q = cols[self.next[r]];
                self.next[r] += 1;
                let r2 = self.row_of_col[q as usize];
                if r2 == NONE {
                    // Flip the path: each row on the stack takes the column it tried last.
                    for &s in self.stack.iter().rev() {
                        let s = s as usize;
                        let c = g.row(s).0[self.next[s] - 1];
                        self.col_of_row[s] = c;
                        self.row_of_col[c as usize] = s as u32;
                    }
                    for &s in &self.stack {
                        self.layer[s as usize] = INF; // used: off the layered graph
                    }
                    return true;
                }
                if self.layer[r2 as usize] == self.layer[r] + 1 {
                    self.stack.push(r2);
                    pushed = true;
                    break;
                }
            }
            if !pushed {
                self.layer[r] = INF; // dead end
                self.stack.pop();
            }
        }
        false
    }
}

/// Exit edges for the Hall-violating set `rows` (sorted): the shortest edges from a row
/// of the set to a column outside its neighbourhood (see the module documentation).
/// Sorted (row, column) pairs; never empty for a genuine violator.
pub(crate) fn exit_edges(
    g: &Graph,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    rows: &[u32],
) -> Vec<(u32, u32)> {
    let n = x0.len();
    let mut inside = vec![false; n];
    for &p in rows {
        for &q in g.row(p as usize).0 {
            inside[q as usize] = true;
        }
    }
    let outside: Vec<u32> = (0..n as u32).filter(|&q| !inside[q as usize]).collect();
    if outside.is_empty() {
        return Vec::new(); // impossible for a violator: |N(S)| < |S| <= n
    }
    let deficit = rows.len().saturating_sub(n - outside.len());
    let pts: Vec<[f64; 3]> = outside.iter().map(|&q| x0[q as usize]).collect();
    let tree = Tree::new_from_slice(&pts).expect("n fits in u32");
    let mut exits: Vec<(f64, u32, u32)> = rows
        .par_iter()
        .with_min_len(256)
        .map(|&p| {
            let hit = tree
                .query(&x1[p as usize])
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            (hit.distance, p, outside[hit.item as usize])
        })
        .collect();
    let keep = (4 * deficit + 64).min(exits.len());
    exits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut edges: Vec<(u32, u32)> = exits[..keep].iter().map(|&(_, p, q)| (p, q)).collect();
    edges.sort_unstable();
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graph(rows: &[&[u32]]) -> Graph {
        let mut g = Graph::default();
        g.offsets.push(0);
        for r in rows {
            g.cols.extend_from_slice(r);
            g.costs.extend(r.iter().map(|_| 0));
            g.offsets.push(g.cols.len());
        }
        g
    }

    #[test]
    fn finds_perfect_matching_through_long_paths() {
        // Greedy takes row i → col i; row 4 then needs the whole chain shifted.
        let g = graph(&[&[0, 1], &[1, 2], &[2, 3], &[3, 4], &[0]]);
        let mut m = Matching::from_partial(&[NONE; 5], &[NONE; 5]);
        assert!(m.deficient_rows(&g).is_empty());
        let mut seen = [false; 5];
        for &q in &m.col_of_row {
            assert!(!std::mem::replace(&mut seen[q as usize], true));
        }
    }

    #[test]
    fn reports_the_hall_violator() {
        // Rows 1, 2, 3 only see columns 1 and 2; rows 0 and 4 are fine.
        let g = graph(&[&[0, 1], &[1, 2], &[2], &[1], &[4, 3]]);
        let mut m = Matching::from_partial(&[NONE; 5], &[NONE; 5]);
        assert_eq!(m.deficient_rows(&g), vec![1, 2, 3]);
        // Columns 0 (x = 0), 3 (x = 3) and 4 are outside N(S) = {1, 2}.
        let x0 = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
        ];
        let x1 = [
            [0.0; 3],
            [0.9, 0.0, 0.0],
            [2.9, 0.0, 0.0],
            [1.2, 0.0, 0.0],
            [4.0, 0.0, 0.0],
        ];
        assert_eq!(
            exit_edges(&g, &x0, &x1, &[1, 2, 3]),
            vec![(1, 0), (2, 3), (3, 0)]
        );
    }
}
