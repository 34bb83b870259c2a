//! AF2: the candidates for a face's new tet (existing points, then a new
//! point at the ideal height), best first, and the first that is free.
use super::*;

impl<'a> Front<'a> {
    pub(super) fn new_point_size(&self, v: [u32; 3], p: P3) -> f64 {
        match self.size {
            SizeMode::Field(f) => f(p),
            SizeMode::Growth(c) => {
                c * (self.hp[v[0] as usize] + self.hp[v[1] as usize] + self.hp[v[2] as usize]) / 3.0
            }
        }
    }

    /// The region filter on point `i`, asked once per point: points do not
    /// move, and a pass's filter is a point location in the DDG.
    pub(super) fn point_in(&mut self, i: u32) -> bool {
        let i = i as usize;
        self.grow_point_cache(i + 1);
        if self.point_in[i] == 0 {
            let (ok, at) = self.region.locate(self.pts[i], &[]);
            self.point_in[i] = if ok { 1 } else { 2 };
            self.point_at[i] = at;
        }
        self.point_in[i] == 1
    }

    /// `point_in` and `point_at` cover points `0..n` and every point so
    /// far.
    pub(super) fn grow_point_cache(&mut self, n: usize) {
        if n > self.point_in.len() {
            let n = self.pts.len().max(n);
            self.point_in.resize(n, 0);
            self.point_at.resize(n, NO_PLACE);
        }
    }

    pub(super) fn try_face(&mut self, fid: u32) -> Outcome {
        let v = self.fv[fid as usize].v;
        // §7: a face with a point or an edge outside the region is skipped.
        if !self.face_in_region(v) {
            return Outcome::Prohibited;
        }
        let Some(mut g) = self.face_goal(v) else {
            return Outcome::Prohibited;
        };
        // This face's round: its own failures and the front's recovery.
        let tries = self.fv[fid as usize].tries;
        let round = tries as u32 + self.relax;
        let mut near_p = std::mem::take(&mut self.near_p);
        let mut near_f = std::mem::take(&mut self.near_f);
        let mut cands = std::mem::take(&mut self.cands);
        near_p.clear();
        near_f.clear();
        cands.clear();
        // AF2.2: close points and faces, from one box holding every
        // candidate tet.
        let qbox = self.search_box(v, &g, tries);
        self.gather(&qbox, fid, &mut near_f, &mut near_p);
        // A gap narrower than two ideal heights (a thin wall, or two fronts
        // meeting): the point goes to the middle, where the other side's
        // point will find it, rather than leave a slab only slivers fill.
        let gap = self.ray_gap(g.m, g.nrm, &near_f, 2.0 * g.alpha);
        if gap < 2.0 * g.alpha && gap > 0.8 * g.alpha {
            g.alpha = 0.5 * gap;
            g.pstar = add(g.m, scale(g.nrm, g.alpha));
        }
        self.rank_candidates(v, &g, round, &near_p, &mut cands);
        let placed = self.first_free(v, &g, round, &cands, &mut near_f, &near_p);
        let outcome = match placed {
            Some((q, pq, matched)) => {
                self.commit(fid, q, pq, Some(matched));
                Outcome::Placed
            }
            None => Outcome::Failed,
        };
        self.near_p = near_p;
        self.near_f = near_f;
        self.cands = cands;
        outcome
    }

    /// Every corner of face `v` in the region, and every edge (§7).
    #[inline(always)]
    fn face_in_region(&mut self, v: [u32; 3]) -> bool {
        if !(self.point_in(v[0]) && self.point_in(v[1]) && self.point_in(v[2])) {
            return false;
        }
        let [pa, pb, pc] = v.map(|i| self.pts[i as usize]);
        let [ta, tb, tc] = v.map(|i| self.point_at[i as usize]);
        let r = self.region;
        r.edge_ok_at(pa, ta, pb, tb) && r.edge_ok_at(pb, tb, pc, tc) && r.edge_ok_at(pc, tc, pa, ta)
    }

