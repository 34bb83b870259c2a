//! The lattice's blocks: the accepted leaves of an octree over the region
//! (see the crate doc for the rules).
use crate::{LatticeOptions, CUBE_PER_SIZE};
use parafront_geom::P3;
use parafront_surface::inside::Inside;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

/// Accepted cells: cell `(d, ijk)` is the cube of side `root / 2^d` at
/// `origin + ijk * side`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Cells {
    pub origin: P3,
    pub root: f64,
    /// Sorted by depth, then `ijk`.
    pub cells: Vec<(u32, [i64; 3])>,
}

impl Cells {
    pub(crate) fn side(&self, d: u32) -> f64 {
        self.root / (1u64 << d) as f64
    }

    pub(crate) fn corner(&self, d: u32, ijk: [i64; 3]) -> P3 {
        let s = self.side(d);
        [0, 1, 2].map(|k| self.origin[k] + ijk[k] as f64 * s)
    }
}

const MAX_DEPTH: u32 = 20;

pub(crate) fn blocks(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &LatticeOptions,
) -> Cells {
    let empty = Cells::default();
    if faces.is_empty() {
        return empty;
    }
    let (fb, lo, hi) = face_boxes(points, faces);
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let (hmin, hmax, hmean) = size_range(point_size, faces, size, lo, hi);
    if !(hmin > 0.0 && hmax.is_finite() && extent > 0.0 && extent.is_finite()) {
        return empty;
    }
    if too_thin(points, faces, lo, hmean, opts.margin) {
        return empty;
    }
    let mut root = CUBE_PER_SIZE * hmax;
    while root < extent {
        root *= 2.0;
    }
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let mut out = Cells {
        origin: c.map(|x| x - 0.5 * root),
        root,
        cells: Vec::new(),
    };
    let inside = Inside::new(points, faces);
    let w = Walk {
        grid: Cells {
            origin: out.origin,
            root,
            cells: Vec::new(),
        },
        fb: &fb,
        inside: &inside,
        size,
        hmin,
        hmax,
        margin: opts.margin,
    };
    // The top levels in order, then their subtrees in parallel (the cells
    // are sorted at the end, so the thread count does not show).
    let all: Vec<u32> = (0..fb.len() as u32).collect();
    let mut top = Vec::new();
    w.run(
        vec![(0, [0; 3], all, false)],
        Some(PAR_DEPTH),
        &mut out.cells,
        &mut top,
    );
    let below: Vec<Vec<(u32, [i64; 3])>> = top
        .into_par_iter()
        .map(|p| {
            let mut cells = Vec::new();
            w.run(vec![p], None, &mut cells, &mut Vec::new());
            cells
        })
        .collect();
    out.cells.extend(below.into_iter().flatten());
    separate(&mut out);
    manifold(&mut out);
    drop_small(&mut out, opts.min_cells);
    out.cells.sort_unstable();
    out
}

