//! The fill's second method: a cavity the constrained Delaunay
//! recovery leaves open is tiled by a search. It is the front again, freed
//! of the front's quality rules and able to take a step back: every front
//! face keeps the apexes whose tet lies in the cavity (exact tests), the
//! face with the fewest goes next, the best tets first, and a dead end
//! undoes the last tet. When the search fails, a Steiner point strictly
//! inside the cavity, seeing the faces that had no apex, joins the points
//! and the search starts again (the twisted prisms that have no
//! tetrahedralization of their own points need one).
use crate::flips::{key3, same_cycle};
use crate::tri::TET_FACES;
use parafront_geom::{centroid3, dist, intersect::faces_meet, orient3d, tri_normal, Aabb, P3};
use std::collections::BTreeMap;

/// A live face of the search's front, and the apexes it may take.
#[derive(Clone)]
struct Entry {
    face: [u32; 3],
    cands: Vec<u32>,
}

/// One step, to undo it.
struct Step {
    removed: Vec<([u32; 3], Entry)>,
    added: Vec<[u32; 3]>,
    filtered: Vec<([u32; 3], Vec<u32>)>,
}

struct Search {
    pts: Vec<P3>,
    front: BTreeMap<[u32; 3], Entry>,
    tets: Vec<[u32; 4]>,
    nodes: usize,
}

/// Candidate apexes of a face in a large cavity: the points nearest it.
const NEAREST: usize = 40;

/// Tile the cavity `faces` (of `pts`, normals inwards; every point a
/// corner) with tets on its points and at most `max_steiner` points added
/// strictly inside it, in at most `nodes` search steps between two Steiner
/// points. The tets use ids of `pts`, then of the added points (returned).
pub(crate) fn search_fill(
    pts: &[P3],
    faces: &[[u32; 3]],
    nodes: usize,
    max_steiner: usize,
) -> Option<(Vec<P3>, Vec<[u32; 4]>)> {
    let n = pts.len();
    let mut s = Search::new(pts.to_vec(), faces);
    let mut added = 0;
    loop {
        // Depth first from the last Steiner point; on failure, back to the
        // deepest dead end, where a Steiner point gives its face an apex.
        let mut deepest: Vec<[u32; 4]> = Vec::new();
        let done = s.tets.len();
        s.nodes = 0;
        let ok = s.run(nodes, &mut deepest);
        tracing::trace!(steiner = added, nodes = s.nodes, ok, "fill search");
        if ok {
            break;
        }
        if added == max_steiner {
            tracing::debug!(
                steiner = added,
                tets = s.tets.len(),
                front = s.front.len(),
                "fill search: Steiner budget spent"
            );
            return None;
        }
        let mut steps = Vec::new();
        for &t in deepest.get(done..).unwrap_or(&[]) {
            let f = [t[0], t[1], t[2]];
            steps.push(s.apply(f, t[3]));
        }
        // Where the dead end has no point to offer, where this try began.
        let mut q = s.steiner();
        if q.is_none() && !steps.is_empty() {
            while let Some(step) = steps.pop() {
                s.undo(step);
            }
            q = s.steiner();
        }
        let Some(q) = q else {
            tracing::debug!(
                steiner = added,
                tets = s.tets.len(),
                front = s.front.len(),
                "fill search: no Steiner point"
            );
            return None;
        };
        s.add_point(q);
        added += 1;
    }
    if !tiles(faces, &s.tets) {
        tracing::debug!("fill search: the tets do not tile the cavity");
        return None;
    }
    Some((s.pts[n..].to_vec(), s.tets))
}

/// Whether `tets` tile the cavity `faces`: each tet face is a cavity face
/// reversed or meets another tet's face the other way round, once.
fn tiles(faces: &[[u32; 3]], tets: &[[u32; 4]]) -> bool {
    let canon = |f: [u32; 3]| {
        let m = (0..3).min_by_key(|&i| f[i]).unwrap();
        [f[m], f[(m + 1) % 3], f[(m + 2) % 3]]
    };
    let mut open: rustc_hash::FxHashMap<[u32; 3], u32> = rustc_hash::FxHashMap::default();
    let mut bump = |f: [u32; 3]| {
        let r = canon([f[0], f[2], f[1]]);
        match open.get_mut(&r) {
            Some(n) => {
                *n -= 1;
                if *n == 0 {
                    open.remove(&r);
                }
            }
            None => *open.entry(canon(f)).or_insert(0) += 1,
        }
    };
    for &f in faces {
        bump(f);
    }
    for t in tets {
        for tf in TET_FACES {
            bump(tf.map(|j| t[j]));
        }
    }
    open.is_empty()
}

