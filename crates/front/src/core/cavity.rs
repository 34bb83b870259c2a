//! Recovery's last resort (step 5.3): a pocket of stuck faces is
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
pub(super) const INPUT_BOUND_FLOOR: f64 = 1e-5;
/// Pockets larger than this are not coned (the cone would be poor and the
/// search slow); recovery removes layers instead.
const MAX_POCKET: usize = 400;
const MAX_GROWTH: usize = 12;
/// Pockets up to this many faces may be closed from their own corners.
const MAX_EXHAUSTIVE: usize = 24;
/// Apex checks one exhaustive search may spend.
const EXHAUSTIVE_BUDGET: usize = 20_000;
/// Recovery round from which pockets are coned in patches, and flat
/// cones are allowed.
const LATE_FROM_ROUND: u32 = 3;
/// Cones one kernel search may place in a row.
const MAX_KERNEL_CONES: usize = 24;
/// Seeds and size of the patches a pocket with no kernel is coned in.
const MAX_PATCH_SEEDS: usize = 32;
const MAX_PATCH: usize = 16;
/// Worst cone a patch may make before late growth.
const PATCH_FLOOR: f64 = 0.02;
/// How far a kernel cone's apex keeps from the front, in mean edges of the
/// faces it cones. Closer, the new point sits on a front face or beside a
/// front point, and the slab it leaves (measured on plate_holes: points
/// 0.002 apart, or 0.002 above an input plane) closes only with tets that
/// no floor accepts; recovery then wanders without closing.
const KERNEL_APEX_CLEARANCE: f64 = 0.1;

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
            if !self.fv[seed].alive || skip[seed] {
                seed += 1;
                continue;
            }
            // The seed may die in the fill; its pocket is then still
            // found from its corners (a dead face's may be gone).
            let v0 = self.fv[seed].v;
            let r = self.fill_pocket(seed as u32);
            if !matches!(r, Pocket::Failed) {
                progress += 1;
            }
            if !matches!(r, Pocket::Filled) {
                failed += 1;
                skip.resize(self.fv.len(), false);
                // Do not try the faces of this pocket again in this round.
                for f in self.pocket_of(seed as u32, v0) {
                    skip[f as usize] = true;
                }
            }
            seed += 1;
        }
        (progress, failed)
    }

    /// The faces reachable from live face `seed` over shared edges.
    fn pocket(&self, seed: u32) -> Vec<u32> {
        self.pocket_of(seed, self.fv[seed as usize].v)
    }

    /// The faces reachable over shared edges from face `seed` with corners
    /// `v0`, which may have died since (the others are live).
    fn pocket_of(&self, seed: u32, v0: [u32; 3]) -> Vec<u32> {
        let mut out = vec![seed];
        let mut seen = FxHashMap::default();
        seen.insert(seed, ());
        let mut i = 0;
        while i < out.len() && out.len() <= MAX_POCKET {
            let f = out[i];
            i += 1;
            let v = if f == seed { v0 } else { self.fv[f as usize].v };
            let bb = tri_box(&self.pts, v);
            self.fgrid.query(&bb, |g, _| {
                if seen.contains_key(&g) || !self.fv[g as usize].alive {
                    return;
                }
                let w = self.fv[g as usize].v;
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
            if round == 0 && self.relax >= LATE_FROM_ROUND && self.fill_by_kernel(&pocket) {
                return Pocket::Filled;
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
                .map(|&f| self.fv[f as usize].owner)
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
            if dead.is_empty()
                && pocket.len() <= MAX_EXHAUSTIVE
                && self.close_by_existing(&pocket, EXHAUSTIVE_BUDGET)
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
            // Late recovery: growth has had its rounds; flat cones instead.
            let late = self.relax >= LATE_FROM_ROUND;
            if round + 1 == MAX_GROWTH
                && self.worst_cone(&pocket, p) >= INPUT_BOUND_FLOOR
                && self.region.point_ok(p)
                && self.cone_is_free(&pocket, p)
            {
                // Growth did not converge but the pocket has a kernel: a
                // flat cone, for improvement to work on, beats no mesh.
                self.commit_cone(&pocket, p);
                return Pocket::Filled;
            }
            if late && round == 0 {
                let r = self.kernel_cone_with(&pocket, PATCH_FLOOR);
                if !matches!(r, Pocket::Failed) {
                    return r;
                }
            }
            if dead.is_empty() || round + 1 == MAX_GROWTH {
                // Only input faces are seen badly, or growth is not
                // converging: cone what the point sees well.
                let r = self.partial_cone(&pocket, p);
                if matches!(r, Pocket::Failed) && late {
                    return self.kernel_cone(&pocket);
                }
                return r;
            }

            let before = self.fv.len();
            self.remove_tets(&dead);
            match self.first_alive(&pocket, before as u32) {
                Some(f) => seed = f,
                None => return Pocket::Failed,
            }
        }
        Pocket::Failed
    }

    /// Late recovery (step 5.3): a pocket whose faces all see one point
    /// is coned from the deepest such point even when the cones are flat
    /// but float-safe. Growing it first, as early rounds do, removes tets
    /// that the next rounds must make again: on thin plates the pocket then
    /// grows round a hole, loses its kernel, and the stuck set wanders.
    fn fill_by_kernel(&mut self, pocket: &[u32]) -> bool {
        let bb = self.faces_box(pocket);
        let Some((x, depth)) = self.deepest_over(pocket, &bb) else {
            return false;
        };
        if depth <= 1e-6 * bb.diagonal()
            || self.worst_cone(pocket, x) < INPUT_BOUND_FLOOR
            || !self.region.point_ok(x)
            || !self.cone_is_free(pocket, x)
        {
            return false;
        }
        self.commit_cone(pocket, x);
        true
    }

    /// Cone the faces `p` sees well and whose cones are free. Those cones
    /// cannot overlap: a face inside another's cone would cross it.
    fn partial_cone(&mut self, pocket: &[u32], p: P3) -> Pocket {
        if !self.region.point_ok(p) {
            return Pocket::Failed;
        }
        // A new point on top of an old one would make slivers later.
        let hmean = self.mean_edge(pocket);
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
            if !self.fv[f as usize].alive || self.cone_shape(f, p) < 10.0 * CONE_FLOOR {
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
        self.commit_cone(&take, p);
        Pocket::Partial
    }

    /// A pocket with no kernel: drop the faces the deepest point sees
    /// worst until the rest has a kernel, and cone those from its deepest
    /// point; the front goes on from the cones' sides. Flat tets are
    /// allowed (validity is exact): recovery tried better ways first.
    fn kernel_cone(&mut self, pocket: &[u32]) -> Pocket {
        self.kernel_cone_with(pocket, INPUT_BOUND_FLOOR)
    }

    fn kernel_cone_with(&mut self, pocket: &[u32], floor: f64) -> Pocket {
        let mut cur = pocket.to_vec();
        let mut made = false;
        // Cone after cone on what is left, without the growth in between
        // that would take the last cone out again.
        for _ in 0..MAX_KERNEL_CONES {
            let before = self.fv.len() as u32;
            if !self.kernel_cone_once(&cur, floor) {
                break;
            }
            made = true;
            let Some(seed) = self.first_alive(&cur, before) else {
                return Pocket::Filled;
            };
            cur = self.pocket(seed);
            if cur.len() > MAX_POCKET {
                break;
            }
            if cur.len() <= MAX_EXHAUSTIVE && self.close_by_existing(&cur, EXHAUSTIVE_BUDGET) {
                return Pocket::Filled;
            }
        }
        if made {
            Pocket::Partial
        } else {
            Pocket::Failed
        }
    }

    /// Each face's plane: a corner and the normal into the pocket.
    fn face_planes(&self, faces: &[u32]) -> Vec<(P3, P3)> {
        faces
            .iter()
            .map(|&f| {
                let [a, b, d] = self.fv[f as usize].v.map(|i| self.pts[i as usize]);
                (a, tri_normal(a, b, d))
            })
            .collect()
    }

    /// The deepest point over the planes of `faces`, kept inside `bb`.
    fn deepest_over(&self, faces: &[u32], bb: &Aabb) -> Option<(P3, f64)> {
        let mut planes = self.face_planes(faces);
        for k in 0..3 {
            let mut n = [0.0; 3];
            n[k] = 1.0;
            planes.push((bb.min, n));
            n[k] = -1.0;
            planes.push((bb.max, n));
        }
        parafront_geom::kernel::deepest_point(&planes)
    }

    fn faces_box(&self, faces: &[u32]) -> Aabb {
        let mut bb = Aabb::EMPTY;
        for &f in faces {
            for i in self.fv[f as usize].v {
                bb.grow(self.pts[i as usize]);
            }
        }
        bb
    }

    /// Mean edge length of the live faces of `faces`. A pocket can hold
    /// faces a failed `close_by_existing` killed (it adds them again under
    /// new ids), and a dead face's corners are gone once its chunk of the
    /// store is (a random star-shaped sphere read corner `NONE` there).
    fn mean_edge(&self, faces: &[u32]) -> f64 {
        let (mut s, mut n) = (0.0, 0usize);
        for &f in faces {
            let face = &self.fv[f as usize];
            if !face.alive {
                continue;
            }
            let v = face.v.map(|i| self.pts[i as usize]);
            s += (dist(v[0], v[1]) + dist(v[1], v[2]) + dist(v[2], v[0])) / 3.0;
            n += 1;
        }
        s / n.max(1) as f64
    }

    /// Cone the faces of `set` that `x` sees and whose cones are free; `x`
    /// keeps `KERNEL_APEX_CLEARANCE` from the other front faces and points.
    fn cone_from(&mut self, set: &[u32], x: P3, floor: f64) -> bool {
        if !self.region.point_ok(x) {
            return false;
        }
        let cl = Clearance {
            new_point: KERNEL_APEX_CLEARANCE * self.mean_edge(set),
            ..Clearance::EXACT
        };
        let take: Vec<u32> = set
            .iter()
            .copied()
            .filter(|&f| self.cone_shape(f, x) >= floor && self.apex_free(f, NONE, x, cl))
            .collect();
        if take.is_empty() {
            return false;
        }
        self.commit_cone(&take, x);
        true
    }

    /// One cone on part of a pocket with no kernel. First the whole pocket
    /// less the faces seen worst; if those cones are blocked, a patch grown
    /// from one face over its neighbours while it keeps a kernel near it.
    fn kernel_cone_once(&mut self, pocket: &[u32], floor: f64) -> bool {
        let mut set: Vec<u32> = pocket
            .iter()
            .copied()
            .filter(|&f| self.fv[f as usize].alive)
            .collect();
        let bb = self.faces_box(&set);
        let tiny = 1e-6 * bb.diagonal();
        while set.len() >= 4 && floor <= INPUT_BOUND_FLOOR {
            let Some((x, depth)) = self.deepest_over(&set, &bb) else {
                break;
            };
            if depth > tiny {
                if self.cone_from(&set, x, INPUT_BOUND_FLOOR) {
                    return true;
                }
                break;
            }
            // The face seen worst from `x` leaves (ties: lowest id).
            let worst = set
                .iter()
                .enumerate()
                .map(|(k, &f)| {
                    let [a, b, d] = self.fv[f as usize].v.map(|i| self.pts[i as usize]);
                    (dot(normalize(tri_normal(a, b, d)), sub(x, a)), k)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|w| w.1)
                .expect("set is not empty");
            set.remove(worst);
        }
        // Patches: neighbours over shared edges.
        let live: Vec<u32> = pocket
            .iter()
            .copied()
            .filter(|&f| self.fv[f as usize].alive)
            .collect();
        let by_edge = self.faces_by_edge(&live);
        for &seed in live.iter().take(MAX_PATCH_SEEDS) {
            let mut patch = vec![seed];
            let mut i = 0;
            let mut best: Option<(P3, f64)> = None;
            while i < patch.len() && patch.len() < MAX_PATCH {
                let f = patch[i];
                i += 1;
                let v = self.fv[f as usize].v;
                for k in 0..3 {
                    let (a, b) = (v[k], v[(k + 1) % 3]);
                    for &g in &by_edge[&(a.min(b), a.max(b))] {
                        if patch.contains(&g) || patch.len() >= MAX_PATCH {
                            continue;
                        }
                        patch.push(g);
                        let pb = self.faces_box(&patch);
                        let grown = pb.inflated(0.5 * pb.diagonal());
                        match self.deepest_over(&patch, &grown) {
                            Some((x, d))
                                if d > tiny
                                    && patch.iter().all(|&f| self.cone_shape(f, x) >= floor) =>
                            {
                                best = Some((x, d))
                            }
                            _ => {
                                patch.pop();
                            }
                        }
                    }
                }
            }
            if patch.len() < 2 {
                continue;
            }
            if let Some((x, _)) = best {
                if self.cone_from(&patch, x, floor) {
                    return true;
                }
            }
        }
        false
    }

    fn prohibited_face(&self, f: u32) -> bool {
        let v = self.fv[f as usize].v;
        v.iter()
            .any(|&p| !self.region.point_ok(self.pts[p as usize]))
    }

    #[inline]
    fn cone_shape(&self, f: u32, p: P3) -> f64 {
        let v = self.fv[f as usize].v;
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

    /// Whether the worst cone over `p` beats `floor`: faces from `*first`
    /// on, wrapping, and `*first` left at the one that failed. The face
    /// that failed one candidate usually fails the next, so a losing
    /// candidate costs a face or two instead of the whole pocket; the
    /// answer is [`Front::worst_cone`]`(pocket, p) > floor` exactly.
    fn cone_beats(&self, pocket: &[u32], p: P3, floor: f64, first: &mut usize) -> Option<f64> {
        let n = pocket.len();
        let mut w = f64::INFINITY;
        for k in 0..n {
            let i = (*first + k) % n;
            w = w.min(self.cone_shape(pocket[i], p));
            if w <= floor {
                *first = i;
                return None;
            }
            if w < -1.0 {
                // `worst_cone` stops here, in its own order.
                let w = self.worst_cone(pocket, p);
                return (w > floor).then_some(w);
            }
        }
        Some(w)
    }

    /// A point that sees every pocket face as well as it can: the best of
    /// a few inward offsets and the vertex centroid, then a pattern search.
    fn kernel_point(&self, pocket: &[u32]) -> P3 {
        let mut cands = Vec::new();
        let mut c = [0.0; 3];
        let mut hsum = 0.0;
        for &f in pocket {
            let v = self.fv[f as usize].v;
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
            let v = self.fv[f as usize].v;
            let [a, b, d] = v.map(|i| self.pts[i as usize]);
            let m = centroid3(a, b, d);
            let nrm = normalize(tri_normal(a, b, d));
            for k in [0.25, 0.5, 0.8] {
                cands.push(add(m, scale(nrm, k * hmean)));
            }
        }
        // The kernel's deepest point (exact LP): thin pockets have kernels
        // far smaller than the pattern search's first step.
        let planes = self.face_planes(pocket);
        if let Some((x, depth)) = parafront_geom::kernel::deepest_point(&planes) {
            if depth > 0.0 {
                cands.push(x);
            }
        }
        let mut best = c;
        let mut bw = f64::NEG_INFINITY;
        let mut first = 0;
        for q in cands {
            if let Some(w) = self.cone_beats(pocket, q, bw, &mut first) {
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
                if let Some(w) = self.cone_beats(pocket, q, bw, &mut first) {
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
    pub(super) fn apex_free(&mut self, f: u32, q: u32, p: P3, cl: Clearance) -> bool {
        let v = self.fv[f as usize].v;
        let [a, b, c] = v.map(|i| self.pts[i as usize]);
        if orient3d(a, b, c, p) <= 0.0 {
            return false;
        }
        // Wide enough for the apex's own clearance from front faces.
        let bb = tri_box(&self.pts, v)
            .union(&Aabb { min: p, max: p })
            .inflated(cl.point.max(cl.new_point));
        let (mut near_f, mut near_p) = (Vec::new(), Vec::new());
        self.gather(&bb, f, &mut near_f, &mut near_p);
        matches!(
            self.tet_is_free(v, q, p, &near_f, &near_p, cl),
            Verdict::Free(_)
        )
    }

    /// The first live face of `faces`, then of those made since `before`.
    fn first_alive(&self, faces: &[u32], before: u32) -> Option<u32> {
        faces
            .iter()
            .copied()
            .chain(before..self.fv.len() as u32)
            .find(|&f| self.fv[f as usize].alive)
    }

    /// `faces` after a commit or an undo: the live ones, and those made
    /// since `before`.
    pub(super) fn refresh(&self, faces: &mut Vec<u32>, before: u32) {
        faces.retain(|&g| self.fv[g as usize].alive);
        faces.extend((before..self.fv.len() as u32).filter(|&g| self.fv[g as usize].alive));
    }

    fn commit_cone(&mut self, pocket: &[u32], p: P3) {
        let id = self.pts.len() as u32;
        self.commit(pocket[0], NONE, p, None);
        for &f in &pocket[1..] {
            self.commit(f, id, p, None);
        }
        self.stats.pockets_filled += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Everywhere;

    /// `faces` turned so their right-hand normals point at `c` (an inner
    /// point every face sees: the polyhedra here are star-shaped about it).
    fn inward(p: &[P3], faces: &[[u32; 3]], c: P3) -> Vec<[u32; 3]> {
        faces
            .iter()
            .map(|&[a, b, d]| {
                if orient3d(p[a as usize], p[b as usize], p[d as usize], c) > 0.0 {
                    [a, b, d]
                } else {
                    [a, d, b]
                }
            })
            .collect()
    }

    fn volume(p: &[P3], faces: &[[u32; 3]]) -> f64 {
        // Inward normals: the divergence theorem with the sign turned.
        -faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| p[i as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum::<f64>()
    }

    /// The tets made are positive, match face to face (the front is
    /// empty and every tet face is an input face or another tet's, turned)
    /// and fill the pocket's volume.
    fn assert_fills(f: &Front, input: &[[u32; 3]], vol: f64) -> usize {
        let live: Vec<[u32; 4]> = (0..f.tets.len())
            .filter(|&t| f.talive[t])
            .map(|t| f.tets[t])
            .collect();
        assert_eq!(f.n_front, 0, "faces left");
        // A face as a cycle starting at its smallest corner: a face and its
        // turned copy differ.
        let cycle = |v: [u32; 3]| {
            let k = (0..3).min_by_key(|&k| v[k]).unwrap_or(0);
            [v[k], v[(k + 1) % 3], v[(k + 2) % 3]]
        };
        let mut sum = 0.0;
        let mut faces: FxHashMap<[u32; 3], usize> = FxHashMap::default();
        for tv in &live {
            let [a, b, c, d] = tv.map(|i| f.pts[i as usize]);
            assert!(orient3d(a, b, c, d) > 0.0, "tet {tv:?} is not positive");
            sum += tet_volume6(a, b, c, d) / 6.0;
            for fc in TET_FACES {
                *faces.entry(cycle(fc.map(|k| tv[k]))).or_default() += 1;
            }
        }
        for (&k, &n) in &faces {
            let turned = cycle([k[0], k[2], k[1]]);
            let on_input = input.iter().any(|g| sorted3(*g) == sorted3(k));
            assert_eq!(n, 1, "face {k:?} twice the same way");
            assert_eq!(
                faces.contains_key(&turned),
                !on_input,
                "face {k:?}: an inner face needs its turned copy, an input face none"
            );
        }
        assert!((sum - vol).abs() <= 1e-9 * vol, "volume {sum} for {vol}");
        live.len()
    }

    #[test]
    fn a_flat_slab_is_coned_from_its_kernel() {
        // A bipyramid 100 wide and 0.004 thick: every cone from its centre
        // is below CONE_FLOOR (early rounds would grow the pocket), all far
        // above rounding.
        let (w, t) = (50.0, 0.002);
        let pts: Vec<P3> = vec![
            [w, w, 0.0],
            [-w, w, 0.0],
            [-w, -w, 0.0],
            [w, -w, 0.0],
            [0.0, 0.0, t],
            [0.0, 0.0, -t],
        ];
        let raw: Vec<[u32; 3]> = (0..4u32)
            .flat_map(|i| [[i, (i + 1) % 4, 4], [i, (i + 1) % 4, 5]])
            .collect();
        let faces = inward(&pts, &raw, [0.0; 3]);
        let vol = volume(&pts, &faces);
        assert!((vol - 4.0 * w * w * 2.0 * t / 3.0).abs() < 1e-9 * vol);
        let opts = FrontOptions::default();
        let input = FrontInput {
            point_size: vec![w; 6],
            points: pts,
            faces: faces.clone(),
        };
        let mut f = Front::new(input, SizeMode::Growth(1.0), &Everywhere, &opts);
        let pocket = f.pocket(0);
        assert_eq!(pocket.len(), 8);
        let (x, _) = f.deepest_over(&pocket, &f.faces_box(&pocket)).unwrap();
        let worst = f.worst_cone(&pocket, x);
        assert!((INPUT_BOUND_FLOOR..CONE_FLOOR).contains(&worst), "{worst}");
        assert!(f.fill_by_kernel(&pocket));
        assert_eq!(assert_fills(&f, &faces, vol), 8);
        assert_eq!(f.pts.len(), 7, "one point inside");
    }

    #[test]
    fn a_schoenhardt_prism_needs_and_gets_one_inner_point() {
        // A triangle and its copy turned by 30 degrees, the side quads cut
        // on their reflex diagonals: no tet on its own corners fits.
        let phi = 30f64.to_radians();
        let mut pts: Vec<P3> = Vec::new();
        for (z, turn) in [(0.0, 0.0), (1.0, phi)] {
            for i in 0..3 {
                let a = 2.0 * std::f64::consts::PI * i as f64 / 3.0 + turn;
                pts.push([a.cos(), a.sin(), z]);
            }
        }
        let raw = [
            [0, 1, 2],
            [3, 5, 4],
            [0, 4, 1],
            [0, 3, 4],
            [1, 5, 2],
            [1, 4, 5],
            [2, 3, 0],
            [2, 5, 3],
        ];
        let faces = inward(&pts, &raw, [0.0, 0.0, 0.5]);
        let vol = volume(&pts, &faces);
        let opts = FrontOptions::default();
        let input = FrontInput {
            point_size: vec![1.0; 6],
            points: pts,
            faces: faces.clone(),
        };
        let mut f = Front::new(input, SizeMode::Growth(1.0), &Everywhere, &opts);
        let pocket = f.pocket(0);
        assert_eq!(pocket.len(), 8);
        assert!(!f.close_by_existing(&pocket, EXHAUSTIVE_BUDGET));
        assert_eq!(f.n_front, 8, "the failed search undoes its tets");
        let pocket = f.pocket(f.first_alive(&pocket, 0).unwrap());
        assert!(f.fill_by_kernel(&pocket));
        assert_eq!(assert_fills(&f, &faces, vol), 8);
    }
}
