//! Spatial renumbering. Particle ids arrive in no spatial order, which makes every
//! graph walk of the solver a cache miss; sorting rows and columns along a Morton
//! (Z-order) curve makes neighbours in space neighbours in memory. The solver works on
//! the renumbered problem and maps the result back.

use rayon::prelude::*;

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(mut x: u64) -> u64 {
    x &= 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The permutation (new index → old index) that sorts `pts` along a Morton curve over
/// the box `[lo, hi]`. Ties are broken by index, so the order is deterministic.
///
/// The curve's cells are cubes in space: one scale for all three axes, set by the box's
/// longest side. Scaled per axis, a long bed's cells are needles: on the long kiln (a box
/// of 634 × 35 × 25 diameters) a cell one diameter across was 20 diameters long, so a
/// row's 32 nearest columns lay 20 845 indices apart on average and on 24.6 distinct
/// cache lines of an 8-byte-per-column array; with cubes, 793 indices and 12.1 lines,
/// and the auction's bids took a fifth to a quarter less time (docs/benchmarks.md).
pub(crate) fn morton_order(pts: &[[f64; 3]], lo: [f64; 3], hi: [f64; 3]) -> Vec<u32> {
    let side = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    let scale = if side > 0.0 {
        ((1u64 << 21) - 1) as f64 / side
    } else {
        0.0
    };
    let mut keyed: Vec<(u64, u32)> = pts
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let mut key = 0;
            for a in 0..3 {
                let c = ((p[a] - lo[a]) * scale).clamp(0.0, ((1u64 << 21) - 1) as f64) as u64;
                key |= spread(c) << a;
            }
            (key, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Bounding box of two point sets.
pub(crate) fn bounds(a: &[[f64; 3]], b: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in a.iter().chain(b) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0x1f_ffff).count_ones(), 21);
    }

    #[test]
    fn order_is_a_permutation_and_local() {
        let pts: Vec<[f64; 3]> = (0..64)
            .rev()
            .map(|i| [(i % 4) as f64, ((i / 4) % 4) as f64, (i / 16) as f64])
            .collect();
        let (lo, hi) = bounds(&pts, &[]);
        let ord = morton_order(&pts, lo, hi);
        let mut s = ord.clone();
        s.sort_unstable();
        assert_eq!(s, (0..64).collect::<Vec<u32>>());
        // The first 8 in Morton order are the 2×2×2 corner cube at the origin.
        for &i in &ord[..8] {
            let p = pts[i as usize];
            assert!(p.iter().all(|&c| c <= 1.0), "{p:?}");
        }
    }

    #[test]
    fn cells_are_cubes_on_a_long_bed() {
        // A lattice 4 × 64 × 4, long along y as a kiln. Each aligned 2×2×2 block of the
        // lattice is one cell of the curve, so it comes out as eight consecutive points
        // (with a scale per axis a cell spans many lattice steps along y).
        let pts: Vec<[f64; 3]> = (0..1024)
            .map(|i| [(i % 4) as f64, (i / 16) as f64, ((i / 4) % 4) as f64])
            .collect();
        let (lo, hi) = bounds(&pts, &[]);
        let ord = morton_order(&pts, lo, hi);
        for block in ord.chunks(8) {
            let corner = pts[block[0] as usize].map(|c| (c / 2.0).floor());
            for &i in block {
                let cell = pts[i as usize].map(|c| (c / 2.0).floor());
                assert_eq!(
                    cell, corner,
                    "{:?} and {:?}",
                    pts[i as usize], pts[block[0] as usize]
                );
            }
        }
    }
}
