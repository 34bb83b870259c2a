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
        if i >= self.point_in.len() {
            self.point_in.resize(self.pts.len().max(i + 1), 0);
        }
        if self.point_in[i] == 0 {
            self.point_in[i] = if self.region.point_ok(self.pts[i]) {
                1
            } else {
                2
            };
        }
        self.point_in[i] == 1
    }

    pub(super) fn try_face(&mut self, fid: u32) -> Outcome {
        let v = self.fv[fid as usize].v;
        let [pa, pb, pc] = v.map(|i| self.pts[i as usize]);
        // §7: a face with a point or an edge outside the region is skipped.
        if !(self.point_in(v[0]) && self.point_in(v[1]) && self.point_in(v[2])) {
            return Outcome::Prohibited;
        }
        if !(self.region.edge_ok(pa, pb)
            && self.region.edge_ok(pb, pc)
            && self.region.edge_ok(pc, pa))
        {
            return Outcome::Prohibited;
        }
        let nrm = normalize(tri_normal(pa, pb, pc));
        let m = centroid3(pa, pb, pc);
        let emax = dist(pa, pb).max(dist(pb, pc)).max(dist(pc, pa));
        // A tet at most `max_growth` times its face: sizes still grow
        // geometrically, and a small face under a large size (CAD needles)
        // keeps a local search.
        let h = ((self.hp[v[0] as usize] + self.hp[v[1] as usize] + self.hp[v[2] as usize]) / 3.0)
            .min(self.opts.max_growth * emax);
        let dm = (dist(m, pa) + dist(m, pb) + dist(m, pc)) / 3.0;
        // AF2.1: the ideal point sits at a regular tet's height.
        let mut alpha = (h * h - dm * dm).max(0.25 * dm * dm).sqrt();
        let mut pstar = add(m, scale(nrm, alpha));
        let star_ok = self.region.point_ok(pstar);
        if !star_ok {
            return Outcome::Prohibited;
        }
        // AF2.2: close points and faces, from one box holding every
        // candidate tet.
        // Wider searches on later rounds, but bounded: near lists grow as r^3.
        let tries = self.fv[fid as usize].tries;
        // This face's round: its own failures and the front's recovery.
        let round = tries as u32 + self.relax;
        let relax = self.relax.min(2) as f64;
        let hs = h.min(WIDE_SEARCH * emax);
        let tall = hs < h;
        let r = hs.max(emax) * (SEARCH_RADIUS + 0.35 * relax + 0.25 * tries as f64);
        let cq = add(m, scale(nrm, 0.5 * alpha));
        let mut qbox = Aabb { min: cq, max: cq }
            .inflated(r)
            .union(&tri_box(&self.pts, v));
        if tall {
            qbox = qbox.union(
                &Aabb {
                    min: pstar,
                    max: pstar,
                }
                .inflated(r),
            );
        }
        let mut near_p = std::mem::take(&mut self.near_p);
        let mut near_f = std::mem::take(&mut self.near_f);
        let mut cands = std::mem::take(&mut self.cands);
        near_p.clear();
        near_f.clear();
        cands.clear();
        self.gather(&qbox, fid, &mut near_f, &mut near_p);
        // A gap narrower than two ideal heights (a thin wall, or two fronts
        // meeting): the point goes to the middle, where the other side's
        // point will find it, rather than leave a slab only slivers fill.
        let gap = self.ray_gap(m, nrm, &near_f, 2.0 * alpha);
        if gap < 2.0 * alpha && gap > 0.8 * alpha {
            alpha = 0.5 * gap;
            pstar = add(m, scale(nrm, alpha));
        }
        // The grid's layout follows from the order of operations alone, so
        // the query order is deterministic without sorting.
        let mut star_clear = true;
        let too_close = 0.55 * h * if tall { TALL_REUSE } else { 1.0 };
        for &q in &near_p {
            if v.contains(&q) {
                continue;
            }
            let pq = self.pts[q as usize];
            if dist2(pq, pstar) < too_close * too_close {
                star_clear = false;
            }
            if !self.point_in(q) {
                continue; // §7: a close point outside the region is dropped
            }
            // A mean ratio over the floor is a volume far above rounding:
            // the float sign is the exact one, no predicate needed here.
            let (shape, mut score) = candidate_score(pa, pb, pc, pq, h);
            if shape <= SHAPE_FLOOR {
                continue;
            }
            if dist2(pq, pstar) < too_close * too_close {
                score += 1.0; // prefer an existing point near the ideal one
            }
            cands.push((score, q));
        }
        // New points: the ideal one, and lower ones once a face has failed
        // (a narrow gap has room for a flat tet only). Id NONE - k codes
        // height k.
        let heights: &[f64] = if round == 0 {
            &[1.0]
        } else {
            &[1.0, 0.7, 0.45, 0.25]
        };
        for (k, &hf) in heights.iter().enumerate() {
            let p = add(m, scale(nrm, alpha * hf));
            let clear = if k == 0 {
                star_clear
            } else {
                let lim = too_close * hf;
                near_p
                    .iter()
                    .all(|&q| v.contains(&q) || dist2(self.pts[q as usize], p) >= lim * lim)
            };
            if clear && self.region.point_ok(p) {
                let (shape, score) = candidate_score(pa, pb, pc, p, h);
                if shape > SHAPE_FLOOR {
                    cands.push((score * (1.0 - 0.1 * k as f64), NONE - k as u32));
                }
            }
        }
        cands.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        // Relative to the best this face allows: a needle surface triangle
        // makes no good tet at all, and must not wait for recovery.
        let best = candidate_score(pa, pb, pc, pstar, h).0;
        let min_score: f64 = match round {
            0 => 0.12f64,
            1 => 0.05,
            2 => 0.01,
            _ => 0.0,
        }
        .min(0.3 * best);
        // Kept clear of other front points (a fraction of the size).
        let cl = Clearance::for_round(round, h);
        let mut placed = None;
        for &(score, q) in &cands {
            let s = if score >= 1.0 { score - 1.0 } else { score };
            if s < min_score {
                continue;
            }
            let pq = if is_new_point(q) {
                add(
                    m,
                    scale(nrm, alpha * [1.0, 0.7, 0.45, 0.25][(NONE - q) as usize]),
                )
            } else {
                self.pts[q as usize]
            };
            match self.tet_is_free(v, q, pq, &near_f, &near_p, cl) {
                Verdict::Free(matched) => {
                    placed = Some((q, pq, matched));
                    break;
                }
                // The face that blocked this candidate likely blocks the
                // next one too: it is checked first (the verdict does not
                // depend on the order).
                Verdict::Face(i) => near_f.swap(0, i),
                Verdict::Point => {}
            }
        }
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
