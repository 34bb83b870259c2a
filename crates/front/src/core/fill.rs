//! A stalled front hands its cavities to the constrained Delaunay fill
//! (`parafront_delaunay::fill_cavity`). Each cavity is a closed
//! component of the live front; one the fill cannot close is grown by
//! removing the tets behind its faces, a bounded number of times. The
//! fills are computed in parallel and applied in cavity order, so the mesh
//! does not depend on the thread count.
use super::*;
use parafront_delaunay::{fill_cavity, FillOptions};
use rayon::prelude::*;

/// Split points per cavity face that the fill may add before it gives up
/// on the cavity. Closed cavities used up to a sixth (the plate's
/// 1,560-face one, 254); the front's thin cracks that no fill closes went
/// on splitting, 400 and more in 3-20 s, where a quarter stops them in
/// 0.1-0.4 s.
const SPLITS_PER_FACE: f64 = 0.25;
/// Rounds of splits with more missing than the fewest before a cavity's
/// fill gives up (`FillOptions::headway_rounds`).
const HEADWAY_ROUNDS: u32 = 3;
/// And at least this many: a 102-face crack of the plate at size 15 takes
/// 84 (with 64 it went on to the Delaunay fill's search, 2.3 s); the
/// front's cracks that no fill closes fail in 0.2-0.5 s at 128.
const MIN_SPLITS: usize = 128;

/// One cavity's fill: the conforming fill, in TetGen's order (edges, then
/// faces, then the split points moved inside; where that fails, edges
/// split until Delaunay), with a bounded number of splits; unless `quick`,
/// then by the Delaunay fill's flips, cone and search. The first closed
/// more of the corpus's first-stall cavities, the second some cracks of
/// later rounds; on a first stall's large cavity (400 faces) it fails in
/// 1-3 s where recovery serves better.
fn fill_one(
    pts: &[P3],
    faces: &[[u32; 3]],
    quick: bool,
) -> Result<parafront_delaunay::Fill, parafront_delaunay::FillError> {
    let seg = FillOptions {
        segments_first: true,
        max_split: ((faces.len() as f64 * SPLITS_PER_FACE) as usize).max(MIN_SPLITS),
        headway_rounds: HEADWAY_ROUNDS,
        ..FillOptions::default()
    };
    let fill = fill_cavity(pts, faces, &seg);
    if quick {
        return fill;
    }
    fill.or_else(|_| fill_cavity(pts, faces, &FillOptions::default()))
}

/// Whether a fill's tets, over `pts` then `steiner`, have one flat in
/// floating point.
fn any_flat(pts: &[P3], steiner: &[P3], tets: &[[u32; 4]]) -> bool {
    let n = pts.len();
    let at = |v: u32| {
        let v = v as usize;
        if v < n {
            pts[v]
        } else {
            steiner[v - n]
        }
    };
    tets.iter().any(|t| parafront_delaunay::is_flat(t.map(at)))
}

impl<'a> Front<'a> {
    /// Fill every cavity of the live front; `false` when one is left after
    /// `growth` growth rounds. `quick`: only the conforming fill.
    pub(super) fn fill_stalled(&mut self, growth: u32, quick: bool) -> bool {
        for round in 0..=growth {
            let comps = self.live_components();
            if comps.is_empty() {
                return true;
            }
            tracing::debug!(
                round,
                cavities = comps.len(),
                "front stalled: constrained fill"
            );
            if let Some(p) = &self.opts.progress {
                p.note_fill();
            }
            let cavities: Vec<Vec<[u32; 3]>> = comps
                .iter()
                .map(|c| c.iter().map(|&f| self.fv[f as usize].v).collect())
                .collect();
            let pts = &self.pts;
            let n0 = pts.len() as u32;
            // Largest first, one cavity per task, so that the big ones
            // start at once on different threads (one 1,560-face cavity
            // takes as long as the rest together); applied in cavity
            // order below, so the mesh does not depend on the threads.
            let mut order: Vec<usize> = (0..cavities.len()).collect();
            order.sort_by_key(|&i| std::cmp::Reverse(cavities[i].len()));
            let mut done: Vec<(usize, _)> = order
                .par_iter()
                .with_max_len(1)
                .map(|&i| (i, fill_one(pts, &cavities[i], quick)))
                .collect();
            done.sort_unstable_by_key(|d| d.0);
            let fills = done.into_iter().map(|d| d.1);
            let mut failed: Vec<u32> = Vec::new();
            let mut closed = 0;
            for ((ids, faces), fill) in comps.iter().zip(&cavities).zip(fills) {
                match fill {
                    Ok(fill) => {
                        closed += 1;
                        self.apply_fill(faces, fill, n0)
                    }
                    Err(e) => {
                        self.stats.fills_failed += 1;
                        tracing::debug!(faces = faces.len(), error = %e, "cavity not filled");
                        failed.extend_from_slice(ids);
                    }
                }
            }
            if failed.is_empty() {
                return true;
            }
            // A growth round that closed nothing is not followed by more.
            if round == growth || (round > 0 && closed == 0) {
                break;
            }
            // Grow each cavity left by the tets behind its faces.
            let mut grow: Vec<u32> = failed
                .iter()
                .filter(|&&f| self.fv[f as usize].alive)
                .map(|&f| self.fv[f as usize].owner)
                .filter(|&o| o != NONE)
                .map(|o| o >> 2)
                .collect();
            grow.sort_unstable();
            grow.dedup();
            if grow.is_empty() {
                break;
            }
            self.remove_tets(&grow);
        }
        self.stuck = (0..self.fv.len() as u32)
            .filter(|&f| self.fv[f as usize].alive)
            .collect();
        false
    }

