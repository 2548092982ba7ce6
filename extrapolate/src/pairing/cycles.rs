//! The cycle structure of a pairing `g`: replaying one recorded period applies `g` again and
//! again, so over any number of periods a particle only plays the roles of its own cycle of
//! `g` — a fixed point never moves, a short cycle never mixes with the rest of the bed.

use serde::Serialize;

/// Cycles of length at most this many periods count as short.
pub const SHORT_CYCLE: usize = 10;

/// How `g` decomposes into cycles.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CycleStructure {
    /// Disjoint cycles of `g` (fixed points included).
    pub cycles: usize,
    /// Particles with `g(p) = p`: they keep their role in every period.
    pub fixed_points: usize,
    /// Particles on cycles of at most [`SHORT_CYCLE`] periods (fixed points included).
    pub on_short_cycles: usize,
    /// Length of the longest cycle (periods before a particle's role repeats).
    pub longest: usize,
}

impl CycleStructure {
    /// Share of the particles on short cycles.
    pub fn short_share(&self, particles: usize) -> f64 {
        self.on_short_cycles as f64 / particles.max(1) as f64
    }
}

/// The cycle structure of the permutation `g` of `0..g.len()`.
///
/// # Panics
/// If `g` is not a permutation (a pairing always is).
pub fn cycle_structure(g: &[u32]) -> CycleStructure {
    let mut seen = vec![false; g.len()];
    let mut s = CycleStructure {
        cycles: 0,
        fixed_points: 0,
        on_short_cycles: 0,
        longest: 0,
    };
    for start in 0..g.len() {
        if seen[start] {
            continue;
        }
        let mut len = 0;
        let mut p = start;
        while !seen[p] {
            seen[p] = true;
            p = g[p] as usize;
            len += 1;
        }
        assert_eq!(p, start, "g is not a permutation");
        s.cycles += 1;
        s.fixed_points += (len == 1) as usize;
        if len <= SHORT_CYCLE {
            s.on_short_cycles += len;
        }
        s.longest = s.longest.max(len);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_fixed_points_and_the_longest_are_counted() {
        // (0) (1 2) (3 4 5 ... 14): a fixed point, a 2-cycle and a 12-cycle
        let mut g: Vec<u32> = vec![0, 2, 1];
        g.extend((3..15).map(|p| if p == 14 { 3 } else { p + 1 }));
        let s = cycle_structure(&g);
        assert_eq!(
            s,
            CycleStructure {
                cycles: 3,
                fixed_points: 1,
                on_short_cycles: 3,
                longest: 12,
            }
        );
        assert_eq!(s.short_share(g.len()), 3.0 / 15.0);
        let identity: Vec<u32> = (0..5).collect();
        assert_eq!(cycle_structure(&identity).fixed_points, 5);
        assert_eq!(cycle_structure(&[]).cycles, 0);
    }

    #[test]
    #[should_panic(expected = "not a permutation")]
    fn a_map_that_is_not_a_permutation_is_refused() {
        cycle_structure(&[1, 1]);
    }
}
