//! The tet measures the front uses to rank candidate points.
use parafront_geom::*;

/// Mean ratio `12 (3V)^(2/3) / sum(l^2)`: 1 for a regular tet, 0 when flat,
/// negative when inverted. It is `parafront_mesh::quality::mean_ratio`
/// but for the rounding of `(3V)^(2/3)` (here the cube root squared, there
/// the cube root of the square): candidates are ranked by it, and the
/// shared rounding changed two of 22 test meshes (spheres27_1e5 and a
/// thin rod), so the front keeps its own.
#[inline]
pub fn mean_ratio(a: P3, b: P3, c: P3, d: P3) -> f64 {
    let v6 = tet_volume6(a, b, c, d);
    let s = dist2(a, b) + dist2(a, c) + dist2(a, d) + dist2(b, c) + dist2(b, d) + dist2(c, d);
    if s <= 0.0 {
        return 0.0;
    }
    let v3 = 0.5 * v6; // 3V
    let c = v3.cbrt();
    12.0 * v3.signum() * c * c / s
}

/// Mean ratio of `abcq` damped by how far its new edges stray from `h`.
#[inline]
pub fn candidate_score(a: P3, b: P3, c: P3, q: P3, h: f64) -> (f64, f64) {
    let shape = mean_ratio(a, b, c, q);
    let mut g = 1.0f64;
    for p in [a, b, c] {
        let l = dist(p, q) / h;
        let r = if l > 1.0 { 1.0 / l } else { l };
        g = g.min(r);
    }
    (shape, shape * g.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn regular_tet_has_mean_ratio_one() {
        let s = (8.0f64 / 9.0).sqrt();
        let a = [0.0, 0.0, 1.0];
        let b = [s, 0.0, -1.0 / 3.0];
        let c = [-s / 2.0, (2.0f64 / 3.0).sqrt(), -1.0 / 3.0];
        let d = [-s / 2.0, -(2.0f64 / 3.0).sqrt(), -1.0 / 3.0];
        let (p, q) = if tet_volume6(a, b, c, d) > 0.0 {
            (c, d)
        } else {
            (d, c)
        };
        assert!((mean_ratio(a, b, p, q) - 1.0).abs() < 1e-12);
        assert!(mean_ratio(a, b, q, p) < 0.0);
        // The mesh crate's measure, up to rounding.
        let w = [a, [0.9, 0.1, 0.0], [0.2, 0.7, 0.3], [0.1, 0.2, 1.4]];
        let m = parafront_mesh::quality::mean_ratio(w);
        assert!(m > 0.1 && (mean_ratio(w[0], w[1], w[2], w[3]) - m).abs() < 1e-14);
    }
}
