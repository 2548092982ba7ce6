//! Small `[f64; 3]` vector helpers used by every stage (kept inline-able and allocation-free).

pub type Vec3 = [f64; 3];

#[inline(always)]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
pub fn norm2(a: Vec3) -> f64 {
    dot(a, a)
}

/// `a` without its component along the unit vector `n`.
#[inline(always)]
pub fn tangential(a: Vec3, n: Vec3) -> Vec3 {
    sub(a, scale(n, dot(a, n)))
}

/// `a` where `keep_a`, else `b`: both already computed, so this is a select, not a branch.
#[inline(always)]
pub fn select(keep_a: bool, a: Vec3, b: Vec3) -> Vec3 {
    [
        if keep_a { a[0] } else { b[0] },
        if keep_a { a[1] } else { b[1] },
        if keep_a { a[2] } else { b[2] },
    ]
}
