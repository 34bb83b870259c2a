//! Delaunay refinement of a filled region to a size field: the start of
//! the paper's other scalar method, the generalized Delaunay triangulation
//! (GDT, §2). A tet whose circumradius exceeds the size wanted at its
//! circumcentre gets a point there by Bowyer-Watson insertion. The
//! region's boundary faces have no neighbour, so no cavity crosses them:
//! the surface keeps every triangle and no point goes on it. A point
//! outside the region, or closer than half a size to a point of its
//! cavity, is not inserted (the spacing bounds the points, so it ends).
use crate::fill::Fill;
use crate::flips::key3;
use crate::tri::{Triangulation, NONE, TET_FACES};
use parafront_geom::{add, cross, dist, dist2, dot, orient3d, scale, sub, P3};
use parafront_mesh::Marks;
use rustc_hash::FxHashMap;

/// How far to refine.
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// A tet is split while its circumradius exceeds this multiple of the
    /// size at its circumcentre (1: tets about the size's edge length).
    pub radius_ratio: f64,
    /// New points at most (a guard on a size field far below the region).
    pub max_points: usize,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            radius_ratio: 1.0,
            max_points: 50_000_000,
        }
    }
}

/// A refined region: the new points (ids after the given ones) and every
/// tet, over the given points then the new ones.
#[derive(Clone, Debug)]
pub struct Refined {
    /// The points added, in order.
    pub points: Vec<P3>,
    /// The tets, positive, the given region's boundary faces kept.
    pub tets: Vec<[u32; 4]>,
    /// Whether `max_points` stopped it.
    pub capped: bool,
}

/// Why a region cannot be refined.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefineError {
    /// A tet is not positive under the exact predicate.
    #[error("tet {0} is not positive")]
    NotPositive(usize),
    /// Three tets or more share a face.
    #[error("face {0:?} is shared by more than two tets")]
    NonManifold([u32; 3]),
    /// A tet names a point that does not exist.
    #[error("tet {0} names a point out of range")]
    BadPoint(usize),
}

/// Refine the region `tets` over `points` (positive, each interior face
/// shared by two) until no tet's circumradius exceeds `radius_ratio` times
/// `size` at its circumcentre, where a point may go.
///
/// `seeds` go in first, in order, each where it lies inside the region and
/// half a size from the points of its cavity (a lattice of the size gives
/// the interior near-ideal tets, where circumcentres leave slivers).
pub fn refine_to_size(
    points: &[P3],
    tets: &[[u32; 4]],
    seeds: &[P3],
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &RefineOptions,
) -> Result<Refined, RefineError> {
    let mut tri = Triangulation::from_tets(points, tets)?;
    let n0 = tri.pts.len();
    for &x in seeds {
        if tri.pts.len() - n0 >= opts.max_points {
            break;
        }
        tri.try_insert(x, 0.5 * size(x));
    }
    // Worklist of (slot, corners): a slot reused since is skipped.
    let mut work: Vec<(u32, [u32; 4])> = tri.live_tets().map(|t| (t, tri.tet(t))).collect();
    work.reverse();
    let mut capped = false;
    while let Some((t, tv)) = work.pop() {
        if !tri.alive[t as usize] || tri.tets[t as usize] != tv {
            continue;
        }
        let tp = tri.tet_points(t);
        let Some((c, r)) = circumsphere(tp) else {
            continue;
        };
        let h = size(c);
        if !(h > 0.0 && r > opts.radius_ratio * h) {
            continue;
        }
        if tri.pts.len() - n0 >= opts.max_points {
            capped = true;
            break;
        }
        // The circumcentre, else (beyond the boundary: a tet on a surface
        // face) the centroid, which the boundary cannot be in the way of.
        let g = scale(add(add(tp[0], tp[1]), add(tp[2], tp[3])), 0.25);
        tri.last = t;
        if let Some(id) = tri
            .try_insert(c, 0.5 * h)
            .or_else(|| tri.try_insert(g, 0.5 * h))
        {
            for u in tri.star(id) {
                work.push((u, tri.tet(u)));
            }
        }
    }
    let new = tri.pts[n0..].to_vec();
    let out = tri.live_tets().map(|t| tri.tet(t).map(|v| v - 4)).collect();
    Ok(Refined {
        points: new,
        tets: out,
        capped,
    })
}

