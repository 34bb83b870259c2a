//! The conforming fill. Where flips cannot recover a cavity's faces, each
//! face is cut into pieces and Steiner points go on the surface: at the
//! midpoint of a piece's edge the triangulation lacks, else where an edge
//! of the triangulation crosses the piece (which the point removes). Each
//! round triangulates the points afresh (Delaunay), recovers the pieces by
//! flips and splits the missing ones, while that converges. Then every
//! surface point is moved off the surface into the cavity: its star gives
//! way to the cone from a point just inside, over the star's link and the
//! faces it had cut made whole again (or, where no point sees them all,
//! to a fill of that small hole). This is the relocation of boundary
//! Steiner points in Si and Gärtner's constraint recovery: the surface
//! keeps every given triangle and no point is left on it.
//!
//! `segments.rs` does the same in one triangulation, in TetGen's order
//! (edges first, kept while the faces are recovered); the relocation here
//! ends both.
use crate::flips::key3;
use crate::recover::{crossings, recover_all};
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::{add, dist, orient2d, orient3d, scale, tri_normal, P3};
use rustc_hash::{FxHashMap, FxHashSet};

/// Each cavity edge (lower id first) as its points in order.
pub(crate) type Chains = FxHashMap<(u32, u32), Vec<u32>>;

/// Triangulations built before the conforming fill gives up.
const REBUILDS: usize = 24;

/// The cavity's points (`lp`, each face's corners index it) and faces; a
/// fill as Steiner points and tets over `lp` then the Steiner points, or
/// `None`.
pub(crate) fn conform_fill(
    lp: &[P3],
    faces: &[[u32; 3]],
    max_split: usize,
    per_face: usize,
    segments_first: bool,
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let mut c = Conforming::new(lp, faces);
    // Edges split until each piece is a Delaunay edge: round.stl's 1,120
    // needle faces take 602 points in 0.15 s; a surface whose split points
    // crowd each other (two needles side by side) needs far more
    // (plate_holes: 17,854 for 1,252 faces), and the budget stops it.
    if segments_first {
        c.split_segments(lp.len(), max_split)?;
    }
    let mut fewest = usize::MAX;
    let mut worse = 0;
    for _ in 0..REBUILDS {
        // Ids in the triangulation are 4 + ids in `pts`; a fresh one each
        // round, as flips leave it non-Delaunay.
        let mut tri = Triangulation::new(&c.pts).ok()?;
        // The triangulation's own pieces where they tile a face.
        c.retile(&tri, false);
        let (sub, origin) = c.flat();
        let tf: Vec<[u32; 3]> = sub.iter().map(|f| f.map(|v| v + 4)).collect();
        let mut flips = 0;
        let still = recover_all(&mut tri, &tf, per_face, &mut flips);
        tracing::debug!(
            faces = faces.len(),
            splits = c.pts.len() - lp.len(),
            missing = still.len(),
            "conform: pieces recovered"
        );
        if still.is_empty() {
            let kept = crate::fill::classify(&tri, &tf)?;
            let tets: Vec<[u32; 4]> = kept.iter().map(|&t| tri.tet(t).map(|v| v - 4)).collect();
            return crate::relocate::relocate(lp.len(), c.pts, &c.chains, tets, sub, origin, faces);
        }
        // Rounds that leave more pieces missing twice over are not
        // converging.
        if still.len() < fewest {
            fewest = still.len();
            worse = 0;
        } else {
            worse += 1;
            if worse >= 2 {
                tracing::debug!(faces = faces.len(), "conform: not converging");
                return None;
            }
        }
        let missing: Vec<([u32; 3], usize)> = still.iter().map(|&m| (sub[m], origin[m])).collect();
        for (piece, face) in missing {
            if c.pts.len() - lp.len() >= max_split {
                return None;
            }
            c.break_piece(&tri, piece, face, true);
        }
    }
    None
}

/// The cavity's surface as it is split: its points, its edges' chains, and
/// each face's pieces.
pub(crate) struct Conforming {
    pub(crate) pts: Vec<P3>,
    pub(crate) chains: Chains,
    pub(crate) faces: Vec<[u32; 3]>,
    pub(crate) pieces: Vec<Vec<[u32; 3]>>,
}

