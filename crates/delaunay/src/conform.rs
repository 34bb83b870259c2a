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
//! With `segments_first`, the cavity's edges are split before any round
//! until each piece is an edge of the Delaunay triangulation (Bowyer-Watson
//! keeps it Delaunay, so no flips and no rebuild): on round.stl's 1,120
//! needle faces, 602 points in 0.15 s, where flips left 296 faces missing.
//! A surface whose split points crowd each other (two needles side by
//! side) needs far more (plate_holes: 17,854 for 1,252 faces), and the
//! budget stops it.
use crate::flips::key3;
use crate::recover::{crossings, recover_all};
use crate::tri::{Triangulation, TET_FACES};
use parafront_geom::{
    add, dist, kernel::deepest_point, normalize, orient2d, orient3d, scale, tri_normal, P3,
};
use rustc_hash::{FxHashMap, FxHashSet};

/// Each cavity edge (lower id first) as its points in order.
type Chains = FxHashMap<(u32, u32), Vec<u32>>;

/// Triangulations built before the conforming fill gives up.
const REBUILDS: usize = 24;
/// Halvings of the step off the surface tried for a relocated point.
const STEP_HALVINGS: usize = 40;

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
        for i in 0..faces.len() {
            if c.pieces[i].len() > 1 {
                if let Some(t) = dt_tiling(&tri, &c, i) {
                    c.pieces[i] = t;
                }
            }
        }
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
            return relocate(lp.len(), c.pts, &c.chains, tets, sub, origin, faces);
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
            c.break_piece(&tri, piece, face);
        }
    }
    None
}

/// The cavity's surface as it is split: its points, its edges' chains, and
/// each face's pieces.
struct Conforming {
    pts: Vec<P3>,
    chains: Chains,
    faces: Vec<[u32; 3]>,
    pieces: Vec<Vec<[u32; 3]>>,
}

