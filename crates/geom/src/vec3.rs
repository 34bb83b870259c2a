//! Small vector helpers on `[f64; 3]`.
use crate::P3;

#[inline(always)]
pub fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
pub fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
pub fn scale(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline(always)]
pub fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline(always)]
pub fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline(always)]
pub fn norm2(a: P3) -> f64 {
    dot(a, a)
}
#[inline(always)]
pub fn norm(a: P3) -> f64 {
    dot(a, a).sqrt()
}
#[inline(always)]
pub fn dist2(a: P3, b: P3) -> f64 {
    norm2(sub(a, b))
}
#[inline(always)]
pub fn dist(a: P3, b: P3) -> f64 {
    norm(sub(a, b))
}
/// Unit vector; the zero vector maps to itself.
#[inline]
pub fn normalize(a: P3) -> P3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        a
    }
}
/// Twice the area vector of triangle abc (right-hand rule).
#[inline(always)]
pub fn tri_normal(a: P3, b: P3, c: P3) -> P3 {
    cross(sub(b, a), sub(c, a))
}
#[inline(always)]
pub fn centroid3(a: P3, b: P3, c: P3) -> P3 {
    [
        (a[0] + b[0] + c[0]) / 3.0,
        (a[1] + b[1] + c[1]) / 3.0,
        (a[2] + b[2] + c[2]) / 3.0,
    ]
}
/// Six times the signed volume of tet abcd, in floating point (not exact).
#[inline(always)]
pub fn tet_volume6(a: P3, b: P3, c: P3, d: P3) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}
