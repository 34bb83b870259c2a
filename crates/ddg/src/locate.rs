//! Point location in the DDG and the region filter of one part (§7).
use crate::Ddg;
use parafront_front::RegionFilter;
use parafront_geom::intersect::{segment_triangle, SegTri};
use parafront_geom::{orient3d, Aabb, P3};
use std::sync::atomic::{AtomicU32, Ordering};

/// A uniform grid of boxes (CSR cells), shared by the tet and face lookups.
#[derive(Clone, Debug)]
struct Bins {
    min: P3,
    inv: f64,
    n: [usize; 3],
    start: Vec<u32>,
    list: Vec<u32>,
    boxes: Vec<Aabb>,
}

impl Bins {
    /// About `per_cell` boxes per cell on average.
    fn new(boxes: Vec<Aabb>, per_cell: f64) -> Bins {
        let mut bb = Aabb::EMPTY;
        for b in &boxes {
            bb = bb.union(b);
        }
        if boxes.is_empty() {
            return Bins {
                min: [0.0; 3],
                inv: 1.0,
                n: [1, 1, 1],
                start: vec![0, 0],
                list: Vec::new(),
                boxes,
            };
        }
        let ext = [0, 1, 2].map(|k| (bb.max[k] - bb.min[k]).max(1e-300));
        let vol = ext[0] * ext[1] * ext[2];
        let cells = (boxes.len() as f64 / per_cell).clamp(1.0, 4e6);
        let mut cell = (vol / cells).cbrt();
        let maxe = ext.iter().cloned().fold(0.0, f64::max);
        cell = cell.max(maxe / 512.0);
        let n = ext.map(|e| ((e / cell).ceil() as usize).clamp(1, 512));
        let inv = 1.0 / cell;
        let min = bb.min;
        let ncell = n[0] * n[1] * n[2];
        let mut count = vec![0u32; ncell + 1];
        let range = |b: &Aabb| {
            let lo = [0, 1, 2]
                .map(|k| (((b.min[k] - min[k]) * inv).floor().max(0.0) as usize).min(n[k] - 1));
            let hi = [0, 1, 2]
                .map(|k| (((b.max[k] - min[k]) * inv).floor().max(0.0) as usize).min(n[k] - 1));
            (lo, hi)
        };
        for b in &boxes {
            let (lo, hi) = range(b);
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        count[(k * n[1] + j) * n[0] + i + 1] += 1;
                    }
                }
            }
        }
        for c in 0..ncell {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut list = vec![0u32; count[ncell] as usize];
        for (x, b) in boxes.iter().enumerate() {
            let (lo, hi) = range(b);
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        let c = (k * n[1] + j) * n[0] + i;
                        list[fill[c] as usize] = x as u32;
                        fill[c] += 1;
                    }
                }
            }
        }
        Bins {
            min,
            inv,
            n,
            start: count,
            list,
            boxes,
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

    fn at(&self, p: P3) -> &[u32] {
        match self.cell_of(p) {
            Some(c) => &self.list[self.start[c] as usize..self.start[c + 1] as usize],
            None => &[],
        }
    }

    /// Calls `f` on every box id whose cell range meets `b` (with repeats).
    fn visit(&self, b: &Aabb, mut f: impl FnMut(u32) -> bool) -> bool {
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
                        if self.boxes[x as usize].overlaps(b) && !f(x) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }
}

/// Which DDG tets hold a point (closed tets, exact predicates).
///
/// The tets by point id (16 B each) rather than by their corners (96 B):
/// every process holds a locator, and on sphere_5e6's DDG the corners
/// were 17 MB of it.
#[derive(Clone, Debug)]
pub struct Locator {
    bins: Bins,
    points: Vec<P3>,
    tets: Vec<[u32; 4]>,
}

impl Locator {
    /// Bins the tets of `d`.
    pub fn new(d: &Ddg) -> Locator {
        let boxes = (0..d.tets.len())
            .map(|t| Aabb::from_points(d.tet_points(t).iter()))
            .collect();
        Locator {
            bins: Bins::new(boxes, 0.5),
            points: d.points.clone(),
            tets: d.tets.clone(),
        }
    }

    /// Calls `f` with every DDG tet whose closure holds `p`, ascending;
    /// stops early when `f` returns false.
    pub fn hosts(&self, p: P3, mut f: impl FnMut(u32) -> bool) {
        for &t in self.bins.at(p) {
            if !self.bins.boxes[t as usize].contains(p) {
                continue;
            }
            if self.holds(t, p).is_some() && !f(t) {
                return;
            }
        }
    }

    /// Whether the closed tet `t` holds `p`: `Some(true)` strictly inside
    /// (then `t` is its only host), `Some(false)` on its boundary, `None`
    /// outside. A corner is on the boundary without a predicate (the
    /// surface points are corners of DDG tets, and every predicate of a
    /// corner takes the slow exact path); else no sub-tet with `p` in
    /// place of a corner may be negative.
    #[inline]
    fn holds(&self, t: u32, p: P3) -> Option<bool> {
        let q = self.tets[t as usize].map(|v| self.points[v as usize]);
        if q.contains(&p) {
            return Some(false);
        }
        let mut strict = true;
        for k in 0..4 {
            let mut r = q;
            r[k] = p;
            let o = orient3d(r[0], r[1], r[2], r[3]);
            if o < 0.0 {
                return None;
            }
            strict &= o > 0.0;
        }
        Some(strict)
    }

    /// Whether `p` lies strictly inside tet `t`: then `t` is its only host.
    #[inline]
    pub fn strictly_holds(&self, t: u32, p: P3) -> bool {
        self.holds(t, p) == Some(true)
    }