impl Search {
    fn new(pts: Vec<P3>, faces: &[[u32; 3]]) -> Search {
        let mut s = Search {
            pts,
            front: BTreeMap::new(),
            tets: Vec::new(),
            nodes: 0,
        };
        for &f in faces {
            let k = key3(f);
            // A face and its reverse (a pinch of no thickness) cancel.
            if s.front.remove(&k).is_none() {
                let e = Entry {
                    face: f,
                    cands: Vec::new(),
                };
                s.front.insert(k, e);
            }
        }
        s.refresh();
        s
    }

    /// Every live face's apexes, afresh.
    fn refresh(&mut self) {
        let keys: Vec<[u32; 3]> = self.front.keys().copied().collect();
        for k in keys {
            let f = self.front[&k].face;
            let c = self.candidates(f);
            self.front.get_mut(&k).unwrap().cands = c;
        }
    }

    /// A Steiner point joins the points: the tets that would hold it leave
    /// the lists, and the faces that see it take it. The search goes on
    /// from here.
    fn add_point(&mut self, q: P3) {
        self.pts.push(q);
        let v = (self.pts.len() - 1) as u32;
        let keys: Vec<[u32; 3]> = self.front.keys().copied().collect();
        for k in keys {
            let e = &self.front[&k];
            let face = e.face;
            let mut c: Vec<u32> = e
                .cands
                .iter()
                .copied()
                .filter(|&a| !self.holds([face[0], face[1], face[2], a], q))
                .collect();
            if self.valid(face, v) {
                c.push(v);
                let sc = |a: u32| self.score(face, a);
                c.sort_by(|&a, &b| sc(b).total_cmp(&sc(a)).then(a.cmp(&b)));
            }
            self.front.get_mut(&k).unwrap().cands = c;
        }
    }

    /// Whether closed tet `t` holds point `q`.
    fn holds(&self, t: [u32; 4], q: P3) -> bool {
        let p = t.map(|i| self.pts[i as usize]);
        TET_FACES.iter().all(|tf| {
            let f = tf.map(|j| p[j]);
            orient3d(f[0], f[1], f[2], q) <= 0.0
        })
    }

    /// Depth first, the most constrained face first; `deepest` keeps the
    /// longest run of tets that ended at a face with no apex.
    fn run(&mut self, budget: usize, deepest: &mut Vec<[u32; 4]>) -> bool {
        let Some((key, cands)) = self.pick() else {
            return true;
        };
        if cands.is_empty() && self.tets.len() >= deepest.len() {
            deepest.clone_from(&self.tets);
        }
        for v in cands {
            if self.nodes >= budget {
                return false;
            }
            self.nodes += 1;
            let face = self.front[&key].face;
            let step = self.apply(face, v);
            if self.run(budget, deepest) {
                return true;
            }
            self.undo(step);
        }
        false
    }

    /// The face with the fewest apexes; `None` when the front is closed.
    fn pick(&self) -> Option<([u32; 3], Vec<u32>)> {
        let mut best: Option<(&[u32; 3], &Entry)> = None;
        for (k, e) in &self.front {
            if best.is_none_or(|(_, b)| e.cands.len() < b.cands.len()) {
                best = Some((k, e));
                if e.cands.len() <= 1 {
                    break;
                }
            }
        }
        best.map(|(k, e)| (*k, e.cands.clone()))
    }

    /// Add tet `face`+`v`: its faces close the front faces they meet and
    /// join the front otherwise; the other faces lose the apexes whose tet
    /// would cross the new faces.
    fn apply(&mut self, face: [u32; 3], v: u32) -> Step {
        let tv = [face[0], face[1], face[2], v];
        self.tets.push(tv);
        let mut step = Step {
            removed: Vec::new(),
            added: Vec::new(),
            filtered: Vec::new(),
        };
        let k = key3(face);
        step.removed.push((k, self.front.remove(&k).unwrap()));
        let mut new_faces = Vec::new();
        for tf in TET_FACES.iter().take(3) {
            let w = tf.map(|j| tv[j]);
            let kw = key3(w);
            if let Some(e) = self.front.remove(&kw) {
                step.removed.push((kw, e));
            } else {
                new_faces.push(w);
            }
        }
        // Tets that would cross the new faces are gone from every list.
        let bb: Vec<Aabb> = new_faces.iter().map(|w| self.bbox(w)).collect();
        let keys: Vec<[u32; 3]> = self.front.keys().copied().collect();
        for kk in keys {
            let e = &self.front[&kk];
            let keep: Vec<u32> = e
                .cands
                .iter()
                .copied()
                .filter(|&c| {
                    let ct = [e.face[0], e.face[1], e.face[2], c];
                    let cb = self.bbox(&ct);
                    new_faces
                        .iter()
                        .zip(&bb)
                        .all(|(w, b)| !b.overlaps(&cb) || self.tet_clears(ct, *w))
                })
                .collect();
            if keep.len() != e.cands.len() {
                let old = std::mem::replace(&mut self.front.get_mut(&kk).unwrap().cands, keep);
                step.filtered.push((kk, old));
            }
        }
        for &w in &new_faces {
            let kw = key3(w);
            self.front.insert(
                kw,
                Entry {
                    face: w,
                    cands: Vec::new(),
                },
            );
            step.added.push(kw);
        }
        for &w in &new_faces {
            let c = self.candidates(w);
            self.front.get_mut(&key3(w)).unwrap().cands = c;
        }
        step
    }

