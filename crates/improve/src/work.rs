//! The mutable working state of an improvement run: the mesh, a tet per
//! point, the quality per tet, dead slots, and the two walks every
//! operation needs (the ball of a point, the ring of an edge). Local
//! operations replace a cavity of tets by new tets through [`Work::replace`],
//! which keeps `neigh` consistent without a global rebuild.
use crate::quality::quality;
use parafront_geom::P3;
use parafront_mesh::{FaceRef, Marks, PointId, TetMesh, NO_FACE, TET_FACES};

/// Vertex ids of a dead tet slot.
pub(crate) const DEAD: [PointId; 4] = [PointId::from_raw(u32::MAX); 4];
/// Most tets around an edge that edge removal considers.
pub(crate) const MAX_RING: usize = 10;

/// Appends the tets of a triangulation of `ring` (a polygon around edge
/// `a b`) to `out`: `split(i, j)` is the ring point that splits polygon
/// `i..=j`, as the edge removals' dynamic programmes leave it. Order: a
/// polygon's two tets, then its right part, then its left.
pub(crate) fn ring_tets(
    ring: &[PointId],
    (i, j): (usize, usize),
    split: &impl Fn(usize, usize) -> usize,
    a: PointId,
    b: PointId,
    out: &mut Vec<[PointId; 4]>,
) {
    if j - i < 2 {
        return;
    }
    let k = split(i, j);
    let (ri, rk, rj) = (ring[i], ring[k], ring[j]);
    out.push([ri, rk, rj, b]);
    out.push([ri, rj, rk, a]);
    ring_tets(ring, (k, j), split, a, b, out);
    ring_tets(ring, (i, k), split, a, b, out);
}

pub(crate) struct Work<'m> {
    pub m: &'m mut TetMesh,
    /// Points that never move or disappear: the caller's frozen points plus
    /// every point of a boundary or region-interface face.
    pub frozen: Vec<bool>,
    pub dead_pt: Vec<bool>,
    /// A tet containing each point (`u32::MAX` when none).
    pub p2t: Vec<u32>,
    /// Quality of each tet ([`quality`]); `INFINITY` for dead slots.
    pub q: Vec<f64>,
    /// Tested and left alone by the swapper since it last changed (§9.1).
    pub tested: Vec<bool>,
    /// Smoothing left the point where it was and nothing in its ball has
    /// changed since: smoothing it again would decide the same (§9.1's
    /// marking, applied to §9.3).
    pub settled: Vec<bool>,
    /// Known to have no dihedral angle under 10° since it last changed
    /// (a cache for the passes on those tets).
    pub dok: Vec<bool>,
    /// The passes on the tets under 10° try the same operations again and
    /// again: a try that did nothing is not repeated until something near
    /// it changes. `touched[p]`: the clock when a tet on point `p` last
    /// changed, or `p` or a neighbour of it moved; `swap_idle[t]` and
    /// `move_idle[p]`: the clock when a count swap of tet `t` or a count
    /// move of point `p` last did nothing (0: never).
    pub touched: Vec<u32>,
    pub swap_idle: Vec<u32>,
    pub move_idle: Vec<u32>,
    pub clock: u32,
    /// The searches' exact shortcuts: the idle memo of the swaps and
    /// collapses (`Improver::idle_at`) and the compass steps cut short once
    /// they cannot win. Off only in the test that compares the two.
    pub shortcuts: bool,
    free: Vec<u32>,
    /// The tets [`Work::ball`] has reached.
    reached: Marks,
    outer: Vec<([u32; 3], FaceRef)>,
    link: Vec<u32>,
    slots: Vec<u32>,
    used: Vec<bool>,
    cav: Vec<PointId>,
}

#[inline]
pub(crate) fn key3(mut k: [u32; 3]) -> [u32; 3] {
    k.sort_unstable();
    k
}