    /// [`Locator::owner`], trying first the tet in `hint` (the last one
    /// found holding a point alone, updated here): a front asks about
    /// points near each other, mostly inside one DDG tet. The answer does
    /// not depend on the hint.
    pub fn owner_near(&self, p: P3, part: &[u32], hint: &AtomicU32) -> Option<u32> {
        let h = hint.load(Ordering::Relaxed);
        if (h as usize) < self.tets.len()
            && self.bins.boxes[h as usize].contains(p)
            && self.strictly_holds(h, p)
        {
            return Some(part[h as usize]);
        }
        // One scan of the bin: a tet that holds `p` strictly is its only
        // host (the common case, answered there); else every host must be
        // in one part.
        let mut own: Option<u32> = None;
        let mut first = u32::MAX;
        let mut hosts = 0;
        for &t in self.bins.at(p) {
            if !self.bins.boxes[t as usize].contains(p) {
                continue;
            }
            match self.holds(t, p) {
                None => {}
                Some(true) => {
                    hint.store(t, Ordering::Relaxed);
                    return Some(part[t as usize]);
                }
                Some(false) => {
                    hosts += 1;
                    let k = part[t as usize];
                    match own {
                        None => {
                            own = Some(k);
                            first = t;
                        }
                        Some(o) if o == k => {}
                        Some(_) => return None,
                    }
                }
            }
        }
        if hosts == 1 {
            hint.store(first, Ordering::Relaxed);
        }
        own
    }

    /// The part that holds `p` conservatively (§7): `Some(k)` when every
    /// DDG tet touching `p` belongs to part `k`; `None` on an inter-part
    /// boundary or outside the DDG.
    pub fn owner(&self, p: P3, part: &[u32]) -> Option<u32> {
        let mut own: Option<u32> = None;
        let mut mixed = false;
        self.hosts(p, |t| {
            let k = part[t as usize];
            match own {
                None => {
                    own = Some(k);
                    true
                }
                Some(o) if o == k => true,
                Some(_) => {
                    mixed = true;
                    false
                }
            }
        });
        if mixed {
            None
        } else {
            own
        }
    }

    /// The lowest part among the DDG tets touching `p` (§8), or `None`
    /// outside the DDG.
    pub fn lowest_host(&self, p: P3, part: &[u32]) -> Option<u32> {
        let mut lo: Option<u32> = None;
        self.hosts(p, |t| {
            let k = part[t as usize];
            lo = Some(lo.map_or(k, |l| l.min(k)));
            true
        });
        lo
    }
}

/// The DDG faces between tets of different parts, with both parts: the
/// walls a part's edges may not cross (§7, the neighbour-to-neighbour
/// traversal, done here as exact segment-triangle tests).
#[derive(Clone, Debug)]
pub struct Interfaces {
    bins: Bins,
    faces: Vec<[P3; 3]>,
    sides: Vec<[u32; 2]>,
}

impl Interfaces {
    /// The walls of partition `part` (DDG tet -> part) of `d`.
    pub fn new(d: &Ddg, part: &[u32]) -> Interfaces {
        let mut faces = Vec::new();
        let mut sides = Vec::new();
        for t in 0..d.tets.len() {
            for f in 0..4 {
                let n = d.neigh[4 * t + f];
                if n.is_none() {
                    continue; // the surface: the front itself stops there
                }
                let u = n.tet().idx();
                if u < t || part[u] == part[t] {
                    continue;
                }
                let tv = d.tets[t];
                let fv: Vec<P3> = (0..4)
                    .filter(|&i| i != f)
                    .map(|i| d.points[tv[i] as usize])
                    .collect();
                faces.push([fv[0], fv[1], fv[2]]);
                sides.push([part[t], part[u]]);
            }
        }
        let boxes = faces.iter().map(|f| Aabb::from_points(f.iter())).collect();
        Interfaces {
            bins: Bins::new(boxes, 1.0),
            faces,
            sides,
        }
    }

    /// Whether segment `a`-`b` meets a wall of part `k`.
    pub fn crosses(&self, k: u32, a: P3, b: P3) -> bool {
        let mut bb = Aabb { min: a, max: a };
        bb.grow(b);
        !self.bins.visit(&bb, |x| {
            let s = self.sides[x as usize];
            if s[0] != k && s[1] != k {
                return true;
            }
            let [p, q, r] = self.faces[x as usize];
            matches!(segment_triangle(a, b, p, q, r), SegTri::Disjoint)
        })
    }
}

/// Region filter of part `k` in one pass (§7): a point must lie inside
/// the part's DDG tets and off its boundary (the conservative assignment),
/// an edge must not cross a wall of the part.
pub struct PartFilter<'a> {
    /// Locates points in the DDG.
    pub loc: &'a Locator,
    /// The walls between parts.
    pub walls: &'a Interfaces,
    /// The partition (DDG tet -> part).
    pub part: &'a [u32],
    /// The part.
    pub k: u32,
    /// The DDG tet of the last point located alone ([`Locator::owner_near`]).
    pub hint: AtomicU32,
}

impl<'a> PartFilter<'a> {
    /// The filter of part `k` of partition `part`, with its walls.
    pub fn new(loc: &'a Locator, walls: &'a Interfaces, part: &'a [u32], k: u32) -> Self {
        PartFilter {
            loc,
            walls,
            part,
            k,
            hint: AtomicU32::new(u32::MAX),
        }
    }
}

impl RegionFilter for PartFilter<'_> {
    fn point_ok(&self, p: P3) -> bool {
        self.loc.owner_near(p, self.part, &self.hint) == Some(self.k)
    }
    fn edge_ok(&self, a: P3, b: P3) -> bool {
        !self.walls.crosses(self.k, a, b)
    }
}