    fn undo(&mut self, step: Step) {
        self.tets.pop();
        for k in step.added {
            self.front.remove(&k);
        }
        for (k, c) in step.filtered {
            self.front.get_mut(&k).unwrap().cands = c;
        }
        for (k, e) in step.removed {
            self.front.insert(k, e);
        }
    }

    fn bbox(&self, vs: &[u32]) -> Aabb {
        Aabb::from_points(vs.iter().map(|&v| &self.pts[v as usize]))
    }

    /// The apexes `v` whose tet on `face` lies in the cavity, best first.
    fn candidates(&self, face: [u32; 3]) -> Vec<u32> {
        let mut c: Vec<(f64, u32)> = self
            .nearest(face)
            .into_iter()
            .filter(|&v| self.valid(face, v))
            .map(|v| (self.score(face, v), v))
            .collect();
        c.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        c.into_iter().map(|(_, v)| v).collect()
    }

    /// All points, or in a large cavity the `NEAREST` to `face`.
    fn nearest(&self, face: [u32; 3]) -> Vec<u32> {
        let mut near: Vec<u32> = (0..self.pts.len() as u32).collect();
        if near.len() > NEAREST {
            let p = face.map(|v| self.pts[v as usize]);
            let d = |v: u32| {
                parafront_geom::point_triangle_dist2(self.pts[v as usize], p[0], p[1], p[2])
            };
            near.select_nth_unstable_by(NEAREST, |&a, &b| d(a).total_cmp(&d(b)).then(a.cmp(&b)));
            near.truncate(NEAREST);
        }
        near
    }

    /// Shape (volume over the cube of the rms edge), doubled for each face
    /// the tet closes.
    fn score(&self, face: [u32; 3], v: u32) -> f64 {
        let tv = [face[0], face[1], face[2], v];
        let p = tv.map(|i| self.pts[i as usize]);
        let vol = orient3d(p[0], p[1], p[2], p[3]);
        let mut l2 = 0.0;
        for i in 0..4 {
            for j in i + 1..4 {
                l2 += parafront_geom::dist2(p[i], p[j]);
            }
        }
        let closes = TET_FACES
            .iter()
            .take(3)
            .filter(|tf| self.front.contains_key(&key3(tf.map(|j| tv[j]))))
            .count();
        vol / (l2 / 6.0).powf(1.5) * (1u32 << closes) as f64
    }

