//! Point insertion that keeps constraints: Bowyer-Watson's cavity grows
//! only across faces that are not protected, then shrinks until the new
//! point sees each of its boundary faces strictly from inside and no
//! protected face, protected edge or point is left inside it (TetGen's
//! constrained insertion of a Steiner point on a segment).
use crate::flips::{edge_key, key3};
use crate::predicates::in_sphere_sos;
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::{orient3d, P3};
use rustc_hash::{FxHashMap, FxHashSet};

/// The six edges of a tet, as corner pairs.
const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

impl Triangulation {
    /// Insert `p`, keeping every face and edge in `protect` (keys as
    /// [`key3`] and [`edge_key`] make them): its id, or `None` (nothing
    /// changed) when `p` is a point already, outside, or on a protected
    /// face.
    pub(crate) fn insert_constrained(
        &mut self,
        p: P3,
        protect: &FxHashSet<[u32; 3]>,
    ) -> Option<u32> {
        if !p.iter().all(|x| x.is_finite()) {
            return None;
        }
        let t0 = self.locate(p, self.last)?;
        if self.tets[t0 as usize]
            .iter()
            .any(|&v| self.pts[v as usize] == p)
        {
            return None;
        }
        let id = self.pts.len() as u32;
        self.pts.push(p);
        self.vtet.push(NONE);
        let mut cav = Vec::new();
        self.new_cavity();
        if self.constrained_cavity(id, t0, protect, &mut cav).is_none() {
            // Its marks go with the next cavity's clear.
            self.pts.pop();
            self.vtet.pop();
            return None;
        }
        self.replace_by_cones(id, &cav);
        Some(id)
    }

