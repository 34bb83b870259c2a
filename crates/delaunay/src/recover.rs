//! Recovery of constraint faces and edges by flips: an edge of the
//! triangulation that pierces a missing face (or that a missing edge
//! passes through) is removed (3-2, 4-4, ...), a face that a missing face's
//! edge (or a missing edge) pierces is flipped 2-3, until the face or edge
//! appears or no flip applies. Each flip may first remove the edges that
//! block it, two levels deep. Faces and edges already present are
//! protected.
use crate::flips::{key3, Flip};
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::{add, cross, orient3d, sub, P3};
use rustc_hash::{FxHashMap, FxHashSet};

/// Recover every face of `cf` it can, in passes while any pass gains one;
/// the indices of the faces still missing.
pub(crate) fn recover_all(
    tri: &mut Triangulation,
    cf: &[[u32; 3]],
    per_face: usize,
    flips: &mut usize,
) -> Vec<usize> {
    recover_all_at(tri, cf, per_face, flips, DEPTH)
}

fn recover_all_at(
    tri: &mut Triangulation,
    cf: &[[u32; 3]],
    per_face: usize,
    flips: &mut usize,
    depth: u32,
) -> Vec<usize> {
    let mut protect: FxHashSet<[u32; 3]> = FxHashSet::default();
    recover_faces(tri, cf, &mut protect, per_face, flips, depth)
}

/// [`recover_faces`] goes on to another pass only when the last one
/// recovered at least one in this many of the faces it tried.
const PASS_GAIN: usize = 20;

/// Whether a pass of [`recover_faces`] that tried `before` faces and left
/// `after` missing is worth another.
fn another_pass(before: usize, after: usize) -> bool {
    after > 0 && (before - after) * PASS_GAIN >= before
}

/// [`recover_all`] keeping the faces and edges (`edge_key`) in `protect`
/// besides the faces of `cf` found or recovered, which join it.
pub(crate) fn recover_faces(
    tri: &mut Triangulation,
    cf: &[[u32; 3]],
    protect: &mut FxHashSet<[u32; 3]>,
    per_face: usize,
    flips: &mut usize,
    depth: u32,
) -> Vec<usize> {
    let mut missing: Vec<usize> = Vec::new();
    for (i, &f) in cf.iter().enumerate() {
        if tri.find_face(f).is_some() {
            protect.insert(key3(f));
        } else {
            missing.push(i);
        }
    }
    // A few passes: a face one pass recovers can unblock another. A pass
    // that recovers under a twentieth of what it tried ends them: the
    // closing fills' passes recover a sixth or more (the plate's
    // 1,560-face cavity: 189, 28, 18, 15), a diverging fill's next passes
    // next to nothing at 2 s each (its 5,088-face one at size 4: 476,
    // 446, 437, 436).
    for _ in 0..4 {
        let before = missing.len();
        let mut still = Vec::new();
        for &i in &missing {
            if recover_face(tri, cf[i], protect, per_face, flips, depth) {
                protect.insert(key3(cf[i]));
            } else {
                still.push(i);
            }
        }
        missing = still;
        if !another_pass(before, missing.len()) {
            break;
        }
    }
    // A face another face's flips brought back is not missing.
    missing.retain(|&i| tri.find_face(cf[i]).is_none());
    missing
}

/// Recover edge `a`-`b` by flips: the edges it crosses are removed and the
/// faces it pierces flipped 2-3, nested to `depth` levels.
pub(crate) fn recover_edge(
    tri: &mut Triangulation,
    a: u32,
    b: u32,
    protect: &FxHashSet<[u32; 3]>,
    budget: usize,
    flips: &mut usize,
    depth: u32,
) -> bool {
    let present = |t: &Triangulation| t.has_edge(a, b);
    let mut memo = FxHashMap::default();
    let blockers = |t: &Triangulation| segment_crossings(t, a, b, &mut memo);
    flip_until(tri, present, blockers, protect, budget, flips, depth)
}

/// Where segment `a`-`b` pierces a face (its points in order): the
/// distance along it and the face's edge it passes through, if any.
type SegHit = Option<(f64, Option<(u32, u32)>)>;