impl Conforming {
    pub(crate) fn new(lp: &[P3], faces: &[[u32; 3]]) -> Conforming {
        let mut chains: Chains = FxHashMap::default();
        for f in faces {
            for k in 0..3 {
                let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
                chains.entry((a, b)).or_insert_with(|| vec![a, b]);
            }
        }
        Conforming {
            pts: lp.to_vec(),
            chains,
            faces: faces.to_vec(),
            pieces: faces.iter().map(|&f| vec![f]).collect(),
        }
    }

    /// Split the cavity's edges until each piece of them is an edge of
    /// the Delaunay triangulation of the points: insertion keeps it
    /// Delaunay, so no rebuild between splits.
    fn split_segments(&mut self, n0: usize, max_split: usize) -> Option<()> {
        let mut tri = Triangulation::new(&self.pts).ok()?;
        loop {
            let mut todo: Vec<(u32, u32)> = Vec::new();
            for ch in self.chains.values() {
                for w in ch.windows(2) {
                    if !tri.has_edge(w[0] + 4, w[1] + 4) {
                        todo.push((w[0], w[1]));
                    }
                }
            }
            tracing::debug!(
                missing = todo.len(),
                splits = self.pts.len() - n0,
                "conform: segments"
            );
            if todo.is_empty() {
                return Some(());
            }
            todo.sort_unstable();
            for (u, v) in todo {
                if self.pts.len() - n0 >= max_split {
                    return None;
                }
                let m = split_point(&self.pts, n0, u, v);
                let id = tri.insert(m).ok()?;
                debug_assert_eq!(id as usize, self.pts.len() + 4);
                self.split_edge(u, v, m);
            }
        }
    }

    /// Each split face's pieces as `tri` tiles it, where it does
    /// ([`tiling`], seen from outside with `outer`).
    pub(crate) fn retile(&mut self, tri: &Triangulation, outer: bool) {
        for i in 0..self.faces.len() {
            if self.pieces[i].len() > 1 {
                if let Some(t) = tiling(tri, self, i, outer) {
                    self.pieces[i] = t;
                }
            }
        }
    }

    /// Every piece, and its face.
    pub(crate) fn flat(&self) -> (Vec<[u32; 3]>, Vec<usize>) {
        let mut sub = Vec::new();
        let mut origin = Vec::new();
        for (i, ps) in self.pieces.iter().enumerate() {
            for &p in ps {
                sub.push(p);
                origin.push(i);
            }
        }
        (sub, origin)
    }

    /// A point on piece `piece` of face `face` that flips could not
    /// recover: the midpoint of an edge of it the triangulation lacks,
    /// else where an edge of the triangulation crosses it (which the point
    /// then removes), else its centroid.
    pub(crate) fn break_piece(
        &mut self,
        tri: &Triangulation,
        piece: [u32; 3],
        face: usize,
        split_edges: bool,
    ) {
        if !self.pieces[face].contains(&piece) {
            return; // already split this round
        }
        for k in 0..3 {
            if !split_edges {
                break;
            }
            let (u, v) = (piece[k], piece[(k + 1) % 3]);
            if !tri.has_edge(u + 4, v + 4) {
                // The midpoint: splitting where a face in the way crosses
                // the edge (as TetGen picks) left the tray's 158-face slab
                // open, which midpoints close.
                let m = mid(&self.pts, u, v);
                self.split_edge(u, v, m);
                return;
            }
        }
        let p = piece.map(|v| self.pts[v as usize]);
        let n = tri_normal_of(&self.pts, self.faces[face]);
        let (edges, _) = crossings(tri, piece.map(|v| v + 4));
        let strictly_in = |x: P3| {
            let q = p.map(|y| project(y, n));
            let qx = project(x, n);
            orient2d(q[0], q[1], qx) > 0.0
                && orient2d(q[1], q[2], qx) > 0.0
                && orient2d(q[2], q[0], qx) > 0.0
        };
        let mut at = None;
        for (u, v) in edges {
            let (pu, pv) = (tri.points()[u as usize], tri.points()[v as usize]);
            let (ou, ov) = (
                orient3d(p[0], p[1], p[2], pu),
                orient3d(p[0], p[1], p[2], pv),
            );
            if (ou > 0.0 && ov < 0.0) || (ou < 0.0 && ov > 0.0) {
                let x = add(pu, scale(parafront_geom::sub(pv, pu), ou / (ou - ov)));
                if strictly_in(x) {
                    at = Some(x);
                    break;
                }
            }
        }
        let x = at.unwrap_or_else(|| parafront_geom::centroid3(p[0], p[1], p[2]));
        if !strictly_in(x) {
            return;
        }
        let s = self.pts.len() as u32;
        self.pts.push(x);
        let ps = &mut self.pieces[face];
        let i = ps.iter().position(|&q| q == piece).unwrap_or(0);
        ps.swap_remove(i);
        let [a, b, c] = piece;
        ps.extend([[a, b, s], [b, c, s], [c, a, s]]);
    }