    /// The cavity of point `id` in `cav` (its tets marked).
    fn constrained_cavity(
        &mut self,
        id: u32,
        t0: u32,
        protect: &FxHashSet<[u32; 3]>,
        cav: &mut Vec<u32>,
    ) -> Option<()> {
        let p = self.pts[id as usize];
        cav.push(t0);
        self.mark.insert(t0 as usize);
        // Grow: every tet that holds `p` (it may lie on a face or an edge),
        // and Bowyer-Watson's, never across a protected face.
        let mut i = 0;
        while i < cav.len() {
            let t = cav[i];
            i += 1;
            for f in 0..4 {
                let nb = self.neigh[4 * t as usize + f];
                if nb == NONE || self.mark.contains((nb >> 2) as usize) {
                    continue;
                }
                let u = nb >> 2;
                let w = self.face_corners(4 * t + f as u32);
                let guarded = protect.contains(&key3(w));
                if self.holds(u, p) {
                    if guarded {
                        return None;
                    }
                } else if guarded
                    || !in_sphere_sos(self.tets[u as usize], self.tet_points(u), id, p)
                {
                    continue;
                }
                self.mark.insert(u as usize);
                cav.push(u);
            }
        }
        // Shrink until it is a star about `p` that keeps the constraints.
        loop {
            let mut drop: Vec<u32> = Vec::new();
            let mut on_boundary: FxHashSet<u32> = FxHashSet::default();
            for &t in cav.iter() {
                let tv = self.tets[t as usize];
                for f in 0..4 {
                    let nb = self.neigh[4 * t as usize + f];
                    let w = TET_FACES[f].map(|k| tv[k]);
                    let inside = nb != NONE && self.mark.contains((nb >> 2) as usize);
                    if inside {
                        // A protected face between two cavity tets: the
                        // one that does not hold `p` goes.
                        if protect.contains(&key3(w)) {
                            drop.push(if self.holds(t, p) { nb >> 2 } else { t });
                        }
                        continue;
                    }
                    on_boundary.extend(w);
                    let fp = w.map(|v| self.pts[v as usize]);
                    if orient3d(fp[0], fp[1], fp[2], p) >= 0.0 {
                        drop.push(t);
                    }
                }
            }
            // Points and protected edges with every tet in the cavity.
            let mut edges_seen: FxHashMap<(u32, u32), ()> = FxHashMap::default();
            for &t in cav.iter() {
                let tv = self.tets[t as usize];
                if tv.iter().any(|v| !on_boundary.contains(v)) && !self.holds(t, p) {
                    drop.push(t);
                    continue;
                }
                for (a, b) in TET_EDGES {
                    let (u, v) = (tv[a].min(tv[b]), tv[a].max(tv[b]));
                    if !protect.contains(&edge_key(u, v)) || edges_seen.insert((u, v), ()).is_some()
                    {
                        continue;
                    }
                    let around: Vec<u32> = self
                        .star(u)
                        .into_iter()
                        .filter(|&s| self.tets[s as usize].contains(&v))
                        .collect();
                    if around.iter().all(|&s| self.mark.contains(s as usize)) {
                        let out = around.iter().copied().find(|&s| !self.holds(s, p));
                        drop.push(out.unwrap_or(t));
                    }
                }
            }
            if drop.is_empty() {
                return Some(());
            }
            for t in drop {
                if self.holds(t, p) {
                    return None;
                }
                self.mark.remove(t as usize);
            }
            cav.retain(|&t| self.mark.contains(t as usize));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points from a fixed xorshift stream, in the unit cube.
    fn points(n: usize, mut seed: u64) -> Vec<P3> {
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    }

    /// Protected faces and edges survive any number of insertions, the
    /// triangulation stays valid, and each point goes in or leaves it as
    /// it was.
    #[test]
    fn keeps_protected_faces_and_edges() {
        for seed in 1..6u64 {
            let mut tri = Triangulation::new(&points(60, seed)).unwrap();
            // Every face and edge of every fifth inner tet.
            let mut protect: FxHashSet<[u32; 3]> = FxHashSet::default();
            let mut faces = Vec::new();
            let mut edges = Vec::new();
            for t in tri.inner_tets().step_by(5).collect::<Vec<_>>() {
                let tv = tri.tet(t);
                for fv in TET_FACES {
                    let w = fv.map(|j| tv[j]);
                    protect.insert(key3(w));
                    faces.push(w);
                }
                for (a, b) in TET_EDGES {
                    protect.insert(edge_key(tv[a], tv[b]));
                    edges.push((tv[a], tv[b]));
                }
            }
            let mut went_in = 0;
            for p in points(200, seed + 100) {
                let before = (tri.points().len(), tri.live_tets().count());
                match tri.insert_constrained(p, &protect) {
                    Some(id) => {
                        went_in += 1;
                        assert!(!tri.star(id).is_empty());
                    }
                    None => {
                        assert_eq!(before, (tri.points().len(), tri.live_tets().count()));
                    }
                }
                tri.check().unwrap();
            }
            for w in &faces {
                assert!(tri.find_face(*w).is_some(), "face {w:?} lost");
            }
            for &(u, v) in &edges {
                assert!(tri.has_edge(u, v), "edge {u}-{v} lost");
            }
            // Most points are outside the kept tets and go in.
            assert!(went_in > 100, "{went_in} of 200 inserted");
        }
    }

    /// A point on a protected face is refused; beside it, it goes in.
    #[test]
    fn refuses_a_point_on_a_protected_face() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ];
        let mut tri = Triangulation::new(&pts).unwrap();
        let w = [5, 6, 7]; // (1,0,0), (0,1,0), (0,0,1)
        assert!(tri.find_face(w).is_some());
        let protect: FxHashSet<[u32; 3]> = [key3(w)].into_iter().collect();
        let on = [0.25, 0.25, 0.5]; // exactly on x + y + z = 1
        assert_eq!(tri.insert_constrained(on, &protect), None);
        assert!(tri.find_face(w).is_some());
        assert!(tri.insert_constrained([0.2, 0.2, 0.2], &protect).is_some());
        assert!(tri.find_face(w).is_some());
        tri.check().unwrap();
    }
}
