//! The quality report's dihedral angles with two arc tangents per tet
//! instead of six, and the same results.
//!
//! Each angle is `atan2(y, x)` of its faces' normals. A polynomial
//! arc tangent, within [`APPROX_ERR`] of it, places every angle in its
//! 1-degree bin unless it lies within [`GUARD`] of a bin edge, and picks
//! the few angles that can be the smallest or the largest. Only those,
//! and the angles near an edge, take `atan2`: the bins, the min and the
//! max are those of six `atan2`s (a test compares them).
use crate::tetmesh::TET_FACES;
use parafront_geom::{cross, dot, norm, sub, P3};

/// Bound on `|atan2_deg_approx - atan2.to_degrees()|`, in degrees: the
/// polynomial's 1e-5 rad (Abramowitz and Stegun 4.4.49) is 5.73e-4
/// degrees; the rest covers its rounding, far smaller.
pub(crate) const APPROX_ERR: f64 = 1e-3;
/// An angle this close to a whole degree takes `atan2` for its bin.
const GUARD: f64 = 2.0 * APPROX_ERR;

/// The `(y, x)` of each dihedral angle at the edges [`crate::quality::TET_EDGES`]:
/// the angle is `atan2(y, x)`, between the faces opposite the other two
/// vertices (pi minus their outward normals' angle).
#[inline]
pub(crate) fn dihedral_pairs(p: [P3; 4]) -> [[f64; 2]; 6] {
    // Plain loops: `array::map` was left as a call in the report's loop.
    let mut n = [[0.0; 3]; 4];
    for (k, f) in TET_FACES.iter().enumerate() {
        let (a, b, c) = (p[f[0]], p[f[1]], p[f[2]]);
        n[k] = cross(sub(b, a), sub(c, a));
    }
    // The faces opposite the two vertices not on each edge of TET_EDGES.
    const OPP: [[usize; 2]; 6] = [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]];
    let mut yx = [[0.0; 2]; 6];
    for (e, [k, l]) in OPP.into_iter().enumerate() {
        yx[e] = [norm(cross(n[k], n[l])), -dot(n[k], n[l])];
    }
    yx
}

/// `atan2(y, x)` in degrees for `y >= 0`, within [`APPROX_ERR`]; NaN
/// where `y` and `x` are both zero or either is not finite.
#[inline]
pub(crate) fn atan2_deg_approx(y: f64, x: f64) -> f64 {
    const A: [f64; 5] = [0.999_866, -0.330_299_5, 0.180_141, -0.085_133, 0.020_835_1];
    let ax = x.abs();
    // Selects, not branches: which side of 45 degrees is a coin toss.
    let steep = y > ax;
    let t = y.min(ax) / y.max(ax);
    let t2 = t * t;
    let a = t * (A[0] + t2 * (A[1] + t2 * (A[2] + t2 * (A[3] + t2 * A[4]))));
    let a = if steep {
        std::f64::consts::FRAC_PI_2 - a
    } else {
        a
    };
    let a = if x < 0.0 { std::f64::consts::PI - a } else { a };
    let d = a.to_degrees();
    if d.is_finite() && ax.is_finite() && y.is_finite() {
        d
    } else {
        f64::NAN
    }
}