    /// The fill of the whole input front, its edges split first (at most
    /// one point per face: a surface of needles closes with fewer, one
    /// whose split points would crowd each other fails fast). On success
    /// every tet the front made gives way to it; `false` leaves the front
    /// as it was.
    pub(super) fn fill_early(&mut self) -> bool {
        self.early = false;
        let faces = std::mem::take(&mut self.input0);
        let fopts = FillOptions::whole_region();
        tracing::debug!(
            faces = faces.len(),
            "front stalled at once: constrained fill of the region"
        );
        let Some(fill) = self.whole_fill(&faces, &fopts, false) else {
            // Kept for the fill and the refinement.
            self.input0 = faces;
            return false;
        };
        let n = self.pts.len() as u32;
        self.take_whole(&faces, fill, n);
        true
    }

    /// The fill of the whole input `faces`, unless it fails or, without
    /// `flat_ok`, has a tet flat in floating point: exactly positive is
    /// valid, but such a tet (a split point moved a hair off the surface,
    /// four corners on one CAD plane) would be the improvement's to undo,
    /// and where the front can still close, its tets serve better.
    fn whole_fill(
        &self,
        faces: &[[u32; 3]],
        fopts: &FillOptions,
        flat_ok: bool,
    ) -> Option<parafront_delaunay::Fill> {
        let fill = fill_cavity(&self.pts, faces, fopts)
            .map_err(|e| tracing::debug!(error = %e, "region not filled"))
            .ok()?;
        if !flat_ok && any_flat(&self.pts, &fill.steiner, &fill.tets) {
            tracing::debug!("region fill has a tet flat in floating point");
            return None;
        }
        Some(fill)
    }

    /// Every tet the front made gives way to `fill`, a fill of its whole
    /// input `faces` whose Steiner points are numbered from `n`.
    fn take_whole(&mut self, faces: &[[u32; 3]], fill: parafront_delaunay::Fill, n: u32) {
        if let Some(p) = &self.opts.progress {
            p.note_fill();
        }
        let live: Vec<u32> = (0..self.tets.len() as u32)
            .filter(|&t| self.talive[t as usize])
            .collect();
        self.remove_tets(&live);
        self.apply_fill(faces, fill, n);
        self.stuck.clear();
        self.heap.clear();
        self.prohibited.clear();
    }

