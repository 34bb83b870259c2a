//! Local re-triangulations that keep a triangulation valid: the 2-3 flip
//! and edge removal (3-2, 4-4 and larger rings, by a fan over the ring),
//! and their nested forms (a flip blocked by an edge removes that edge
//! first, a few levels deep, as TetGen's flipnm).
//! Each is tried, checked exactly, and done only when every new tet is
//! positive; faces in `protect` are never removed.
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::orient3d;
use rustc_hash::{FxHashMap, FxHashSet};

/// What a local operation did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flip {
    /// Done: the new tets, each positive, replace the old ones.
    Done,
    /// A new tet would not be positive.
    NotConvex,
    /// It would remove a protected face or edge.
    Protected,
    /// The configuration does not allow it (an open ring, a bounding face).
    NotApplicable,
}

#[inline]
pub(crate) fn key3(mut w: [u32; 3]) -> [u32; 3] {
    w.sort_unstable();
    w
}

/// A protected edge's key in a set of face keys: its ends in order, then
/// `NONE`, which no face holds.
#[inline]
pub(crate) fn edge_key(u: u32, v: u32) -> [u32; 3] {
    [u.min(v), u.max(v), NONE]
}

/// Whether `a` and `b` are the same oriented triangle (one a rotation of
/// the other).
#[inline]
pub(crate) fn same_cycle(a: [u32; 3], b: [u32; 3]) -> bool {
    a == b || a == [b[1], b[2], b[0]] || a == [b[2], b[0], b[1]]
}

impl Triangulation {
    /// Replace the live tets `old` (which must form a region) by `new`
    /// (positive tets covering the same region), relinking the faces.
    pub(crate) fn replace(&mut self, old: &[u32], new: &[[u32; 4]]) -> Vec<u32> {
        let mut outer: FxHashMap<[u32; 3], u32> = FxHashMap::default();
        let olds: FxHashSet<u32> = old.iter().copied().collect();
        for &t in old {
            let tv = self.tets[t as usize];
            for f in 0..4 {
                let nb = self.neigh[4 * t as usize + f];
                if nb != NONE && olds.contains(&(nb >> 2)) {
                    continue;
                }
                outer.insert(key3(TET_FACES[f].map(|k| tv[k])), nb);
            }
        }
        for &t in old {
            self.kill_tet(t);
        }
        let mut inner: FxHashMap<[u32; 3], u32> = FxHashMap::default();
        let mut made = Vec::with_capacity(new.len());
        for &tv in new {
            let t = self.new_tet(tv);
            made.push(t);
            for f in 0..4 {
                let k = key3(TET_FACES[f].map(|i| tv[i]));
                let fr = 4 * t + f as u32;
                if let Some(nb) = outer.remove(&k) {
                    self.neigh[fr as usize] = nb;
                    if nb != NONE {
                        self.neigh[nb as usize] = fr;
                    }
                } else if let Some(o) = inner.remove(&k) {
                    self.link(fr, o);
                } else {
                    inner.insert(k, fr);
                }
            }
            for &v in &tv {
                self.vtet[v as usize] = t;
            }
        }
        debug_assert!(
            outer.is_empty() && inner.is_empty(),
            "re-triangulation does not match its region"
        );
        made
    }

    /// 2-3 flip of face `4t+f`: the two tets on it become three around the
    /// edge between their apexes.
    pub fn flip23(&mut self, fr: u32, protect: &FxHashSet<[u32; 3]>) -> Flip {
        let (t, f) = (fr >> 2, (fr & 3) as usize);
        let nb = self.neigh[fr as usize];
        if nb == NONE {
            return Flip::NotApplicable;
        }
        let tv = self.tets[t as usize];
        let w = TET_FACES[f].map(|k| tv[k]);
        if protect.contains(&key3(w)) {
            return Flip::Protected;
        }
        let a = tv[f];
        let b = self.tets[(nb >> 2) as usize][(nb & 3) as usize];
        // w is outward from t, so b lies on its normal side.
        let mut new = Vec::with_capacity(3);
        for i in 0..3 {
            let (x, y) = (w[i], w[(i + 1) % 3]);
            // (x, y, b, a) is positive iff the edge a-b passes inside w
            // on the far side of x-y from w's third corner.
            let tv2 = [x, y, a, b];
            let p = tv2.map(|v| self.pts[v as usize]);
            if orient3d(p[0], p[1], p[2], p[3]) <= 0.0 {
                return Flip::NotConvex;
            }
            new.push(tv2);
        }
        self.replace(&[t, nb >> 2], &new);
        Flip::Done
    }

    /// The tets around edge `p`-`q` and the ring of their other corners in
    /// order, or `None` when the ring is open or the edge is missing.
    pub(crate) fn edge_ring(&self, p: u32, q: u32) -> Option<(Vec<u32>, Vec<u32>)> {
        if let Some((mp, mq, g, tets, ring)) = &*self.ring_memo.borrow() {
            if (*mp, *mq, *g) == (p, q, self.generation) {
                return Some((tets.clone(), ring.clone()));
            }
        }
        let out = self.edge_ring_walk(p, q)?;
        *self.ring_memo.borrow_mut() = Some((p, q, self.generation, out.0.clone(), out.1.clone()));
        Some(out)
    }