    /// Split edge `u`-`v` at `m`: the pieces on it (in every face) and its
    /// chain; an edge inside a face gets a chain of its own.
    pub(crate) fn split_edge(&mut self, u: u32, v: u32, m: P3) {
        let id = self.pts.len() as u32;
        self.pts.push(m);
        for ps in &mut self.pieces {
            let mut add_ = Vec::new();
            ps.retain(|&f| {
                for k in 0..3 {
                    let (a, b, w) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
                    if (a, b) == (u, v) || (a, b) == (v, u) {
                        add_.push([a, id, w]);
                        add_.push([id, b, w]);
                        return false;
                    }
                }
                true
            });
            ps.extend(add_);
        }
        for c in self.chains.values_mut() {
            if let Some(i) = c
                .windows(2)
                .position(|w| (w[0], w[1]) == (u, v) || (w[0], w[1]) == (v, u))
            {
                c.insert(i + 1, id);
                return;
            }
        }
        self.chains
            .insert((u.min(v), u.max(v)), vec![u.min(v), id, u.max(v)]);
    }
}

/// Where to split segment piece `u`-`v`: the midpoint, except next to an
/// input corner (`< n0`), where the piece from the corner gets a length
/// that is a power of two (Ruppert's concentric shells), so that the
/// splits of two edges at a small angle stop meeting.
pub(crate) fn split_point(pts: &[P3], n0: usize, u: u32, v: u32) -> P3 {
    let (pu, pv) = (pts[u as usize], pts[v as usize]);
    let (iu, iv) = ((u as usize) < n0, (v as usize) < n0);
    if iu == iv {
        return mid(pts, u, v);
    }
    let (a, b) = if iu { (pu, pv) } else { (pv, pu) };
    let l = dist(a, b);
    let d = 2f64.powf((0.5 * l).log2().round());
    let d = if d < l / 3.0 {
        2.0 * d
    } else if d > 2.0 * l / 3.0 {
        0.5 * d
    } else {
        d
    };
    let t = (d / l).clamp(0.25, 0.75);
    add(a, scale(parafront_geom::sub(b, a), t))
}

fn mid(pts: &[P3], u: u32, v: u32) -> P3 {
    scale(add(pts[u as usize], pts[v as usize]), 0.5)
}

/// The triangulation's own triangles on face `i`'s points, when they
/// tile it: as many as its pieces, none on one cavity edge, their areas
/// adding up to the face's. Oriented as the face. With `outer`, seen from
/// outside the cavity: split points lie off the face's plane by rounding,
/// so the triangulation may hold flat tets on a face's points, and of such
/// a layer the outer faces are taken (the flat tets are then inside, and go
/// when the split points move off the surface).
pub(crate) fn tiling(
    tri: &Triangulation,
    c: &Conforming,
    i: usize,
    outer: bool,
) -> Option<Vec<[u32; 3]>> {
    let set: FxHashSet<u32> = c.pieces[i].iter().flatten().map(|&v| v + 4).collect();
    let mut own: Vec<u32> = set.iter().map(|&v| v - 4).collect();
    own.sort_unstable();
    let on = chains_on(&c.chains, &own);
    let n = tri_normal_of(&c.pts, c.faces[i]);
    let flat = |t: u32| tri.tet(t).iter().all(|v| set.contains(v));
    let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
    let mut out = Vec::new();
    let mut area = 0.0;
    for &v in &set {
        for t in tri.star(v) {
            let tv = tri.tet(t);
            for (k, fv) in TET_FACES.iter().enumerate() {
                let w = fv.map(|j| tv[j]);
                if !w.iter().all(|x| set.contains(x)) || !seen.insert(key3(w)) {
                    continue;
                }
                let w = w.map(|x| x - 4);
                let d = parafront_geom::dot(tri_normal_of(&c.pts, w), n);
                if outer {
                    // Face k of t points away from t.
                    let beyond = if d > 0.0 {
                        t
                    } else {
                        let nb = tri.neighbour(t, k);
                        if nb == NONE {
                            return None;
                        }
                        nb >> 2
                    };
                    if flat(beyond) {
                        continue;
                    }
                }
                if one_chain(&on, w) {
                    return None;
                }
                area += d.abs();
                out.push(if d > 0.0 { w } else { [w[0], w[2], w[1]] });
            }
        }
    }
    out.sort_unstable();
    let whole = parafront_geom::dot(n, n);
    (out.len() == c.pieces[i].len() && (area - whole).abs() <= 1e-9 * whole).then_some(out)
}