/// The edges segment `a`-`b` passes through (their interiors) and the
/// faces it pierces, in order from `a`. `memo` keeps each face's answer
/// for the next call on the same segment (points do not move).
fn segment_crossings(
    tri: &Triangulation,
    a: u32,
    b: u32,
    memo: &mut FxHashMap<[u32; 3], SegHit>,
) -> (Vec<(u32, u32)>, Vec<u32>) {
    let (pa, pb) = (tri.pts[a as usize], tri.pts[b as usize]);
    let near = tets_near(tri, &[a], &[pa, pb], |tp| segment_near_tet(pa, pb, tp));
    // (distance along the segment, the face, the edge it passes through).
    type Hit = (f64, u32, Option<(u32, u32)>);
    let mut hits: Vec<Hit> = Vec::new();
    let mut fseen: FxHashSet<[u32; 3]> = FxHashSet::default();
    let d = sub(pb, pa);
    for &t in &near {
        let tv = tri.tet(t);
        for k in 0..4 {
            let w = TET_FACES[k].map(|j| tv[j]);
            if w.contains(&a)
                || w.contains(&b)
                || tri.neighbour(t, k) == NONE
                || !fseen.insert(key3(w))
            {
                continue;
            }
            let hit = *memo.entry(w).or_insert_with(|| {
                let wp = w.map(|v| tri.pts[v as usize]);
                let sides = (
                    orient3d(wp[0], wp[1], wp[2], pa),
                    orient3d(wp[0], wp[1], wp[2], pb),
                );
                if !pierces(pa, pb, wp, sides) {
                    return None;
                }
                // The edge it passes through, if any.
                let s = [
                    orient3d(pa, pb, wp[0], wp[1]),
                    orient3d(pa, pb, wp[1], wp[2]),
                    orient3d(pa, pb, wp[2], wp[0]),
                ];
                let e = (0..3)
                    .find(|&e| s[e] == 0.0)
                    .map(|e| (w[e], w[(e + 1) % 3]));
                let c = [0, 1, 2].map(|j| (wp[0][j] + wp[1][j] + wp[2][j]) / 3.0);
                let along = (0..3).map(|j| (c[j] - pa[j]) * d[j]).sum::<f64>();
                Some((along, e))
            });
            let Some((along, e)) = hit else {
                continue;
            };
            hits.push((along, 4 * t + k as u32, e));
        }
    }
    hits.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut faces = Vec::new();
    for (_, fr, e) in hits {
        if let Some((u, v)) = e {
            let k = (u.min(v), u.max(v));
            if !edges.contains(&k) {
                edges.push(k);
            }
        }
        faces.push(fr);
    }
    (edges, faces)
}

