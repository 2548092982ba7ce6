//! Haydar Algorithm 2: a collision of duration `Δt_c` becomes `⌊Δt_c/Δt_c^max⌋` rows of
//! `Δt_c^max` and one row of the remainder (if any), each starting where the previous ended.

/// The rows `(start, duration)` of a collision starting at `start` and lasting `duration`
/// (any time unit), with rows at most `max_duration` long.
pub fn split(start: u64, duration: u64, max_duration: u64) -> Vec<(u64, u64)> {
    assert!(max_duration > 0, "Δt_c^max must be positive");
    let full = duration / max_duration;
    let mut rows: Vec<(u64, u64)> = (0..full)
        .map(|k| (start + k * max_duration, max_duration))
        .collect();
    let rest = duration % max_duration;
    if rest > 0 {
        rows.push((start + full * max_duration, rest));
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::split;

    #[test]
    fn paper_table_1_example() {
        // a 25-unit collision: 10 + 10 + 5 with Δt_c^max = 10, 20 + 5 with Δt_c^max = 20
        assert_eq!(split(3, 25, 10), vec![(3, 10), (13, 10), (23, 5)]);
        assert_eq!(split(3, 25, 20), vec![(3, 20), (23, 5)]);
    }

    #[test]
    fn exact_multiples_and_short_collisions() {
        assert_eq!(split(0, 20, 10), vec![(0, 10), (10, 10)]);
        assert_eq!(split(7, 4, 10), vec![(7, 4)]);
        assert!(split(7, 0, 10).is_empty());
    }
}