    /// Tet `face`+`v` is positive, holds no point, and its three new faces
    /// meet no front face but in shared corners and edges (or close one,
    /// seen from its other side).
    fn valid(&self, face: [u32; 3], v: u32) -> bool {
        if face.contains(&v) {
            return false;
        }
        let tv = [face[0], face[1], face[2], v];
        let p = tv.map(|i| self.pts[i as usize]);
        if !(orient3d(p[0], p[1], p[2], p[3]) > 0.0) {
            return false;
        }
        let tb = self.bbox(&tv);
        for (w, &q) in self.pts.iter().enumerate() {
            if tv.contains(&(w as u32)) || !tb.contains(q) {
                continue;
            }
            if self.holds(tv, q) {
                return false;
            }
        }
        for tf in TET_FACES.iter().take(3) {
            let w = tf.map(|j| tv[j]);
            if let Some(e) = self.front.get(&key3(w)) {
                // A face the tet closes lies the other way round.
                if same_cycle(e.face, w) {
                    return false;
                }
            }
            let wb = self.bbox(&w);
            for e in self.front.values() {
                if key3(e.face) == key3(w) || !self.bbox(&e.face).overlaps(&wb) {
                    continue;
                }
                if faces_meet(w, e.face, &self.pts) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether tet `t`'s three faces through `t[3]` clear face `w`.
    fn tet_clears(&self, t: [u32; 4], w: [u32; 3]) -> bool {
        TET_FACES.iter().take(3).all(|tf| {
            let f = tf.map(|j| t[j]);
            if key3(f) == key3(w) {
                // The same face: only from its other side.
                return !same_cycle(w, f);
            }
            !faces_meet(f, w, &self.pts)
        })
    }

    /// A point strictly inside the cavity for the search to use: in front
    /// of a face with the fewest apexes, the one that gives apexes to the
    /// most such faces, then to the most faces.
    fn steiner(&self) -> Option<P3> {
        const HARD: usize = 8;
        let faces: Vec<[u32; 3]> = self.front.values().map(|e| e.face).collect();
        let fewest = self.front.values().map(|e| e.cands.len()).min()?;
        let hard: Vec<[u32; 3]> = self
            .front
            .values()
            .filter(|e| e.cands.len() == fewest)
            .map(|e| e.face)
            .take(HARD)
            .collect();
        let mut with = Search {
            pts: self.pts.clone(),
            front: self.front.clone(),
            tets: Vec::new(),
            nodes: 0,
        };
        with.pts.push([0.0; 3]);
        let v = (with.pts.len() - 1) as u32;
        let mut best: Option<((usize, usize, usize), P3)> = None;
        for &f in &hard {
            // Scored on the hard faces, then on the faces about this one.
            let around: Vec<[u32; 3]> = faces
                .iter()
                .copied()
                .filter(|g| g.iter().any(|v| f.contains(v)))
                .collect();
            let (mut n_in, mut n_ok) = (0, 0);
            let near = self.points_near(f);
            for &q in &near {
                if !self.inside(&faces, q) {
                    continue;
                }
                n_in += 1;
                with.pts[v as usize] = q;
                if !with.valid(f, v) {
                    continue;
                }
                n_ok += 1;
                let helps = hard.iter().filter(|&&g| with.valid(g, v)).count();
                // Scores compare by `helps` first: a point that helps fewer
                // faces than the best so far cannot win (and its kills, a
                // pass over the whole front, need not be counted).
                if best.is_some_and(|(b, _)| helps < b.0) {
                    continue;
                }
                let sees = around.iter().filter(|&&g| with.valid(g, v)).count();
                // Faces the point would leave with no apex: each tet they
                // had holds it, and it is not one of theirs.
                let kills = self
                    .front
                    .values()
                    .filter(|e| {
                        !e.cands.is_empty()
                            && e.cands
                                .iter()
                                .all(|&a| self.holds([e.face[0], e.face[1], e.face[2], a], q))
                            && !with.valid(e.face, v)
                    })
                    .count();
                let score = (helps, usize::MAX - kills, sees);
                if best.is_none_or(|(b, _)| score > b) {
                    best = Some((score, q));
                }
            }
            tracing::trace!(?f, near = near.len(), n_in, n_ok, "steiner candidates");
        }
        best.map(|(_, q)| q)
    }

    /// Points in front of `face`: the deepest point of the faces around it
    /// within a box, and points along its normal.
    fn points_near(&self, face: [u32; 3]) -> Vec<P3> {
        let pt = |v: u32| self.pts[v as usize];
        let fp = face.map(pt);
        let c = centroid3(fp[0], fp[1], fp[2]);
        let n = parafront_geom::normalize(tri_normal(fp[0], fp[1], fp[2]));
        let lmax = (0..3)
            .map(|e| dist(fp[e], fp[(e + 1) % 3]))
            .fold(0.0, f64::max);
        let planes: Vec<(P3, P3)> = self
            .front
            .values()
            .filter(|e| e.face.iter().any(|v| face.contains(v)))
            .map(|e| {
                let p = e.face.map(pt);
                (centroid3(p[0], p[1], p[2]), tri_normal(p[0], p[1], p[2]))
            })
            .collect();
        let mut out: Vec<P3> = crate::fill::deepest_in_box(planes, c, lmax)
            .into_iter()
            .collect();
        for s in [0.5, 0.25, 0.1, 0.03, 0.01, 1e-3, 1e-4] {
            out.push(parafront_geom::add(c, parafront_geom::scale(n, s * lmax)));
        }
        // Inside the tets on the face, and halfway to their apexes (the
        // nearest points).
        for v in self.nearest(face) {
            let q = self.pts[v as usize];
            if face.contains(&v) || !(orient3d(fp[0], fp[1], fp[2], q) > 0.0) {
                continue;
            }
            for t in [0.25, 0.5] {
                out.push(parafront_geom::add(
                    c,
                    parafront_geom::scale(parafront_geom::sub(q, c), t),
                ));
            }
        }
        out
    }

    /// Whether `q` lies strictly inside the closed surface `faces`.
    fn inside(&self, faces: &[[u32; 3]], q: P3) -> bool {
        crate::fill::inside_surface(&self.pts, faces, q)
    }
}
