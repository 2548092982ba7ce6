//! Four contacts' `f64`s in one AVX register: the batched pair law's lane type on CPUs with
//! AVX2 but not AVX-512, where the compiler leaves the lane loop scalar (its cost model
//! declines the four-wide roots and divisions that are in fact worth it).
//!
//! Each operation is the single IEEE instruction `f64` does (no fused multiply–add, no
//! approximate root), so a lane's result has the bits of the lone contact's.
//!
//! Only `pair_batch::lanes_avx2`, reached once AVX2 is detected, makes values of this type;
//! the module is private to `pair_batch`, so no other code can name the type (the law's
//! generic functions get it from there as their `T`).

use super::Lane;
use crate::math::Real;
use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Clone, Copy)]
pub struct F64x4(__m256d);

impl Lane for F64x4 {
    const WIDTH: usize = 4;

    /// `a[0..4]`.
    #[inline(always)]
    fn load(a: &[f64]) -> Self {
        let a = &a[..Self::WIDTH];
        // SAFETY: four doubles are in bounds; AVX is present (module docs)
        Self(unsafe { _mm256_loadu_pd(a.as_ptr()) })
    }

    /// Into `a[0..4]`.
    #[inline(always)]
    fn store(self, a: &mut [f64]) {
        let a = &mut a[..Self::WIDTH];
        // SAFETY: as in `load`
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), self.0) }
    }
}

macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                // SAFETY: AVX is present (module docs)
                Self(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    };
}
binary!(Add, add, _mm256_add_pd);
binary!(Sub, sub, _mm256_sub_pd);
binary!(Mul, mul, _mm256_mul_pd);
binary!(Div, div, _mm256_div_pd);

impl Neg for F64x4 {
    type Output = Self;
    /// Flips the sign bit, as `f64`'s negation does (a subtraction from zero would not
    /// give −0 for 0).
    #[inline(always)]
    fn neg(self) -> Self {
        // SAFETY: AVX is present (module docs)
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl Real for F64x4 {
    /// All ones in the lanes where a comparison holds.
    type Mask = __m256d;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: AVX is present (module docs)
        Self(unsafe { _mm256_set1_pd(x) })
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: AVX is present (module docs); correctly rounded, as `f64::sqrt`
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }

    /// Clears the sign bit, as `f64::abs` does.
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: AVX is present (module docs)
        Self(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
    }

    /// Ordered and quiet: false where either lane is NaN, as `>` on `f64`.
    #[inline(always)]
    fn gt(self, other: Self) -> __m256d {
        // SAFETY: AVX is present (module docs)
        unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, other.0) }
    }

    #[inline(always)]
    fn select(keep_a: __m256d, a: Self, b: Self) -> Self {
        // SAFETY: AVX is present (module docs); blendv takes the second operand where the
        // mask's sign bit is set
        Self(unsafe { _mm256_blendv_pd(b.0, a.0, keep_a) })
    }
}