    fn edge_ring_walk(&self, p: u32, q: u32) -> Option<(Vec<u32>, Vec<u32>)> {
        // Not from a bounding corner, whose star holds the hull.
        let (a, b) = if p < 4 { (q, p) } else { (p, q) };
        let mut tets: Vec<u32> = Vec::new();
        self.star_find(a, |t| {
            if self.tets[t as usize].contains(&b) {
                tets.push(t);
            }
            false
        });
        if tets.len() < 3 {
            return None;
        }
        // Each tet as (its two other corners in the order that makes
        // (p, q, r0, r1) positive); a ring is short, so a list serves.
        let mut next: Vec<(u32, u32)> = Vec::with_capacity(tets.len());
        for &t in &tets {
            let mut others = self.tets[t as usize]
                .into_iter()
                .filter(|&v| v != p && v != q);
            let (Some(o0), Some(o1)) = (others.next(), others.next()) else {
                return None; // not a tet on the edge
            };
            let o = [o0, o1];
            let pts = [p, q, o[0], o[1]].map(|v| self.pts[v as usize]);
            let (r0, r1) = if orient3d(pts[0], pts[1], pts[2], pts[3]) > 0.0 {
                (o[0], o[1])
            } else {
                (o[1], o[0])
            };
            // A later tet with the same r0 replaced the earlier (a map's
            // insert).
            match next.iter_mut().find(|e| e.0 == r0) {
                Some(e) => e.1 = r1,
                None => next.push((r0, r1)),
            }
        }
        let start = next.iter().map(|e| e.0).min()?;
        let mut ring = vec![start];
        let mut v = start;
        for _ in 0..tets.len() {
            v = next.iter().find(|e| e.0 == v)?.1;
            if v == start {
                break;
            }
            ring.push(v);
        }
        (ring.len() == tets.len()).then_some((tets, ring))
    }

    /// Remove edge `p`-`q`: its ring of tets is re-triangulated as a fan
    /// over the ring polygon joined to `p` and to `q` (a 3-2 flip for a
    /// ring of three, 4-4 for four). Every fan apex is tried.
    pub fn remove_edge(&mut self, p: u32, q: u32, protect: &FxHashSet<[u32; 3]>) -> Flip {
        self.remove_edge_deep(p, q, protect, 0)
    }

    /// [`Triangulation::remove_edge`], where no fan is positive shrinking
    /// the ring by 2-3 flips of the faces around the edge (each takes one
    /// corner out of the ring; Shewchuk's edge removal by flips), each
    /// flip itself [`Triangulation::flip23_deep`] to `depth` levels.
    pub(crate) fn remove_edge_deep(
        &mut self,
        p: u32,
        q: u32,
        protect: &FxHashSet<[u32; 3]>,
        depth: u32,
    ) -> Flip {
        let r = self.remove_edge_fan(p, q, protect);
        if r != Flip::NotConvex {
            return r;
        }
        let Some((_, ring0)) = self.edge_ring(p, q) else {
            return Flip::NotApplicable;
        };
        for _ in 0..2 * ring0.len() + 8 {
            let Some((_, ring)) = self.edge_ring(p, q) else {
                return Flip::NotApplicable;
            };
            if ring.len() <= 3 {
                return self.remove_edge_fan(p, q, protect);
            }
            let mut shrunk = false;
            for &r in &ring {
                let Some(fr) = self.find_face([p, q, r]) else {
                    continue;
                };
                if self.flip23_deep(fr, protect, depth, (p, q)) == Flip::Done {
                    shrunk = true;
                    break;
                }
            }
            if !shrunk {
                return Flip::NotConvex;
            }
            if self.remove_edge_fan(p, q, protect) == Flip::Done {
                return Flip::Done;
            }
        }
        Flip::NotConvex
    }

    /// The 2-3 flip of face `fr`, or, where the edge between its two
    /// apexes passes outside it across one of its edges (other than
    /// `keep`), that edge's removal, to `depth` levels (TetGen's flipnm).
    pub(crate) fn flip23_deep(
        &mut self,
        fr: u32,
        protect: &FxHashSet<[u32; 3]>,
        depth: u32,
        keep: (u32, u32),
    ) -> Flip {
        let r = self.flip23(fr, protect);
        if r != Flip::NotConvex || depth == 0 {
            return r;
        }
        let nb = self.neigh[fr as usize];
        let w = self.face_corners(fr);
        let a = self.tets[(fr >> 2) as usize][(fr & 3) as usize];
        let b = self.tets[(nb >> 2) as usize][(nb & 3) as usize];
        for i in 0..3 {
            let (x, y) = (w[i], w[(i + 1) % 3]);
            if (x, y) == keep || (y, x) == keep {
                continue;
            }
            let pt = |v: u32| self.pts[v as usize];
            if orient3d(pt(x), pt(y), pt(a), pt(b)) <= 0.0
                && self.remove_edge_deep(x, y, protect, depth - 1) == Flip::Done
            {
                return Flip::Done;
            }
        }
        Flip::NotConvex
    }

