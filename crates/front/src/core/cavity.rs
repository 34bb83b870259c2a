//! Recovery's last resort (issue 3, step 5.3): a pocket of stuck faces is
//! grown, by removing the tet behind each face it sees badly, until one
//! inner point sees every face well; the pocket is then filled by coning
//! its faces to that point. A closed pocket whose every face sees the point
//! on its inner side is star-shaped about it, so the cones tile it; each
//! cone is still checked exactly against the rest of the front.
use super::*;
use crate::quality::mean_ratio;

/// Smallest mean ratio of a cone tet: far from flat in floating point.
const CONE_FLOOR: f64 = 2e-3;
/// The floor when only input faces are seen worse than `CONE_FLOOR`: a
/// volume still about 1e-8 of the edge cubed, far above rounding.
const INPUT_BOUND_FLOOR: f64 = 1e-5;
/// Pockets larger than this are not coned (the cone would be poor and the
/// search slow); recovery removes layers instead.
const MAX_POCKET: usize = 400;
const MAX_GROWTH: usize = 12;
/// Pockets up to this many faces may be closed from their own corners.
const MAX_EXHAUSTIVE: usize = 24;

enum Pocket {
    Filled,
    /// Part of it coned; the front goes on from the new faces.
    Partial,
    Failed,
}

impl<'a> Front<'a> {
    /// Fill every pocket of the front that holds no prohibited face.
    /// Returns the number of pockets left unfilled.
    pub(super) fn fill_pockets(&mut self) -> (usize, usize) {
        let mut failed = 0;
        let mut progress = 0;
        let mut skip = vec![false; self.fv.len()];
        let mut seed = 0usize;
        // Faces made here wait for the next round.
        let end = self.fv.len();
        while seed < end {
            if seed >= skip.len() {
                skip.resize(self.fv.len(), false);
            }
            if !self.falive[seed] || skip[seed] {
                seed += 1;
                continue;
            }
            let r = self.fill_pocket(seed as u32);
            if !matches!(r, Pocket::Failed) {
                progress += 1;
            }
            if !matches!(r, Pocket::Filled) {
                failed += 1;
                skip.resize(self.fv.len(), false);
                // Do not try the faces of this pocket again in this round.
                for f in self.pocket(seed as u32) {
                    skip[f as usize] = true;
                }
            }
            seed += 1;
        }
        (progress, failed)
    }

    /// The faces reachable from `seed` over shared edges.
    fn pocket(&self, seed: u32) -> Vec<u32> {
        let mut out = vec![seed];
        let mut seen = FxHashMap::default();
        seen.insert(seed, ());
        let mut i = 0;
        while i < out.len() && out.len() <= MAX_POCKET {
            let f = out[i];
            i += 1;
            let v = self.fv[f as usize];
            let bb = tri_box(&self.pts, v);
            self.fgrid.query(&bb, |g| {
                if seen.contains_key(&g) || !self.falive[g as usize] {
                    return;
                }
                let w = self.fv[g as usize];
                if w.iter().filter(|x| v.contains(x)).count() >= 2 {
                    seen.insert(g, ());
                    out.push(g);
                }
            });
        }
        out.sort_unstable();
        out
    }

    fn fill_pocket(&mut self, seed: u32) -> Pocket {
        let mut seed = seed;
        for round in 0..MAX_GROWTH {
            let pocket = self.pocket(seed);
            if pocket.len() > MAX_POCKET || pocket.iter().any(|&f| self.prohibited_face(f)) {
                return Pocket::Failed;
            }
            let p = self.kernel_point(&pocket);
            let bad: Vec<u32> = pocket
                .iter()
                .copied()
                .filter(|&f| self.cone_shape(f, p) < CONE_FLOOR)
                .collect();
            if bad.is_empty() {
                return if self.region.point_ok(p) && self.cone_is_free(&pocket, p) {
                    self.commit_cone(&pocket, p);
                    Pocket::Filled
                } else {
                    Pocket::Failed
                };
            }
            // Grow: the tets behind the badly seen faces leave.
            let mut dead: Vec<u32> = bad
                .iter()
                .map(|&f| self.fowner[f as usize])
                .filter(|&o| o != NONE)
                .map(|o| o >> 2)
                .collect();
            dead.sort_unstable();
            dead.dedup();
            if dead.is_empty()
                && self.worst_cone(&pocket, p) >= INPUT_BOUND_FLOOR
                && self.region.point_ok(p)
                && self.cone_is_free(&pocket, p)
            {
                // The input itself leaves no room for better (a thin part
                // between close input faces): a flat but float-safe cone.
                self.commit_cone(&pocket, p);
                return Pocket::Filled;
            }
            if dead.is_empty() && pocket.len() <= MAX_EXHAUSTIVE && self.close_by_existing(&pocket)
            {
                return Pocket::Filled;
            }
            tracing::trace!(
                round,
                faces = pocket.len(),
                bad = bad.len(),
                dead = dead.len(),
                worst = self.worst_cone(&pocket, p),
                "pocket"
            );
            if dead.is_empty() || round + 1 == MAX_GROWTH {
                // Only input faces are seen badly, or growth is not
                // converging: cone what the point sees well.
                return self.partial_cone(&pocket, p);
            }
            let before = self.fv.len();
            for &t in &dead {
                self.talive[t as usize] = false;
            }
            for &t in &dead {
                self.unlink_tet(t);
            }
            self.stats.tets_removed += dead.len();
            let next = pocket
                .iter()
                .copied()
                .chain(before as u32..self.fv.len() as u32)
                .find(|&f| self.falive[f as usize]);
            match next {
                Some(f) => seed = f,
                None => return Pocket::Failed,
            }
        }
        Pocket::Failed
    }