    /// AF2.1: the ideal new point over face `v`, at a regular tet's height;
    /// `None` when it falls outside the region.
    #[inline(always)]
    fn face_goal(&self, v: [u32; 3]) -> Option<FaceGoal> {
        let p = v.map(|i| self.pts[i as usize]);
        let [pa, pb, pc] = p;
        let nrm = normalize(tri_normal(pa, pb, pc));
        let m = centroid3(pa, pb, pc);
        let emax = dist(pa, pb).max(dist(pb, pc)).max(dist(pc, pa));
        // A tet at most `max_growth` times its face: sizes still grow
        // geometrically, and a small face under a large size (CAD needles)
        // keeps a local search.
        let h = ((self.hp[v[0] as usize] + self.hp[v[1] as usize] + self.hp[v[2] as usize]) / 3.0)
            .min(self.opts.max_growth * emax);
        let dm = (dist(m, pa) + dist(m, pb) + dist(m, pc)) / 3.0;
        let alpha = (h * h - dm * dm).max(0.25 * dm * dm).sqrt();
        let pstar = add(m, scale(nrm, alpha));
        // Tried first: where the face's corners are (the region filter
        // asked about them already), mostly the same place.
        let near = v.map(|i| self.point_at.get(i as usize).copied().unwrap_or(NO_PLACE));
        let (ok, at) = self.region.locate(pstar, &near);
        if !ok {
            return None;
        }
        Some(FaceGoal {
            p,
            nrm,
            m,
            emax,
            h,
            alpha,
            pstar,
            at,
        })
    }

    /// The box that holds every candidate tet over the face: wider on later
    /// rounds, but bounded, since near lists grow as r^3; a tall tet's box
    /// also holds its ideal point's surroundings.
    #[inline(always)]
    fn search_box(&self, v: [u32; 3], g: &FaceGoal, tries: u8) -> Aabb {
        let relax = self.relax.min(2) as f64;
        let hs = g.h.min(WIDE_SEARCH * g.emax);
        let r = hs.max(g.emax) * (SEARCH_RADIUS + 0.35 * relax + 0.25 * tries as f64);
        let cq = add(g.m, scale(g.nrm, 0.5 * g.alpha));
        let mut qbox = Aabb { min: cq, max: cq }
            .inflated(r)
            .union(&tri_box(&self.pts, v));
        if g.tall() {
            qbox = qbox.union(
                &Aabb {
                    min: g.pstar,
                    max: g.pstar,
                }
                .inflated(r),
            );
        }
        qbox
    }

    /// AF2.2: the candidates, best first: the close points, then new points
    /// at the heights of `round`.
    #[inline(always)]
    fn rank_candidates(
        &mut self,
        v: [u32; 3],
        g: &FaceGoal,
        round: u32,
        near_p: &[u32],
        cands: &mut Vec<(f64, u32)>,
    ) {
        let [pa, pb, pc] = g.p;
        // The grid's layout follows from the order of operations alone, so
        // the query order is deterministic without sorting.
        let mut star_clear = true;
        let too_close = g.too_close();
        for &q in near_p {
            if v.contains(&q) {
                continue;
            }
            let pq = self.pts[q as usize];
            if dist2(pq, g.pstar) < too_close * too_close {
                star_clear = false;
            }
            if !self.point_in(q) {
                continue; // §7: a close point outside the region is dropped
            }
            // A mean ratio over the floor is a volume far above rounding:
            // the float sign is the exact one, no predicate needed here.
            // Points behind the face (about half) skip the mean ratio's
            // cube root.
            if tet_volume6(pa, pb, pc, pq) <= 0.0 {
                continue;
            }
            let (shape, mut score) = candidate_score(pa, pb, pc, pq, g.h);
            if shape <= SHAPE_FLOOR {
                continue;
            }
            if dist2(pq, g.pstar) < too_close * too_close {
                score += 1.0; // prefer an existing point near the ideal one
            }
            cands.push((score, q));
        }
        for (k, &hf) in policy::new_heights(round).iter().enumerate() {
            let p = add(g.m, scale(g.nrm, g.alpha * hf));
            let clear = if k == 0 {
                star_clear
            } else {
                let lim = too_close * hf;
                near_p
                    .iter()
                    .all(|&q| v.contains(&q) || dist2(self.pts[q as usize], p) >= lim * lim)
            };
            if k == 0 {
                self.new_at.clear();
            }
            let ok = clear && {
                let (ok, at) = self.region.locate(p, &[g.at]);
                if ok {
                    self.new_at.push((p, at));
                }
                ok
            };
            if ok {
                let (shape, score) = candidate_score(pa, pb, pc, p, g.h);
                if shape > SHAPE_FLOOR {
                    cands.push((score * (1.0 - 0.1 * k as f64), policy::new_point_id(k)));
                }
            }
        }
        cands.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    }

