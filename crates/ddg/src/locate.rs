//! Point location in the DDG (§7): which DDG tets hold a point, and the
//! lowest part among them.
use crate::Ddg;
use parafront_geom::{cross, dot, orient3d, sub, Aabb, P3};
use parafront_mesh::FaceRef;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// A uniform grid of boxes (CSR cells), shared by the tet and face lookups.
/// It keeps no boxes: the caller has them, or recomputes them.
#[derive(Clone, Debug)]
pub(crate) struct Bins {
    min: P3,
    inv: f64,
    n: [usize; 3],
    start: Vec<u32>,
    list: Vec<u32>,
}

impl Bins {
    /// The `n` boxes `bx(i)`, about `per_cell` of them per cell on average;
    /// item `i` goes into the cells its box meets where `keep(k, cell)`,
    /// `k = prep(i, cell diagonal)`, and `cell` a box a little larger than
    /// the cell, so that a point binned there by rounding is inside it.
    pub(crate) fn new<K>(
        n: usize,
        bx: impl Fn(usize) -> Aabb + Sync,
        prep: impl Fn(usize, f64) -> K + Sync,
        keep: impl Fn(&K, &Aabb) -> bool + Sync,
        per_cell: f64,
    ) -> Bins {
        let mut bb = Aabb::EMPTY;
        for i in 0..n {
            bb = bb.union(&bx(i));
        }
        if n == 0 {
            return Bins {
                min: [0.0; 3],
                inv: 1.0,
                n: [1, 1, 1],
                start: vec![0, 0],
                list: Vec::new(),
            };
        }
        let ext = [0, 1, 2].map(|k| (bb.max[k] - bb.min[k]).max(1e-300));
        let vol = ext[0] * ext[1] * ext[2];
        let cells = (n as f64 / per_cell).clamp(1.0, 4e6);
        let mut cell = (vol / cells).cbrt();
        let maxe = ext.iter().cloned().fold(0.0, f64::max);
        cell = cell.max(maxe / 512.0);
        let nc = ext.map(|e| ((e / cell).ceil() as usize).clamp(1, 512));
        let inv = 1.0 / cell;
        let min = bb.min;
        let ncell = nc[0] * nc[1] * nc[2];
        let range = |b: &Aabb| {
            let lo = [0, 1, 2]
                .map(|k| (((b.min[k] - min[k]) * inv).floor().max(0.0) as usize).min(nc[k] - 1));
            let hi = [0, 1, 2]
                .map(|k| (((b.max[k] - min[k]) * inv).floor().max(0.0) as usize).min(nc[k] - 1));
            (lo, hi)
        };
        let pad = 1e-6 * cell;
        let cell_diag = 3f64.sqrt() * cell;
        let cells_of = |x: usize, f: &mut dyn FnMut(usize)| {
            let (lo, hi) = range(&bx(x));
            let key = prep(x, cell_diag);
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        let c0 = [i, j, k].map(|v| v as f64);
                        let cb = Aabb {
                            min: [0, 1, 2].map(|d| min[d] + c0[d] * cell - pad),
                            max: [0, 1, 2].map(|d| min[d] + (c0[d] + 1.0) * cell + pad),
                        };
                        if keep(&key, &cb) {
                            f((k * nc[1] + j) * nc[0] + i);
                        }
                    }
                }
            }
        };
        // Each chunk of items finds its cells in parallel (the cell tests
        // are the cost), in item order; then one counting sort by cell
        // keeps each cell's items ascending.
        const CHUNK: usize = 4096;
        let found: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|ch| {
                let (mut cells, mut per) = (Vec::new(), Vec::new());
                for x in ch * CHUNK..((ch + 1) * CHUNK).min(n) {
                    let before = cells.len();
                    cells_of(x, &mut |c| cells.push(c as u32));
                    per.push((cells.len() - before) as u32);
                }
                (cells, per)
            })
            .collect();
        let mut count = vec![0u32; ncell + 1];
        for (cells, _) in &found {
            for &c in cells {
                count[c as usize + 1] += 1;
            }
        }
        for c in 0..ncell {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut list = vec![0u32; count[ncell] as usize];
        for (ch, (cells, per)) in found.iter().enumerate() {
            let mut at = 0;
            for (i, &m) in per.iter().enumerate() {
                for &c in &cells[at..at + m as usize] {
                    list[fill[c as usize] as usize] = (ch * CHUNK + i) as u32;
                    fill[c as usize] += 1;
                }
                at += m as usize;
            }
        }
        Bins {
            min,
            inv,
            n: nc,
            start: count,
            list,
        }
    }

    fn cell_of(&self, p: P3) -> Option<usize> {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let x = (p[k] - self.min[k]) * self.inv;
            if x.is_nan() || x < 0.0 || x >= self.n[k] as f64 + 1e-9 {
                return None;
            }
            c[k] = (x as usize).min(self.n[k] - 1);
        }
        Some((c[2] * self.n[1] + c[1]) * self.n[0] + c[0])
    }

    /// The ids binned in the cell of `p`, ascending.
    fn at(&self, p: P3) -> &[u32] {
        match self.cell_of(p) {
            Some(c) => &self.list[self.start[c] as usize..self.start[c + 1] as usize],
            None => &[],
        }
    }

    /// Calls `f` on every id whose cell range meets `b` (with repeats).
    pub(crate) fn visit(&self, b: &Aabb, mut f: impl FnMut(u32) -> bool) -> bool {
        let lo = [0, 1, 2].map(|k| ((b.min[k] - self.min[k]) * self.inv).floor());
        let hi = [0, 1, 2].map(|k| ((b.max[k] - self.min[k]) * self.inv).floor());
        let mut l = [0usize; 3];
        let mut h = [0usize; 3];
        for k in 0..3 {
            if hi[k] < 0.0 || lo[k] >= self.n[k] as f64 {
                return true;
            }
            l[k] = lo[k].max(0.0) as usize;
            h[k] = (hi[k] as usize).min(self.n[k] - 1);
        }
        for k in l[2]..=h[2] {
            for j in l[1]..=h[1] {
                for i in l[0]..=h[0] {
                    let c = (k * self.n[1] + j) * self.n[0] + i;
                    for &x in &self.list[self.start[c] as usize..self.start[c + 1] as usize] {
                        if !f(x) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    fn heap_bytes(&self) -> usize {
        4 * (self.start.capacity() + self.list.capacity())
    }
}

/// DDG tets per bin on average: at 0.5 the bins are 1.6 times larger and
/// the queries no faster.
const PER_CELL: f64 = 1.0;

/// DDG tets per bin for a process that holds only some of the parts (an MPI
/// rank), where the replicated locator counts against each rank's share:
/// on sphere_5e6's DDG (206k tets) it takes 5.7 MB, not 10.5 (6.6 at 8).
/// The scans take longer (at 8 on one process, torus_1e6: 5.0 % of the
/// run against 3.4 %); 4 ranks on sphere_5e6 took no longer over all.
pub const SHARED_PER_CELL: f64 = 16.0;

/// A tet's face planes, with inward normals, for [`Faces::beyond`].
struct Faces([(P3, P3, f64); 4]);

impl Faces {
    /// The planes of tet `q`, for boxes of diagonal up to `diag`: the
    /// margin, 1e-9 of the sizes involved, keeps the test on the safe side
    /// of rounding.
    fn of(q: &[P3; 4], diag: f64) -> Faces {
        let scale = Aabb::from_points(q.iter()).diagonal() + diag;
        Faces([0, 1, 2, 3].map(|f| {
            let [a, c, e] = [1, 2, 3].map(|i| q[(f + i) % 4]);
            let mut n = cross(sub(c, a), sub(e, a));
            // Towards the opposite corner: inside.
            if dot(n, sub(q[f], a)) < 0.0 {
                n = n.map(|x| -x);
            }
            (n, a, 1e-9 * dot(n, n).sqrt() * scale)
        }))
    }

    /// Whether box `b` lies clearly beyond a face plane, so that no point
    /// of it is in the tet.
    fn beyond(&self, b: &Aabb) -> bool {
        self.0.iter().any(|&(n, a, margin)| {
            // The box's corner farthest inside.
            let far = [0, 1, 2].map(|k| if n[k] >= 0.0 { b.max[k] } else { b.min[k] });
            dot(n, sub(far, a)) < -margin
        })
    }
}

/// Whether the closed tet `q` holds `p`: `Some(true)` strictly inside (then
/// it is its only host), `Some(false)` on its boundary, `None` outside. A
/// corner is on the boundary without a predicate (the surface points are
/// corners of DDG tets, and every predicate of a corner takes the slow
/// exact path); else no sub-tet with `p` in place of a corner may be
/// negative.
#[inline]
fn holds(q: &[P3; 4], p: P3) -> Option<bool> {
    if q.contains(&p) {
        return Some(false);
    }
    let mut strict = true;
    for k in 0..4 {
        let mut r = *q;
        r[k] = p;
        let o = orient3d(r[0], r[1], r[2], r[3]);
        if o < 0.0 {
            return None;
        }
        strict &= o > 0.0;
    }
    Some(strict)
}

/// Which DDG tets hold a point (closed tets, exact predicates).
///
/// It borrows the DDG, keeps the tets' boxes on an 8-bit grid over the
/// DDG's box and bins them one tet per cell on average, each tet only in
/// the cells no face plane of it cuts off: every process holds a locator
/// through the passes, and on sphere_5e6's DDG (184k tets) copies, f64
/// boxes and finer bins by box alone were 34 MB of each MPI rank's 125 MB
/// heap (13 MB with f32 boxes, 10.5 MB with 16-bit ones). The boxes only
/// spare the exact test most tets of a bin: coarser ones cost no time.
#[derive(Clone, Debug)]
pub struct Locator<'a> {
    bins: Bins,
    grid: Grid8,
    /// Each tet's box on the grid, rounded outwards: `[min, max]`.
    boxes: Vec<[[u8; 3]; 2]>,
    d: &'a Ddg,
}

/// Coordinates scaled onto `[0, 253]` over a box. Rounding is monotone,
/// so a point of a box lies between the box's corners scaled, floor and
/// ceiling: the scaled boxes hold every point their boxes hold.
#[derive(Clone, Debug)]
struct Grid8 {
    min: P3,
    scale: [f64; 3],
}

impl Grid8 {
    fn new(b: &Aabb) -> Grid8 {
        let scale = [0, 1, 2].map(|k| {
            let e = b.max[k] - b.min[k];
            if e > 0.0 && e.is_finite() {
                253.0 / e
            } else {
                0.0
            }
        });
        Grid8 { min: b.min, scale }
    }

    #[inline]
    fn at(&self, p: P3) -> P3 {
        [0, 1, 2].map(|k| (p[k] - self.min[k]) * self.scale[k])
    }

    /// The box `b` on the grid (rounded outwards).
    fn scaled(&self, b: &Aabb) -> [[u8; 3]; 2] {
        let (lo, hi) = (self.at(b.min), self.at(b.max));
        let q = |x: f64| x.clamp(0.0, 255.0) as u8;
        [lo.map(|x| q(x.floor())), hi.map(|x| q(x.ceil()))]
    }
}

impl<'a> Locator<'a> {
    /// Bins the tets of `d`, one a bin on average.
    pub fn new(d: &'a Ddg) -> Locator<'a> {
        Locator::with_bins(d, PER_CELL)
    }

    /// Bins the tets of `d`, `per_cell` a bin on average: fewer, larger
    /// bins hold fewer entries and take longer to scan. The answers do not
    /// depend on it.
    pub fn with_bins(d: &'a Ddg, per_cell: f64) -> Locator<'a> {
        let bins = Bins::new(
            d.tets.len(),
            |t| Aabb::from_points(d.tet_points(t).iter()),
            |t, cell_diag| Faces::of(&d.tet_points(t), cell_diag),
            |faces, cell| !faces.beyond(cell),
            per_cell,
        );
        let grid = Grid8::new(&Aabb::from_points(d.points.iter()));
        let boxes = (0..d.tets.len())
            .map(|t| grid.scaled(&Aabb::from_points(d.tet_points(t).iter())))
            .collect();
        Locator {
            bins,
            grid,
            boxes,
            d,
        }
    }

    /// Bytes the locator holds beside the DDG.
    pub fn heap_bytes(&self) -> usize {
        self.bins.heap_bytes() + 6 * self.boxes.capacity()
    }

    /// Whether the box of tet `t` holds the point at `g` on the grid.
    #[inline]
    fn in_box(&self, t: u32, g: P3) -> bool {
        let [lo, hi] = &self.boxes[t as usize];
        (0..3).all(|k| lo[k] as f64 <= g[k] && g[k] <= hi[k] as f64)
    }

    #[inline]
    fn corners(&self, t: u32) -> [P3; 4] {
        self.d.tets[t as usize].map(|v| self.d.points[v as usize])
    }

    /// Calls `f` with every DDG tet whose closure holds `p`, ascending;
    /// stops early when `f` returns false.
    pub fn hosts(&self, p: P3, mut f: impl FnMut(u32) -> bool) {
        if let Some(t) = self.scan(p, &mut f) {
            f(t);
        }
    }

    /// One scan of the bin of `p`: a tet that holds `p` strictly (then its
    /// only host), or `None` after calling `on_face` with each tet that
    /// holds it on its boundary, ascending, until `on_face` returns false.
    fn scan(&self, p: P3, mut on_face: impl FnMut(u32) -> bool) -> Option<u32> {
        let g = self.grid.at(p);
        for &t in self.bins.at(p) {
            if !self.in_box(t, g) {
                continue;
            }
            match holds(&self.corners(t), p) {
                None => {}
                Some(true) => return Some(t),
                Some(false) if !on_face(t) => return None,
                Some(false) => {}
            }
        }
        None
    }

    /// Whether `p` lies strictly inside tet `t`: then `t` is its only host.
    #[inline]
    pub fn strictly_holds(&self, t: u32, p: P3) -> bool {
        holds(&self.corners(t), p) == Some(true)
    }

    /// Whether `t` is a tet id (a hint may be `u32::MAX`) that holds `p`
    /// strictly.
    #[inline]
    fn holds_alone(&self, t: u32, p: P3) -> bool {
        (t as usize) < self.d.tets.len()
            && self.in_box(t, self.grid.at(p))
            && self.strictly_holds(t, p)
    }

    /// The tet that holds `p` strictly, found by walking from tet `t`
    /// through the face neighbours `neigh` ([`Ddg::neigh`]) towards `p`
    /// (across the first face that has `p` outside), over at most `steps`
    /// tets; `None` where the walk ends otherwise: on a face, outside the
    /// DDG, out of steps, or off an empty `neigh` (a let-go table: then
    /// only `t` itself is tried).
    pub(crate) fn walk(&self, neigh: &[FaceRef], mut t: u32, p: P3, steps: usize) -> Option<u32> {
        for _ in 0..steps {
            if t as usize >= self.d.tets.len() {
                return None;
            }
            let q = self.corners(t);
            let mut strict = true;
            let mut exit = None;
            for k in 0..4 {
                // Face k is opposite corner k.
                let mut r = q;
                r[k] = p;
                let o = orient3d(r[0], r[1], r[2], r[3]);
                if o < 0.0 {
                    exit = Some(k);
                    break;
                }
                strict &= o > 0.0;
            }
            let Some(k) = exit else {
                return strict.then_some(t);
            };
            let n = *neigh.get(4 * t as usize + k)?;
            if n.is_none() {
                return None;
            }
            t = n.tet().idx() as u32;
        }
        None
    }

    /// [`Locator::owner`], trying first the tet in `hint` (the last one
    /// found holding a point alone, updated here): a front asks about
    /// points near each other, mostly inside one DDG tet. The answer does
    /// not depend on the hint.
    pub fn owner_near(&self, p: P3, part: &[u32], hint: &AtomicU32) -> Option<u32> {
        self.owner_placed(p, part, hint).0
    }

    /// [`Locator::owner_near`], and the tet that holds `p` strictly when
    /// one does.
    pub fn owner_placed(
        &self,
        p: P3,
        part: &[u32],
        hint: &AtomicU32,
    ) -> (Option<u32>, Option<u32>) {
        let h = hint.load(Ordering::Relaxed);
        if self.holds_alone(h, p) {
            return (Some(part[h as usize]), Some(h));
        }
        let (own, remember, strict) = self.one_part(p, part);
        if let Some(t) = remember {
            hint.store(t, Ordering::Relaxed);
        }
        (own, remember.filter(|_| strict))
    }

    /// The part that holds `p` conservatively (§7): `Some(k)` when every
    /// DDG tet touching `p` belongs to part `k`; `None` on an inter-part
    /// boundary or outside the DDG.
    pub fn owner(&self, p: P3, part: &[u32]) -> Option<u32> {
        self.one_part(p, part).0
    }

    /// [`Locator::owner`], with the tet worth trying first next time (the
    /// host of `p` when it has one host only) and whether that tet holds
    /// `p` strictly.
    fn one_part(&self, p: P3, part: &[u32]) -> (Option<u32>, Option<u32>, bool) {
        // A tet that holds `p` strictly is its only host (the common case);
        // else every host must be in one part.
        let mut own: Option<u32> = None;
        let (mut first, mut hosts, mut mixed) = (u32::MAX, 0, false);
        let strict = self.scan(p, |t| {
            hosts += 1;
            let k = part[t as usize];
            match own {
                None => {
                    own = Some(k);
                    first = t;
                    true
                }
                Some(o) if o == k => true,
                Some(_) => {
                    mixed = true;
                    false
                }
            }
        });
        match strict {
            Some(t) => (Some(part[t as usize]), Some(t), true),
            None if mixed => (None, None, false),
            None => (own, (hosts == 1).then_some(first), false),
        }
    }

    /// [`Locator::lowest_host`] of each of the DDG's input points (its
    /// vertices on the region's boundary, by id), or `u32::MAX` for one on
    /// no tet: the lowest part among the tets on it. A vertex of a
    /// conforming mesh lies on no other tet, so this is the bins' answer;
    /// those points are on the DDG's boundary, never strictly inside a
    /// tet, and the bins were most of the redistribution's time.
    pub fn lowest_at_inputs(&self, part: &[u32]) -> Vec<u32> {
        let mut low = vec![u32::MAX; self.d.n_input];
        for (tv, &k) in self.d.tets.iter().zip(part) {
            for &v in tv {
                if let Some(l) = low.get_mut(v as usize) {
                    *l = (*l).min(k);
                }
            }
        }
        low
    }

    /// The lowest part among the DDG tets touching `p` (§8), or `None`
    /// outside the DDG. `hint` is a tet near `p` (or `u32::MAX`), updated
    /// to the tet found holding `p` strictly (else `u32::MAX`): the answer
    /// does not depend on it. A walk from it over `neigh` ([`Ddg::neigh`],
    /// or none) goes first.
    pub fn lowest_host(
        &self,
        neigh: &[FaceRef],
        p: P3,
        part: &[u32],
        hint: &mut u32,
    ) -> Option<u32> {
        if let Some(t) = self.walk(neigh, *hint, p, WALK_STEPS) {
            *hint = t;
            return Some(part[t as usize]);
        }
        *hint = u32::MAX;
        let mut lo: Option<u32> = None;
        if let Some(t) = self.scan(p, |t| {
            let k = part[t as usize];
            lo = Some(lo.map_or(k, |l| l.min(k)));
            true
        }) {
            *hint = t;
            return Some(part[t as usize]);
        }
        lo
    }
}

/// Tets a walk from a nearby point's tet visits before the bins decide.
pub(crate) const WALK_STEPS: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Interfaces, PartFilter};
    use parafront_front::{RegionFilter, NO_PLACE};
    use parafront_surface::generate;

    /// The DDG of a torus: not convex, so points of its box fall outside.
    fn torus_ddg() -> Ddg {
        crate::ddg_of(&generate::torus([0.0; 3], 1.0, 0.35, 24, 12))
    }

    /// Every tet whose closure holds `p`, ascending, by a scan of all tets.
    fn brute(d: &Ddg, p: P3) -> Vec<u32> {
        (0..d.tets.len() as u32)
            .filter(|&t| holds(&d.tet_points(t as usize), p).is_some())
            .collect()
    }

    /// Uniform in [0, 1): xorshift64 from `x`.
    fn rng(mut x: u64) -> impl FnMut() -> f64 {
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Inside points, corners, edge midpoints, face centroids and points of
    /// the torus' box, in a scrambled order.
    fn probes(d: &Ddg) -> Vec<P3> {
        let mut out = d.points.clone();
        let mut rnd = rng(0x9e37_79b9_7f4a_7c15);
        for t in 0..d.tets.len() {
            let q = d.tet_points(t);
            let mid = |a: P3, b: P3| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
            out.push(mid(q[0], q[1]));
            out.push([0, 1, 2].map(|k| (q[1][k] + q[2][k] + q[3][k]) / 3.0));
            let w = [rnd(), rnd(), rnd(), rnd()];
            let s: f64 = w.iter().sum();
            out.push([0, 1, 2].map(|k| (0..4).map(|i| w[i] / s * q[i][k]).sum()));
            out.push([0, 1, 2].map(|k| [1.4, 1.4, 0.4][k] * (2.0 * rnd() - 1.0)));
        }
        for i in (1..out.len()).rev() {
            out.swap(i, (rnd() * (i + 1) as f64) as usize % (i + 1));
        }
        out
    }

    /// The lowest part on each input vertex, from the tets, is the one
    /// the bins give (a vertex is on no tet it is not a corner of).
    #[test]
    fn lowest_at_inputs_is_lowest_host() {
        let d = torus_ddg();
        let loc = Locator::new(&d);
        let part: Vec<u32> = (0..d.tets.len() as u32).map(|t| (t / 7) % 5).collect();
        let low = loc.lowest_at_inputs(&part);
        assert_eq!(low.len(), d.n_input);
        let mut mixed = 0;
        for (v, &l) in low.iter().enumerate() {
            let want = brute(&d, d.points[v]);
            assert!(!want.is_empty(), "input point {v} is on a tet");
            let parts: Vec<u32> = want.iter().map(|&t| part[t as usize]).collect();
            assert_eq!(Some(l), parts.iter().min().copied(), "vertex {v}");
            assert_eq!(
                Some(l),
                loc.lowest_host(&d.neigh(), d.points[v], &part, &mut u32::MAX.clone())
            );
            mixed += usize::from(parts.iter().any(|&k| k != l));
        }
        assert!(mixed > 10, "vertices between parts: {mixed}");
    }

    #[test]
    fn the_locator_finds_every_host_a_scan_finds() {
        let d = torus_ddg();
        for per_cell in [PER_CELL, SHARED_PER_CELL] {
            finds_every_host(&d, &Locator::with_bins(&d, per_cell));
        }
    }

    fn finds_every_host(d: &Ddg, loc: &Locator) {
        let part: Vec<u32> = (0..d.tets.len() as u32).map(|t| (t / 7) % 5).collect();
        let hint = AtomicU32::new(u32::MAX);
        let mut lo_hint = u32::MAX;
        let neigh = d.neigh();
        let (mut inside, mut outside, mut shared) = (0, 0, 0);
        for p in probes(d) {
            let want = brute(d, p);
            let mut got = Vec::new();
            loc.hosts(p, |t| {
                got.push(t);
                true
            });
            assert_eq!(got, want, "hosts of {p:?}");
            let parts: Vec<u32> = want.iter().map(|&t| part[t as usize]).collect();
            let one = parts.first().filter(|&&k| parts.iter().all(|&j| j == k));
            assert_eq!(loc.owner(p, &part), one.copied(), "owner of {p:?}");
            assert_eq!(
                loc.owner_near(p, &part, &hint),
                one.copied(),
                "owner_near {p:?}"
            );
            let lowest = parts.iter().min().copied();
            assert_eq!(
                loc.lowest_host(&neigh, p, &part, &mut lo_hint),
                lowest,
                "lowest {p:?}"
            );
            // A point strictly inside a tet is in no other tet's closure.
            for &t in &want {
                assert!(!loc.strictly_holds(t, p) || want.len() == 1, "{p:?}");
            }
            match want.len() {
                0 => outside += 1,
                1 => inside += 1,
                _ => shared += 1,
            }
        }
        // The probes reach all three cases.
        assert!(
            inside > 100 && outside > 100 && shared > 100,
            "{inside} {outside} {shared}"
        );
    }

    /// The part filter's `locate`, from any hints, with the face
    /// neighbours to walk or without them, answers as `point_ok`, and the
    /// place it gives holds the point strictly; a walk ends only at such a
    /// tet; `edge_ok_at` answers as `edge_ok`.
    #[test]
    fn hinted_location_answers_as_the_bins() {
        let d = torus_ddg();
        let loc = Locator::new(&d);
        let part: Vec<u32> = (0..d.tets.len() as u32).map(|t| (t / 7) % 5).collect();
        let walls = Interfaces::new(&d, &part, 0..5);
        let neigh = d.neigh().to_vec();
        let probes = probes(&d);
        let n = d.tets.len() as u32;
        for table in [&neigh[..], &[]] {
            let f = PartFilter::new(&loc, &walls, &part, 2, table);
            let (mut walked, mut placed) = (0, 0);
            let mut at = Vec::new();
            for (i, &p) in probes.iter().enumerate() {
                // Hints: the host of the previous probe, a tet far off, none.
                let near = [
                    at.last().copied().unwrap_or(NO_PLACE),
                    (i as u32 * 7919) % n,
                    NO_PLACE,
                ];
                let (ok, t) = f.locate(p, &near);
                assert_eq!(ok, f.point_ok(p), "locate {p:?}");
                if t != NO_PLACE {
                    assert!(loc.strictly_holds(t, p), "place of {p:?}");
                    placed += 1;
                }
                for &h in &near[..2] {
                    if let Some(w) = loc.walk(table, h, p, WALK_STEPS) {
                        assert!(loc.strictly_holds(w, p), "walk to {p:?}");
                        walked += 1;
                    }
                }
                at.push(t);
            }
            // Without the table a walk only tries its first tet.
            let walks = if table.is_empty() { 0 } else { 100 };
            assert!(walked >= walks && placed > 1000, "{walked} {placed}");
            for i in 1..probes.len() {
                let (a, b) = (probes[i - 1], probes[i]);
                assert_eq!(f.edge_ok_at(a, at[i - 1], b, at[i]), f.edge_ok(a, b));
                // The short edge inside the place of `a`.
                let c = [0, 1, 2].map(|k| 0.9 * a[k] + 0.1 * b[k]);
                let tc = f.locate(c, &[at[i - 1]]).1;
                assert_eq!(f.edge_ok_at(a, at[i - 1], c, tc), f.edge_ok(a, c));
            }
        }
    }

    /// The walls kept for some parts answer for those parts as all the
    /// walls do, and there are fewer of them.
    #[test]
    fn the_walls_of_held_parts_answer_as_all_walls() {
        let d = torus_ddg();
        let part: Vec<u32> = (0..d.tets.len() as u32).map(|t| (t / 7) % 5).collect();
        let all = Interfaces::new(&d, &part, 0..5);
        let held = Interfaces::new(&d, &part, 1..3);
        assert!(held.sides.len() < all.sides.len(), "{}", held.sides.len());
        assert!(held
            .sides
            .iter()
            .all(|s| (1..3).contains(&s[0]) || (1..3).contains(&s[1])));
        let probes = probes(&d);
        let mut crossing = 0;
        for w in probes.windows(2) {
            for k in 1..3 {
                let c = all.crosses(k, w[0], w[1]);
                assert_eq!(held.crosses(k, w[0], w[1]), c, "part {k}: {:?}", w);
                crossing += c as usize;
            }
        }
        assert!(crossing > 100, "{crossing}");
    }

    /// A box on the grid holds every point of the box: its corners, and
    /// points in it, on boxes of many sizes about many places.
    #[test]
    fn boxes_on_the_grid_hold_their_points() {
        let mut rnd = rng(0x2545_f491_4f6c_dd1d);
        let all = Aabb {
            min: [-3.7, 0.1, 1e3],
            max: [2.9, 0.1000001, 1e3 + 1e-9],
        };
        let g = Grid8::new(&all);
        let mut misses = 0;
        for _ in 0..20000 {
            let at = |t: f64, k: usize| all.min[k] + t * (all.max[k] - all.min[k]);
            let (u, w) = (rnd(), rnd() * rnd() * rnd());
            let b = Aabb {
                min: [0, 1, 2].map(|k| at(u * (1.0 - w), k)),
                max: [0, 1, 2].map(|k| at(u * (1.0 - w) + w, k)),
            };
            let [lo, hi] = g.scaled(&b);
            let t = rnd();
            for p in [
                b.min,
                b.max,
                [0, 1, 2].map(|k| b.min[k] + t * (b.max[k] - b.min[k])),
            ] {
                let p = [0, 1, 2].map(|k| p[k].clamp(b.min[k], b.max[k]));
                let q = g.at(p);
                assert!((0..3).all(|k| lo[k] as f64 <= q[k] && q[k] <= hi[k] as f64));
            }
            // Points well outside are left out by some axis.
            let out = [0, 1, 2].map(|k| b.max[k] + 0.01 * (all.max[k] - all.min[k]));
            let q = g.at(out);
            misses += (0..3).all(|k| q[k] <= hi[k] as f64) as usize;
        }
        assert_eq!(misses, 0);
    }
}