/// The chains (of three points or more) that hold at least three of
/// `on`: the only ones [`between`] and [`one_chain`] can find three given
/// points of `on` on. Looked up once per polygon, not per test (a split
/// point's polygon took a tenth of the plate's fill over all chains).
pub(crate) fn chains_on<'c>(chains: &'c Chains, on: &[u32]) -> Vec<&'c [u32]> {
    chains
        .values()
        .filter(|ch| ch.len() >= 3 && ch.iter().filter(|v| on.contains(v)).count() >= 3)
        .map(|ch| ch.as_slice())
        .collect()
}

/// Point `x` lies between `a` and `c` on a cavity edge (one of `chains`).
fn between(chains: &[&[u32]], a: u32, x: u32, c: u32) -> bool {
    chains.iter().any(|ch| {
        let pos = |v: u32| ch.iter().position(|&w| w == v);
        match (pos(a), pos(x), pos(c)) {
            (Some(i), Some(j), Some(k)) => (i < j && j < k) || (k < j && j < i),
            _ => false,
        }
    })
}

/// Points on one cavity edge (one of `chains`; rounding may leave them
/// not quite in line). Only a split edge holds three points.
pub(crate) fn one_chain(chains: &[&[u32]], w: [u32; 3]) -> bool {
    chains
        .iter()
        .any(|c| c.len() >= 3 && w.iter().all(|v| c.contains(v)))
}

pub(crate) fn tri_normal_of(pts: &[P3], f: [u32; 3]) -> P3 {
    tri_normal(pts[f[0] as usize], pts[f[1] as usize], pts[f[2] as usize])
}

/// 2D coordinates in the plane with normal `n`, orientation kept.
fn project(p: P3, n: P3) -> [f64; 2] {
    let k = (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2);
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    if n[k] >= 0.0 {
        [p[i], p[j]]
    } else {
        [p[j], p[i]]
    }
}

/// A triangulation of the planar polygon `poly` (counter-clockwise seen
/// from normal `n`) by ears, the fattest ear first.
#[cfg(test)]
fn ear_clip(pts: &[P3], chains: &Chains, poly: &[u32], n: P3) -> Option<Vec<[u32; 3]>> {
    ear_clip_preferring(pts, chains, poly, n, &FxHashSet::default())
}

/// [`ear_clip`], taking ears in `prefer` (as [`key3`] keys) first.
pub(crate) fn ear_clip_preferring(
    pts: &[P3],
    chains: &Chains,
    poly: &[u32],
    n: P3,
    prefer: &FxHashSet<[u32; 3]>,
) -> Option<Vec<[u32; 3]>> {
    if poly.len() < 3 {
        return None;
    }
    let q: FxHashMap<u32, [f64; 2]> = poly
        .iter()
        .map(|&v| (v, project(pts[v as usize], n)))
        .collect();
    let chains = chains_on(chains, poly);
    let chains = chains.as_slice();
    let mut ring: Vec<u32> = poly.to_vec();
    let mut out = Vec::new();
    while ring.len() > 3 {
        let m = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..m {
            let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            let (pa, pb, pc) = (q[&a], q[&b], q[&c]);
            if orient2d(pa, pb, pc) <= 0.0 || one_chain(chains, [a, b, c]) {
                continue;
            }
            // A point inside the ear, or on its new edge's line between
            // its ends (rounding can put it on either side).
            let blocked = ring.iter().any(|&x| {
                x != a
                    && x != b
                    && x != c
                    && (between(chains, a, x, c) || {
                        let px = q[&x];
                        orient2d(pa, pb, px) >= 0.0
                            && orient2d(pb, pc, px) >= 0.0
                            && orient2d(pc, pa, px) >= 0.0
                    })
            });
            if blocked {
                continue;
            }
            let mut s = ear_shape(pts, a, b, c);
            if prefer.contains(&key3([a, b, c])) {
                s += 1.0;
            }
            if best.is_none_or(|(bs, _)| s > bs) {
                best = Some((s, i));
            }
        }
        let (_, i) = best?;
        out.push([ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]]);
        ring.remove(i);
    }
    let (pa, pb, pc) = (q[&ring[0]], q[&ring[1]], q[&ring[2]]);
    if orient2d(pa, pb, pc) <= 0.0 || one_chain(chains, [ring[0], ring[1], ring[2]]) {
        return None;
    }
    out.push([ring[0], ring[1], ring[2]]);
    Some(out)
}

