//! Exact intersection tests between segments and triangles.
//!
//! Every decision is a sign of `orient3d` or `orient2d`; there is no
//! tolerance. Coplanar configurations are projected on a coordinate plane
//! chosen so that the projection is one-to-one on the common plane (an exact
//! test, not a float guess). These are the tests the surface check uses for
//! self-intersections and the advancing front will use for its crossing
//! checks.
use crate::{orient2d, orient3d, P3};

/// How a closed segment meets a closed triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SegTri {
    /// No common point.
    Disjoint,
    /// Common points, but only on the boundary of one of them: an endpoint
    /// of the segment, or an edge or vertex of the triangle.
    Touch,
    /// The relative interiors meet: the open segment passes through the open
    /// triangle (a proper crossing, or a coplanar segment running through the
    /// inside of the triangle).
    Cross,
}

#[inline(always)]
fn sgn(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

#[inline(always)]
fn o3(a: P3, b: P3, c: P3, d: P3) -> i8 {
    // Points on one axis-aligned plane (flat CAD faces) are coplanar: skip
    // the slow exact stage that a zero determinant always reaches.
    for k in 0..3 {
        if a[k] == b[k] && a[k] == c[k] && a[k] == d[k] {
            return 0;
        }
    }
    sgn(orient3d(a, b, c, d))
}

/// Drop axis `k`, keeping the other two in cyclic order, so that the 2D
/// orientation of a projected triangle has the sign of its normal's `k`
/// component.
#[inline(always)]
fn proj(p: P3, k: usize) -> [f64; 2] {
    match k {
        0 => [p[1], p[2]],
        1 => [p[2], p[0]],
        _ => [p[0], p[1]],
    }
}

#[inline(always)]
fn o2(a: P3, b: P3, c: P3, k: usize) -> i8 {
    sgn(orient2d(proj(a, k), proj(b, k), proj(c, k)))
}

/// True when `a`, `b`, `c` are collinear (zero area), including repeated
/// points. Exact.
pub fn is_collinear(a: P3, b: P3, c: P3) -> bool {
    (0..3).all(|k| o2(a, b, c, k) == 0)
}

/// A projection axis on which triangle `abc` keeps a non-zero area, and the
/// sign of its projected orientation; `None` for a zero-area triangle.
/// The float normal only orders the tries; the answer is exact.
fn plane_axis(a: P3, b: P3, c: P3) -> Option<(usize, i8)> {
    let n = crate::tri_normal(a, b, c);
    let mut ks = [0usize, 1, 2];
    ks.sort_by(|&i, &j| n[j].abs().total_cmp(&n[i].abs()));
    ks.into_iter().find_map(|k| {
        let s = o2(a, b, c, k);
        (s != 0).then_some((k, s))
    })
}

/// `p` in the closed triangle `abc` (coplanar, non-degenerate, axis `k`,
/// orientation `s`): 1 inside, 0 on the boundary, -1 outside.
fn point_in_tri_2d(p: P3, a: P3, b: P3, c: P3, k: usize, s: i8) -> i8 {
    let d = [s * o2(a, b, p, k), s * o2(b, c, p, k), s * o2(c, a, p, k)];
    if d.iter().any(|&x| x < 0) {
        -1
    } else if d.iter().all(|&x| x > 0) {
        1
    } else {
        0
    }
}

/// `x` within the coordinate box of `p`, `q` (meaningful for collinear points).
fn in_box_2d(p: P3, q: P3, x: P3, k: usize) -> bool {
    let (p, q, x) = (proj(p, k), proj(q, k), proj(x, k));
    (0..2).all(|i| p[i].min(q[i]) <= x[i] && x[i] <= p[i].max(q[i]))
}

/// Closed segments `pq` and `ab` meet, all four points coplanar and the
/// projection on axis `k` one-to-one on their plane.
fn seg_seg_2d(p: P3, q: P3, a: P3, b: P3, k: usize) -> bool {
    let d1 = o2(p, q, a, k);
    let d2 = o2(p, q, b, k);
    let d3 = o2(a, b, p, k);
    let d4 = o2(a, b, q, k);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && in_box_2d(p, q, a, k))
        || (d2 == 0 && in_box_2d(p, q, b, k))
        || (d3 == 0 && in_box_2d(a, b, p, k))
        || (d4 == 0 && in_box_2d(a, b, q, k))
}

