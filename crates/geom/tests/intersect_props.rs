//! Property tests of the exact segment/triangle tests against an
//! independent integer reference (separating axes, rational parameters) on
//! small grid coordinates, where degenerate contacts are frequent.
use parafront_geom::intersect::{
    is_collinear, segment_triangle, segment_triangle_parity, triangles_intersect, SegTri,
};
use parafront_geom::P3;
use proptest::prelude::*;

type I3 = [i128; 3];

fn ti(p: P3) -> I3 {
    [p[0] as i128, p[1] as i128, p[2] as i128]
}
fn sub(a: I3, b: I3) -> I3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: I3, b: I3) -> I3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: I3, b: I3) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn lin(m: i128, a: I3, b: I3) -> I3 {
    // m*a + b
    [m * a[0] + b[0], m * a[1] + b[1], m * a[2] + b[2]]
}
fn sc(m: i128, a: I3) -> I3 {
    [m * a[0], m * a[1], m * a[2]]
}

/// Separating-axis test for two closed convex planar polygons: `pts` are
/// the (possibly scaled) vertices; the axes come from the unscaled triangle
/// each polygon was cut from (same edge directions and normal).
fn sat_intersect(p: &[I3], tp: [I3; 3], q: &[I3], tq: [I3; 3]) -> bool {
    let edges = |t: [I3; 3]| [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
    let (ep, eq) = (edges(tp), edges(tq));
    let (np, nq) = (cross(ep[0], ep[1]), cross(eq[0], eq[1]));
    let mut axes = vec![np, nq];
    for i in 0..3 {
        axes.push(cross(np, ep[i]));
        axes.push(cross(nq, eq[i]));
        for e in eq {
            axes.push(cross(ep[i], e));
        }
    }
    for ax in axes {
        if ax == [0, 0, 0] {
            continue;
        }
        let pr = |s: &[I3]| {
            let v: Vec<i128> = s.iter().map(|x| dot(*x, ax)).collect();
            (*v.iter().min().unwrap(), *v.iter().max().unwrap())
        };
        let (a0, a1) = pr(p);
        let (b0, b1) = pr(q);
        if a1 < b0 || b1 < a0 {
            return false;
        }
    }
    true
}

const M: i128 = 1 << 56;

/// Reference for `shared = 1`: T1 without a 2^-56 neighbourhood of the
/// common vertex meets T2 (exact on these grids: the second extreme point of
/// T1 ∩ T2 is at least 2^-45 away in barycentric terms).
fn ref_vertex(t1: [I3; 3], t2: [I3; 3]) -> bool {
    let v = t1[0];
    let p = [
        lin(M, v, sub(t1[1], v)),
        sc(M, t1[1]),
        sc(M, t1[2]),
        lin(M, v, sub(t1[2], v)),
    ];
    let q = [sc(M, t2[0]), sc(M, t2[1]), sc(M, t2[2])];
    sat_intersect(&p, t1, &q, t2)
}

/// Reference for `shared = 2`: T1 without a thin strip along the common edge.
fn ref_edge(t1: [I3; 3], t2: [I3; 3]) -> bool {
    let (u, v, x) = (t1[0], t1[1], t1[2]);
    let p = [lin(M, u, sub(x, u)), lin(M, v, sub(x, v)), sc(M, x)];
    let q = [sc(M, t2[0]), sc(M, t2[1]), sc(M, t2[2])];
    sat_intersect(&p, t1, &q, t2)
}

fn lt(a: (i128, i128), b: (i128, i128)) -> bool {
    a.0 * b.1 < b.0 * a.1
}

/// Reference segment/triangle classification with rational parameters
/// (triangle non-degenerate, segment not a point).
fn ref_seg_tri(p: P3, q: P3, t: [P3; 3]) -> SegTri {
    let (p, q) = (ti(p), ti(q));
    let t = t.map(ti);
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let h = |x: I3| dot(n, sub(x, t[0]));
    let f = |i: usize, x: I3| dot(n, cross(sub(t[(i + 1) % 3], t[i]), sub(x, t[i])));
    let classify = |vals: [i128; 3]| {
        if vals.iter().all(|&v| v > 0) {
            SegTri::Cross
        } else if vals.iter().all(|&v| v >= 0) {
            SegTri::Touch
        } else {
            SegTri::Disjoint
        }
    };
    let (hp, hq) = (h(p), h(q));
    if hp.signum() * hq.signum() > 0 {
        return SegTri::Disjoint;
    }
    if hp != 0 && hq != 0 {
        let d = (hp - hq).signum();
        return classify([0, 1, 2].map(|i| d * (-hq * f(i, p) + hp * f(i, q))));
    }
    if hp != 0 || hq != 0 {
        let x = if hp == 0 { p } else { q };
        return match classify([0, 1, 2].map(|i| f(i, x))) {
            SegTri::Disjoint => SegTri::Disjoint,
            _ => SegTri::Touch,
        };
    }
    // Coplanar: constraints alpha + t beta >= 0 (> 0) on t in [0, 1] ((0, 1)).
    let feasible = |strict: bool| {
        let (mut lo, mut hi) = ((0i128, 1i128), (1i128, 1i128));
        for i in 0..3 {
            let (a, b) = (f(i, p), f(i, q) - f(i, p));
            if b == 0 {
                if a < 0 || (strict && a == 0) {
                    return false;
                }
            } else if b > 0 {
                let l = (-a, b);
                if lt(lo, l) {
                    lo = l;
                }
            } else {
                let u = (a, -b);
                if lt(u, hi) {
                    hi = u;
                }
            }
        }
        if strict {
            lt(lo, hi)
        } else {
            !lt(hi, lo)
        }
    };
    if feasible(true) {
        SegTri::Cross
    } else if feasible(false) {
        SegTri::Touch
    } else {
        SegTri::Disjoint
    }
}

/// `n` grid points: half of the time anywhere in a small cube, half of the
/// time all in one slanted plane, where coplanar contacts are frequent.
fn scene(n: usize) -> impl Strategy<Value = Vec<P3>> {
    let cube = prop::collection::vec(prop::array::uniform3(-4i32..=4), n)
        .prop_map(|v| v.into_iter().map(|a| a.map(f64::from)).collect::<Vec<P3>>());
    let plane = (
        prop::array::uniform3(-2i32..=2),
        prop::array::uniform3(-2i32..=2),
        prop::array::uniform3(-2i32..=2),
        prop::collection::vec(prop::array::uniform2(-3i32..=3), n),
    )
        .prop_map(|(o, e1, e2, uv)| {
            uv.into_iter()
                .map(|[x, y]| [0, 1, 2].map(|k| f64::from(o[k] + x * e1[k] + y * e2[k])))
                .collect::<Vec<P3>>()
        });
    prop_oneof![cube, plane]
}
fn flat(t: [P3; 3]) -> bool {
    is_collinear(t[0], t[1], t[2])
}
fn shift(t: [P3; 3], k: i32, s: i32) -> [P3; 3] {
    let d = 2f64.powi(k);
    let m = 2f64.powi(s);
    t.map(|p| p.map(|x| x * m + d))
}
const PERMS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [0, 2, 1],
    [2, 1, 0],
    [1, 0, 2],
];

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 4000,
        max_global_rejects: 1 << 20,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn seg_tri_matches_reference(v in scene(5)) {
        let (p, q, t) = (v[0], v[1], [v[2], v[3], v[4]]);
        prop_assume!(!flat(t) && p != q);
        prop_assert_eq!(segment_triangle(p, q, t[0], t[1], t[2]), ref_seg_tri(p, q, t));
    }

    #[test]
    fn seg_tri_invariants(v in scene(5), k in 0i32..30, s in -20i32..20) {
        let (p, q, t) = (v[0], v[1], [v[2], v[3], v[4]]);
        let r = segment_triangle(p, q, t[0], t[1], t[2]);
        prop_assert_eq!(r, segment_triangle(q, p, t[0], t[1], t[2]));
        for pm in PERMS {
            prop_assert_eq!(r, segment_triangle(p, q, t[pm[0]], t[pm[1]], t[pm[2]]));
        }
        let [p2, q2, _] = shift([p, q, p], k, s);
        let t2 = shift(t, k, s);
        prop_assert_eq!(r, segment_triangle(p2, q2, t2[0], t2[1], t2[2]));
        if flat(t) || p == q {
            prop_assert_ne!(r, SegTri::Cross);
        }
        // The parity variant commits only when the contact is generic.
        match segment_triangle_parity(p, q, t[0], t[1], t[2]) {
            Some(true) => prop_assert_eq!(r, SegTri::Cross),
            Some(false) => prop_assert_eq!(r, SegTri::Disjoint),
            None => prop_assert_ne!(r, SegTri::Disjoint),
        }
    }

    #[test]
    fn tri_tri_matches_sat(v in scene(6)) {
        let (t1, t2) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
        prop_assume!(!flat(t1) && !flat(t2));
        prop_assert_eq!(
            triangles_intersect(t1, t2, 0),
            sat_intersect(&t1.map(ti), t1.map(ti), &t2.map(ti), t2.map(ti))
        );
    }

    #[test]
    fn tri_tri_invariants(v in scene(6), k in 0i32..30, s in -20i32..20) {
        let (t1, t2) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
        let r = triangles_intersect(t1, t2, 0);
        prop_assert_eq!(r, triangles_intersect(t2, t1, 0));
        for pm in PERMS {
            let u1 = [t1[pm[0]], t1[pm[1]], t1[pm[2]]];
            prop_assert_eq!(r, triangles_intersect(u1, t2, 0));
            let u2 = [t2[pm[2]], t2[pm[0]], t2[pm[1]]];
            prop_assert_eq!(r, triangles_intersect(t1, u2, 0));
        }
        prop_assert_eq!(r, triangles_intersect(shift(t1, k, s), shift(t2, k, s), 0));
    }

    #[test]
    fn shared_vertex_matches_reference(w in scene(5)) {
        let (v, a, b, c, d) = (w[0], w[1], w[2], w[3], w[4]);
        let (t1, t2) = ([v, a, b], [v, c, d]);
        prop_assume!(!flat(t1) && !flat(t2));
        prop_assert_eq!(triangles_intersect(t1, t2, 1), ref_vertex(t1.map(ti), t2.map(ti)));
    }

    #[test]
    fn shared_vertex_invariants(w in scene(5), k in 0i32..30, s in -20i32..20) {
        let (v, a, b, c, d) = (w[0], w[1], w[2], w[3], w[4]);
        let r = triangles_intersect([v, a, b], [v, c, d], 1);
        prop_assert_eq!(r, triangles_intersect([v, c, d], [v, a, b], 1));
        prop_assert_eq!(r, triangles_intersect([v, b, a], [v, d, c], 1));
        let (t1, t2) = (shift([v, a, b], k, s), shift([v, c, d], k, s));
        prop_assert_eq!(r, triangles_intersect(t1, t2, 1));
        // Meeting beyond the common vertex implies meeting at all.
        if r {
            prop_assert!(triangles_intersect([v, a, b], [v, c, d], 0));
        }
    }

    #[test]
    fn shared_edge_matches_reference(w in scene(4)) {
        let (u, v, x, y) = (w[0], w[1], w[2], w[3]);
        let (t1, t2) = ([u, v, x], [u, v, y]);
        prop_assume!(!flat(t1) && !flat(t2));
        prop_assert_eq!(triangles_intersect(t1, t2, 2), ref_edge(t1.map(ti), t2.map(ti)));
    }

    #[test]
    fn shared_edge_invariants(w in scene(4), k in 0i32..30, s in -20i32..20) {
        let (u, v, x, y) = (w[0], w[1], w[2], w[3]);
        let r = triangles_intersect([u, v, x], [u, v, y], 2);
        prop_assert_eq!(r, triangles_intersect([u, v, y], [u, v, x], 2));
        prop_assert_eq!(r, triangles_intersect([v, u, x], [v, u, y], 2));
        let (t1, t2) = (shift([u, v, x], k, s), shift([u, v, y], k, s));
        prop_assert_eq!(r, triangles_intersect(t1, t2, 2));
    }
}