/// Whether the permutation `p` of 0..4 is even.
#[inline]
pub(crate) fn even(p: [usize; 4]) -> bool {
    let mut inv = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            inv += usize::from(p[i] > p[j]);
        }
    }
    inv % 2 == 0
}

impl<'m> Work<'m> {
    /// A count swap of tet `t` did nothing when last tried, and no tet on
    /// its corners has changed nor a point near them moved since.
    pub(crate) fn swap_idle(&self, t: u32) -> bool {
        let at = self.swap_idle[t as usize];
        at != 0
            && self.m.tets[t as usize]
                .iter()
                .all(|p| self.touched[p.idx()] < at)
    }

    /// A count move of point `p` did nothing when last tried, and its ball
    /// has not changed since.
    pub(crate) fn move_idle(&self, p: PointId) -> bool {
        let at = self.move_idle[p.idx()];
        at != 0 && self.touched[p.idx()] < at
    }

    /// The clock for a try that did nothing: later than every change so
    /// far, and no later than the changes to come.
    pub(crate) fn tick(&mut self) -> u32 {
        self.clock += 1;
        self.clock
    }

    /// Needs `m.neigh` built. `frozen` is per point (shorter means the rest
    /// is free).
    pub fn new(m: &'m mut TetMesh, frozen: &[bool]) -> Work<'m> {
        let np = m.points.len();
        let nt = m.tets.len();
        if m.region.len() < nt {
            m.region.resize(nt, 0);
        }
        let mut fr = vec![false; np];
        fr[..frozen.len().min(np)].copy_from_slice(&frozen[..frozen.len().min(np)]);
        let mut p2t = vec![u32::MAX; np];
        let mut q = Vec::with_capacity(nt);
        for (t, v) in m.tets.iter().enumerate() {
            for f in 0..4 {
                p2t[v[f].idx()] = t as u32;
                let n = m.neigh[4 * t + f];
                let constrained = n.is_none() || m.region[n.tet().idx()] != m.region[t];
                if constrained {
                    for l in TET_FACES[f] {
                        fr[v[l].idx()] = true;
                    }
                }
            }
            q.push(quality(v.map(|p| m.points[p.idx()])));
        }
        Work {
            frozen: fr,
            dead_pt: vec![false; np],
            p2t,
            tested: vec![false; nt],
            settled: vec![false; np],
            dok: vec![false; nt],
            touched: vec![0; np],
            swap_idle: vec![0; nt],
            move_idle: vec![0; np],
            clock: 1,
            shortcuts: true,
            q,
            free: Vec::new(),
            reached: Marks::default(),
            outer: Vec::new(),
            link: Vec::new(),
            slots: Vec::new(),
            used: Vec::new(),
            cav: Vec::new(),
            m,
        }
    }

    #[inline]
    pub fn pts(&self, v: [PointId; 4]) -> [P3; 4] {
        v.map(|p| self.m.points[p.idx()])
    }

    /// Tet `t`'s corners with point `p` at `pos` (a move being weighed).
    #[inline(always)]
    pub(crate) fn pts_moved(&self, t: u32, p: PointId, pos: P3) -> [P3; 4] {
        let v = self.m.tets[t as usize];
        let mut x = self.pts(v);
        for k in 0..4 {
            if v[k] == p {
                x[k] = pos;
            }
        }
        x
    }

    /// The worst quality of the tets `ball` (any list of live tets).
    #[inline]
    pub(crate) fn ball_qmin(&self, ball: &[u32]) -> f64 {
        ball.iter()
            .map(|&t| self.q[t as usize])
            .fold(f64::INFINITY, f64::min)
    }

    #[inline]
    pub fn alive(&self, t: u32) -> bool {
        self.m.tets[t as usize][0] != DEAD[0]
    }

    /// The face across face `f` of `t` when it is free to change: it has a
    /// tet behind it in the same region (§9.1: constrained faces stay).
    #[inline]
    pub fn free_neighbour(&self, t: u32, f: usize) -> Option<FaceRef> {
        let n = self.m.neigh[4 * t as usize + f];
        (!n.is_none() && self.m.region[n.tet().idx()] == self.m.region[t as usize]).then_some(n)
    }

    /// The 2-3 swap across face `f` of `t` (§9.1), when that face is free:
    /// the tet behind it, and the three tets around the edge joining the
    /// two apexes.
    pub(crate) fn face_swap(&self, t: u32, f: usize) -> Option<(u32, [[PointId; 4]; 3])> {
        let n = self.free_neighbour(t, f)?;
        let v = self.m.tets[t as usize];
        let d = v[f];
        let [a, b, c] = TET_FACES[f].map(|l| v[l]);
        let nt = n.tet().raw();
        let e = self.m.tets[nt as usize][n.local()];
        Some((nt, [[d, e, a, b], [d, e, b, c], [d, e, c, a]]))
    }

    /// The tets containing `p`, by a walk over faces through `p` (a point
    /// of a manifold mesh has a connected ball). Empty when `p` is dead.
    pub fn ball(&mut self, p: PointId, out: &mut Vec<u32>) {
        out.clear();
        let t0 = self.p2t[p.idx()];
        // An empty ball makes every operation on p a no-op, never a walk
        // from a tet that does not hold p.
        if t0 == u32::MAX || !self.m.tets[t0 as usize].contains(&p) {
            debug_assert!(t0 == u32::MAX, "p2t of {p} is stale");
            return;
        }
        self.reached.clear(self.m.tets.len());
        self.reached.insert(t0 as usize);
        out.push(t0);
        let mut i = 0;
        while i < out.len() {
            let t = out[i] as usize;
            i += 1;
            for f in 0..4 {
                if self.m.tets[t][f] == p {
                    continue;
                }
                let n = self.m.neigh[4 * t + f];
                if n.is_none() {
                    continue;
                }
                let nt = n.tet().idx();
                if self.reached.insert(nt) {
                    out.push(nt as u32);
                }
            }
        }
    }

    /// The tets around edge `ab` of tet `t`, in order, and the ring of
    /// vertices: tet `i` is `(a, b, ring[i], ring[i+1])`, positive. `None`
    /// when the edge is on a constrained face or the ring is longer than
    /// [`MAX_RING`].
    pub fn ring(
        &self,
        t: u32,
        a: PointId,
        b: PointId,
        tets: &mut Vec<u32>,
        ring: &mut Vec<PointId>,
    ) -> Option<()> {
        tets.clear();
        ring.clear();
        let v = self.m.tets[t as usize];
        let ia = v.iter().position(|&x| x == a)?;
        let ib = v.iter().position(|&x| x == b)?;
        let mut o = (0..4).filter(|&k| k != ia && k != ib);
        let (k, l) = (o.next()?, o.next()?);
        let (mut r0, mut r1) = if even([ia, ib, k, l]) {
            (v[k], v[l])
        } else {
            (v[l], v[k])
        };
        let mut cur = t;
        loop {
            tets.push(cur);
            ring.push(r0);
            if tets.len() > MAX_RING {
                return None;
            }
            let cv = self.m.tets[cur as usize];
            let lf = cv.iter().position(|&x| x == r0)?;
            let n = self.free_neighbour(cur, lf)?;
            let nt = n.tet().raw();
            if nt == t {
                return Some(());
            }
            let nv = self.m.tets[nt as usize];
            let r2 = *nv.iter().find(|&&x| x != a && x != b && x != r1)?;
            cur = nt;
            r0 = r1;
            r1 = r2;
        }
    }

    /// Replaces the tets `old` (all of one region) by `new`, which must
    /// cover the same cavity: the faces of `new` pair up among themselves or
    /// with the cavity's outer faces, each exactly once. Returns false, and
    /// changes nothing, when they do not.
    pub fn replace(&mut self, old: &[u32], new: &[[PointId; 4]]) -> bool {
        let region = self.m.region[old[0] as usize];
        let mut outer = std::mem::take(&mut self.outer);
        let mut link = std::mem::take(&mut self.link);
        self.outer_faces(old, &mut outer);
        if !self.link_faces(&outer, new, &mut link) {
            self.outer = outer;
            self.link = link;
            return false;
        }
        let mut slots = std::mem::take(&mut self.slots);
        self.take_slots(old, new.len(), region, &mut slots);
        // Points of the cavity that may lose their p2t tet.
        let mut cav = std::mem::take(&mut self.cav);
        cav.clear();
        for &t in old {
            for p in self.m.tets[t as usize] {
                if !cav.contains(&p) {
                    cav.push(p);
                }
            }
        }
        for &t in &old[new.len().min(old.len())..] {
            self.m.tets[t as usize] = DEAD;
            self.q[t as usize] = f64::INFINITY;
            for f in 0..4 {
                self.m.neigh[4 * t as usize + f] = NO_FACE;
            }
            self.free.push(t);
        }
        self.write_new(new, region, &slots, &outer, &link);
        // Cavity points in no new tet: point them at an outer tet.
        for &p in &cav {
            let t = self.p2t[p.idx()];
            if t != u32::MAX && self.m.tets[t as usize].contains(&p) {
                continue;
            }
            self.p2t[p.idx()] = outer
                .iter()
                .find(|o| !o.1.is_none() && o.0.contains(&p.raw()))
                .map_or(u32::MAX, |o| o.1.tet().raw());
        }
        self.outer = outer;
        self.link = link;
        self.slots = slots;
        self.cav = cav;
        true
    }

    /// The faces of the cavity `old` towards the rest of the mesh (or the
    /// boundary), by sorted corners, with what lies across each.
    #[inline(always)]
    fn outer_faces(&self, old: &[u32], outer: &mut Vec<([u32; 3], FaceRef)>) {
        outer.clear();
        for &t in old {
            let v = self.m.tets[t as usize];
            for (f, fl) in TET_FACES.iter().enumerate() {
                let n = self.m.neigh[4 * t as usize + f];
                if !n.is_none() && old.contains(&n.tet().raw()) {
                    continue;
                }
                outer.push((key3(fl.map(|l| v[l].raw())), n));
            }
        }
    }

    /// Dry run of [`Work::replace`]: `link[4i+g]` is the outer face that
    /// face `g` of new tet `i` meets, or [`NEW_FACE`] `| 4j+h` for a face of
    /// another new tet. False when a face pairs with none or with two, or
    /// an outer face is left.
    #[inline(always)]
    fn link_faces(
        &mut self,
        outer: &[([u32; 3], FaceRef)],
        new: &[[PointId; 4]],
        link: &mut Vec<u32>,
    ) -> bool {
        const UNSET: u32 = u32::MAX;
        link.clear();
        link.resize(4 * new.len(), UNSET);
        let mut used = std::mem::take(&mut self.used);
        used.clear();
        used.resize(outer.len(), false);
        let mut ok = true;
        'faces: for i in 0..new.len() {
            for (g, fl) in TET_FACES.iter().enumerate() {
                if !ok {
                    break 'faces;
                }
                if link[4 * i + g] != UNSET {
                    continue;
                }
                let k = key3(fl.map(|l| new[i][l].raw()));
                if let Some(o) = outer.iter().position(|x| x.0 == k) {
                    if used[o] {
                        ok = false;
                        continue;
                    }
                    used[o] = true;
                    link[4 * i + g] = o as u32;
                    continue;
                }
                let mut found = false;
                for j in i + 1..new.len() {
                    for (h, hl) in TET_FACES.iter().enumerate() {
                        if key3(hl.map(|l| new[j][l].raw())) == k {
                            if found || link[4 * j + h] != UNSET {
                                ok = false;
                            }
                            found = true;
                            link[4 * i + g] = NEW_FACE | (4 * j + h) as u32;
                            link[4 * j + h] = NEW_FACE | (4 * i + g) as u32;
                        }
                    }
                }
                ok &= found;
            }
        }
        ok &= used.iter().all(|&u| u);
        self.used = used;
        ok
    }