/// An axis along which not all of `pts` have the same coordinate.
fn varying_axis(pts: &[P3]) -> Option<usize> {
    (0..3).find(|&k| pts.iter().any(|p| p[k] != pts[0][k]))
}

/// Closed segments `pq` and `ab` in space meet (either may be a point).
fn seg_seg_3d(p: P3, q: P3, a: P3, b: P3) -> bool {
    if o3(p, q, a, b) != 0 {
        return false;
    }
    // Some triple is non-collinear in projection k only if the plane's normal
    // has a non-zero k component, which makes the projection one-to-one.
    for k in 0..3 {
        if o2(p, q, a, k) != 0 || o2(p, q, b, k) != 0 || o2(a, b, p, k) != 0 || o2(a, b, q, k) != 0
        {
            return seg_seg_2d(p, q, a, b, k);
        }
    }
    // All four on one line: compare intervals along an axis where it varies.
    let Some(k) = varying_axis(&[p, q, a, b]) else {
        return true;
    };
    p[k].min(q[k]).max(a[k].min(b[k])) <= p[k].max(q[k]).min(a[k].max(b[k]))
}

/// `x` and `b` lie on the same open ray from `v` (exact).
fn same_ray(v: P3, x: P3, b: P3) -> bool {
    if x == v || b == v || !is_collinear(v, x, b) {
        return false;
    }
    let k = varying_axis(&[v, x]).unwrap_or(0);
    (x[k] > v[k]) == (b[k] > v[k]) && b[k] != v[k]
}

/// The open segment `pq` meets the open triangle `abc`; all coplanar,
/// triangle non-degenerate with projection axis `k` and orientation `s`.
fn open_cross_2d(p: P3, q: P3, t: [P3; 3], k: usize, s: i8) -> bool {
    // Side of each vertex with respect to the directed line p->q.
    let g = [
        s * o2(p, q, t[0], k),
        s * o2(p, q, t[1], k),
        s * o2(p, q, t[2], k),
    ];
    if !(g.iter().any(|&x| x > 0) && g.iter().any(|&x| x < 0)) {
        return false; // the line misses the open triangle
    }
    // The line's chord through the triangle runs from an entry to an exit
    // edge (or vertex); the open segment overlaps the open chord iff q lies
    // past the entry and p before the exit.
    for i in 0..3 {
        let (u, w) = (i, (i + 1) % 3);
        let (gu, gw) = (g[u], g[w]);
        if gu == 0 && gw == 0 {
            continue;
        }
        if gu >= 0 && gw <= 0 {
            if s * o2(t[u], t[w], q, k) <= 0 {
                return false;
            }
        } else if gu <= 0 && gw >= 0 && s * o2(t[u], t[w], p, k) <= 0 {
            return false;
        }
    }
    true
}

/// Classifies closed segment `pq` against closed triangle `abc`.
///
/// Zero-area triangles count as the union of their edges and never give
/// `Cross`; a zero-length segment never gives `Cross` either.
pub fn segment_triangle(p: P3, q: P3, a: P3, b: P3, c: P3) -> SegTri {
    seg_tri_signed(p, q, [a, b, c], o3(a, b, c, p), o3(a, b, c, q))
}

/// [`segment_triangle`] with the sides `sp`, `sq` of `p`, `q` from the
/// triangle's plane already known (callers reuse them).
fn seg_tri_signed(p: P3, q: P3, t: [P3; 3], sp: i8, sq: i8) -> SegTri {
    let [a, b, c] = t;
    if sp * sq > 0 {
        return SegTri::Disjoint;
    }
    if sp != 0 && sq != 0 {
        // The open segment crosses the plane at one point X; where X lies
        // relative to the edges is the side of each edge from line pq.
        let e = [o3(p, q, a, b), o3(p, q, b, c), o3(p, q, c, a)];
        if e.iter().all(|&x| x > 0) || e.iter().all(|&x| x < 0) {
            return SegTri::Cross;
        }
        if e.iter().any(|&x| x > 0) && e.iter().any(|&x| x < 0) {
            return SegTri::Disjoint;
        }
        return SegTri::Touch;
    }
    let Some((k, s)) = plane_axis(a, b, c) else {
        let hit = seg_seg_3d(p, q, a, b) || seg_seg_3d(p, q, b, c) || seg_seg_3d(p, q, c, a);
        return if hit { SegTri::Touch } else { SegTri::Disjoint };
    };
    if sp != 0 || sq != 0 {
        // One endpoint on the plane, the other off it.
        let x = if sp == 0 { p } else { q };
        return if point_in_tri_2d(x, a, b, c, k, s) >= 0 {
            SegTri::Touch
        } else {
            SegTri::Disjoint
        };
    }
    // Coplanar.
    if p != q && open_cross_2d(p, q, [a, b, c], k, s) {
        return SegTri::Cross;
    }
    let hit = point_in_tri_2d(p, a, b, c, k, s) >= 0
        || point_in_tri_2d(q, a, b, c, k, s) >= 0
        || seg_seg_2d(p, q, a, b, k)
        || seg_seg_2d(p, q, b, c, k)
        || seg_seg_2d(p, q, c, a, k);
    if hit {
        SegTri::Touch
    } else {
        SegTri::Disjoint
    }
}