/// A tet's dihedral angles as the report uses them: a value in the
/// 1-degree bin of each (a bin of width 1 from 0 truncates it), the
/// smallest and the largest, exactly as from six `atan2`s. `None` where
/// an angle is not defined (a degenerate face): the caller then takes the
/// six `atan2`s.
#[inline]
pub(crate) fn report_angles(p: [P3; 4]) -> Option<([f64; 6], f64, f64)> {
    let yx = dihedral_pairs(p);
    let mut approx = [0.0; 6];
    let (mut lo, mut hi, mut nan) = (f64::INFINITY, f64::NEG_INFINITY, false);
    for e in 0..6 {
        let a = atan2_deg_approx(yx[e][0], yx[e][1]);
        approx[e] = a;
        nan |= a.is_nan();
        lo = lo.min(a);
        hi = hi.max(a);
    }
    if nan {
        return None;
    }
    let exact = |e: usize| yx[e][0].atan2(yx[e][1]).to_degrees();
    let mut binned = approx;
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    for e in 0..6 {
        let a = approx[e];
        // Near a whole degree (or below 0): the exact value for the bin.
        let frac = a - (a as i64) as f64;
        let near_edge = !(GUARD..=1.0 - GUARD).contains(&frac);
        // Any angle that can be the smallest (largest) is within
        // 2 APPROX_ERR of the smallest (largest) approximation.
        let near_lo = a <= lo + 2.0 * APPROX_ERR;
        let near_hi = a >= hi - 2.0 * APPROX_ERR;
        if near_edge || near_lo || near_hi {
            let x = exact(e);
            if near_edge {
                binned[e] = x;
            }
            if near_lo {
                min = min.min(x);
            }
            if near_hi {
                max = max.max(x);
            }
        }
    }
    Some((binned, min, max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::dihedral_angles;

    fn rng(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn the_approximation_is_within_its_bound() {
        let mut r = rng(7);
        let mut worst: f64 = 0.0;
        for i in 0..2_000_000 {
            // Angles all over [0, 180], at scales from 1e-150 to 1e150.
            let th = std::f64::consts::PI * r();
            let s = 10f64.powf(300.0 * r() - 150.0);
            let (y, x) = (s * th.sin().abs(), s * th.cos());
            let (y, x) = match i % 1000 {
                0 => (0.0, x),
                1 => (y, 0.0),
                2 => (y, -0.0),
                _ => (y, x),
            };
            let d = (atan2_deg_approx(y, x) - y.atan2(x).to_degrees()).abs();
            worst = worst.max(d);
        }
        assert!(worst < 0.7 * APPROX_ERR, "worst error {worst} deg");
        assert!(atan2_deg_approx(0.0, 0.0).is_nan());
        assert!(atan2_deg_approx(f64::INFINITY, 1.0).is_nan());
        assert!(atan2_deg_approx(1.0, f64::NAN).is_nan());
    }

    /// Bins, min and max as six `atan2`s give them, on tets from regular to
    /// needles, slivers and caps, and on angles right at bin edges.
    #[test]
    fn report_angles_are_those_of_six_arc_tangents() {
        let mut r = rng(11);
        let mut tets: Vec<[P3; 4]> = Vec::new();
        for _ in 0..300_000 {
            let mut p = [[0.0; 3]; 4];
            let squash = 10f64.powf(-6.0 * r());
            for v in &mut p {
                *v = [r(), r(), squash * r()];
            }
            tets.push(p);
        }
        // Regular tets, turned and scaled: six angles a few ulps apart,
        // whose smallest and largest the polynomial cannot tell.
        for _ in 0..20_000 {
            let (a, b, c) = (6.3 * r(), 6.3 * r(), 10f64.powf(8.0 * r() - 4.0));
            let turn = |v: P3| {
                let (x, y) = (
                    v[0] * a.cos() - v[1] * a.sin(),
                    v[0] * a.sin() + v[1] * a.cos(),
                );
                let (y, z) = (y * b.cos() - v[2] * b.sin(), y * b.sin() + v[2] * b.cos());
                [c * x + 0.3, c * y - 1.7, c * z + 2.2]
            };
            let s = 1.0 / 2f64.sqrt();
            tets.push([
                turn([1.0, 0.0, -s]),
                turn([-1.0, 0.0, -s]),
                turn([0.0, 1.0, s]),
                turn([0.0, -1.0, s]),
            ]);
        }
        // Whole-degree angles: the bin edges themselves.
        for deg in 1..180 {
            let th = (deg as f64).to_radians();
            tets.push([
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.3, 1.0, 0.0],
                [0.5, th.cos(), th.sin()],
            ]);
        }
        let mut fast = 0;
        for p in tets {
            let d = dihedral_angles(p);
            let Some((bins, min, max)) = report_angles(p) else {
                assert!(d.iter().any(|a| a.is_nan()) || d.iter().any(|&a| a == 0.0 || a == 180.0));
                continue;
            };
            fast += 1;
            for e in 0..6 {
                assert_eq!(bins[e].floor(), d[e].floor(), "{p:?} edge {e}");
            }
            assert_eq!(
                min,
                d.iter().copied().fold(f64::INFINITY, f64::min),
                "{p:?}"
            );
            assert_eq!(
                max,
                d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                "{p:?}"
            );
        }
        assert!(fast > 290_000, "{fast}");
    }
}
