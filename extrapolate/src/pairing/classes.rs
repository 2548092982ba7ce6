//! Pairing within size classes: a particle only takes the role of one of its own radius.

use super::{pair, total_distance, validate, Pairing, PairingError, PairingOptions};
use std::collections::BTreeMap;
use std::time::Instant;

/// Whether `g` keeps every particle in its class: `g` holds one index into `r0` per entry
/// of `r1`, each in range, and `r0[g[p]]` has the bits of `r1[p]` for every `p`. A stored
/// pairing of a bed of several sizes that fails this was not computed for these radii.
#[must_use]
pub fn respects_classes(g: &[u32], r0: &[f64], r1: &[f64]) -> bool {
    g.len() == r1.len()
        && g.iter().zip(r1).all(|(&q, r)| {
            r0.get(q as usize)
                .is_some_and(|r0q| r0q.to_bits() == r.to_bits())
        })
}

/// The indices of the particles of each radius (keyed by the radius's bits), ascending.
fn members_by_radius(radius: &[f64]) -> BTreeMap<u64, Vec<u32>> {
    let mut members: BTreeMap<u64, Vec<u32>> = BTreeMap::new();
    for (index, r) in radius.iter().enumerate() {
        // `validate` refuses more than u32::MAX particles before any class is paired
        members.entry(r.to_bits()).or_default().push(index as u32);
    }
    members
}

/// Whether every radius of both snapshots has the bits of the first one at `t0`: a bed of one
/// size (also true of empty snapshots).
fn one_size(r0: &[f64], r1: &[f64]) -> bool {
    r0.first().is_none_or(|first| {
        let bits = first.to_bits();
        r0.iter().chain(r1).all(|r| r.to_bits() == bits)
    })
}

