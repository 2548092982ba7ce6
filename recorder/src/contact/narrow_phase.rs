//! The pair stage's narrow phase: which entries of the half list touch now. Touching pairs
//! go into a [`PairBatch`] with the index of their history before this step: the histories
//! of a task's touching entries are stored packed, in entry order, so the `k`-th entry that
//! touched at the last step has history `k`, and a pair that has just touched gets a zero one.
//!
//! About one entry in three touches, in no pattern the branch predictor can learn, so the
//! scan is worth doing without a branch per entry: when the batch runs with AVX-512
//! (`crate::simd`) eight entries are tested at once and their hits compressed into the batch. Both scans push the same pairs
//! in the same order (and compute the same bits), so the results do not depend on the CPU.

use super::contact_sphere_sphere::overlapping;
use super::pair_batch::PairBatch;
use crate::math::*;
use crate::periodic::{nearest_image, AxialPeriod};
use std::ops::Range;

/// The list entries of a run of slots, and where their histories begin.
#[derive(Clone)]
pub struct ListEntries<'a> {
    pub slots: Range<usize>,
    /// Entries of slot `i` are `offsets[i]..offsets[i + 1]` of `partners`.
    pub offsets: &'a [u32],
    pub partners: &'a [u32],
    /// Entry `e`'s touching flag is at `e - first_entry` of the slice the scan is given.
    pub first_entry: usize,
    /// The old-history index of a pair that has just touched: a zero history.
    pub fresh: u32,
}

/// Scans the entries and updates their touching flags: each touching pair is pushed into
/// `batch`, and `full(batch)` is called whenever the batch is full (the caller evaluates it
/// and consumes what it evaluated). Returns the touching pairs; the batch may hold some of
/// them when it returns.
#[inline(always)]
pub fn scan(
    entries: &ListEntries,
    pos: &[Vec3],
    radius: &[f64],
    period: Option<AxialPeriod>,
    touching: &mut [bool],
    batch: &mut PairBatch,
    full: &mut impl FnMut(&mut PairBatch),
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    {
        if batch.simd() == crate::simd::Simd::Avx512 {
            // SAFETY: a batch runs with AVX-512 only on a CPU with its F, VL and BW parts
            // (`PairBatch::with_simd`)
            return unsafe { scan_avx512(entries, pos, radius, period, touching, batch, full) };
        }
    }
    scan_entries(entries, pos, radius, period, touching, batch, full)
}

/// One entry at a time.
#[inline(always)]
fn scan_entries(
    entries: &ListEntries,
    pos: &[Vec3],
    radius: &[f64],
    period: Option<AxialPeriod>,
    touch: &mut [bool],
    batch: &mut PairBatch,
    full: &mut impl FnMut(&mut PairBatch),
) -> u64 {
    let ListEntries {
        slots,
        offsets,
        partners,
        first_entry,
        fresh,
    } = entries.clone();
    let (mut touching, mut touched_before) = (0, 0);
    for i in slots.clone() {
        let (pos_i, radius_i) = (pos[i], radius[i]);
        let (first, last) = (offsets[i] as usize, offsets[i + 1] as usize);
        for (e, &partner) in (first..last).zip(&partners[first..last]) {
            let j = partner as usize;
            let delta = nearest_image(sub(pos_i, pos[j]), period);
            let local = e - first_entry;
            let old = if touch[local] { touched_before } else { fresh };
            touched_before += u32::from(touch[local]);
            let Some(r2) = overlapping(delta, radius_i, radius[j]) else {
                touch[local] = false;
                continue;
            };
            touch[local] = true;
            touching += 1;
            if batch.push(i, j, old as usize, delta, r2) {
                full(batch);
            }
        }
    }
    touching
}

