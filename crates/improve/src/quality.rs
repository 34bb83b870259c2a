//! The one quality measure every operation uses: the mean ratio,
//! `12 (3|V|)^(2/3) / sum l^2`, signed by the volume. Smooth, scale
//! invariant, 1 for the regular tet, 0 for a flat one, and cheap (a cube
//! root, no arc-cosines; §9.4 warns about their cost). It equals
//! `parafront_mesh::quality::mean_ratio`.
use parafront_geom::{dist2, tet_volume6, P3};

#[inline]
pub fn quality(p: [P3; 4]) -> f64 {
    let v6 = tet_volume6(p[0], p[1], p[2], p[3]);
    let l2 = dist2(p[0], p[1])
        + dist2(p[0], p[2])
        + dist2(p[0], p[3])
        + dist2(p[1], p[2])
        + dist2(p[1], p[3])
        + dist2(p[2], p[3]);
    if l2 > 0.0 {
        let v3 = 0.5 * v6; // 3V
        (12.0 * (v3 * v3).cbrt() / l2).copysign(v6)
    } else {
        0.0
    }
}

/// Each edge of a tet (its first two corners) with the two other corners.
const EDGE_SIDES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [0, 2, 1, 3],
    [0, 3, 1, 2],
    [1, 2, 0, 3],
    [1, 3, 0, 2],
    [2, 3, 0, 1],
];

/// The smallest dihedral angle of a tet, in degrees (the other
/// measure): the last polish, and the passes for the tets under 10° and
/// for the worst ones, which work on the angles themselves.
pub fn min_dihedral_deg(p: [P3; 4]) -> f64 {
    use parafront_geom::{cross, dot, norm, sub};
    let mut m = f64::INFINITY;
    for [a, b, c, d] in EDGE_SIDES {
        let e = sub(p[b], p[a]);
        let n1 = cross(e, sub(p[c], p[a]));
        let n2 = cross(e, sub(p[d], p[a]));
        m = m.min(norm(cross(n1, n2)).atan2(dot(n1, n2)));
    }
    m.to_degrees()
}

/// Whether a dihedral angle of the tet is under `tan_max` in tangent
/// (and acute): `min_dihedral_deg(p) < deg` with `tan_max = tan(deg)`,
/// without the arc tangents. At edge `e`, `|n1 x n2| = |e| |6V|`.
pub fn has_dihedral_under(p: [P3; 4], tan_max: f64) -> bool {
    use parafront_geom::{cross, dot, norm, sub};
    let v6 = tet_volume6(p[0], p[1], p[2], p[3]).abs();
    EDGE_SIDES.iter().any(|&[a, b, c, d]| {
        let e = sub(p[b], p[a]);
        let c12 = dot(cross(e, sub(p[c], p[a])), cross(e, sub(p[d], p[a])));
        c12 > 0.0 && norm(e) * v6 < tan_max * c12
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_mesh_crate() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 0.7],
        ];
        let a = quality(p);
        let b = parafront_mesh::quality::mean_ratio(p);
        assert!((a - b).abs() < 1e-12, "{a} {b}");
        let r = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        assert!((quality(r).abs() - 1.0).abs() < 1e-12);
        // The regular tet: arccos(1/3) at every edge.
        let d = min_dihedral_deg(r);
        assert!((d - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-9, "{d}");
        // The fourth point at the centroid of the first three's face.
        let flat = [r[0], r[1], r[2], [1.0 / 3.0, 1.0 / 3.0, -1.0 / 3.0]];
        assert!(min_dihedral_deg(flat) < 1e-6);
        let t10 = 10f64.to_radians().tan();
        assert!(has_dihedral_under(flat, t10) && !has_dihedral_under(r, t10));
        // Wedges with a dihedral of 5° and 15° at edge 01: the cheap test
        // agrees with the angles.
        for deg in [5.0f64, 15.0] {
            let a = deg.to_radians();
            let w = [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 1.0, 0.0],
                [0.5, a.cos(), a.sin()],
            ];
            assert_eq!(has_dihedral_under(w, t10), min_dihedral_deg(w) < 10.0);
            assert_eq!(has_dihedral_under(w, t10), deg < 10.0);
        }
    }
}