/// Whether segment `pq` crosses triangle `abc` transversally, for ray
/// parity counts: `Some(true)` for a proper crossing through the open
/// triangle with `p`, `q` strictly on either side, `Some(false)` when they
/// are disjoint, `None` for any other contact (the ray must be re-chosen).
pub fn segment_triangle_parity(p: P3, q: P3, a: P3, b: P3, c: P3) -> Option<bool> {
    let sp = o3(a, b, c, p);
    let sq = o3(a, b, c, q);
    if sp * sq > 0 {
        return Some(false);
    }
    if sp != 0 && sq != 0 {
        let e = [o3(p, q, a, b), o3(p, q, b, c), o3(p, q, c, a)];
        if e.iter().all(|&x| x > 0) || e.iter().all(|&x| x < 0) {
            return Some(true);
        }
        if e.iter().any(|&x| x > 0) && e.iter().any(|&x| x < 0) {
            return Some(false);
        }
        return None;
    }
    match segment_triangle(p, q, a, b, c) {
        SegTri::Disjoint => Some(false),
        _ => None,
    }
}

/// Whether two closed triangles meet in more than their `shared` common
/// vertices (0, 1 or 2; 3 or more means the same triangle, answered `true`).
///
/// The shared vertices come first in both, in the same order:
/// `t1[i] == t2[i]` for `i < shared` (the caller knows the vertex ids and
/// rotates the triangles so). With `shared = 2` the common edge `t[0]t[1]`
/// is allowed; with `shared = 1` the common vertex `t[0]`. Exact for every
/// input, zero-area triangles included (they are the union of their edges).
pub fn triangles_intersect(t1: [P3; 3], t2: [P3; 3], shared: usize) -> bool {
    match shared {
        0 => tri_tri_closed(t1, t2),
        1 => tri_tri_vertex(t1, t2),
        2 => tri_tri_edge(t1, t2),
        _ => true,
    }
}

/// Both triangles (vertex ids `a`, `b`, their points `ap`, `bp`) reordered
/// so their common vertices come first, in the same order in both (in
/// `a`'s order): what [`triangles_intersect`] expects.
#[inline]
pub fn shared_first(a: [u32; 3], ap: [P3; 3], b: [u32; 3], bp: [P3; 3]) -> ([P3; 3], [P3; 3]) {
    let (mut oa, mut ob) = ([0usize; 3], [0usize; 3]);
    let (mut ua, mut ub) = ([false; 3], [false; 3]);
    let mut n = 0;
    for i in 0..3 {
        for j in 0..3 {
            if a[i] == b[j] {
                oa[n] = i;
                ob[n] = j;
                ua[i] = true;
                ub[j] = true;
                n += 1;
            }
        }
    }
    let (mut ka, mut kb) = (n, n);
    for i in 0..3 {
        if !ua[i] {
            oa[ka] = i;
            ka += 1;
        }
        if !ub[i] {
            ob[kb] = i;
            kb += 1;
        }
    }
    (oa.map(|i| ap[i]), ob.map(|j| bp[j]))
}

/// Whether triangles `a` and `b` (vertex ids into `pts`) meet beyond the
/// vertices they share ([`triangles_intersect`]; the same triangle meets
/// itself).
pub fn faces_meet(a: [u32; 3], b: [u32; 3], pts: &[P3]) -> bool {
    let shared = a.iter().filter(|v| b.contains(v)).count();
    let (pa, pb) = shared_first(a, a.map(|v| pts[v as usize]), b, b.map(|v| pts[v as usize]));
    triangles_intersect(pa, pb, shared)
}