/// Eight entries at a time: the partners' positions and radii are gathered, the overlap
/// test gives a mask, and the hits are compressed into the batch (with their old history
/// indices, expanded from a running count into the lanes that touched before). The
/// arithmetic is `overlapping`'s, operation for operation (no fused multiply-add), so the
/// pairs and their `delta` and `r2` are those of [`scan_entries`]; so is the nearest image
/// of a periodic section ([`nearest_image_lanes`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw")]
fn scan_avx512(
    entries: &ListEntries,
    pos: &[Vec3],
    radius: &[f64],
    period: Option<AxialPeriod>,
    touch: &mut [bool],
    batch: &mut PairBatch,
    full: &mut impl FnMut(&mut PairBatch),
) -> u64 {
    use std::arch::x86_64::*;
    let ListEntries {
        slots,
        offsets,
        partners,
        first_entry,
        fresh,
    } = entries.clone();
    let coordinates = pos.as_ptr() as *const f64;
    let last = offsets[slots.end] as usize;
    // the masked loads and stores below rely on it (offsets do not decrease)
    assert!(last <= partners.len() && last - first_entry <= touch.len());
    assert!(pos.len() == radius.len() && pos.len() <= i32::MAX as usize / 3);
    let slot_count = _mm256_set1_epi32(pos.len() as i32);
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let fresh = _mm256_set1_epi32(fresh as i32);
    let (mut touching, mut touched_before) = (0, 0u32);
    for i in slots.clone() {
        let (pos_i, radius_i) = (pos[i], radius[i]);
        let xi = pos_i.map(|x| _mm512_set1_pd(x));
        let ri = _mm512_set1_pd(radius_i);
        let end = offsets[i + 1] as usize;
        let mut e = offsets[i] as usize;
        while e < end {
            let valid: __mmask8 = if end - e >= 8 {
                0xff
            } else {
                (1u8 << (end - e)) - 1
            };
            let local = e - first_entry;
            // SAFETY: the masked loads and stores reach only the valid lanes, entries
            // e..end, inside `partners` and (shifted by first_entry) `touch` (asserted above);
            // the gathers read the valid lanes' partner slots, checked below pos.len()
            let (j, delta, r2, hit, was) = unsafe {
                let j = _mm256_maskz_loadu_epi32(valid, partners.as_ptr().add(e) as *const i32);
                // a partner outside the arrays would make the gathers read past them
                let outside = _mm256_mask_cmpge_epu32_mask(valid, j, slot_count);
                assert!(outside == 0, "a list entry of slot {i} names no particle");
                let j3 = _mm256_add_epi32(_mm256_add_epi32(j, j), j);
                let zero = _mm512_setzero_pd();
                let mut delta: [__m512d; 3] = std::array::from_fn(|a| {
                    let xj = _mm512_mask_i32gather_pd::<8>(zero, valid, j3, coordinates.add(a));
                    _mm512_sub_pd(xi[a], xj)
                });
                if let Some(period) = period {
                    delta[1] = nearest_image_lanes(delta[1], period.length);
                }
                let rj = _mm512_mask_i32gather_pd::<8>(zero, valid, j, radius.as_ptr());
                let r2 = _mm512_add_pd(
                    _mm512_add_pd(
                        _mm512_mul_pd(delta[0], delta[0]),
                        _mm512_mul_pd(delta[1], delta[1]),
                    ),
                    _mm512_mul_pd(delta[2], delta[2]),
                );
                let radsum = _mm512_add_pd(ri, rj);
                let reach = _mm512_mul_pd(radsum, radsum);
                let hit = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(valid, r2, reach);
                let flags = touch.as_mut_ptr().add(local) as *mut i8;
                let was = _mm_maskz_loadu_epi8(valid as __mmask16, flags);
                let was = _mm_test_epi8_mask(was, was) as __mmask8;
                _mm_mask_storeu_epi8(
                    flags,
                    valid as __mmask16,
                    _mm_maskz_set1_epi8(hit as __mmask16, 1),
                );
                (j, delta, r2, hit, was)
            };
            // the lanes that touched before take the next old indices in order, the others
            // the zero history
            let count = _mm256_add_epi32(_mm256_set1_epi32(touched_before as i32), lane);
            let old = _mm256_mask_expand_epi32(fresh, was, count);
            touched_before += was.count_ones();
            if hit != 0 {
                touching += u64::from(hit.count_ones());
                if batch.push_lanes(hit, i, j, old, delta, r2) {
                    full(batch);
                }
            }
            e += 8;
        }
    }
    touching
}