#[test]
fn known_configurations() {
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    // Pierced through the middle.
    let s = [[0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [5.0, 5.0, 0.0]];
    assert!(triangles_intersect(t, s, 0));
    // Same plane, apart.
    let far = [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]];
    assert!(!triangles_intersect(t, far, 0));
    // Touching corner to corner counts for shared = 0.
    let corner = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
    assert!(triangles_intersect(t, corner, 0));
    // Tiny offsets: exact arithmetic still separates them.
    let e = f64::EPSILON;
    let above = [[0.1, 0.1, e * e], [0.5, 0.1, e * e], [0.1, 0.5, e * e]];
    assert!(!triangles_intersect(t, above, 0));
    let on = [[0.1, 0.1, 0.0], [0.5, 0.1, 1.0], [0.1, 0.5, 1.0]];
    assert!(triangles_intersect(t, on, 0));
    // Zero-area triangles do not panic and behave as segments.
    let needle = [[0.5, -1.0, 0.0], [0.5, 0.0, 0.0], [0.5, 1.0, 0.0]];
    assert!(triangles_intersect(t, needle, 0));
    let point = [[3.0; 3]; 3];
    assert!(!triangles_intersect(t, point, 0));
    assert!(!triangles_intersect(point, point, 1));
    assert!(triangles_intersect(point, point, 3));
}