fn all_strict_same(s: [i8; 3]) -> bool {
    s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0)
}

fn tri_tri_closed(t1: [P3; 3], t2: [P3; 3]) -> bool {
    // Quick rejection: one triangle strictly on one side of the other's plane.
    let s2 = [0, 1, 2].map(|i| o3(t1[0], t1[1], t1[2], t2[i]));
    if all_strict_same(s2) {
        return false;
    }
    // Coplanar pairs are common on flat faces: one projection, then 2D.
    if s2 == [0; 3] {
        if let Some((k, s)) = plane_axis(t1[0], t1[1], t1[2]) {
            return coplanar_closed(t1, t2, k, s);
        }
    }
    let s1 = [0, 1, 2].map(|i| o3(t2[0], t2[1], t2[2], t1[i]));
    if all_strict_same(s1) {
        return false;
    }
    if s1 == [0; 3] {
        if let Some((k, s)) = plane_axis(t2[0], t2[1], t2[2]) {
            return coplanar_closed(t2, t1, k, s);
        }
    }
    // Two closed convex sets meet iff an edge of one meets the other.
    for i in 0..3 {
        let j = (i + 1) % 3;
        if seg_tri_signed(t1[i], t1[j], t2, s1[i], s1[j]) != SegTri::Disjoint
            || seg_tri_signed(t2[i], t2[j], t1, s2[i], s2[j]) != SegTri::Disjoint
        {
            return true;
        }
    }
    false
}

/// Closed `t1` (non-degenerate, axis `k`, orientation `s`) and `t2` in its
/// plane meet.
fn coplanar_closed(t1: [P3; 3], t2: [P3; 3], k: usize, s: i8) -> bool {
    for i in 0..3 {
        for j in 0..3 {
            if seg_seg_2d(t1[i], t1[(i + 1) % 3], t2[j], t2[(j + 1) % 3], k) {
                return true;
            }
        }
    }
    // No edges meet: either one holds the other or they are apart.
    if point_in_tri_2d(t2[0], t1[0], t1[1], t1[2], k, s) >= 0 {
        return true;
    }
    let s2 = o2(t2[0], t2[1], t2[2], k);
    s2 != 0 && point_in_tri_2d(t1[0], t2[0], t2[1], t2[2], k, s2) >= 0
}

/// Segment `[v, x]` meets triangle `t` (with `t[0] == v`) in a point other
/// than `v`.
fn ray_beyond(v: P3, x: P3, t: [P3; 3]) -> bool {
    if x == v {
        return false;
    }
    match plane_axis(t[0], t[1], t[2]) {
        Some((k, s)) => {
            o3(t[0], t[1], t[2], x) == 0 && s * o2(v, t[1], x, k) >= 0 && s * o2(v, x, t[2], k) >= 0
        }
        None => {
            same_ray(v, x, t[1])
                || same_ray(v, x, t[2])
                || (!seg_seg_3d(t[1], t[2], v, v) && seg_seg_3d(v, x, t[1], t[2]))
        }
    }
}