/// Each face's box, and the region's.
#[allow(clippy::type_complexity)]
fn face_boxes(points: &[P3], faces: &[[u32; 3]]) -> (Vec<(P3, P3)>, P3, P3) {
    let fb: Vec<(P3, P3)> = faces
        .iter()
        .map(|f| {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for &v in f {
                let p = points[v as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            (lo, hi)
        })
        .collect();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for b in &fb {
        for k in 0..3 {
            lo[k] = lo[k].min(b.0[k]);
            hi[k] = hi[k].max(b.1[k]);
        }
    }
    (fb, lo, hi)
}

/// The smallest and the mean surface size, and the largest size in the
/// region (the surface's, and the field's on a 7^3 grid over the box
/// `lo`-`hi`): the levels are the largest halved per level, so a uniform
/// field is exactly a level's size.
fn size_range(
    point_size: &[f64],
    faces: &[[u32; 3]],
    size: &(dyn Fn(P3) -> f64 + Sync),
    lo: P3,
    hi: P3,
) -> (f64, f64, f64) {
    let (mut hmin, mut hmax, mut hsum) = (f64::INFINITY, 0.0f64, 0.0);
    for f in faces {
        for &v in f {
            let h = point_size[v as usize];
            hmin = hmin.min(h);
            hmax = hmax.max(h);
            hsum += h;
        }
    }
    let n = 6;
    for i in 0..=n {
        for j in 0..=n {
            for k in 0..=n {
                let t = [i, j, k].map(|x| x as f64 / n as f64);
                let p = [0, 1, 2].map(|a| lo[a] + t[a] * (hi[a] - lo[a]));
                hmax = hmax.max(size(p));
            }
        }
    }
    (hmin, hmax, hsum / (3 * faces.len()) as f64)
}

/// A thin region (three times its volume over its area is a ball's
/// radius, 1.5 times a slab's thickness) has no room for a cell between
/// its margins at the surface's mean size `hmean`: the octree would be
/// searched in vain.
fn too_thin(points: &[P3], faces: &[[u32; 3]], lo: P3, hmean: f64, margin: f64) -> bool {
    let (mut vol6, mut area2) = (0.0, 0.0);
    for f in faces {
        let [a, b, c] = f.map(|v| points[v as usize]);
        vol6 += parafront_geom::tet_volume6(a, b, c, lo);
        area2 += parafront_geom::norm(parafront_geom::tri_normal(a, b, c));
    }
    // A ball's radius; a slab's thickness is 2/3 of it.
    let depth = 3.0 * (vol6 / 6.0) / (0.5 * area2);
    !(depth >= (2.0 * margin + 1.0) * CUBE_PER_SIZE * hmean)
}

/// A cell on the octree's stack: its depth, its index, the faces within
/// its margin, and whether it is known to be inside.
type Pending = (u32, [i64; 3], Vec<u32>, bool);

/// The depth from which the octree's subtrees are walked in parallel:
/// 8^3 of them at most.
const PAR_DEPTH: u32 = 3;

/// The octree walk's inputs; `grid` places its cells (it holds none).
struct Walk<'a> {
    grid: Cells,
    fb: &'a [(P3, P3)],
    inside: &'a Inside<'a>,
    size: &'a (dyn Fn(P3) -> f64 + Sync),
    hmin: f64,
    hmax: f64,
    margin: f64,
}

impl Walk<'_> {
    /// The octree walk from the cells on `stack`: a cell with surface
    /// within its margin is split where a child could fit the local size;
    /// a clear cell inside is kept (into `cells`) when the size at its
    /// corners and centre is within its band, else split when the size is
    /// smaller. Cells at depth `stop` go to `left` instead.
    fn run(
        &self,
        mut stack: Vec<Pending>,
        stop: Option<u32>,
        cells: &mut Vec<(u32, [i64; 3])>,
        left: &mut Vec<Pending>,
    ) {
        let band = std::f64::consts::SQRT_2;
        let (fb, size, margin) = (self.fb, self.size, self.margin);
        while let Some((d, ijk, near, known_in)) = stack.pop() {
            if stop == Some(d) {
                left.push((d, ijk, near, known_in));
                continue;
            }
            let s = self.grid.side(d);
            let h = s / CUBE_PER_SIZE;
            if h < self.hmin / band || d > MAX_DEPTH {
                continue;
            }
            let a = self.grid.corner(d, ijk);
            if !near.is_empty() {
                // Split only where a child could fit the local size: with
                // the cell's samples all over a child's band (a quarter of
                // slack for the size between them) there is nothing to gain.
                let hc = 0.5 * h * band * 1.25;
                let fine = hc >= self.hmax || (0..9).any(|b| size(sample(a, s, b)) <= hc);
                if fine {
                    split(&mut stack, fb, &near, false, (d, ijk, a, s), margin);
                }
                continue;
            }
            // No surface within the margin: the whole cell is in or out.
            if !known_in && !cell_inside(self.inside, a, s) {
                continue;
            }
            if h / band > self.hmax {
                // Larger than any size in the region: only children can fit.
                split(&mut stack, fb, &[], true, (d, ijk, a, s), margin);
                continue;
            }
            let mut small = false;
            let mut fits = true;
            for b in 0..9 {
                let hp = size(sample(a, s, b));
                small |= hp < h / band;
                fits &= hp >= h / band && hp <= h * band;
            }
            if fits {
                cells.push((d, ijk));
            } else if small {
                split(&mut stack, fb, &[], true, (d, ijk, a, s), margin);
            }
        }
    }
}

