//! Small vector helpers on `[f64; 3]`.
use crate::P3;

/// The difference `a - b`.
#[inline(always)]
pub fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// The sum `a + b`.
#[inline(always)]
pub fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `a` multiplied by the scalar `s`.
#[inline(always)]
pub fn scale(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// The dot product of `a` and `b`.
#[inline(always)]
pub fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// The cross product `a x b` (right-hand rule).
#[inline(always)]
pub fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
/// The squared length of `a`, without the square root.
#[inline(always)]
pub fn norm2(a: P3) -> f64 {
    dot(a, a)
}
/// The Euclidean length of `a`.
#[inline(always)]
pub fn norm(a: P3) -> f64 {
    dot(a, a).sqrt()
}
/// The squared distance between `a` and `b`, without the square root.
#[inline(always)]
pub fn dist2(a: P3, b: P3) -> f64 {
    norm2(sub(a, b))
}
/// The Euclidean distance between `a` and `b`.
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
/// The centroid of triangle `abc`.
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

/// Squared distance from `p` to triangle `abc` (closest point by regions,
/// Ericson, Real-Time Collision Detection §5.1.5).
pub fn point_triangle_dist2(p: P3, a: P3, b: P3, c: P3) -> f64 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return norm2(ap);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return norm2(bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return dist2(p, add(a, scale(ab, v)));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return norm2(cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return dist2(p, add(a, scale(ac, w)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return dist2(p, add(b, scale(sub(c, b), w)));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    dist2(p, add(a, add(scale(ab, v), scale(ac, w))))
}

/// Squared distance between segments `p0p1` and `q0q1` (closest points by
/// clamped parameters, Ericson §5.1.9).
pub fn segment_segment_dist2(p0: P3, p1: P3, q0: P3, q1: P3) -> f64 {
    let d1 = sub(p1, p0);
    let d2 = sub(q1, q0);
    let r = sub(p0, q0);
    let a = norm2(d1);
    let e = norm2(d2);
    let f = dot(d2, r);
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return norm2(r);
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = dot(d1, r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = dot(d1, d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    dist2(add(p0, scale(d1, s)), add(q0, scale(d2, t)))
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn point_triangle_distance_by_region() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        assert_eq!(point_triangle_dist2([0.5, 0.5, 3.0], a, b, c), 9.0); // face
        assert_eq!(point_triangle_dist2([-1.0, -1.0, 0.0], a, b, c), 2.0); // vertex a
        assert_eq!(point_triangle_dist2([1.0, -2.0, 0.0], a, b, c), 4.0); // edge ab
        assert!((point_triangle_dist2([2.0, 2.0, 0.0], a, b, c) - 2.0).abs() < 1e-15); // edge bc
        assert_eq!(point_triangle_dist2([3.0, 0.0, 1.0], a, b, c), 2.0); // vertex b
    }

    #[test]
    fn segment_distance_by_region() {
        let o = [0.0, 0.0, 0.0];
        let x = [2.0, 0.0, 0.0];
        // Crossing at a height: interior to interior.
        assert_eq!(
            segment_segment_dist2(o, x, [1.0, -1.0, 0.5], [1.0, 1.0, 0.5]),
            0.25
        );
        // Parallel and overlapping.
        assert_eq!(
            segment_segment_dist2(o, x, [1.0, 1.0, 0.0], [3.0, 1.0, 0.0]),
            1.0
        );
        // End to end.
        assert_eq!(
            segment_segment_dist2(o, x, [3.0, 0.0, 0.0], [4.0, 1.0, 0.0]),
            1.0
        );
        // End to interior.
        assert_eq!(
            segment_segment_dist2(o, x, [1.0, 2.0, 0.0], [1.0, 5.0, 0.0]),
            4.0
        );
        // Degenerate segment.
        assert_eq!(
            segment_segment_dist2(o, x, [1.0, 0.0, 3.0], [1.0, 0.0, 3.0]),
            9.0
        );
    }
}
