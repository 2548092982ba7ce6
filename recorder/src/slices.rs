//! Disjoint mutable pieces of one array, for parallel tasks that each own a consecutive range.

/// Splits `items` into consecutive mutable pieces, piece `b` covering `bounds[b].0..bounds[b].1`
/// (bounds increasing and not overlapping; gaps are skipped).
pub fn split_by<T>(
    mut items: &mut [T],
    bounds: impl Iterator<Item = (usize, usize)>,
) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    let mut at = 0;
    for (lo, hi) in bounds {
        let (_, rest) = std::mem::take(&mut items).split_at_mut(lo - at);
        let (piece, rest) = rest.split_at_mut(hi - lo);
        pieces.push(piece);
        items = rest;
        at = hi;
    }
    pieces
}

#[cfg(test)]
mod tests {
    #[test]
    fn pieces_cover_their_ranges_and_skip_gaps() {
        let mut v: Vec<u32> = (0..10).collect();
        let pieces = super::split_by(&mut v, [(1, 3), (3, 3), (5, 9)].into_iter());
        let got: Vec<Vec<u32>> = pieces.into_iter().map(|p| p.to_vec()).collect();
        assert_eq!(got, vec![vec![1, 2], vec![], vec![5, 6, 7, 8]]);
    }
}