/// Segment `a`-`b` comes within rounding of tet `tp` (clipped by its
/// four face planes, each moved out by a relative tolerance, something is
/// left): a float filter that keeps every tet the segment meets.
fn segment_near_tet(a: P3, b: P3, tp: &[P3; 4]) -> bool {
    let d = sub(b, a);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for f in TET_FACES {
        let (p, q, r) = (tp[f[0]], tp[f[1]], tp[f[2]]);
        // Outward for a positive tet.
        let n = cross(sub(q, p), sub(r, p));
        let scale = n[0].abs() + n[1].abs() + n[2].abs();
        let ap = sub(a, p);
        let size = ap[0].abs() + ap[1].abs() + ap[2].abs() + d[0].abs() + d[1].abs() + d[2].abs();
        let tol = 1e-9 * scale * size;
        let num = n[0] * ap[0] + n[1] * ap[1] + n[2] * ap[2] - tol;
        let den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        if den == 0.0 {
            if num > 0.0 {
                return false;
            }
        } else {
            let t = -num / den;
            if den > 0.0 {
                t1 = t1.min(t);
            } else {
                t0 = t0.max(t);
            }
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// Triangle `p` comes within rounding of tet `tp`: no corner of the
/// tet is on the inner side of the triangle's plane (or of the plane
/// through one of its edges, square to it) and all of them are beyond it,
/// each plane moved out by a relative tolerance. A float filter that keeps
/// every tet the triangle meets (the tets around a face of a thin crack,
/// whose box meets it, were most of its recovery's time).
fn triangle_near_tet(p: [P3; 3], tp: &[P3; 4]) -> bool {
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let l1 = |x: P3| x[0].abs() + x[1].abs() + x[2].abs();
    let mut size = 0.0f64;
    for q in tp {
        size = size.max(l1(sub(*q, p[0])));
    }
    for q in &p[1..] {
        size = size.max(l1(sub(*q, p[0])));
    }
    // Outside one plane (through `a`, normal `m`) with every corner.
    let beyond = |a: P3, m: P3, sign: f64| {
        let tol = 1e-9 * l1(m) * size;
        tp.iter()
            .all(|q| sign * parafront_geom::dot(m, sub(*q, a)) > tol)
    };
    if beyond(p[0], n, 1.0) || beyond(p[0], n, -1.0) {
        return false;
    }
    for e in 0..3 {
        let (a, b) = (p[e], p[(e + 1) % 3]);
        // Outward from the triangle, in its plane.
        if beyond(a, cross(sub(b, a), n), 1.0) {
            return false;
        }
    }
    true
}

/// Levels of nested flips (`flip23_deep`). On the thin cracks the front
/// leaves on CAD parts (six cavities of 144-296 faces), plain flips left
/// 20-144 faces missing, two levels 12-77, three 0-66 at several times the
/// cost, four no fewer.
pub(crate) const DEPTH: u32 = 2;

fn recover_face(
    tri: &mut Triangulation,
    f: [u32; 3],
    protect: &FxHashSet<[u32; 3]>,
    budget: usize,
    flips: &mut usize,
    depth: u32,
) -> bool {
    let present = |t: &Triangulation| t.find_face(f).is_some();
    let mut memo = CrossMemo::default();
    let blockers = |t: &Triangulation| crossings_memo(t, f, &mut memo);
    flip_until(tri, present, blockers, protect, budget, flips, depth)
}

/// Flip what `blockers` finds in the way, one flip at a time ([`flip_one`])
/// and at most `budget`, until `present` holds; whether it does.
fn flip_until(
    tri: &mut Triangulation,
    present: impl Fn(&Triangulation) -> bool,
    mut blockers: impl FnMut(&Triangulation) -> (Vec<(u32, u32)>, Vec<u32>),
    protect: &FxHashSet<[u32; 3]>,
    budget: usize,
    flips: &mut usize,
    depth: u32,
) -> bool {
    for _ in 0..budget {
        if present(tri) {
            return true;
        }
        let (edges, faces) = blockers(tri);
        if !flip_one(tri, &edges, &faces, protect, depth) {
            return false;
        }
        *flips += 1;
    }
    present(tri)
}

/// The tets around the points `from` and those reached from them, across
/// faces, whose box meets the box of `corners` and that `keep` takes (the
/// near tets of a face or a segment).
fn tets_near(
    tri: &Triangulation,
    from: &[u32],
    corners: &[P3],
    keep: impl Fn(&[P3; 4]) -> bool,
) -> Vec<u32> {
    let mut lo = corners[0];
    let mut hi = corners[0];
    for q in &corners[1..] {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let mut seen: FxHashSet<u32> = FxHashSet::default();
    let mut near: Vec<u32> = Vec::new();
    for &v in from {
        for t in tri.star(v) {
            if seen.insert(t) {
                near.push(t);
            }
        }
    }
    let mut i = 0;
    while i < near.len() {
        let t = near[i];
        i += 1;
        for k in 0..4 {
            let nb = tri.neighbour(t, k);
            if nb == NONE || seen.contains(&(nb >> 2)) {
                continue;
            }
            let u = nb >> 2;
            let tp = tri.tet_points(u);
            let meets = (0..3)
                .all(|d| tp.iter().any(|q| q[d] >= lo[d]) && tp.iter().any(|q| q[d] <= hi[d]))
                && keep(&tp);
            seen.insert(u);
            if meets {
                near.push(u);
            }
        }
    }
    near
}

/// One flip out of the way: the first of the blocking `edges` that can be
/// removed, else the first of the pierced `faces` (slots) that can be
/// flipped 2-3, each nested to `depth` levels; whether one was.
fn flip_one(
    tri: &mut Triangulation,
    edges: &[(u32, u32)],
    faces: &[u32],
    protect: &FxHashSet<[u32; 3]>,
    depth: u32,
) -> bool {
    for &(u, v) in edges {
        if tri.remove_edge_deep(u, v, protect, depth) == Flip::Done {
            return true;
        }
    }
    // By corners: a nested flip that fails may still have changed the
    // tets, and a face's slot then holds another tet.
    let faces: Vec<[u32; 3]> = faces.iter().map(|&fr| tri.face_corners(fr)).collect();
    for w in faces {
        let Some(fr) = tri.find_face(w) else {
            continue;
        };
        if tri.flip23_deep(fr, protect, depth, (NONE, NONE)) == Flip::Done {
            return true;
        }
    }
    false
}

/// What [`crossings_memo`] learnt about one face: each point's side of its
/// plane, and whether an edge or a face (by its points' ids) is in its
/// way. Points never move while a face is recovered, so the answers hold
/// across its flips; on a CAD plane most points are in the face's plane,
/// the exact predicate's slowest answer.
#[derive(Default)]
pub(crate) struct CrossMemo {
    side: FxHashMap<u32, f64>,
    edge: FxHashMap<(u32, u32), bool>,
    face: FxHashMap<[u32; 3], bool>,
}

/// The triangulation's edges that meet face `f` (outside its own edges),
/// and its faces that an edge of `f` pierces, found among the tets near
/// `f`.
pub(crate) fn crossings(tri: &Triangulation, f: [u32; 3]) -> (Vec<(u32, u32)>, Vec<u32>) {
    crossings_memo(tri, f, &mut CrossMemo::default())
}

/// [`crossings`], with what `memo` holds about `f` from earlier calls (and
/// adding to it).
pub(crate) fn crossings_memo(
    tri: &Triangulation,
    f: [u32; 3],
    memo: &mut CrossMemo,
) -> (Vec<(u32, u32)>, Vec<u32>) {
    let p = f.map(|v| tri.pts[v as usize]);
    // A point off the face's plane, to order points within it.
    let off = add(p[0], cross(sub(p[1], p[0]), sub(p[2], p[0])));
    let near = tets_near(tri, &f, &p, |tp| triangle_near_tet(p, tp));
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut eseen: FxHashSet<(u32, u32)> = FxHashSet::default();
    let mut faces: Vec<u32> = Vec::new();
    let mut fseen: FxHashSet<[u32; 3]> = FxHashSet::default();
    let CrossMemo { side, edge, face } = memo;
    for &t in &near {
        let tv = tri.tet(t);
        for a in 0..4 {
            for b in a + 1..4 {
                let (u, v) = (tv[a].min(tv[b]), tv[a].max(tv[b]));
                if f.contains(&u) && f.contains(&v) || !eseen.insert((u, v)) {
                    continue;
                }
                let blocks = *edge.entry((u, v)).or_insert_with(|| {
                    let mut side_of = |v: u32| {
                        *side
                            .entry(v)
                            .or_insert_with(|| orient3d(p[0], p[1], p[2], tri.pts[v as usize]))
                    };
                    let sides = (side_of(u), side_of(v));
                    edge_blocks(tri, p, f, off, (u, v), sides)
                });
                if blocks {
                    edges.push((u, v));
                }
            }
        }
        for k in 0..4 {
            let w = TET_FACES[k].map(|j| tv[j]);
            let key = key3(w);
            if tri.neighbour(t, k) == NONE || !fseen.insert(key) {
                continue;
            }
            // Whether an edge of `f` pierces `w` does not depend on `w`'s
            // orientation.
            let pierced = *face.entry(key).or_insert_with(|| {
                let wp = w.map(|v| tri.pts[v as usize]);
                // The face's corners' sides of this plane, each once.
                let mut o: [Option<f64>; 3] = [None; 3];
                let mut o_of =
                    |k: usize| *o[k].get_or_insert_with(|| orient3d(wp[0], wp[1], wp[2], p[k]));
                (0..3).any(|e| {
                    let (a, b) = (f[e], f[(e + 1) % 3]);
                    !w.contains(&a)
                        && !w.contains(&b)
                        && pierces(p[e], p[(e + 1) % 3], wp, (o_of(e), o_of((e + 1) % 3)))
                })
            });
            if pierced {
                faces.push(4 * t + k as u32);
            }
        }
    }
    (edges, faces)
}

/// Edge `u`-`v` meets face `f` (points `p`) elsewhere than along its own
/// edges' ends: through its interior, or through one of its edges, or
/// lying in its plane across it.
/// `sides`: the orientations of `u` and `v` against the face's plane.
fn edge_blocks(
    tri: &Triangulation,
    p: [P3; 3],
    f: [u32; 3],
    off: P3,
    (u, v): (u32, u32),
    (ou, ov): (f64, f64),
) -> bool {
    let (pu, pv) = (tri.pts[u as usize], tri.pts[v as usize]);
    if opp(ou, ov) {
        let s = [
            orient3d(pu, pv, p[0], p[1]),
            orient3d(pu, pv, p[1], p[2]),
            orient3d(pu, pv, p[2], p[0]),
        ];
        let zeros = s.iter().filter(|&&x| x == 0.0).count();
        return zeros < 2 && (s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0));
    }
    if ou == 0.0 && ov == 0.0 {
        // In the face's plane: it crosses one of the face's edges properly,
        // or has an end strictly inside the face.
        let o2 = |a: P3, b: P3, c: P3| orient3d(a, b, c, off);
        for e in 0..3 {
            let (a, b) = (p[e], p[(e + 1) % 3]);
            if f[e] == u || f[e] == v || f[(e + 1) % 3] == u || f[(e + 1) % 3] == v {
                continue;
            }
            let s1 = o2(a, b, pu);
            let s2 = o2(a, b, pv);
            let s3 = o2(pu, pv, a);
            let s4 = o2(pu, pv, b);
            if opp(s1, s2) && opp(s3, s4) {
                return true;
            }
        }
        let strictly_in = |x: P3| {
            let s = [o2(p[0], p[1], x), o2(p[1], p[2], x), o2(p[2], p[0], x)];
            s.iter().all(|&y| y > 0.0) || s.iter().all(|&y| y < 0.0)
        };
        return strictly_in(pu) || strictly_in(pv);
    }
    false
}

/// Segment `a`-`b` passes through triangle `w` (its interior or an edge's
/// interior), its ends strictly on either side (`oa`, `ob`: their
/// orientations against `w`'s plane).
fn pierces(a: P3, b: P3, w: [P3; 3], (oa, ob): (f64, f64)) -> bool {
    if !opp(oa, ob) {
        return false;
    }
    let s = [
        orient3d(a, b, w[0], w[1]),
        orient3d(a, b, w[1], w[2]),
        orient3d(a, b, w[2], w[0]),
    ];
    let zeros = s.iter().filter(|&&x| x == 0.0).count();
    zeros < 2 && (s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0))
}

/// Strictly opposite signs (a product could underflow).
#[inline]
fn opp(a: f64, b: f64) -> bool {
    (a > 0.0 && b < 0.0) || (a < 0.0 && b > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The passes go on while each recovers a twentieth of what it tried:
    /// the plate's closing 1,560-face cavity's passes (189, 28, 18, 15)
    /// all run; a diverging 5,088-face one's (476, 446, 437, 436) stop
    /// after the second.
    #[test]
    fn face_passes_stop_when_they_recover_next_to_nothing() {
        // The passes run over the missing counts `missing` lists.
        let passes = |missing: &[usize]| {
            let go_on = missing
                .windows(2)
                .take_while(|w| another_pass(w[0], w[1]))
                .count();
            (1 + go_on).min(missing.len() - 1)
        };
        assert_eq!(passes(&[189, 28, 18, 15, 15]), 4);
        assert_eq!(passes(&[476, 446, 437, 436, 436]), 2);
        // Exactly a twentieth goes on; less does not.
        assert_eq!(passes(&[20, 19, 18, 18]), 3);
        assert_eq!(passes(&[100, 96, 95]), 1);
        assert_eq!(passes(&[26, 17, 5, 3, 1]), 4);
        assert!(!another_pass(5, 0));
        assert!(!another_pass(7, 7));
    }

    /// A cavity from an OBJ file, its faces in triangulation ids (after
    /// the bounding tet's four corners).
    fn read_obj(text: &str) -> (Vec<P3>, Vec<[u32; 3]>) {
        use parafront_surface::read::{read_surface_bytes, Format};
        let s = read_surface_bytes("cavity.obj", text.as_bytes(), Format::Obj).expect("OBJ");
        let faces = s.tris.iter().map(|f| f.map(|v| v + 4)).collect();
        (s.points, faces)
    }

    /// Thin cracks the front left on the tray and the hinge: nested flips
    /// recover more of their faces than plain ones, keep the triangulation
    /// valid (a nested flip that fails can still change the tets: the
    /// hinge's crack once left a face linked to a tet that had been
    /// replaced), and keep every face they recovered.
    #[test]
    fn nested_flips_recover_more_and_keep_the_triangulation_valid() {
        for text in [
            include_str!("../tests/data/tray_crack_150.obj"),
            include_str!("../tests/data/tray_crack_188.obj"),
            include_str!("../tests/data/hinge_crack_184.obj"),
        ] {
            let (pts, cf) = read_obj(text);
            let mut missing = [0; 2];
            for (k, depth) in [0, DEPTH].into_iter().enumerate() {
                let mut tri = Triangulation::new(&pts).unwrap();
                let mut flips = 0;
                let still = recover_all_at(&mut tri, &cf, 8, &mut flips, depth);
                tri.check().unwrap();
                for (i, &f) in cf.iter().enumerate() {
                    assert_eq!(tri.find_face(f).is_none(), still.contains(&i), "face {i}");
                }
                missing[k] = still.len();
            }
            assert!(missing[1] < missing[0], "{missing:?}");
        }
    }

    /// Recovery remembers, per face and per segment, which edges and faces
    /// are in the way (points do not move while it flips): at every flip
    /// of the thin cracks' faces and of their edges, what it remembered
    /// gives the same answer as asking afresh.
    #[test]
    fn remembered_crossings_match_fresh_ones_as_flips_go_on() {
        for text in [
            include_str!("../tests/data/tray_crack_150.obj"),
            include_str!("../tests/data/hinge_crack_184.obj"),
        ] {
            let (pts, cf) = read_obj(text);
            let mut tri = Triangulation::new(&pts).unwrap();
            let protect = FxHashSet::default();
            let (mut faces_seen, mut segments_seen) = (0, 0);
            for &f in &cf {
                let mut memo = CrossMemo::default();
                for _ in 0..8 {
                    if tri.find_face(f).is_some() {
                        break;
                    }
                    let fresh = crossings(&tri, f);
                    assert_eq!(crossings_memo(&tri, f, &mut memo), fresh);
                    faces_seen += 1;
                    if !flip_one(&mut tri, &fresh.0, &fresh.1, &protect, DEPTH) {
                        break;
                    }
                }
                let (a, b) = (f[0], f[1]);
                let mut memo = FxHashMap::default();
                for _ in 0..8 {
                    if tri.has_edge(a, b) {
                        break;
                    }
                    let fresh = segment_crossings(&tri, a, b, &mut FxHashMap::default());
                    assert_eq!(segment_crossings(&tri, a, b, &mut memo), fresh);
                    segments_seen += 1;
                    if !flip_one(&mut tri, &fresh.0, &fresh.1, &protect, DEPTH) {
                        break;
                    }
                }
            }
            tri.check().unwrap();
            assert!(
                faces_seen > 100 && segments_seen > 10,
                "{faces_seen} {segments_seen}"
            );
        }
    }
}