/// Push cell `(d, ijk)` (corner `a`, side `s`)'s eight children, each with
/// the faces of `near` within its margin, sorted out in one pass.
fn split(
    stack: &mut Vec<Pending>,
    fb: &[(P3, P3)],
    near: &[u32],
    known: bool,
    (d, ijk, a, s): (u32, [i64; 3], P3, f64),
    margin: f64,
) {
    let (h2, m2) = (0.5 * s, margin * 0.5 * s);
    let mut lists: [Vec<u32>; 8] = Default::default();
    for &f in near {
        let (l, u) = fb[f as usize];
        let mut lo_ok = [false; 3];
        let mut hi_ok = [false; 3];
        for k in 0..3 {
            lo_ok[k] = l[k] <= a[k] + h2 + m2 && u[k] >= a[k] - m2;
            hi_ok[k] = l[k] <= a[k] + s + m2 && u[k] >= a[k] + h2 - m2;
        }
        for (b, list) in lists.iter_mut().enumerate() {
            if (0..3).all(|k| {
                if (b >> k) & 1 == 1 {
                    hi_ok[k]
                } else {
                    lo_ok[k]
                }
            }) {
                list.push(f);
            }
        }
    }
    for (b, list) in lists.into_iter().enumerate() {
        let c = [0, 1, 2].map(|k| 2 * ijk[k] + ((b >> k) & 1) as i64);
        stack.push((d + 1, c, list, known));
    }
}

/// The cell's corners (`b` < 8) and centre (`b` = 8).
fn sample(a: P3, s: f64, b: usize) -> P3 {
    if b == 8 {
        a.map(|x| x + 0.5 * s)
    } else {
        [0, 1, 2].map(|k| a[k] + if (b >> k) & 1 == 1 { s } else { 0.0 })
    }
}

/// The cell's inside status, from its centre or, where the ray grazes an
/// edge, from other points of the cell (all share the status).
fn cell_inside(inside: &Inside, a: P3, s: f64) -> bool {
    for f in [
        [0.5, 0.5, 0.5],
        [0.31, 0.57, 0.43],
        [0.61, 0.29, 0.71],
        [0.23, 0.77, 0.37],
    ] {
        let p = [0, 1, 2].map(|k| a[k] + f[k] * s);
        if let Some(x) = inside.at(p) {
            return x;
        }
    }
    false
}

