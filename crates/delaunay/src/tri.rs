//! The tet store and Bowyer-Watson insertion.
use crate::predicates::in_sphere_sos;
use parafront_geom::{orient3d, Aabb, P3};
use parafront_mesh::Marks;
use rustc_hash::FxHashMap;

/// No tet: the outside of the bounding tet, or a dead slot.
pub const NONE: u32 = u32::MAX;

/// The faces of tet `[a, b, c, d]`, face `i` opposite corner `i`, each with
/// its right-hand normal pointing out of a positive tet (parafront's
/// convention, as `parafront_mesh::TET_FACES`).
pub const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Why a point was not inserted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InsertError {
    /// A coordinate is NaN or infinite.
    #[error("point {0:?} is not finite")]
    NotFinite(P3),
    /// The point lies outside the bounding tet.
    #[error("point {0:?} lies outside the bounding tet")]
    Outside(P3),
    /// The point coincides exactly with point `.1` (a triangulation id).
    #[error("point {0:?} coincides with point {1}")]
    Duplicate(P3, u32),
}

/// An edge's ring as [`Triangulation::edge_ring`] gave it: `(p, q,
/// generation, tets, ring)`.
pub(crate) type RingMemo = (u32, u32, u64, Vec<u32>, Vec<u32>);

/// A tetrahedralization of a bounding tet: struct of arrays, `u32` ids,
/// `neigh[4t+f] = 4u+g` (or [`NONE`] on the bounding tet's faces).
///
/// Points `0..4` are the bounding tet's corners; the points given to
/// [`Triangulation::new`] follow in order. Dead tets keep their slot (their
/// `alive` is false) and are reused.
#[derive(Clone, Debug)]
pub struct Triangulation {
    pub(crate) pts: Vec<P3>,
    pub(crate) tets: Vec<[u32; 4]>,
    pub(crate) neigh: Vec<u32>,
    pub(crate) alive: Vec<bool>,
    pub(crate) free: Vec<u32>,
    /// A live tet on each point (a hint, refreshed on use).
    pub(crate) vtet: Vec<u32>,
    pub(crate) last: u32,
    // Scratch for insertion.
    conflict: Vec<u32>,
    /// The tets of the cavity being built (one at a time).
    pub(crate) mark: Marks,
    /// Scratch for [`Triangulation::star`]: the tet slots reached, and
    /// the walk's queue.
    star_mark: std::cell::RefCell<(Marks, Vec<u32>)>,
    /// Bumped by every change of the tets, for the memo below.
    pub(crate) generation: u64,
    /// The last [`Triangulation::edge_ring`] asked: its edge, the
    /// generation it holds for, and its answer (an edge removal asks for
    /// the same ring three times before it changes anything).
    pub(crate) ring_memo: std::cell::RefCell<Option<RingMemo>>,
}

impl Triangulation {
    /// The Delaunay tetrahedralization of `points`, inserted in a spatially
    /// coherent order inside a bounding tet far around them.
    pub fn new(points: &[P3]) -> Result<Triangulation, InsertError> {
        let mut t = Triangulation::bounding(points)?;
        for i in brio_order(points) {
            t.insert_with_id(4 + i as u32)?;
        }
        Ok(t)
    }

    /// Only the bounding tet of `points`, with the points stored (ids
    /// `4..`) but not inserted yet.
    pub(crate) fn bounding(points: &[P3]) -> Result<Triangulation, InsertError> {
        if let Some(p) = points.iter().find(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(InsertError::NotFinite(*p));
        }
        let bb = if points.is_empty() {
            Aabb {
                min: [0.0; 3],
                max: [1.0; 3],
            }
        } else {
            Aabb::from_points(points)
        };
        let c = bb.center();
        // A scale the predicates resolve without underflow, also for one
        // point or coincident ones.
        let mag = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let d = bb.diagonal();
        let r = 50.0
            * if d > 1e-9 * mag && d > 1e-100 {
                d
            } else {
                mag.max(1.0)
            };
        // A regular tet whose insphere has radius r about c.
        let s = 3.0 * r;
        let corners = [
            [c[0] + s, c[1] + s, c[2] + s],
            [c[0] - s, c[1] - s, c[2] + s],
            [c[0] - s, c[1] + s, c[2] - s],
            [c[0] + s, c[1] - s, c[2] - s],
        ];
        let mut pts = corners.to_vec();
        pts.extend_from_slice(points);
        let mut tv = [0u32, 1, 2, 3];
        if orient3d(pts[0], pts[1], pts[2], pts[3]) < 0.0 {
            tv.swap(2, 3);
        }
        let n = pts.len();
        Ok(Triangulation {
            pts,
            tets: vec![tv],
            neigh: vec![NONE; 4],
            alive: vec![true],
            free: Vec::new(),
            vtet: vec![NONE; n],
            last: 0,
            conflict: Vec::new(),
            mark: Marks::default(),
            star_mark: Default::default(),
            generation: 0,
            ring_memo: Default::default(),
        })
        .map(|mut t| {
            for k in 0..4 {
                t.vtet[k] = 0;
            }
            t
        })
    }