    /// Slots for `n` new tets: the old ones first, then free ones, then
    /// new ones.
    #[inline(always)]
    fn take_slots(&mut self, old: &[u32], n: usize, region: u32, slots: &mut Vec<u32>) {
        slots.clear();
        for i in 0..n {
            let s = if i < old.len() {
                old[i]
            } else if let Some(s) = self.free.pop() {
                s
            } else {
                if self.m.tets.len() == self.m.tets.capacity() {
                    self.grow_tets();
                }
                self.m.tets.push(DEAD);
                self.m.region.push(region);
                self.m.neigh.extend([NO_FACE; 4]);
                self.q.push(f64::INFINITY);
                self.tested.push(false);
                self.dok.push(false);
                self.swap_idle.push(0);
                (self.m.tets.len() - 1) as u32
            };
            slots.push(s);
        }
    }

    /// Room for more tets in every per-tet array, a sixteenth more: a
    /// `Vec`'s doubling would take twice the mesh's tet arrays for the few
    /// tets the swaps and insertions add (sphere_5e6 at `--size 0.021`
    /// under `mpirun -n 4`: 60 of a rank's 158 MiB).
    #[cold]
    fn grow_tets(&mut self) {
        let more = self.m.tets.len() / 16 + 256;
        self.m.tets.reserve_exact(more);
        self.m.region.reserve_exact(more);
        self.m.neigh.reserve_exact(4 * more);
        self.q.reserve_exact(more);
        self.tested.reserve_exact(more);
        self.dok.reserve_exact(more);
        self.swap_idle.reserve_exact(more);
    }