/// Drops each cell that comes within its own side of a coarser cell:
/// blocks of different sizes then leave the front a gap.
fn separate(c: &mut Cells) {
    let set: FxHashSet<(u32, [i64; 3])> = c.cells.iter().copied().collect();
    let depths: Vec<u32> = {
        let mut d: Vec<u32> = c.cells.iter().map(|x| x.0).collect();
        d.sort_unstable();
        d.dedup();
        d
    };
    let keep: Vec<bool> = c
        .cells
        .iter()
        .map(|&(d, ijk)| {
            let s = c.side(d);
            let a = c.corner(d, ijk);
            depths.iter().filter(|&&e| e < d).all(|&e| {
                let se = c.side(e);
                let r = |x: f64, k: usize| ((x - c.origin[k]) / se).floor() as i64;
                let lo = [0, 1, 2].map(|k| r(a[k] - s * 0.999, k));
                let hi = [0, 1, 2].map(|k| r(a[k] + s * 1.999, k));
                for i in lo[0]..=hi[0] {
                    for j in lo[1]..=hi[1] {
                        for k in lo[2]..=hi[2] {
                            if set.contains(&(e, [i, j, k])) {
                                return false;
                            }
                        }
                    }
                }
                true
            })
        })
        .collect();
    let mut i = 0;
    c.cells.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

/// Drops cells until, at every corner, a level's cells and the space
/// around them are each face-connected among the eight cells there (no
/// block meets another, or itself, at an edge or a corner only).
fn manifold(c: &mut Cells) {
    let mut set: FxHashSet<(u32, [i64; 3])> = c.cells.iter().copied().collect();
    let mut work: Vec<(u32, [i64; 3])> = Vec::new();
    let corners = |d: u32, ijk: [i64; 3], w: &mut Vec<(u32, [i64; 3])>| {
        for b in 0..8 {
            w.push((d, [0, 1, 2].map(|k| ijk[k] + ((b >> k) & 1) as i64)));
        }
    };
    let mut sorted = c.cells.clone();
    sorted.sort_unstable();
    for &(d, ijk) in sorted.iter().rev() {
        corners(d, ijk, &mut work);
    }
    while let Some((d, v)) = work.pop() {
        let cell = |b: usize| (d, [0, 1, 2].map(|k| v[k] - 1 + ((b >> k) & 1) as i64));
        let occ: [bool; 8] = std::array::from_fn(|b| set.contains(&cell(b)));
        let n = occ.iter().filter(|&&x| x).count();
        if n == 0 || n == 8 || (connected(&occ, true) && connected(&occ, false)) {
            continue;
        }
        // Drop the occupied cell last in order; its corners are checked again.
        let b = (0..8).rev().find(|&b| occ[b]).expect("n > 0");
        let (_, ijk) = cell(b);
        set.remove(&(d, ijk));
        corners(d, ijk, &mut work);
        work.push((d, v));
    }
    c.cells.retain(|x| set.contains(x));
}

/// Whether the cells `b` with `occ[b] == want` of a 2x2x2 block are
/// face-connected (cells differing in one bit are face neighbours).
fn connected(occ: &[bool; 8], want: bool) -> bool {
    let Some(s) = (0..8).find(|&b| occ[b] == want) else {
        return true;
    };
    let mut seen = [false; 8];
    seen[s] = true;
    let mut stack = vec![s];
    while let Some(b) = stack.pop() {
        for k in 0..3 {
            let nb = b ^ (1 << k);
            if occ[nb] == want && !seen[nb] {
                seen[nb] = true;
                stack.push(nb);
            }
        }
    }
    (0..8).all(|b| occ[b] != want || seen[b])
}

/// Drops the face-connected blocks of fewer than `min` cells.
fn drop_small(c: &mut Cells, min: usize) {
    let index: FxHashMap<(u32, [i64; 3]), usize> =
        c.cells.iter().enumerate().map(|(i, &x)| (x, i)).collect();
    let mut comp = vec![usize::MAX; c.cells.len()];
    let mut keep = vec![false; c.cells.len()];
    for s in 0..c.cells.len() {
        if comp[s] != usize::MAX {
            continue;
        }
        comp[s] = s;
        let mut list = vec![s];
        let mut i = 0;
        while i < list.len() {
            let (d, ijk) = c.cells[list[i]];
            i += 1;
            for k in 0..3 {
                for dx in [-1, 1] {
                    let mut n = ijk;
                    n[k] += dx;
                    if let Some(&j) = index.get(&(d, n)) {
                        if comp[j] == usize::MAX {
                            comp[j] = s;
                            list.push(j);
                        }
                    }
                }
            }
        }
        if list.len() >= min {
            for j in list {
                keep[j] = true;
            }
        }
    }
    let mut i = 0;
    c.cells.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

#[cfg(test)]
pub(crate) fn connected_for_tests(occ: &[bool; 8]) -> bool {
    connected(occ, true) && connected(occ, false)
}