    fn remove_edge_fan(&mut self, p: u32, q: u32, protect: &FxHashSet<[u32; 3]>) -> Flip {
        let Some((tets, ring)) = self.edge_ring(p, q) else {
            return Flip::NotApplicable;
        };
        let n = ring.len();
        if protect.contains(&edge_key(p, q)) {
            return Flip::Protected;
        }
        for &r in &ring {
            if protect.contains(&key3([p, q, r])) {
                return Flip::Protected;
            }
        }
        let pt = |v: u32| self.pts[v as usize];
        'apex: for k in 0..n {
            let mut new = Vec::with_capacity(2 * (n - 2));
            for i in 1..n - 1 {
                let (a, b, c) = (ring[k], ring[(k + i) % n], ring[(k + i + 1) % n]);
                // (p, q, a, b) positive means the ring turns (a -> b) about
                // p -> q; the triangle (a, b, c) then has q ... check both.
                let tq = [a, b, c, q];
                let tp = [a, c, b, p];
                for tv in [tq, tp] {
                    if orient3d(pt(tv[0]), pt(tv[1]), pt(tv[2]), pt(tv[3])) <= 0.0 {
                        continue 'apex;
                    }
                }
                new.push(tq);
                new.push(tp);
            }
            self.replace(&tets, &new);
            return Flip::Done;
        }
        Flip::NotConvex
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_geom::P3;

    fn points(n: usize, mut s: u64) -> Vec<P3> {
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| [r(), r(), r()]).collect()
    }

    /// The edges of live tets between given points (ids from 4).
    fn inner_edges(tri: &Triangulation) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = tri
            .live_tets()
            .flat_map(|t| {
                let v = tri.tet(t);
                [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                    .map(|(a, b)| (v[a].min(v[b]), v[a].max(v[b])))
            })
            .filter(|&(a, _)| a >= 4)
            .collect();
        e.sort_unstable();
        e.dedup();
        e
    }

    /// Each edge's ring holds exactly the live tets on both ends, its
    /// memo answers as a fresh walk does, also after flips change the
    /// tets; `find_face` finds the first tet of the star that holds the
    /// face, as a scan of the whole star does.
    #[test]
    fn rings_and_faces_match_a_fresh_search_after_flips() {
        let mut tri = Triangulation::new(&points(80, 7)).unwrap();
        let none = FxHashSet::default();
        for round in 0..40 {
            for (p, q) in inner_edges(&tri) {
                let fresh = tri.edge_ring_walk(p, q);
                assert_eq!(tri.edge_ring(p, q), fresh, "round {round}, edge {p}-{q}");
                assert_eq!(tri.edge_ring(p, q), fresh, "memo, edge {p}-{q}");
                if let Some((tets, ring)) = fresh {
                    let mut on: Vec<u32> = tri
                        .live_tets()
                        .filter(|&t| tri.tet(t).contains(&p) && tri.tet(t).contains(&q))
                        .collect();
                    let mut got = tets.clone();
                    on.sort_unstable();
                    got.sort_unstable();
                    assert_eq!(got, on);
                    assert_eq!(ring.len(), tets.len());
                }
            }
            for t in tri.live_tets().collect::<Vec<_>>() {
                for f in 0..4 {
                    let w = tri.face_corners(4 * t + f);
                    let a = w.iter().copied().find(|&x| x >= 4).unwrap_or(w[0]);
                    let first = tri
                        .star(a)
                        .into_iter()
                        .find(|&u| w.iter().all(|x| tri.tet(u).contains(x)))
                        .unwrap();
                    let fr = tri.find_face(w).unwrap();
                    assert_eq!(fr >> 2, first);
                    assert_eq!(key3(tri.face_corners(fr)), key3(w));
                }
            }
            // Change the tets around an edge whose ring was just asked: a
            // 2-3 flip of a face on it takes a corner out of its ring, or
            // else the edge's removal.
            let edges = inner_edges(&tri);
            let (p, q) = edges[(round * 37) % edges.len()];
            let Some((_, ring)) = tri.edge_ring(p, q) else {
                continue;
            };
            let flipped = ring.iter().any(|&r| {
                let fr = tri.find_face([p, q, r]).unwrap();
                tri.flip23(fr, &none) == Flip::Done
            });
            if flipped {
                let (_, after) = tri.edge_ring(p, q).unwrap();
                assert!(after.len() < ring.len());
                assert_eq!(tri.edge_ring(p, q), tri.edge_ring_walk(p, q));
            } else {
                tri.remove_edge(p, q, &none);
            }
            tri.check().unwrap();
        }
    }
}