    /// The same for the per-point arrays.
    #[cold]
    pub(crate) fn grow_points(&mut self) {
        let more = self.m.points.len() / 16 + 256;
        self.m.points.reserve_exact(more);
        self.frozen.reserve_exact(more);
        self.dead_pt.reserve_exact(more);
        self.p2t.reserve_exact(more);
        self.settled.reserve_exact(more);
        self.touched.reserve_exact(more);
        self.move_idle.reserve_exact(more);
    }

    /// Write the new tets into their slots, linked as `link` says.
    #[inline(always)]
    fn write_new(
        &mut self,
        new: &[[PointId; 4]],
        region: u32,
        slots: &[u32],
        outer: &[([u32; 3], FaceRef)],
        link: &[u32],
    ) {
        for (i, &s) in slots.iter().enumerate() {
            let s = s as usize;
            self.m.tets[s] = new[i];
            self.m.region[s] = region;
            self.q[s] = quality(self.pts(new[i]));
            self.tested[s] = false;
            self.dok[s] = false;
            self.swap_idle[s] = 0;
            for g in 0..4 {
                let me = FaceRef::of(parafront_mesh::TetId::from_raw(s as u32), g);
                let l = link[4 * i + g];
                if l & NEW_FACE != 0 {
                    let jh = (l & !NEW_FACE) as usize;
                    self.m.neigh[4 * s + g] =
                        FaceRef::of(parafront_mesh::TetId::from_raw(slots[jh / 4]), jh % 4);
                } else {
                    let n = outer[l as usize].1;
                    self.m.neigh[4 * s + g] = n;
                    if !n.is_none() {
                        self.m.neigh[n.raw() as usize] = me;
                        // Its surroundings changed: worth testing again.
                        self.tested[n.tet().idx()] = false;
                    }
                }
            }
            for p in new[i] {
                self.p2t[p.idx()] = s as u32;
                self.settled[p.idx()] = false;
                self.touched[p.idx()] = self.clock;
            }
        }
    }