    /// AF2.3: the first candidate over the round's score floor whose tet is
    /// free, with its point and its new faces' matches.
    #[inline(always)]
    fn first_free(
        &mut self,
        v: [u32; 3],
        g: &FaceGoal,
        round: u32,
        cands: &[(f64, u32)],
        near_f: &mut [Near],
        near_p: &[u32],
    ) -> Option<(u32, P3, [u32; 3])> {
        let [pa, pb, pc] = g.p;
        let best = candidate_score(pa, pb, pc, g.pstar, g.h).0;
        let min_score = policy::min_score(round, best);
        // Kept clear of other front points (a fraction of the size).
        let cl = Clearance::for_round(round, g.h);
        for &(score, q) in cands {
            let s = if score >= 1.0 { score - 1.0 } else { score };
            if s < min_score {
                continue;
            }
            let pq = if policy::is_new_point(q) {
                add(g.m, scale(g.nrm, g.alpha * policy::new_point_height(q)))
            } else {
                self.pts[q as usize]
            };
            match self.tet_is_free(v, q, pq, near_f, near_p, cl) {
                Verdict::Free(matched) => return Some((q, pq, matched)),
                // The face that blocked this candidate likely blocks the
                // next one too, and the ones before it the next after: it
                // goes first, the others one down (the verdict does not
                // depend on the order).
                Verdict::Face(i) => near_f[..=i].rotate_right(1),
                Verdict::Point => {}
            }
        }
        None
    }

    /// Distance along the ray `m + t n` to the first front face it meets,
    /// or `limit` if none closer.
    pub(super) fn ray_gap(&self, m: P3, n: P3, near_f: &[Near], limit: f64) -> f64 {
        let mut best = limit;
        let end = add(m, scale(n, limit));
        let mut rb = Aabb { min: m, max: m };
        rb.grow(end);
        for i in Overlapping::new(near_f, rb) {
            let g = near_f[i].p;
            // Nothing on or under the plane through m is ahead of the ray:
            // the base face's neighbours, most of what passes the box.
            if g.iter().all(|&x| dot(sub(x, m), n) <= 0.0) {
                continue;
            }
            // Moller-Trumbore; faces through m (t ~ 0) are the neighbours.
            let e1 = sub(g[1], g[0]);
            let e2 = sub(g[2], g[0]);
            let pv = cross(n, e2);
            let det = dot(e1, pv);
            if det.abs() < 1e-300 {
                continue;
            }
            let inv = 1.0 / det;
            let tv = sub(m, g[0]);
            let u = dot(tv, pv) * inv;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let qv = cross(tv, e1);
            let w = dot(n, qv) * inv;
            if w < 0.0 || u + w > 1.0 {
                continue;
            }
            let t = dot(e2, qv) * inv;
            if t > 1e-6 * limit && t < best {
                best = t;
            }
        }
        best
    }
}

/// A face's ideal new point (AF2.1) and what its candidates are measured
/// by.
struct FaceGoal {
    p: [P3; 3],
    nrm: P3,
    m: P3,
    emax: f64,
    /// The size a tet on the face should have.
    h: f64,
    /// The ideal point's height, and the point.
    alpha: f64,
    pstar: P3,
    /// Where the region filter located `pstar`.
    at: u32,
}

impl FaceGoal {
    /// Taller than [`WIDE_SEARCH`] face edges: the DDG's first layer.
    fn tall(&self) -> bool {
        self.h.min(WIDE_SEARCH * self.emax) < self.h
    }

    /// An existing point this close to the ideal one is preferred, and no
    /// new point is made that close to an existing one.
    fn too_close(&self) -> f64 {
        0.55 * self.h * if self.tall() { TALL_REUSE } else { 1.0 }
    }
}