/// The fans of the planar polygon `poly` (counter-clockwise seen from
/// normal `n`) from each of its corners that has one.
pub(crate) fn polygon_fans(pts: &[P3], chains: &Chains, poly: &[u32], n: P3) -> Vec<Vec<[u32; 3]>> {
    let m = poly.len();
    let q: Vec<[f64; 2]> = poly.iter().map(|&v| project(pts[v as usize], n)).collect();
    let chains = chains_on(chains, poly);
    let chains = chains.as_slice();
    let mut out = Vec::new();
    'apex: for k in 0..m {
        let mut fan = Vec::with_capacity(m - 2);
        for i in 1..m - 1 {
            let (a, b, c) = (k, (k + i) % m, (k + i + 1) % m);
            let w = [poly[a], poly[b], poly[c]];
            if orient2d(q[a], q[b], q[c]) <= 0.0 || one_chain(chains, w) {
                continue 'apex;
            }
            fan.push(w);
        }
        out.push(fan);
    }
    out
}

/// Area over the squared edge lengths (scale-free).
fn ear_shape(pts: &[P3], a: u32, b: u32, c: u32) -> f64 {
    let (pa, pb, pc) = (pts[a as usize], pts[b as usize], pts[c as usize]);
    let area = parafront_geom::norm(tri_normal(pa, pb, pc));
    let l = parafront_geom::dist2(pa, pb)
        + parafront_geom::dist2(pb, pc)
        + parafront_geom::dist2(pc, pa);
    area / l
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::relocate::verify;

    #[test]
    fn ears_skip_a_split_point_on_the_new_edge() {
        // A needle face (0, 1, 2) with point 3 on its edge 2-0, slightly
        // off the line: the fattest ear (0, 1, 2) would leave 0, 2, 3.
        let pts = vec![
            [103.9553374716597, 2.1166666666666667, -336.28027547894186],
            [118.1576, 0.0, -325.5918],
            [104.0257, 3.175, -355.6],
            [103.99051873582985, 2.645833333333333, -345.94013773947097],
        ];
        let mut chains = Chains::default();
        chains.insert((0, 2), vec![2, 3, 0]);
        let ears =
            ear_clip(&pts, &chains, &[0, 1, 2, 3], tri_normal_of(&pts, [0, 1, 2])).expect("ears");
        assert_eq!(ears.len(), 2);
        assert!(ears.iter().all(|e| e.contains(&3) && e.contains(&1)));
    }

    /// Schönhardt's twisted prism, faces inward: no tetrahedralization
    /// without a Steiner point.
    fn schonhardt(twist: f64, height: f64) -> (Vec<P3>, Vec<[u32; 3]>) {
        let mut pts = Vec::new();
        for (z, t) in [(0.0, 0.0), (height, twist)] {
            for k in 0..3 {
                let a = t + k as f64 * std::f64::consts::TAU / 3.0;
                pts.push([a.cos(), a.sin(), z]);
            }
        }
        let mut faces = vec![[0, 1, 2], [3, 5, 4]];
        for k in 0..3u32 {
            let (a, b) = (k, (k + 1) % 3);
            // The twisted quad a, b, b+3, a+3 split along a-(b+3).
            faces.push([a, b + 3, b]);
            faces.push([a, a + 3, b + 3]);
        }
        (pts, faces)
    }

    #[test]
    fn conforms_twisted_prisms_with_points_inside() {
        for (twist, height) in [(0.5, 1.0), (0.9, 0.01), (0.3, 50.0)] {
            let (pts, faces) = schonhardt(twist, height);
            let (steiner, tets) = conform_fill(&pts, &faces, 256, 8, false).expect("conformed");
            let mut all = pts.clone();
            all.extend_from_slice(&steiner);
            assert!(verify(&all, &tets, &faces).is_some());
            assert!(!steiner.is_empty());
            // No point is left on the prism's surface.
            for q in &steiner {
                assert!(
                    crate::fill::inside_surface(&pts, &faces, *q),
                    "{q:?} not inside"
                );
            }
        }
    }
}