/// The exact pairing of the `t1` snapshot (`x1`, radii `r1`) to `t0` (`x0`, radii `r0`)
/// among the bijections that map every particle onto a role of its own radius: the minimum
/// of `Σ_p round(|x1[p] − x0[g(p)]| / unit)` under that constraint.
///
/// Why: a bed of several particle sizes is made of size classes, each of one radius (the
/// engine gives every particle of a class the same `f64`, so classes are told apart by the
/// radius's bits). A particle in the role of one of another size would carry its temperature
/// into a heat capacity up to 25 times larger or smaller (a 1 mm against a 2.8 mm sphere).
///
/// Exact: a class-preserving bijection is one bijection per class, and its cost is the sum
/// of theirs, so the constrained optimum is the union of the per-class optima, each found
/// and certified by [`pair`].
///
/// A bed of one size (every radius the same bits at both instants) is paired by [`pair`]
/// itself, so its result is [`pair`]'s, byte for byte. A bed of several sizes is paired one
/// class at a time, in ascending order of radius, each with [`pair`] on the class's particles
/// (in index order) and the same `opts`. Give them a `unit` computed on the whole bed
/// ([`PairingOptions::for_bed`] with the bed's mean diameter) so that the classes' costs
/// share one scale. The classes run one after the other, each on the current rayon pool:
/// the result does not depend on the number of threads. The merged [`Pairing`]:
///
/// * `g` in the snapshots' own indices, a permutation of `0..n` that keeps every class;
/// * `total_cost`: the classes' totals summed in order of radius; `total_distance`:
///   `Σ_p |x1[p] − x0[g[p]]|` summed over the whole bed in row order, as [`pair`] sums it;
/// * `certified`: every class certified;
/// * `k_used` and `rounds`: the largest over the classes (`rounds` stays 1 when every class
///   was certified at its first solve);
/// * `added_pairs`, `growth_pairs`, `edges`, `certificate_examined`, `auction_bids`: sums
///   over the classes;
/// * `seconds`: the wall time of the whole call.
///
/// # Errors
///
/// [`PairingError::RadiusCount`] if a snapshot does not hold one radius per position;
/// [`PairingError::ClassMismatch`] if a radius has not as many particles at `t0` as at `t1`
/// (the smallest such radius is named); otherwise whatever [`pair`] reports for the whole bed
/// (lengths, empty or non-finite input, options) or for a class (a `unit` too small).
pub fn pair_by_size(
    x0: &[[f64; 3]],
    r0: &[f64],
    x1: &[[f64; 3]],
    r1: &[f64],
    opts: &PairingOptions,
) -> Result<Pairing, PairingError> {
    let start = Instant::now();
    for (snapshot, positions, radii) in [("t0", x0, r0), ("t1", x1, r1)] {
        if radii.len() != positions.len() {
            return Err(PairingError::RadiusCount {
                snapshot,
                radii: radii.len(),
                positions: positions.len(),
            });
        }
    }
    if one_size(r0, r1) {
        return pair(x0, x1, opts);
    }
    let n = validate(x0, x1)?;
    let members0 = members_by_radius(r0);
    let mut members1 = members_by_radius(r1);
    let mut classes = Vec::with_capacity(members0.len());
    for (bits, at_t0) in members0 {
        let at_t1 = members1.remove(&bits).unwrap_or_default();
        classes.push((f64::from_bits(bits), at_t0, at_t1));
    }
    // a radius present at t1 only has no particle at t0
    classes.extend(
        members1
            .into_iter()
            .map(|(bits, at_t1)| (f64::from_bits(bits), Vec::new(), at_t1)),
    );
    classes.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((radius, at_t0, at_t1)) = classes.iter().find(|c| c.1.len() != c.2.len()) {
        return Err(PairingError::ClassMismatch {
            radius: *radius,
            n0: at_t0.len(),
            n1: at_t1.len(),
        });
    }

    let mut g = vec![0u32; n];
    let mut merged = Pairing {
        g: Vec::new(),
        total_cost: 0,
        total_distance: 0.0,
        k_used: 0,
        certified: true,
        rounds: 0,
        added_pairs: 0,
        growth_pairs: 0,
        edges: 0,
        certificate_examined: 0,
        auction_bids: 0,
        seconds: 0.0,
    };
    for (_, at_t0, at_t1) in &classes {
        let positions = |x: &[[f64; 3]], members: &[u32]| -> Vec<[f64; 3]> {
            members.iter().map(|&i| x[i as usize]).collect()
        };
        let class = pair(&positions(x0, at_t0), &positions(x1, at_t1), opts)?;
        for (p, &q) in class.g.iter().enumerate() {
            g[at_t1[p] as usize] = at_t0[q as usize];
        }
        merged.total_cost += class.total_cost;
        merged.k_used = merged.k_used.max(class.k_used);
        merged.certified &= class.certified;
        merged.rounds = merged.rounds.max(class.rounds);
        merged.added_pairs += class.added_pairs;
        merged.growth_pairs += class.growth_pairs;
        merged.edges += class.edges;
        merged.certificate_examined += class.certificate_examined;
        merged.auction_bids += class.auction_bids;
    }
    merged.total_distance = total_distance(x0, x1, &g, opts.axial_period);
    merged.g = g;
    merged.seconds = start.elapsed().as_secs_f64();
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_size_means_the_bits_of_the_first_radius_throughout() {
        assert!(one_size(&[], &[]));
        assert!(one_size(&[1.0, 1.0], &[1.0]));
        assert!(!one_size(&[1.0, 1.0], &[1.0, 2.0]));
        assert!(!one_size(&[1.0, 2.0], &[1.0, 1.0]));
    }

    #[test]
    fn a_map_across_classes_or_out_of_range_does_not_respect_them() {
        let (r0, r1) = ([1.0, 2.0, 1.0], [2.0, 1.0, 1.0]);
        assert!(respects_classes(&[1, 0, 2], &r0, &r1));
        assert!(respects_classes(&[1, 2, 0], &r0, &r1));
        assert!(!respects_classes(&[0, 1, 2], &r0, &r1));
        assert!(!respects_classes(&[1, 0, 3], &r0, &r1));
        assert!(!respects_classes(&[1, 0], &r0, &r1));
    }

    /// Two classes whose unconstrained optimum crosses between them: the small particles
    /// stand at t1 where the large ones stood at t0, and the reverse.
    #[test]
    fn the_constraint_is_kept_where_the_unconstrained_optimum_breaks_it() {
        let x0 = [
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [0.0, 5.0, 0.0],
            [10.0, 5.0, 0.0],
        ];
        let r0 = [1.0, 2.0, 1.0, 2.0];
        // particle 0 (small) now near x0[1] (large), particle 1 (large) near x0[0] (small)
        let x1 = [
            [10.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 5.0, 0.0],
            [10.0, 5.0, 0.0],
        ];
        let opts = PairingOptions::for_diameter(2.0);
        let free = pair(&x0, &x1, &opts).unwrap();
        assert_eq!(free.g, [1, 0, 2, 3]);
        let kept = pair_by_size(&x0, &r0, &x1, &r0, &opts).unwrap();
        assert!(respects_classes(&kept.g, &r0, &r0));
        assert!(kept.certified);
        // small: p0 at (10, 0) onto role 0 (10) and p2 onto role 2 (0), not crossed
        // (√125 + 5); large likewise
        assert_eq!(kept.g, [0, 1, 2, 3]);
        assert!((kept.total_distance - 20.0).abs() < 1e-9);
        assert_eq!(kept.total_cost, 2 * (10.0 / opts.unit).round() as i64);
        assert!(kept.total_cost > free.total_cost);
    }
}
