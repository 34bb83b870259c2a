//! The in-sphere test under a symbolic perturbation (the exact test is
//! `parafront_geom::in_sphere`).
use parafront_geom::{in_sphere, orient3d, P3};

/// Whether point `e` (id `ie`) is inside the circumsphere of the positive
/// tet with ids `t` and points `p`, under a symbolic perturbation: a point
/// with a larger id is lifted less, so no five points are cospherical.
/// The tie-break is the perturbed lifting's leading non-zero term, the
/// orientation with the largest id replaced by `e` (as in CGAL's
/// `side_of_oriented_sphere`); it never answers "on the sphere".
#[inline]
pub(crate) fn in_sphere_sos(t: [u32; 4], p: [P3; 4], ie: u32, e: P3) -> bool {
    let s = in_sphere(p[0], p[1], p[2], p[3], e);
    if s != 0.0 {
        return s > 0.0;
    }
    // Corners by id, largest first; `e` among them as index 4.
    let mut order = [0usize, 1, 2, 3, 4];
    let id = |k: usize| if k == 4 { ie } else { t[k] };
    order.sort_unstable_by_key(|&x| std::cmp::Reverse(id(x)));
    for &k in &order {
        if k == 4 {
            // The query has the largest perturbation left: outside.
            return false;
        }
        let mut q = p;
        q[k] = e;
        let o = orient3d(q[0], q[1], q[2], q[3]);
        if o != 0.0 {
            return o > 0.0;
        }
    }
    false
}

/// Six times a tet's volume under this much of its longest edge cubed
/// reads as flat to a checker in floating point that measures volumes
/// against the mesh's mean edge (four corners on one plane of a CAD
/// surface, positive only by rounding; a point a hair off a face).
pub const FLAT: f64 = 1e-10;

/// Tet `p` is flat, or negative, in floating point ([`FLAT`]).
pub fn is_flat(p: [P3; 4]) -> bool {
    let mut l2: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l2 = l2.max(parafront_geom::dist2(p[i], p[j]));
        }
    }
    !(parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) >= FLAT * l2 * l2.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_and_outside_the_unit_tet_sphere() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert!(orient3d(p[0], p[1], p[2], p[3]) > 0.0);
        assert!(in_sphere(p[0], p[1], p[2], p[3], [0.3, 0.3, 0.3]) > 0.0);
        assert!(in_sphere(p[0], p[1], p[2], p[3], [2.0, 2.0, 2.0]) < 0.0);
        // (1, 1, 1) is on the sphere through the cube's corners.
        assert_eq!(in_sphere(p[0], p[1], p[2], p[3], [1.0, 1.0, 0.0]), 0.0);
    }

    #[test]
    fn perturbation_is_antisymmetric_on_cospherical_points() {
        // Five corners of a cube: of the two tets on four of them, exactly
        // one sees the fifth inside its perturbed sphere.
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
        ];
        let t = [0u32, 1, 2, 3];
        let inside = in_sphere_sos(t, [c[0], c[1], c[2], c[3]], 4, c[4]);
        let t2 = [4u32, 1, 3, 2];
        let p2 = [c[4], c[1], c[3], c[2]];
        assert!(orient3d(p2[0], p2[1], p2[2], p2[3]) > 0.0);
        let inside2 = in_sphere_sos(t2, p2, 0, c[0]);
        // Two tets sharing face (1, 2, 3) on opposite sides: the Delaunay
        // choice keeps that face iff neither apex is inside the other's.
        assert_eq!(inside, inside2);
    }
}