/// Common vertex `t1[0] == t2[0]`.
fn tri_tri_vertex(t1: [P3; 3], t2: [P3; 3]) -> bool {
    let v = t1[0];
    // The other two vertices strictly on one side of the other plane: the
    // triangle meets that plane only in v.
    let a = [1, 2].map(|i| o3(t1[0], t1[1], t1[2], t2[i]));
    if a[0] * a[1] > 0 {
        return false;
    }
    // The same test the other way round, before the projection axes
    // (t2 in t1's plane takes b = [0, 0] below).
    if a != [0, 0] {
        let b = [1, 2].map(|i| o3(t2[0], t2[1], t2[2], t1[i]));
        if b[0] * b[1] > 0 {
            return false;
        }
    }
    let p1 = plane_axis(t1[0], t1[1], t1[2]);
    let p2 = plane_axis(t2[0], t2[1], t2[2]);
    let b = if a == [0, 0] && p1.is_some() {
        [0, 0] // t2 lies in t1's plane
    } else {
        [1, 2].map(|i| o3(t2[0], t2[1], t2[2], t1[i]))
    };
    if b[0] * b[1] > 0 {
        return false;
    }
    if let (Some((k, s1)), Some(_)) = (p1, p2) {
        if a == [0, 0] {
            // Coplanar: near v each triangle is its wedge, so they overlap
            // beyond v iff a wedge's side ray lies in the other's closed wedge.
            let s2 = o2(t2[0], t2[1], t2[2], k);
            let in_wedge =
                |x: P3, t: [P3; 3], s: i8| s * o2(v, t[1], x, k) >= 0 && s * o2(v, x, t[2], k) >= 0;
            return in_wedge(t1[1], t2, s2)
                || in_wedge(t1[2], t2, s2)
                || in_wedge(t2[1], t1, s1)
                || in_wedge(t2[2], t1, s1);
        }
        // Crossing planes. T1 ∩ T2 lies on their common line through v; an
        // end other than v is on an edge opposite v, or on an edge at v
        // lying in the other plane.
        return seg_tri_signed(t1[1], t1[2], t2, b[0], b[1]) != SegTri::Disjoint
            || seg_tri_signed(t2[1], t2[2], t1, a[0], a[1]) != SegTri::Disjoint
            || (b[0] == 0 && ray_beyond(v, t1[1], t2))
            || (b[1] == 0 && ray_beyond(v, t1[2], t2))
            || (a[0] == 0 && ray_beyond(v, t2[1], t1))
            || (a[1] == 0 && ray_beyond(v, t2[2], t1));
    }
    // A zero-area triangle: T1 ∩ T2 is convex and holds v; if it holds
    // another point, one of its extreme points other than v lies on the
    // edge opposite v of one triangle, or on an edge at v of one inside the
    // other.
    let opposite = |a: [P3; 3], b: [P3; 3]| {
        // A zero-area triangle with v inside its opposite edge: that edge
        // is the union of the two edges at v, tested below.
        if is_collinear(a[0], a[1], a[2]) && seg_seg_3d(a[1], a[2], v, v) {
            return false;
        }
        segment_triangle(a[1], a[2], b[0], b[1], b[2]) != SegTri::Disjoint
    };
    opposite(t1, t2)
        || opposite(t2, t1)
        || ray_beyond(v, t1[1], t2)
        || ray_beyond(v, t1[2], t2)
        || ray_beyond(v, t2[1], t1)
        || ray_beyond(v, t2[2], t1)
}