impl Conforming {
    fn new(lp: &[P3], faces: &[[u32; 3]]) -> Conforming {
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
                    if !has_edge(&tri, w[0] + 4, w[1] + 4) {
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

    /// Every piece, and its face.
    fn flat(&self) -> (Vec<[u32; 3]>, Vec<usize>) {
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
    fn break_piece(&mut self, tri: &Triangulation, piece: [u32; 3], face: usize) {
        if !self.pieces[face].contains(&piece) {
            return; // already split this round
        }
        for k in 0..3 {
            let (u, v) = (piece[k], piece[(k + 1) % 3]);
            if !has_edge(tri, u + 4, v + 4) {
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
    fn split_edge(&mut self, u: u32, v: u32, m: P3) {
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
fn split_point(pts: &[P3], n0: usize, u: u32, v: u32) -> P3 {
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
/// adding up to the face's. Oriented as the face.
fn dt_tiling(tri: &Triangulation, c: &Conforming, i: usize) -> Option<Vec<[u32; 3]>> {
    let set: FxHashSet<u32> = c.pieces[i].iter().flatten().map(|&v| v + 4).collect();
    let n = tri_normal_of(&c.pts, c.faces[i]);
    let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
    let mut out = Vec::new();
    let mut area = 0.0;
    for &v in &set {
        for t in tri.star(v) {
            let tv = tri.tet(t);
            for fv in TET_FACES {
                let w = fv.map(|j| tv[j]);
                if !w.iter().all(|x| set.contains(x)) || !seen.insert(key3(w)) {
                    continue;
                }
                let w = w.map(|x| x - 4);
                if one_chain(&c.chains, w) {
                    return None;
                }
                let m = tri_normal_of(&c.pts, w);
                let d = parafront_geom::dot(m, n);
                area += d.abs();
                out.push(if d > 0.0 { w } else { [w[0], w[2], w[1]] });
            }
        }
    }
    out.sort_unstable();
    let whole = parafront_geom::dot(n, n);
    (out.len() == c.pieces[i].len() && (area - whole).abs() <= 1e-9 * whole).then_some(out)
}

/// Point `x` lies between `a` and `c` on a cavity edge.
fn between(chains: &Chains, a: u32, x: u32, c: u32) -> bool {
    chains.values().any(|ch| {
        let pos = |v: u32| ch.iter().position(|&w| w == v);
        match (pos(a), pos(x), pos(c)) {
            (Some(i), Some(j), Some(k)) => (i < j && j < k) || (k < j && j < i),
            _ => false,
        }
    })
}

/// Points on one cavity edge (rounding may leave them not quite in line).
fn one_chain(chains: &Chains, w: [u32; 3]) -> bool {
    chains.values().any(|c| w.iter().all(|v| c.contains(v)))
}

fn has_edge(tri: &Triangulation, u: u32, v: u32) -> bool {
    tri.star(u).iter().any(|&t| tri.tet(t).contains(&v))
}

fn tri_normal_of(pts: &[P3], f: [u32; 3]) -> P3 {
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
fn ear_clip(pts: &[P3], chains: &Chains, poly: &[u32], n: P3) -> Option<Vec<[u32; 3]>> {
    if poly.len() < 3 {
        return None;
    }
    let q: FxHashMap<u32, [f64; 2]> = poly
        .iter()
        .map(|&v| (v, project(pts[v as usize], n)))
        .collect();
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
            let s = ear_shape(pts, a, b, c);
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

/// Area over the squared edge lengths (scale-free).
fn ear_shape(pts: &[P3], a: u32, b: u32, c: u32) -> f64 {
    let (pa, pb, pc) = (pts[a as usize], pts[b as usize], pts[c as usize]);
    let area = parafront_geom::norm(tri_normal(pa, pb, pc));
    let l = parafront_geom::dist2(pa, pb)
        + parafront_geom::dist2(pb, pc)
        + parafront_geom::dist2(pc, pa);
    area / l
}

/// Move each split point off the surface: its star's tets give way to the
/// cone from a point just inside over the star's link and the faces it
/// split, made whole without it (`sub` are the current surface pieces,
/// `origin` their cavity faces). Checked: every tet positive, the surface
/// exactly `faces`, the volume the cavity's.
fn relocate(
    n: usize,
    mut pts: Vec<P3>,
    chains: &Chains,
    mut tets: Vec<[u32; 4]>,
    mut sub: Vec<[u32; 3]>,
    mut origin: Vec<usize>,
    faces: &[[u32; 3]],
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let split_points: Vec<u32> = (n as u32..pts.len() as u32).collect();
    for s in split_points {
        let star: Vec<usize> = (0..tets.len()).filter(|&t| tets[t].contains(&s)).collect();
        // The link, each face seen from inside the hole.
        let mut hole: Vec<[u32; 3]> = Vec::new();
        for &t in &star {
            let tv = tets[t];
            let k = tv.iter().position(|&v| v == s)?;
            let w = TET_FACES[k].map(|j| tv[j]);
            hole.push([w[0], w[2], w[1]]);
        }
        // The surface pieces on `s`, by cavity face, made whole without it.
        let mut by_face: Vec<(usize, Vec<usize>)> = Vec::new();
        for (i, f) in sub.iter().enumerate() {
            if f.contains(&s) {
                match by_face.iter_mut().find(|(o, _)| *o == origin[i]) {
                    Some((_, l)) => l.push(i),
                    None => by_face.push((origin[i], vec![i])),
                }
            }
        }
        let mut patch: Vec<([u32; 3], usize)> = Vec::new();
        let mut normals: Vec<P3> = Vec::new();
        for (o, list) in &by_face {
            let nrm = tri_normal_of(&pts, faces[*o]);
            normals.push(normalize(nrm));
            let poly = fan_polygon(&sub, list, s)?;
            for p in ear_clip(&pts, chains, &poly, nrm)? {
                patch.push((p, *o));
            }
        }
        hole.extend(patch.iter().map(|(p, _)| *p));
        let new_tets: Vec<[u32; 4]> = match cone_point(&pts, &hole, s, &normals) {
            Some(q) => {
                let qid = pts.len() as u32;
                pts.push(q);
                hole.iter().map(|w| [w[0], w[1], w[2], qid]).collect()
            }
            None => {
                // No point sees the whole hole: it is a cavity of its own,
                // filled without splits.
                let opts = crate::fill::FillOptions {
                    max_split: 0,
                    ..Default::default()
                };
                let fill = match crate::fill::fill_cavity(&pts, &hole, &opts) {
                    Ok(f) => f,
                    Err(e) => {
                        tracing::debug!(hole = hole.len(), error = %e, "conform: hole not filled");
                        return None;
                    }
                };
                pts.extend_from_slice(&fill.steiner);
                fill.tets
            }
        };
        let mut dead = vec![false; tets.len()];
        for &t in &star {
            dead[t] = true;
        }
        let mut next: Vec<[u32; 4]> = (0..tets.len())
            .filter(|&t| !dead[t])
            .map(|t| tets[t])
            .collect();
        next.extend(new_tets);
        tets = next;
        let keep: Vec<usize> = (0..sub.len()).filter(|&i| !sub[i].contains(&s)).collect();
        sub = keep.iter().map(|&i| sub[i]).collect();
        origin = keep.iter().map(|&i| origin[i]).collect();
        for (p, o) in patch {
            sub.push(p);
            origin.push(o);
        }
    }
    if verify(&pts, &tets, faces).is_none() {
        tracing::debug!("conform: verify failed");
        return None;
    }
    // Renumber: the cavity's points, then the relocated points in order.
    let mut used: Vec<u32> = tets
        .iter()
        .flatten()
        .copied()
        .filter(|&v| v as usize >= n)
        .collect();
    used.sort_unstable();
    used.dedup();
    let id: FxHashMap<u32, u32> = used
        .iter()
        .enumerate()
        .map(|(k, &v)| (v, (n + k) as u32))
        .collect();
    let steiner = used.iter().map(|&v| pts[v as usize]).collect();
    let tets = tets
        .iter()
        .map(|t| t.map(|v| if (v as usize) < n { v } else { id[&v] }))
        .collect();
    Some((steiner, tets))
}

/// The outer chain of the fan of pieces `list` around `s`: from the
/// corner after `s` on its edge round to the one before it, or the whole
/// ring when `s` is inside the face.
fn fan_polygon(sub: &[[u32; 3]], list: &[usize], s: u32) -> Option<Vec<u32>> {
    // Each piece (s, x, y) in its cyclic order gives the chain step x -> y.
    let mut next: FxHashMap<u32, u32> = FxHashMap::default();
    let mut has_in: FxHashSet<u32> = FxHashSet::default();
    for &i in list {
        let f = sub[i];
        let k = f.iter().position(|&v| v == s)?;
        let (x, y) = (f[(k + 1) % 3], f[(k + 2) % 3]);
        if next.insert(x, y).is_some() {
            return None;
        }
        has_in.insert(y);
    }
    // A point on an edge has a path of pieces on each face; one inside a
    // face has a closed fan.
    let open = next.keys().filter(|x| !has_in.contains(x)).min().copied();
    let start = match open {
        Some(v) => v,
        None => *next.keys().min()?,
    };
    let mut chain = vec![start];
    let mut v = start;
    while let Some(&w) = next.get(&v) {
        if w == start {
            break;
        }
        chain.push(w);
        v = w;
        if chain.len() > list.len() + 1 {
            return None;
        }
    }
    let want = if open.is_some() {
        list.len() + 1
    } else {
        list.len()
    };
    (chain.len() == want).then_some(chain)
}

/// A point that sees every face of `hole` from inside: the kernel's deepest
/// point, else `s` moved into the cavity along the faces' `normals`, a step
/// halved until it sees them all.
fn cone_point(pts: &[P3], hole: &[[u32; 3]], s: u32, normals: &[P3]) -> Option<P3> {
    let sees = |q: P3| {
        hole.iter().all(|w| {
            let p = w.map(|v| pts[v as usize]);
            orient3d(p[0], p[1], p[2], q) > 0.0
        })
    };
    let planes: Vec<(P3, P3)> = hole
        .iter()
        .map(|w| {
            let p = w.map(|v| pts[v as usize]);
            (p[0], tri_normal(p[0], p[1], p[2]))
        })
        .collect();
    if let Some((q, depth)) = deepest_point(&planes) {
        if depth > 0.0 && q.iter().all(|x| x.is_finite()) && sees(q) {
            return Some(q);
        }
    }
    let ps = pts[s as usize];
    let d = normalize(normals.iter().fold([0.0; 3], |a, &b| add(a, b)));
    let mut step = hole
        .iter()
        .flatten()
        .map(|&v| dist(pts[v as usize], ps))
        .fold(f64::INFINITY, f64::min)
        * 0.25;
    for _ in 0..STEP_HALVINGS {
        let q = add(ps, scale(d, step));
        if sees(q) {
            return Some(q);
        }
        step *= 0.5;
    }
    None
}

/// Every tet positive, every inner face in two tets from either side, the
/// outer faces exactly the cavity's faces, and the tets' volume the
/// cavity's.
fn verify(pts: &[P3], tets: &[[u32; 4]], faces: &[[u32; 3]]) -> Option<()> {
    let mut open: FxHashMap<[u32; 3], [u32; 3]> = FxHashMap::default();
    let mut vol = 0.0;
    for t in tets {
        let p = t.map(|v| pts[v as usize]);
        let o = orient3d(p[0], p[1], p[2], p[3]);
        if !(o > 0.0) {
            return None;
        }
        vol += o;
        for fv in TET_FACES {
            let w = fv.map(|j| t[j]);
            let k = key3(w);
            match open.remove(&k) {
                Some(o) if !crate::flips::same_cycle(o, w) => {}
                Some(_) => return None,
                None => {
                    open.insert(k, w);
                }
            }
        }
    }
    if open.len() != faces.len() {
        return None;
    }
    let o = pts[faces[0][0] as usize];
    let mut cav = 0.0;
    for f in faces {
        // A cavity face's outward tet face is the face reversed.
        let w = *open.get(&key3(*f))?;
        if !crate::flips::same_cycle([f[0], f[2], f[1]], w) {
            return None;
        }
        let p = f.map(|v| pts[v as usize]);
        cav += orient3d(p[0], p[1], p[2], o);
    }
    let ok = tets.iter().flatten().all(|&v| (v as usize) < pts.len())
        && (vol - cav).abs() <= 1e-9 * cav.abs().max(f64::MIN_POSITIVE);
    ok.then_some(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