/// [`refine_to_size`] of a cavity's fill over `points` (its Steiner points
/// numbered after them): the fill again, its Steiner points followed by
/// the refinement's.
pub fn refine_fill(
    points: &[P3],
    fill: &Fill,
    seeds: &[P3],
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &RefineOptions,
) -> Result<Fill, RefineError> {
    let mut all = points.to_vec();
    all.extend_from_slice(&fill.steiner);
    let r = refine_to_size(&all, &fill.tets, seeds, size, opts)?;
    let mut steiner = fill.steiner.clone();
    steiner.extend_from_slice(&r.points);
    Ok(Fill {
        steiner,
        tets: r.tets,
        ..*fill
    })
}

/// The cone from `p` over outward face `w` is not positive, or so flat
/// (6V under 1e-9 of its longest edge cubed) that a float volume, which
/// other tools check, would call it flat: `p` does not see `w`.
fn flat_cone(w: [P3; 3], p: P3) -> bool {
    let o = orient3d(w[0], w[1], w[2], p);
    if o >= 0.0 {
        return true;
    }
    let l2 = [
        dist2(w[0], w[1]),
        dist2(w[1], w[2]),
        dist2(w[2], w[0]),
        dist2(w[0], p),
        dist2(w[1], p),
        dist2(w[2], p),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    -o < 1e-9 * l2 * l2.sqrt()
}

/// Faces `a` and `b` (`4t+f`, the same three corners) have the same
/// orientation: their tets lie on one side.
fn same_side(tri: &Triangulation, a: u32, b: u32) -> bool {
    let face = |r: u32| {
        let tv = tri.tets[(r >> 2) as usize];
        TET_FACES[(r & 3) as usize].map(|j| tv[j])
    };
    crate::flips::same_cycle(face(a), face(b))
}

/// The circumcentre and circumradius of a tet, when finite.
fn circumsphere(p: [P3; 4]) -> Option<(P3, f64)> {
    let a = sub(p[1], p[0]);
    let b = sub(p[2], p[0]);
    let c = sub(p[3], p[0]);
    let d = 2.0 * dot(a, cross(b, c));
    if d == 0.0 {
        return None;
    }
    let x = add(
        add(scale(cross(b, c), dot(a, a)), scale(cross(c, a), dot(b, b))),
        scale(cross(a, b), dot(c, c)),
    );
    let o = add(p[0], scale(x, 1.0 / d));
    let r = dist(o, p[0]);
    (o.iter().all(|v| v.is_finite()) && r.is_finite()).then_some((o, r))
}

impl Triangulation {
    /// A triangulation of a region given as tets: no bounding tet (its
    /// four corner slots stay, unused, so that ids are the given ones plus
    /// 4), and the region's boundary faces have no neighbour.
    pub fn from_tets(points: &[P3], tets: &[[u32; 4]]) -> Result<Triangulation, RefineError> {
        let mut tri = Triangulation::bounding(points).map_err(|_| RefineError::BadPoint(0))?;
        tri.tets.clear();
        tri.neigh.clear();
        tri.alive.clear();
        tri.mark = Marks::default();
        tri.vtet.iter_mut().for_each(|v| *v = NONE);
        let n = points.len() as u32;
        let mut open: FxHashMap<[u32; 3], u32> = FxHashMap::default();
        for (i, tv) in tets.iter().enumerate() {
            if tv.iter().any(|&v| v >= n) {
                return Err(RefineError::BadPoint(i));
            }
            let tv = tv.map(|v| v + 4);
            let p = tv.map(|v| tri.pts[v as usize]);
            if orient3d(p[0], p[1], p[2], p[3]) <= 0.0 {
                return Err(RefineError::NotPositive(i));
            }
            let t = tri.new_tet(tv);
            for (f, fv) in TET_FACES.iter().enumerate() {
                let k = key3(fv.map(|j| tv[j]));
                let fr = 4 * t + f as u32;
                // A face seen twice must be seen from both sides; a third
                // time (NONE marks a closed face) is never right.
                match open.get(&k).copied() {
                    Some(o) if o != NONE && !same_side(&tri, o, fr) => {
                        tri.link(fr, o);
                        open.insert(k, NONE);
                    }
                    Some(_) => return Err(RefineError::NonManifold(k.map(|v| v - 4))),
                    None => {
                        open.insert(k, fr);
                    }
                }
            }
            for v in tv {
                tri.vtet[v as usize] = t;
            }
            tri.last = t;
        }
        Ok(tri)
    }

    /// Shrink the cavity `cav` (marked) until `p` sees each of its
    /// boundary faces strictly from inside: a tet with a face it does not
    /// see leaves (the region's boundary is not to be crossed, so growing
    /// is no way out), then what is no longer joined to `t0`. `None` when
    /// `t0` itself has such a face (`p` on it).
    fn shrink_to_star(&mut self, p: P3, t0: u32, cav: &mut Vec<u32>) -> Option<()> {
        loop {
            let mut out = Vec::new();
            for &t in cav.iter() {
                let tv = self.tets[t as usize];
                let blind = (0..4).any(|f| {
                    let nb = self.neigh[4 * t as usize + f];
                    (nb == NONE || !self.mark.contains((nb >> 2) as usize)) && {
                        let w = TET_FACES[f].map(|k| self.pts[tv[k] as usize]);
                        flat_cone(w, p)
                    }
                });
                if blind {
                    if t == t0 {
                        return None;
                    }
                    out.push(t);
                }
            }
            if out.is_empty() {
                return Some(());
            }
            // Unmark them, then keep what is still joined to `t0`.
            for &t in &out {
                self.mark.remove(t as usize);
            }
            let inside: Vec<u32> = cav
                .iter()
                .copied()
                .filter(|&t| self.mark.contains(t as usize))
                .collect();
            for &t in &inside {
                self.mark.remove(t as usize);
            }
            let keep: rustc_hash::FxHashSet<u32> = inside.iter().copied().collect();
            cav.clear();
            cav.push(t0);
            self.mark.insert(t0 as usize);
            self.grow_cavity(cav, |_, u| keep.contains(&u));
        }
    }

    /// Add point `x` and insert it where [`Triangulation::spaced_cavity`]
    /// allows: its id; otherwise the point is dropped again.
    fn try_insert(&mut self, x: P3, spacing: f64) -> Option<u32> {
        let id = self.pts.len() as u32;
        self.pts.push(x);
        self.vtet.push(NONE);
        match self.spaced_cavity(id, spacing) {
            Some(cav) => {
                self.replace_by_cones(id, &cav);
                Some(id)
            }
            None => {
                self.pts.pop();
                self.vtet.pop();
                None
            }
        }
    }

    /// The Bowyer-Watson cavity of point `id` (stored, not inserted),
    /// shrunk until star-shaped; `None` when the point lies
    /// outside the region or on a face of the tet that holds it, a corner
    /// would be dropped, or one is nearer than `spacing`.
    fn spaced_cavity(&mut self, id: u32, spacing: f64) -> Option<Vec<u32>> {
        let p = self.pts[id as usize];
        let t0 = self.locate(p, self.last)?;
        // `t0` stays in the cavity: its corners are checked at once, before
        // the cavity is built (most rejected points fail here).
        if !self.holds(t0, p)
            || self.tets[t0 as usize]
                .iter()
                .any(|&v| dist(self.pts[v as usize], p) < spacing)
        {
            return None;
        }
        let mut cav = Vec::new();
        self.conflict_region(id, t0, &mut cav);
        self.shrink_to_star(p, t0, &mut cav)?;
        // Every corner must stay on the cavity's boundary: in a region that
        // is not Delaunay (recovery flips, moved Steiner points) a cavity
        // can hold a point's whole star, and the cones would drop it.
        let mut on_boundary: Vec<u32> = Vec::new();
        let mut corners: Vec<u32> = Vec::new();
        for &t in &cav {
            let tv = self.tets[t as usize];
            corners.extend_from_slice(&tv);
            for (f, fv) in TET_FACES.iter().enumerate() {
                let nb = self.neigh[4 * t as usize + f];
                if nb == NONE || !self.mark.contains((nb >> 2) as usize) {
                    on_boundary.extend(fv.map(|j| tv[j]));
                }
            }
        }
        on_boundary.sort_unstable();
        on_boundary.dedup();
        corners.sort_unstable();
        corners.dedup();
        let ok = corners.len() == on_boundary.len()
            && corners
                .iter()
                .all(|&v| dist(self.pts[v as usize], p) >= spacing);
        ok.then_some(cav)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube as 6 positive tets around its main diagonal.
    fn cube() -> (Vec<P3>, Vec<[u32; 4]>) {
        let p: Vec<P3> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let mut tets = Vec::new();
        for (a, b) in [(1, 3), (3, 2), (2, 6), (6, 4), (4, 5), (5, 1)] {
            let mut t = [0u32, a, b, 7];
            let q = t.map(|v| p[v as usize]);
            if orient3d(q[0], q[1], q[2], q[3]) < 0.0 {
                t.swap(2, 3);
            }
            tets.push(t);
        }
        (p, tets)
    }

    fn volume(p: &[P3], tets: &[[u32; 4]]) -> f64 {
        tets.iter()
            .map(|t| {
                let q = t.map(|v| p[v as usize]);
                parafront_geom::tet_volume6(q[0], q[1], q[2], q[3]) / 6.0
            })
            .sum()
    }

    /// Boundary faces (those of one tet), sorted.
    fn boundary(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
        let mut count: FxHashMap<[u32; 3], usize> = FxHashMap::default();
        for t in tets {
            for fv in TET_FACES {
                *count.entry(key3(fv.map(|j| t[j]))).or_default() += 1;
            }
        }
        assert!(count.values().all(|&c| c <= 2));
        let mut b: Vec<[u32; 3]> = count
            .into_iter()
            .filter(|x| x.1 == 1)
            .map(|x| x.0)
            .collect();
        b.sort_unstable();
        b
    }

    #[test]
    fn a_cube_is_refined_to_its_size_and_keeps_its_faces() {
        let (p, tets) = cube();
        let before = boundary(&tets);
        for h in [0.5, 0.2, 0.1] {
            let r = refine_to_size(&p, &tets, &[], &|_| h, &RefineOptions::default()).unwrap();
            assert!(!r.capped);
            let mut all = p.clone();
            all.extend_from_slice(&r.points);
            // Valid: positive, manifold, the same boundary, the volume.
            for t in &r.tets {
                let q = t.map(|v| all[v as usize]);
                assert!(orient3d(q[0], q[1], q[2], q[3]) > 0.0, "{t:?}");
            }
            assert_eq!(boundary(&r.tets), before, "h = {h}");
            assert!((volume(&all, &r.tets) - 1.0).abs() < 1e-9);
            let mut used = vec![false; all.len()];
            r.tets
                .iter()
                .flatten()
                .for_each(|&v| used[v as usize] = true);
            assert!(used.iter().all(|&u| u), "h = {h}: a point left out");
            // New points strictly inside, none on the surface.
            for x in &r.points {
                assert!(x.iter().all(|&c| c > 0.0 && c < 1.0), "{x:?}");
            }
            // As many points as the size asks, give or take: a cube of
            // side 1 at spacing h holds about 1/h^3 of them.
            let want = 1.0 / (h * h * h);
            let got = r.points.len() as f64;
            assert!(
                got > 0.2 * want && got < 5.0 * want,
                "h = {h}: {got} for {want}"
            );
            // Away from the surface (whose faces are larger than h, so the
            // tets on them are flat), the tets' edges are about h: slivers
            // (short edges, a large circumsphere) are the improvement's.
            let inner: Vec<_> = r
                .tets
                .iter()
                .filter(|t| t.iter().all(|&v| v >= 8))
                .collect();
            let long = inner
                .iter()
                .filter(|t| {
                    let q = t.map(|v| all[v as usize]);
                    (0..4).any(|i| (i + 1..4).any(|j| dist(q[i], q[j]) > 2.5 * h))
                })
                .count();
            assert!(
                long * 20 < inner.len(),
                "h = {h}: {long} of {}",
                inner.len()
            );
        }
    }

    #[test]
    fn a_graded_size_gives_graded_points() {
        let (p, tets) = cube();
        let size = |x: P3| 0.05 + 0.3 * x[0];
        let r = refine_to_size(&p, &tets, &[], &size, &RefineOptions::default()).unwrap();
        let left = r.points.iter().filter(|x| x[0] < 0.5).count();
        let right = r.points.len() - left;
        assert!(left > 4 * right, "{left} {right}");
    }

    #[test]
    fn the_cap_stops_it_with_a_valid_region() {
        let (p, tets) = cube();
        let opts = RefineOptions {
            max_points: 10,
            ..RefineOptions::default()
        };
        let r = refine_to_size(&p, &tets, &[], &|_| 0.05, &opts).unwrap();
        assert!(r.capped && r.points.len() == 10);
        let mut all = p.clone();
        all.extend_from_slice(&r.points);
        assert!((volume(&all, &r.tets) - 1.0).abs() < 1e-9);
        assert_eq!(boundary(&r.tets), boundary(&tets));
    }

    #[test]
    fn bad_regions_are_errors() {
        let (p, mut tets) = cube();
        tets[0].swap(0, 1);
        assert_eq!(
            refine_to_size(&p, &tets, &[], &|_| 0.1, &RefineOptions::default()).unwrap_err(),
            RefineError::NotPositive(0)
        );
        let (p, mut tets) = cube();
        tets.push(tets[0]);
        assert!(matches!(
            refine_to_size(&p, &tets, &[], &|_| 0.1, &RefineOptions::default()),
            Err(RefineError::NonManifold(_))
        ));
        let (p, mut tets) = cube();
        tets[2][1] = 99;
        assert_eq!(
            refine_to_size(&p, &tets, &[], &|_| 0.1, &RefineOptions::default()).unwrap_err(),
            RefineError::BadPoint(2)
        );
    }
}