/// Common edge `t1[0]t1[1] == t2[0]t2[1]`.
fn tri_tri_edge(t1: [P3; 3], t2: [P3; 3]) -> bool {
    let (u, v, x, y) = (t1[0], t1[1], t1[2], t2[2]);
    // Four points off one plane: neither triangle is flat, nor folded
    // onto the other (the first case below), so they meet in uv only.
    if o3(u, v, x, y) != 0 {
        return false;
    }
    let d1 = is_collinear(u, v, x);
    let d2 = is_collinear(u, v, y);
    match (d1, d2) {
        (false, false) => {
            // Folded onto each other: coplanar with x, y on the same side of uv.
            if o3(u, v, x, y) != 0 {
                return false;
            }
            let (k, _) = plane_axis(u, v, x).expect("non-degenerate");
            o2(u, v, x, k) * o2(u, v, y, k) > 0
        }
        // A proper triangle meets the line uv only in the edge uv, which
        // holds all of the other (flat) one that is on that line.
        (true, false) | (false, true) => false,
        (true, true) => {
            if u == v {
                return same_ray(u, x, y);
            }
            // All on line uv: overlap beyond the edge means both x and y
            // stick out past the same end.
            let k = varying_axis(&[u, v]).unwrap_or(0);
            let up = v[k] > u[k];
            let past_v = |z: P3| z[k] != v[k] && ((z[k] > v[k]) == up);
            let past_u = |z: P3| z[k] != u[k] && ((z[k] < u[k]) == up);
            (past_v(x) && past_v(y)) || (past_u(x) && past_u(y))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: P3 = [0.0, 0.0, 0.0];
    const B: P3 = [4.0, 0.0, 0.0];
    const C: P3 = [0.0, 4.0, 0.0];

    #[test]
    fn segment_through_interior_crosses() {
        let r = segment_triangle([1.0, 1.0, -1.0], [1.0, 1.0, 1.0], A, B, C);
        assert_eq!(r, SegTri::Cross);
    }

    #[test]
    fn segment_through_edge_or_vertex_touches() {
        assert_eq!(
            segment_triangle([2.0, 0.0, -1.0], [2.0, 0.0, 1.0], A, B, C),
            SegTri::Touch
        );
        assert_eq!(
            segment_triangle([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], A, B, C),
            SegTri::Touch
        );
        // Endpoint inside the triangle.
        assert_eq!(
            segment_triangle([1.0, 1.0, 0.0], [1.0, 1.0, 1.0], A, B, C),
            SegTri::Touch
        );
    }

    #[test]
    fn segment_beside_is_disjoint() {
        assert_eq!(
            segment_triangle([3.0, 3.0, -1.0], [3.0, 3.0, 1.0], A, B, C),
            SegTri::Disjoint
        );
        assert_eq!(
            segment_triangle([1.0, 1.0, 0.5], [1.0, 1.0, 1.0], A, B, C),
            SegTri::Disjoint
        );
        assert_eq!(
            segment_triangle([5.0, 0.0, 0.0], [6.0, 1.0, 0.0], A, B, C),
            SegTri::Disjoint
        );
    }

    #[test]
    fn coplanar_cases() {
        // Vertex to the middle of the opposite edge: inside, though neither
        // endpoint is strictly inside and no edge is crossed properly.
        assert_eq!(segment_triangle(A, [2.0, 2.0, 0.0], A, B, C), SegTri::Cross);
        // Along an edge.
        assert_eq!(segment_triangle(A, B, A, B, C), SegTri::Touch);
        assert_eq!(
            segment_triangle([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], A, B, C),
            SegTri::Touch
        );
        // Straight through.
        assert_eq!(
            segment_triangle([-1.0, 1.0, 0.0], [5.0, 1.0, 0.0], A, B, C),
            SegTri::Cross
        );
        // Touching the corner from outside.
        assert_eq!(
            segment_triangle([-1.0, 1.0, 0.0], [1.0, -1.0, 0.0], A, B, C),
            SegTri::Touch
        );
        assert_eq!(
            segment_triangle([-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], A, B, C),
            SegTri::Disjoint
        );
    }

    #[test]
    fn degenerate_triangle_and_segment_do_not_panic() {
        let d = [2.0, 0.0, 0.0];
        assert_eq!(
            segment_triangle([1.0, -1.0, 0.0], [1.0, 1.0, 0.0], A, d, B),
            SegTri::Touch
        );
        assert_eq!(
            segment_triangle([1.0, 1.0, 0.0], [1.0, 2.0, 0.0], A, d, B),
            SegTri::Disjoint
        );
        assert_eq!(segment_triangle(A, A, A, A, A), SegTri::Touch);
        assert_eq!(
            segment_triangle([1.0, 1.0, 0.0], [1.0, 1.0, 0.0], A, B, C),
            SegTri::Touch
        );
        assert!(is_collinear(A, d, B));
        assert!(!is_collinear(A, B, C));
    }

    #[test]
    fn shared_edge_cases() {
        let below = [0.0, -4.0, 0.0];
        let fold = [1.0, 1.0, 0.0];
        let up = [0.0, -4.0, 1.0];
        assert!(!triangles_intersect([A, B, C], [A, B, below], 2));
        assert!(triangles_intersect([A, B, C], [A, B, fold], 2));
        assert!(!triangles_intersect([A, B, C], [A, B, up], 2));
    }

    #[test]
    fn shared_vertex_cases() {
        // Fan neighbours in the same plane: no overlap.
        let t1 = [A, B, C];
        let t2 = [A, [-1.0, 4.0, 0.0], [-4.0, 0.0, 0.0]];
        assert!(!triangles_intersect(t1, t2, 1));
        // Overlapping wedges in the plane.
        let t3 = [A, [4.0, 1.0, 0.0], [1.0, 4.0, 0.0]];
        assert!(triangles_intersect(t1, t3, 1));
        // Piercing: t4 passes through t1's interior from the shared vertex.
        let t4 = [A, [1.0, 1.0, 1.0], [1.0, 1.0, -1.0]];
        assert!(triangles_intersect(t1, t4, 1));
        // Only the vertex in common.
        let t5 = [A, [-1.0, -1.0, 1.0], [-1.0, 0.0, 1.0]];
        assert!(!triangles_intersect(t1, t5, 1));
        // The opposite edge of t6 cuts t1.
        let t6 = [A, [1.0, 1.0, 1.0], [1.0, 2.0, -1.0]];
        assert!(triangles_intersect(t1, t6, 1));
    }
}