    /// Every point, by triangulation id: the bounding tet's four corners, then
    /// the points given to [`Triangulation::new`] and any inserted after them.
    pub fn points(&self) -> &[P3] {
        &self.pts
    }
    /// Whether point `i` is a corner of the bounding tet.
    pub fn is_bounding(&self, i: u32) -> bool {
        i < 4
    }
    /// Tet slots, dead ones included (see [`Triangulation::is_alive`]).
    pub fn tet_slots(&self) -> usize {
        self.tets.len()
    }
    /// The corners of tet slot `t` (meaningful only while it is alive), ordered
    /// so the tet is positive.
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize]
    }
    /// Whether tet slot `t` holds a live tet (dead slots wait for reuse).
    pub fn is_alive(&self, t: u32) -> bool {
        self.alive[t as usize]
    }
    /// The face across face `f` of tet `t` (face `f` is opposite corner `f`), as
    /// a `4u+g` reference to face `g` of tet `u`, or [`NONE`] on the bounding
    /// tet's hull.
    pub fn neighbour(&self, t: u32, f: usize) -> u32 {
        self.neigh[4 * t as usize + f]
    }
    /// Live tets.
    pub fn live_tets(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tets.len() as u32).filter(|&t| self.alive[t as usize])
    }
    /// Live tets none of whose corners is a bounding corner.
    pub fn inner_tets(&self) -> impl Iterator<Item = u32> + '_ {
        self.live_tets()
            .filter(|&t| self.tets[t as usize].iter().all(|&v| v >= 4))
    }

    pub(crate) fn tet_points(&self, t: u32) -> [P3; 4] {
        self.tets[t as usize].map(|v| self.pts[v as usize])
    }

    /// Add a point and insert it: its id.
    pub fn insert(&mut self, p: P3) -> Result<u32, InsertError> {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(InsertError::NotFinite(p));
        }
        let id = self.pts.len() as u32;
        self.pts.push(p);
        self.vtet.push(NONE);
        match self.insert_with_id(id) {
            Ok(()) => Ok(id),
            Err(e) => {
                self.pts.pop();
                self.vtet.pop();
                Err(e)
            }
        }
    }

    /// The live tet that holds `p` (in its closure), by a visibility walk
    /// from `start`; a scan when the walk runs long (a triangulation that
    /// flips have made non-Delaunay can cycle it).
    pub fn locate(&self, p: P3, start: u32) -> Option<u32> {
        let mut t = if start != NONE && self.alive[start as usize] {
            start
        } else {
            self.live_tets().next()?
        };
        let mut seed = 0x9e37_79b9u32 ^ t;
        let limit = 64 + 4 * (self.tets.len() as f64).sqrt() as usize * 8;
        'walk: for _ in 0..limit {
            let tp = self.tet_points(t);
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let r = (seed >> 28) as usize;
            for k in 0..4 {
                let f = (r + k) & 3;
                let fv = TET_FACES[f];
                if orient3d(tp[fv[0]], tp[fv[1]], tp[fv[2]], p) > 0.0 {
                    let nb = self.neigh[4 * t as usize + f];
                    if nb == NONE {
                        return None;
                    }
                    t = nb >> 2;
                    continue 'walk;
                }
            }
            return Some(t);
        }
        self.live_tets().find(|&t| self.holds(t, p))
    }

    /// `p` lies in the closed tet `t`.
    pub fn holds(&self, t: u32, p: P3) -> bool {
        let tp = self.tet_points(t);
        TET_FACES
            .iter()
            .all(|fv| orient3d(tp[fv[0]], tp[fv[1]], tp[fv[2]], p) <= 0.0)
    }

    /// Empties the cavity marks for the next cavity.
    pub(crate) fn new_cavity(&mut self) {
        self.mark.clear(self.tets.len());
    }

    /// Bowyer-Watson: the tets whose perturbed circumsphere holds point
    /// `id`, grown from the tet that holds it, are replaced by cones from
    /// it. A cone that would be flat (a degenerate input the perturbation
    /// leaves flat) takes the tet beyond it into the cavity as well.
    pub(crate) fn insert_with_id(&mut self, id: u32) -> Result<(), InsertError> {
        let p = self.pts[id as usize];
        let t0 = self.locate(p, self.last).ok_or(InsertError::Outside(p))?;
        for &v in &self.tets[t0 as usize] {
            if self.pts[v as usize] == p {
                return Err(InsertError::Duplicate(p, v));
            }
        }
        let mut cav = std::mem::take(&mut self.conflict);
        self.conflict_region(id, t0, &mut cav);
        self.star_cavity(id, &mut cav)?;
        self.replace_by_cones(id, &cav);
        self.conflict = cav;
        Ok(())
    }

    /// The tets whose perturbed circumsphere holds point `id`, grown from
    /// `t0` (which holds it) into `cav`, marked.
    pub(crate) fn conflict_region(&mut self, id: u32, t0: u32, cav: &mut Vec<u32>) {
        let p = self.pts[id as usize];
        self.new_cavity();
        cav.clear();
        cav.push(t0);
        self.mark.insert(t0 as usize);
        self.grow_cavity(cav, |tri, u| {
            in_sphere_sos(tri.tets[u as usize], tri.tet_points(u), id, p)
        });
    }

    /// Grow the cavity `cav` (its tets marked), breadth first, across
    /// faces to every tet `accept` takes.
    pub(crate) fn grow_cavity(
        &mut self,
        cav: &mut Vec<u32>,
        accept: impl Fn(&Triangulation, u32) -> bool,
    ) {
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
                if accept(self, u) {
                    self.mark.insert(u as usize);
                    cav.push(u);
                }
            }
        }
    }

    /// Grow the cavity `cav` (marked) until point `id` sees every face of
    /// its boundary strictly from inside.
    pub(crate) fn star_cavity(&mut self, id: u32, cav: &mut Vec<u32>) -> Result<(), InsertError> {
        let p = self.pts[id as usize];
        loop {
            let mut grew = false;
            let mut i = 0;
            while i < cav.len() {
                let t = cav[i];
                i += 1;
                for f in 0..4 {
                    let nb = self.neigh[4 * t as usize + f];
                    if nb != NONE && self.mark.contains((nb >> 2) as usize) {
                        continue;
                    }
                    let tv = self.tets[t as usize];
                    let fv = TET_FACES[f].map(|k| self.pts[tv[k] as usize]);
                    if orient3d(fv[0], fv[1], fv[2], p) < 0.0 {
                        continue;
                    }
                    if nb == NONE {
                        return Err(InsertError::Outside(p));
                    }
                    let u = nb >> 2;
                    self.mark.insert(u as usize);
                    cav.push(u);
                    grew = true;
                }
            }
            if !grew {
                return Ok(());
            }
        }
    }

    /// Replace the cavity `cav` (marked, star-shaped about point `id`) by
    /// the cones from `id` over its boundary faces.
    pub(crate) fn replace_by_cones(&mut self, id: u32, cav: &[u32]) {
        // Boundary faces: (outer face ref or NONE, the face's corners as
        // seen from the cavity, outward).
        let mut bnd: Vec<(u32, [u32; 3])> = Vec::new();
        for &t in cav {
            let tv = self.tets[t as usize];
            for f in 0..4 {
                let nb = self.neigh[4 * t as usize + f];
                if nb != NONE && self.mark.contains((nb >> 2) as usize) {
                    continue;
                }
                bnd.push((nb, TET_FACES[f].map(|k| tv[k])));
            }
        }
        for &t in cav {
            self.kill_tet(t);
        }
        let mut edges: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for (nb, w) in bnd {
            // Outward face w seen from inside: the cone (w0, w2, w1, id) is
            // positive, its face 3 is w reversed... i.e. w itself outward.
            let tv = [w[0], w[2], w[1], id];
            let t = self.new_tet(tv);
            self.neigh[4 * t as usize + 3] = nb;
            if nb != NONE {
                self.neigh[nb as usize] = 4 * t + 3;
            }
            // Faces 0, 1, 2 hold `id` and the edge opposite corner 0, 1, 2.
            for f in 0..3 {
                let fv = TET_FACES[f];
                let e: Vec<u32> = fv.iter().map(|&k| tv[k]).filter(|&v| v != id).collect();
                let key = (e[0].min(e[1]), e[0].max(e[1]));
                let fr = 4 * t + f as u32;
                if let Some(o) = edges.remove(&key) {
                    self.neigh[fr as usize] = o;
                    self.neigh[o as usize] = fr;
                } else {
                    edges.insert(key, fr);
                }
            }
            for &v in &tv {
                self.vtet[v as usize] = t;
            }
            self.last = t;
        }
        debug_assert!(edges.is_empty(), "cavity boundary is not closed");
    }

    pub(crate) fn new_tet(&mut self, tv: [u32; 4]) -> u32 {
        self.generation += 1;
        if let Some(t) = self.free.pop() {
            self.tets[t as usize] = tv;
            self.alive[t as usize] = true;
            for f in 0..4 {
                self.neigh[4 * t as usize + f] = NONE;
            }
            t
        } else {
            let t = self.tets.len() as u32;
            self.tets.push(tv);
            self.alive.push(true);
            self.neigh.extend_from_slice(&[NONE; 4]);
            self.mark.grow(self.tets.len());
            t
        }
    }

    pub(crate) fn kill_tet(&mut self, t: u32) {
        self.generation += 1;
        self.alive[t as usize] = false;
        self.free.push(t);
    }

    /// Link face `a` (`4t+f`) and face `b` both ways.
    pub(crate) fn link(&mut self, a: u32, b: u32) {
        if a != NONE {
            self.neigh[a as usize] = b;
        }
        if b != NONE {
            self.neigh[b as usize] = a;
        }
    }

    /// The live tets around point `v`.
    pub fn star(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        self.star_find(v, |t| {
            out.push(t);
            false
        });
        out
    }

    /// The tets of [`Triangulation::star`], in its order, handed to `stop`
    /// until it returns true; that tet, or `None`. The searches of one face
    /// or edge stop at their first hit rather than build the whole star
    /// (they were a sixth of a CAD cavity's fill). `stop` must not walk a
    /// star itself (the scratch is borrowed).
    pub(crate) fn star_find(&self, v: u32, mut stop: impl FnMut(u32) -> bool) -> Option<u32> {
        let mut t0 = self.vtet[v as usize];
        if t0 == NONE || !self.alive[t0 as usize] || !self.tets[t0 as usize].contains(&v) {
            t0 = self
                .live_tets()
                .find(|&t| self.tets[t as usize].contains(&v))?;
        }
        let mut scratch = self.star_mark.borrow_mut();
        let (marks, queue) = &mut *scratch;
        marks.clear(self.tets.len());
        marks.insert(t0 as usize);
        queue.clear();
        queue.push(t0);
        if stop(t0) {
            return Some(t0);
        }
        let mut i = 0;
        while i < queue.len() {
            let t = queue[i];
            i += 1;
            let tv = self.tets[t as usize];
            for f in 0..4 {
                if tv[f] == v {
                    continue; // the face opposite v does not hold it
                }
                let nb = self.neigh[4 * t as usize + f];
                if nb != NONE && marks.insert((nb >> 2) as usize) {
                    queue.push(nb >> 2);
                    if stop(nb >> 2) {
                        return Some(nb >> 2);
                    }
                }
            }
        }
        None
    }

    /// The corners of face `4t+f`.
    pub(crate) fn face_corners(&self, fr: u32) -> [u32; 3] {
        let tv = self.tets[(fr >> 2) as usize];
        TET_FACES[(fr & 3) as usize].map(|k| tv[k])
    }

    /// Whether `u`-`v` is an edge of a live tet.
    pub(crate) fn has_edge(&self, u: u32, v: u32) -> bool {
        // Not from a bounding corner, whose star holds the hull.
        let (u, v) = if u < 4 { (v, u) } else { (u, v) };
        self.star_find(u, |t| self.tets[t as usize].contains(&v))
            .is_some()
    }

    /// The tet face `4t+f` with corners `w` (any order), if it exists.
    pub fn find_face(&self, w: [u32; 3]) -> Option<u32> {
        let a = w.iter().copied().find(|&x| x >= 4).unwrap_or(w[0]);
        let t = self.star_find(a, |t| {
            let tv = self.tets[t as usize];
            w.iter().all(|x| tv.contains(x))
        })?;
        let tv = self.tets[t as usize];
        let f = (0..4).find(|&k| !w.contains(&tv[k])).unwrap();
        Some(4 * t + f as u32)
    }
}

/// Insertion order: along a Morton curve, so that each walk is short and
/// runs are repeatable.
fn brio_order(points: &[P3]) -> Vec<usize> {
    if points.is_empty() {
        return Vec::new();
    }
    let bb = Aabb::from_points(points);
    let a = bb.longest_axis();
    let ext = (bb.max[a] - bb.min[a]).max(1e-300);
    let key = |p: &P3| parafront_geom::morton_key(*p, bb.min, ext);
    let mut idx: Vec<(u64, usize)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect();
    idx.sort_unstable();
    idx.into_iter().map(|x| x.1).collect()
}