    /// The region's whole input surface filled (its edges split first)
    /// and refined to the size field by Delaunay insertion: GDT (§2) in
    /// place of the front, for a region whose first stall left cavities the
    /// fill could not close on much of it. On success every tet the front
    /// made gives way to it; `false` leaves the front as it was.
    ///
    /// It is the fill the pipeline falls back on when the front gives up
    /// (`FillOptions::segments_first`, the kernel's split budget), and like
    /// that one it takes a fill with a tet flat in floating point. Where it
    /// refused such a fill, or stopped at a cavity's split budget, the
    /// front went on to recovery rounds that never closed these regions,
    /// and the pipeline then made the same fill: the hinge at size 2 spent
    /// 10 s so, round.stl at size 0.5 26 s, the plate at size 6 8 s.
    pub(super) fn fill_region(&mut self) -> bool {
        let SizeMode::Field(size) = self.size else {
            return false;
        };
        let faces = std::mem::take(&mut self.input0);
        if faces.is_empty() {
            return false;
        }
        tracing::debug!(
            faces = faces.len(),
            "front stalled on much of the region: constrained fill of the region, refined"
        );
        let fopts = FillOptions::whole_region();
        let Some(fill) = self.whole_fill(&faces, &fopts, true) else {
            return false;
        };
        let opts = parafront_delaunay::RefineOptions::default();
        let fill = match parafront_delaunay::refine_fill(&self.pts, &fill, &[], size, &opts) {
            Ok(f) => f,
            Err(e) => {
                tracing::debug!(error = %e, "region fill not refined");
                return false;
            }
        };
        // The region is one cavity now: the fills before it gave way.
        self.stats.cavities_filled = 0;
        self.stats.fill_tets = 0;
        let n = self.pts.len() as u32;
        self.take_whole(&faces, fill, n);
        self.stats.regions_refined += 1;
        true
    }

    /// The most faces of one cavity the front leaves (its live faces, by
    /// edge-connected component).
    pub(super) fn largest_cavity(&mut self) -> usize {
        let comps = self.live_components();
        let n = comps.iter().map(Vec::len).max().unwrap_or(0);
        tracing::debug!(cavities = comps.len(), largest = n, "front stalled");
        n
    }

    /// The live faces in components joined by shared edges, each sorted,
    /// in order of their smallest face id.
    fn live_components(&mut self) -> Vec<Vec<u32>> {
        let live: Vec<u32> = (0..self.fv.len() as u32)
            .filter(|&f| self.fv[f as usize].alive)
            .collect();
        let by_edge = self.faces_by_edge(&live);
        let mut comp: FxHashMap<u32, usize> = FxHashMap::default();
        let mut out: Vec<Vec<u32>> = Vec::new();
        for &s in &live {
            if comp.contains_key(&s) {
                continue;
            }
            let c = out.len();
            comp.insert(s, c);
            let mut list = vec![s];
            let mut i = 0;
            while i < list.len() {
                let f = list[i];
                i += 1;
                let v = self.fv[f as usize].v;
                for k in 0..3 {
                    let (a, b) = (v[k], v[(k + 1) % 3]);
                    for &g in &by_edge[&(a.min(b), a.max(b))] {
                        if let std::collections::hash_map::Entry::Vacant(e) = comp.entry(g) {
                            e.insert(c);
                            list.push(g);
                        }
                    }
                }
            }
            list.sort_unstable();
            out.push(list);
        }
        out
    }

    /// Add a fill's points and tets; each tet's faces close the front faces
    /// they meet and open the others (AF5 on all four faces). The fill
    /// numbered its Steiner points from `n0`, the point count when the
    /// round's fills were computed; earlier fills may have added points since.
    fn apply_fill(&mut self, faces: &[[u32; 3]], mut fill: parafront_delaunay::Fill, n0: u32) {
        let n = self.pts.len() as u32;
        for t in &mut fill.tets {
            for v in t.iter_mut() {
                if *v >= n0 {
                    *v = *v - n0 + n;
                }
            }
        }
        let mut h = 0.0;
        let mut k = 0usize;
        for f in faces {
            for &v in f {
                h += self.hp[v as usize];
                k += 1;
            }
        }
        let h = h / k.max(1) as f64;
        for &p in &fill.steiner {
            self.pts.push(p);
            self.hp.push(h);
            self.stats.new_points += 1;
        }
        debug_assert!(fill
            .tets
            .iter()
            .flatten()
            .all(|&v| v < n + fill.steiner.len() as u32));
        for &tv in &fill.tets {
            self.add_tet(tv);
        }
        self.stats.cavities_filled += 1;
        self.stats.fill_tets += fill.tets.len();
    }

    /// Add tet `tv`: each face matches a live front face (which leaves the
    /// front, the two linked) or joins the front.
    fn add_tet(&mut self, tv: [u32; 4]) {
        let t = self.tets.len() as u32;
        self.tets.push(tv);
        self.talive.push(true);
        self.neigh.extend_from_slice(&[NONE; 4]);
        self.stats.tets += 1;
        for i in 0..4 {
            let w = TET_FACES[i].map(|k| tv[k]);
            let fr = 4 * t + i as u32;
            let found = self.face_id(w);
            self.close_or_open(w, fr, found);
        }
    }
}