/// [`AxialPeriod::nearest_image`] on eight y differences at once, bit for bit:
/// `Δy − L · round(Δy / L)`. Positions are wrapped into the section at every step, so
/// `|Δy / L| < 1` and `round` is 1 from ½ up, −1 from −½ down and a zero of `Δy`'s sign
/// between (the product and the difference then give the scalar's bits, `−0.0` included).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw")]
fn nearest_image_lanes(dy: std::arch::x86_64::__m512d, length: f64) -> std::arch::x86_64::__m512d {
    use std::arch::x86_64::*;
    let l = _mm512_set1_pd(length);
    let q = _mm512_div_pd(dy, l);
    let up = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(q, _mm512_set1_pd(0.5));
    let down = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(q, _mm512_set1_pd(-0.5));
    // a zero with q's sign, then ±1 where q rounds away from it
    let sign = _mm512_and_si512(_mm512_castpd_si512(q), _mm512_set1_epi64(i64::MIN));
    let signed_zero = _mm512_castsi512_pd(sign);
    let k = _mm512_mask_mov_pd(signed_zero, up, _mm512_set1_pd(1.0));
    let k = _mm512_mask_mov_pd(k, down, _mm512_set1_pd(-1.0));
    _mm512_sub_pd(dy, _mm512_mul_pd(l, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::pair_batch::LANES;
    use crate::insertion::uniform;
    use rand_xoshiro::rand_core::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    type Pushed = Vec<(u32, u32, u32, [u64; 3], u64)>;

    /// What a scan did: the pairs pushed in order (old history index, bits of `delta` and
    /// `r2`), the touching flags after it, and the count it returned.
    fn outcome(
        vector: bool,
        entries: &ListEntries,
        pos: &[Vec3],
        radius: &[f64],
        period: Option<AxialPeriod>,
        touching: &[bool],
    ) -> (Pushed, Vec<bool>, u64) {
        let mut touch = touching.to_vec();
        let mut pushed = Pushed::new();
        let mut take = |batch: &mut PairBatch| {
            // what `evaluate` would take: the first LANES pushed
            let n = batch.len().min(LANES);
            for l in 0..n {
                let (i, j, e, d, r2) = batch.pushed(l);
                pushed.push((i, j, e, d.map(f64::to_bits), r2.to_bits()));
            }
            batch.skip(n);
        };
        let mut batch = PairBatch::default();
        let count = if vector {
            assert!(
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                    && std::arch::is_x86_feature_detected!("avx512bw")
            );
            // SAFETY: the features were checked just above
            unsafe {
                scan_avx512(
                    entries, pos, radius, period, &mut touch, &mut batch, &mut take,
                )
            }
        } else {
            scan_entries(
                entries, pos, radius, period, &mut touch, &mut batch, &mut take,
            )
        };
        take(&mut batch);
        assert_eq!(batch.len(), 0);
        (pushed, touch, count)
    }

    #[test]
    fn a_pair_gets_the_packed_index_of_its_old_history_or_the_zero_one() {
        // four partners of sphere 0: 1 and 2 touch it now, 3 is out of reach, 4 touches
        let pos = [
            [0.0; 3],
            [0.009, 0.0, 0.0],
            [0.0, 0.0095, 0.0],
            [0.02, 0.0, 0.0],
            [0.0, 0.0, -0.0099],
        ];
        let radius = [0.005; 5];
        let (offsets, partners) = ([0, 4, 4, 4, 4, 4], [1, 2, 3, 4]);
        let entries = ListEntries {
            slots: 0..5,
            offsets: &offsets,
            partners: &partners,
            first_entry: 0,
            fresh: 99,
        };
        // entries 0, 2 and 3 touched at the last step: old histories 0, 1 and 2
        let (pushed, touch, count) = outcome(
            false,
            &entries,
            &pos,
            &radius,
            None,
            &[true, false, true, true],
        );
        let old: Vec<u32> = pushed.iter().map(|p| p.2).collect();
        assert_eq!(
            old,
            [0, 99, 2],
            "entry 1 has just touched, entry 2 no longer does"
        );
        assert_eq!(touch, [true, true, false, true]);
        assert_eq!(count, 3);
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_vector_scan_pushes_the_pairs_and_bits_of_the_entry_by_entry_scan() {
        if !std::arch::is_x86_feature_detected!("avx512bw")
            || !std::arch::is_x86_feature_detected!("avx512vl")
        {
            eprintln!("no AVX-512 on this CPU: the vector scan is not used here");
            return;
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut u = move || uniform(&mut rng);
        // spheres of unequal radii in a small box: about a third of the entries touch
        let n = 400;
        let pos: Vec<Vec3> = (0..n)
            .map(|_| [0.05 * u(), 0.05 * u(), 0.05 * u()])
            .collect();
        let radius: Vec<f64> = (0..n).map(|_| 0.004 + 0.002 * u()).collect();
        // 0 to 19 entries per slot: every tail length of the 8-wide groups, and several
        // batches filled in the middle of a slot's entries
        let (mut offsets, mut partners) = (vec![0u32], vec![]);
        for _ in 0..n {
            let count = (19.0 * u()) as usize;
            partners.extend((0..count).map(|_| ((n as f64 * u()) as u32).min(n as u32 - 1)));
            offsets.push(partners.len() as u32);
        }
        // slots 37.. of a task whose histories start at its first entry
        let first_entry = offsets[37] as usize;
        let entries = ListEntries {
            slots: 37..n,
            offsets: &offsets,
            partners: &partners,
            first_entry,
            fresh: u32::MAX,
        };
        let local = partners.len() - first_entry;
        let touching: Vec<bool> = (0..local).map(|_| u() < 0.4).collect();

        let one = outcome(false, &entries, &pos, &radius, None, &touching);
        let eight = outcome(true, &entries, &pos, &radius, None, &touching);
        assert_eq!(one.0, eight.0, "pushed pairs");
        assert_eq!(one.1, eight.1, "touching flags");
        assert_eq!(one.2, eight.2, "count");
        // the sample exercises every path: hits, misses, contacts that ended and several
        // full batches
        let ended = (0..local).filter(|&e| touching[e] && !one.1[e]).count();
        let hits = one.1.iter().filter(|&&t| t).count();
        let kept = one.0.iter().filter(|p| p.2 != u32::MAX).count();
        assert!(
            ended > 0 && kept > 0 && kept < hits && hits > 3 * 16 && hits < local,
            "{ended} ended, {kept} kept, {hits} of {local}"
        );
        assert_eq!(one.2 as usize, hits);
    }

    /// In a periodic section the vector scan takes the same nearest image as the entry by
    /// entry one, bit for bit: pairs across the seam, differences of exactly half a period
    /// (which round away from zero) and a difference of −0.0.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn the_vector_scan_takes_the_nearest_image_of_the_entry_by_entry_scan() {
        if !std::arch::is_x86_feature_detected!("avx512bw")
            || !std::arch::is_x86_feature_detected!("avx512vl")
        {
            eprintln!("no AVX-512 on this CPU: the vector scan is not used here");
            return;
        }
        let length = 0.04;
        let period = Some(AxialPeriod { length });
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let mut u = move || uniform(&mut rng);
        // a thin periodic box: y in [−L/2, L/2), every sphere near some face
        let n = 300;
        let mut pos: Vec<Vec3> = (0..n)
            .map(|_| [0.03 * u(), length * (u() - 0.5), 0.03 * u()])
            .collect();
        // exactly half a period apart along y (q = ±0.5), and y = −0.0 against y = +0.0
        pos[0] = [0.01, 0.01, 0.01];
        pos[1] = [0.01, -0.01, 0.01];
        pos[2] = [0.02, -0.0, 0.02];
        pos[3] = [0.02, 0.0, 0.02];
        let mut radius: Vec<f64> = (0..n).map(|_| 0.003 + 0.002 * u()).collect();
        // 0 and 1 touch whichever image: the nearest is the one the scans must agree on
        (radius[0], radius[1]) = (0.011, 0.011);
        let (mut offsets, mut partners) = (vec![0u32], vec![]);
        for i in 0..n {
            let mut mine: Vec<u32> = match i {
                0 => vec![1],
                1 => vec![0],
                2 => vec![3],
                3 => vec![2],
                _ => vec![],
            };
            let count = (19.0 * u()) as usize;
            mine.extend((0..count).map(|_| ((n as f64 * u()) as u32).min(n as u32 - 1)));
            partners.extend(mine);
            offsets.push(partners.len() as u32);
        }
        let entries = ListEntries {
            slots: 0..n,
            offsets: &offsets,
            partners: &partners,
            first_entry: 0,
            fresh: u32::MAX,
        };
        let touching: Vec<bool> = (0..partners.len()).map(|_| u() < 0.4).collect();
        let one = outcome(false, &entries, &pos, &radius, period, &touching);
        let eight = outcome(true, &entries, &pos, &radius, period, &touching);
        assert_eq!(one.0, eight.0, "pushed pairs");
        assert_eq!(one.1, eight.1, "touching flags");
        assert_eq!(one.2, eight.2, "count");
        // the seam matters: without the nearest image fewer pairs touch
        let plain = outcome(false, &entries, &pos, &radius, None, &touching);
        assert!(
            plain.2 < one.2,
            "{} without the seam, {} across it",
            plain.2,
            one.2
        );
        // half a period apart, the pair takes the image at Δy = −L/2, as round(½) = 1
        let half = one
            .0
            .iter()
            .find(|p| (p.0, p.1) == (0, 1))
            .expect("0 and 1 touch");
        assert_eq!(f64::from_bits(half.3[1]), 0.02 - length);
        let zero = one
            .0
            .iter()
            .find(|p| (p.0, p.1) == (2, 3))
            .expect("2 and 3 touch");
        assert_eq!(
            zero.3[1],
            0.0f64.to_bits(),
            "−0.0 − 0.0 across no seam is +0.0"
        );
    }
}
