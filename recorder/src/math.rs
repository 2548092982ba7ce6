//! Small `[f64; 3]` vector helpers used by every stage (kept inline-able and allocation-free),
//! generic over [`Real`] so that the contact law can run on several contacts at once.

use std::ops::{Add, Div, Mul, Neg, Sub};

pub type Vec3 = [f64; 3];

/// A number the contact law runs on: one `f64`, or the `f64`s of several contacts in one
/// vector register (the batched pair law, `contact::pair_batch`). Every lane does the IEEE
/// operation `f64` does, so a contact's result has the same bits whichever type carried it.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Which lanes a comparison holds in.
    type Mask: Copy;
    /// `x` in every lane.
    fn splat(x: f64) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `self > other`, false where either is NaN.
    fn gt(self, other: Self) -> Self::Mask;
    /// `a` where `keep_a`, else `b`.
    fn select(keep_a: Self::Mask, a: Self, b: Self) -> Self;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn select(keep_a: bool, a: Self, b: Self) -> Self {
        if keep_a {
            a
        } else {
            b
        }
    }
}

#[inline(always)]
pub fn add<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub fn sub<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn scale<T: Real>(a: [T; 3], s: T) -> [T; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub fn dot<T: Real>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn cross<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
pub fn norm2<T: Real>(a: [T; 3]) -> T {
    dot(a, a)
}

/// `a` without its component along the unit vector `n`.
#[inline(always)]
pub fn tangential<T: Real>(a: [T; 3], n: [T; 3]) -> [T; 3] {
    sub(a, scale(n, dot(a, n)))
}

/// `a` where `keep_a`, else `b`: both already computed, so this is a select, not a branch.
#[inline(always)]
pub fn select<T: Real>(keep_a: T::Mask, a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        T::select(keep_a, a[0], b[0]),
        T::select(keep_a, a[1], b[1]),
        T::select(keep_a, a[2], b[2]),
    ]
}