    /// Drops dead tets, and dead points when `drop_points`, renumbering
    /// what is left in order (surviving ids keep their relative order).
    /// Returns which points died.
    pub fn compact(self, drop_points: bool) -> Vec<bool> {
        let m = self.m;
        if !drop_points {
            let keep = vec![false; m.points.len()];
            compact_arrays(m, &keep);
            return self.dead_pt;
        }
        compact_arrays(m, &self.dead_pt);
        self.dead_pt
    }
}

/// In [`Work::replace`]'s links: a face of another new tet.
const NEW_FACE: u32 = 1 << 31;

/// Drops the dead tet slots and the points marked in `dead_pt`,
/// renumbering tets, neighbours (when built) and boundary triangles.
pub(crate) fn compact_arrays(m: &mut TetMesh, dead_pt: &[bool]) {
    use parafront_mesh::compact::{compact, keep_map, remap_face};
    let nt = m.tets.len();
    let has_neigh = m.neigh.len() == 4 * nt;
    let (tmap, _) = keep_map(m.tets.iter().map(|t| *t != DEAD));
    let (pmap, _) =
        keep_map((0..m.points.len()).map(|p| !dead_pt.get(p).copied().unwrap_or(false)));
    compact(&mut m.tets, &tmap, 1);
    for t in &mut m.tets {
        *t = t.map(|p| PointId::from_raw(pmap[p.idx()]));
    }
    compact(&mut m.region, &tmap, 1);
    if has_neigh {
        compact(&mut m.neigh, &tmap, 4);
        for n in &mut m.neigh {
            *n = FaceRef::from_raw(remap_face(n.raw(), &tmap, NO_FACE.raw()));
        }
    } else {
        m.neigh.clear();
    }
    compact(&mut m.points, &pmap, 1);
    for t in &mut m.bnd_tris {
        *t = t.map(|p| PointId::from_raw(pmap[p.idx()]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Point 0 inside an octahedron (points 1-6): eight tets around it.
    fn ball_mesh() -> TetMesh {
        let points = vec![
            [0.1, 0.05, -0.02],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let mut m = TetMesh {
            points,
            ..Default::default()
        };
        let eq = [1, 2, 3, 4];
        for i in 0..4 {
            let (x, y) = (eq[i], eq[(i + 1) % 4]);
            for apex in [5u32, 6] {
                let mut v = [0, x, y, apex].map(PointId::from_raw);
                let p = v.map(|q| m.points[q.idx()]);
                if parafront_geom::orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
                    v.swap(2, 3);
                }
                m.push_tet(v, 0);
            }
        }
        m.build_adjacency().unwrap();
        m
    }

    /// A try marked idle stays idle until a point of its tet (or the
    /// point itself) is touched: by a move in its ball, or by a new tet.
    #[test]
    fn idle_marks_end_when_something_near_changes() {
        let mut m = ball_mesh();
        let mut w = Work::new(&mut m, &[]);
        let t = 0u32;
        let p = PointId::from_raw(0);
        assert!(!w.swap_idle(t) && !w.move_idle(p));
        w.swap_idle[t as usize] = w.tick();
        w.move_idle[p.idx()] = w.tick();
        assert!(w.swap_idle(t) && w.move_idle(p));
        // Moving a point of the octahedron touches every point of its
        // ball, point 0 and the corners of tet 0 among them.
        let q = PointId::from_raw(5);
        let mut ball = Vec::new();
        w.ball(q, &mut ball);
        assert!(!ball.is_empty());
        let pos = w.m.points[q.idx()];
        w.commit_move(q, [pos[0], pos[1], pos[2] + 0.01], &ball);
        // Point 0 is on every tet, so tet 0 shares a corner with q's ball.
        assert!(!w.move_idle(p) && !w.swap_idle(t));
        // Marked again after the move, then a new point leaves it alone.
        w.move_idle[p.idx()] = w.tick();
        w.swap_idle[t as usize] = w.tick();
        let n = w.push_point([5.0, 5.0, 5.0]);
        assert!(w.move_idle(p) && w.swap_idle(t) && !w.move_idle(n));
    }
}