    /// Cone the faces `p` sees well and whose cones are free. Those cones
    /// cannot overlap: a face inside another's cone would cross it.
    fn partial_cone(&mut self, pocket: &[u32], p: P3) -> Pocket {
        if !self.region.point_ok(p) {
            return Pocket::Failed;
        }
        // A new point on top of an old one would make slivers later.
        let hmean = pocket
            .iter()
            .map(|&f| {
                let v = self.fv[f as usize].map(|i| self.pts[i as usize]);
                (dist(v[0], v[1]) + dist(v[1], v[2]) + dist(v[2], v[0])) / 3.0
            })
            .sum::<f64>()
            / pocket.len() as f64;
        let (mut nf, mut np) = (Vec::new(), Vec::new());
        self.gather(
            &Aabb { min: p, max: p }.inflated(0.2 * hmean),
            NONE,
            &mut nf,
            &mut np,
        );
        if np
            .iter()
            .any(|&q| dist2(self.pts[q as usize], p) < 0.04 * hmean * hmean)
        {
            return Pocket::Failed;
        }
        let mut take = Vec::new();
        for &f in pocket {
            // A failed close_by_existing re-adds its faces under new ids.
            if !self.falive[f as usize] || self.cone_shape(f, p) < 10.0 * CONE_FLOOR {
                continue;
            }
            let cl = Clearance {
                point: 0.02 * hmean,
                wedge: 0.05,
                new_point: 0.02 * hmean,
            };
            if self.apex_free(f, NONE, p, cl) {
                take.push(f);
            }
        }
        if take.is_empty() {
            return Pocket::Failed;
        }
        let id = self.pts.len() as u32;
        self.commit(take[0], NONE, p);
        for &f in &take[1..] {
            self.commit(f, id, p);
        }
        self.stats.pockets_filled += 1;
        Pocket::Partial
    }

    /// Close a small pocket with tets on its own corners, best first: the
    /// space between close input faces may need no new point, only tets
    /// flatter than the front accepts. Undone if it does not close.
    fn close_by_existing(&mut self, pocket: &[u32]) -> bool {
        let mut faces: Vec<u32> = pocket.to_vec();
        let mut made = Vec::new();
        for _ in 0..4 * pocket.len() {
            let corners: Vec<u32> = {
                let mut c: Vec<u32> = faces.iter().flat_map(|&f| self.fv[f as usize]).collect();
                c.sort_unstable();
                c.dedup();
                c
            };
            let mut best: Option<(f64, u32, u32)> = None;
            for &f in &faces {
                let v = self.fv[f as usize];
                let [a, b, c] = v.map(|i| self.pts[i as usize]);
                for &q in &corners {
                    if v.contains(&q) {
                        continue;
                    }
                    let shape = mean_ratio(a, b, c, self.pts[q as usize]);
                    if shape < INPUT_BOUND_FLOOR || best.is_some_and(|b| b.0 >= shape) {
                        continue;
                    }
                    if self.apex_free(f, q, self.pts[q as usize], Clearance::EXACT) {
                        best = Some((shape, f, q));
                    }
                }
            }
            let Some((_, f, q)) = best else {
                break;
            };
            let before = self.fv.len() as u32;
            made.push(self.tets.len() as u32);
            self.commit(f, q, self.pts[q as usize]);
            faces.retain(|&g| self.falive[g as usize]);
            faces.extend((before..self.fv.len() as u32).filter(|&g| self.falive[g as usize]));
            if faces.is_empty() {
                self.stats.pockets_filled += 1;
                return true;
            }
        }
        // Not closed: take the tets back out; the pocket is as it was.
        for &t in &made {
            self.talive[t as usize] = false;
        }
        for &t in made.iter().rev() {
            self.unlink_tet(t);
        }
        false
    }

    fn prohibited_face(&self, f: u32) -> bool {
        let v = self.fv[f as usize];
        v.iter()
            .any(|&p| !self.region.point_ok(self.pts[p as usize]))
    }

    #[inline]
    fn cone_shape(&self, f: u32, p: P3) -> f64 {
        let v = self.fv[f as usize];
        mean_ratio(
            self.pts[v[0] as usize],
            self.pts[v[1] as usize],
            self.pts[v[2] as usize],
            p,
        )
    }

    fn worst_cone(&self, pocket: &[u32], p: P3) -> f64 {
        let mut w = f64::INFINITY;
        for &f in pocket {
            w = w.min(self.cone_shape(f, p));
            if w < -1.0 {
                break;
            }
        }
        w
    }

    /// A point that sees every pocket face as well as it can: the best of
    /// a few inward offsets and the vertex centroid, then a pattern search.
    fn kernel_point(&self, pocket: &[u32]) -> P3 {
        let mut cands = Vec::new();
        let mut c = [0.0; 3];
        let mut hsum = 0.0;
        for &f in pocket {
            let v = self.fv[f as usize];
            let [a, b, d] = v.map(|i| self.pts[i as usize]);
            let m = centroid3(a, b, d);
            c = add(c, m);
            hsum += (dist(a, b) + dist(b, d) + dist(d, a)) / 3.0;
        }
        let n = pocket.len() as f64;
        c = scale(c, 1.0 / n);
        let hmean = hsum / n;
        cands.push(c);
        let stride = (pocket.len() / 48).max(1);
        for &f in pocket.iter().step_by(stride) {
            let v = self.fv[f as usize];
            let [a, b, d] = v.map(|i| self.pts[i as usize]);
            let m = centroid3(a, b, d);
            let nrm = normalize(tri_normal(a, b, d));
            for k in [0.25, 0.5, 0.8] {
                cands.push(add(m, scale(nrm, k * hmean)));
            }
        }
        let mut best = c;
        let mut bw = f64::NEG_INFINITY;
        for q in cands {
            let w = self.worst_cone(pocket, q);
            if w > bw {
                bw = w;
                best = q;
            }
        }
        // Pattern search on the worst cone.
        let mut step = 0.25 * hmean;
        for _ in 0..48 {
            let mut moved = false;
            for k in 0..6 {
                let mut q = best;
                q[k / 2] += if k % 2 == 0 { step } else { -step };
                let w = self.worst_cone(pocket, q);
                if w > bw {
                    bw = w;
                    best = q;
                    moved = true;
                }
            }
            if !moved {
                step *= 0.5;
                if step < 1e-3 * hmean {
                    break;
                }
            }
        }
        best
    }

    /// Every cone tet crosses no other front face and holds no front point.
    fn cone_is_free(&mut self, pocket: &[u32], p: P3) -> bool {
        pocket
            .iter()
            .all(|&f| self.apex_free(f, NONE, p, Clearance::EXACT))
    }

    /// The tet on face `f` with apex `p` (point `q`, or `NONE` for a new
    /// one) is positive and free, checked against the front around it alone.
    fn apex_free(&mut self, f: u32, q: u32, p: P3, cl: Clearance) -> bool {
        let v = self.fv[f as usize];
        let [a, b, c] = v.map(|i| self.pts[i as usize]);
        if orient3d(a, b, c, p) <= 0.0 {
            return false;
        }
        let bb = tri_box(&self.pts, v)
            .union(&Aabb { min: p, max: p })
            .inflated(cl.point);
        let (mut near_f, mut near_p) = (Vec::new(), Vec::new());
        self.gather(&bb, f, &mut near_f, &mut near_p);
        self.tet_is_free(v, q, p, &near_f, &near_p, cl)
    }

    fn commit_cone(&mut self, pocket: &[u32], p: P3) {
        let id = self.pts.len() as u32;
        self.commit(pocket[0], NONE, p);
        for &f in &pocket[1..] {
            self.commit(f, id, p);
        }
        self.stats.pockets_filled += 1;
    }
}
