//! Background grid (paper AG1): a coarse tet mesh with a size per node,
//! interpolated linearly (barycentric) in the tet containing the query.
//!
//! Point location: test the hint tet (the last one found by this thread, or
//! a caller's), walk up to `WALK_STEPS` tets towards the point, and if that
//! fails test the tets listed in the point's bin. Outside the grid the
//! background imposes nothing (+inf), so the other components decide.
use crate::SizeError;
use parafront_geom::{tet_volume6, P3};
use parafront_mesh::TetMesh;
use std::cell::Cell;
use std::collections::HashMap;

const WALK_STEPS: usize = 64;
/// Barycentric tolerance: a point this close outside a face still counts
/// (the interpolant is continuous, so the neighbour would give the same).
const BARY_TOL: f64 = 1e-10;
const NONE: u32 = u32::MAX;

thread_local! {
    static HINT: Cell<u32> = const { Cell::new(0) };
}

/// A background tet grid with a size at each node, interpolated linearly
/// inside each tet (AG1's background mesh).
#[derive(Clone, Debug)]
pub struct BackgroundGrid {
    points: Vec<P3>,
    tets: Vec<[u32; 4]>,
    sizes: Vec<f64>,
    /// `neigh[4t+f]`: the tet across face f (opposite vertex f), or NONE.
    neigh: Vec<u32>,
    bin_lo: P3,
    bin_inv: f64,
    dims: [usize; 3],
    /// CSR: tets whose bounding box overlaps bin b are
    /// `bin_tets[bin_start[b]..bin_start[b+1]]`.
    bin_start: Vec<u32>,
    bin_tets: Vec<u32>,
}

impl BackgroundGrid {
    /// `sizes[i]` is the size at `mesh.points[i]`. Only `points` and `tets`
    /// are used (adjacency is rebuilt here).
    pub fn new(mesh: &TetMesh, sizes: &[f64]) -> Result<BackgroundGrid, SizeError> {
        let bad = |why: String| Err(SizeError::Background { why });
        if sizes.len() != mesh.points.len() {
            return bad(format!(
                "{} sizes for {} points",
                sizes.len(),
                mesh.points.len()
            ));
        }
        if mesh.tets.is_empty() {
            return bad("the grid has no tets".into());
        }
        if mesh.tets.len() >= (u32::MAX / 4) as usize {
            return bad(format!("too many tets ({})", mesh.tets.len()));
        }
        for (i, p) in mesh.points.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) {
                return bad(format!("point {i} has non-finite coordinates {p:?}"));
            }
            if !(sizes[i] > 0.0 && sizes[i].is_finite()) {
                return bad(format!(
                    "size at point {i} is {}, must be finite and > 0",
                    sizes[i]
                ));
            }
        }
        let np = mesh.points.len();
        let mut tets = Vec::with_capacity(mesh.tets.len());
        for (t, tet) in mesh.tets.iter().enumerate() {
            let v = tet.map(|p| p.raw());
            if let Some(x) = v.iter().find(|&&x| x as usize >= np) {
                return bad(format!(
                    "tet {t} refers to point {x}, but there are {np} points"
                ));
            }
            tets.push(v);
        }
        let neigh = adjacency(&tets);
        let mut g = BackgroundGrid {
            points: mesh.points.clone(),
            tets,
            sizes: sizes.to_vec(),
            neigh,
            bin_lo: [0.0; 3],
            bin_inv: 1.0,
            dims: [1; 3],
            bin_start: Vec::new(),
            bin_tets: Vec::new(),
        };
        g.build_bins();
        Ok(g)
    }

    fn tet_box(&self, t: usize) -> (P3, P3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &v in &self.tets[t] {
            let p = self.points[v as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    fn build_bins(&mut self) {
        let bb = parafront_geom::Aabb::from_points(&self.points);
        let ext: Vec<f64> = (0..3).map(|k| (bb.max[k] - bb.min[k]).max(0.0)).collect();
        let vol = ext.iter().map(|e| e.max(1e-300)).product::<f64>();
        // About one bin per tet; fewer if long tets would fill too many bins.
        let mut target = (self.tets.len() as f64).clamp(1.0, (1 << 22) as f64);
        loop {
            let mut side = (vol / target).cbrt();
            let emax = ext.iter().cloned().fold(0.0, f64::max);
            if !(side > 0.0 && side.is_finite()) {
                side = emax.max(1.0);
            }
            side = side.max(emax / 256.0).max(f64::MIN_POSITIVE);
            let mut dims = [0, 1, 2].map(|k| ((ext[k] / side) as usize + 1).min(1024));
            // Flat grids: vol/target understates the bin side.
            while dims.iter().product::<usize>() > 1 << 22 {
                side *= 1.25;
                dims = [0, 1, 2].map(|k| ((ext[k] / side) as usize + 1).min(1024));
            }
            self.bin_lo = bb.min;
            self.bin_inv = 1.0 / side;
            self.dims = dims;
            let nb = dims[0] * dims[1] * dims[2];
            let mut count = vec![0u32; nb + 1];
            let mut total = 0usize;
            for t in 0..self.tets.len() {
                let (r0, r1) = self.bin_range(t);
                total += (r1[0] - r0[0] + 1) * (r1[1] - r0[1] + 1) * (r1[2] - r0[2] + 1);
            }
            if total > 64 * self.tets.len() + 4096 && target > 1.0 {
                target /= 8.0;
                continue;
            }
            for t in 0..self.tets.len() {
                let (r0, r1) = self.bin_range(t);
                for i in r0[0]..=r1[0] {
                    for j in r0[1]..=r1[1] {
                        for k in r0[2]..=r1[2] {
                            count[self.bin_id([i, j, k]) + 1] += 1;
                        }
                    }
                }
            }
            for b in 0..nb {
                count[b + 1] += count[b];
            }
            let mut fill = count.clone();
            let mut bt = vec![0u32; total];
            for t in 0..self.tets.len() {
                let (r0, r1) = self.bin_range(t);
                for i in r0[0]..=r1[0] {
                    for j in r0[1]..=r1[1] {
                        for k in r0[2]..=r1[2] {
                            let b = self.bin_id([i, j, k]);
                            bt[fill[b] as usize] = t as u32;
                            fill[b] += 1;
                        }
                    }
                }
            }
            self.bin_start = count;
            self.bin_tets = bt;
            return;
        }
    }

    #[inline]
    fn bin_of(&self, p: P3) -> [usize; 3] {
        [0, 1, 2].map(|k| {
            let x = ((p[k] - self.bin_lo[k]) * self.bin_inv).floor();
            (x.max(0.0) as usize).min(self.dims[k] - 1)
        })
    }
    #[inline]
    fn bin_id(&self, b: [usize; 3]) -> usize {
        (b[2] * self.dims[1] + b[1]) * self.dims[0] + b[0]
    }
    fn bin_range(&self, t: usize) -> ([usize; 3], [usize; 3]) {
        let (lo, hi) = self.tet_box(t);
        (self.bin_of(lo), self.bin_of(hi))
    }

    /// Barycentric coordinates of `p` in tet `t` (coordinate f belongs to
    /// vertex f), or None for a flat tet.
    #[inline]
    fn bary(&self, t: usize, p: P3) -> Option<[f64; 4]> {
        let [a, b, c, d] = self.tets[t].map(|v| self.points[v as usize]);
        let v = tet_volume6(a, b, c, d);
        if v == 0.0 || !v.is_finite() {
            return None;
        }
        let inv = 1.0 / v;
        Some([
            tet_volume6(p, b, c, d) * inv,
            tet_volume6(a, p, c, d) * inv,
            tet_volume6(a, b, p, d) * inv,
            tet_volume6(a, b, c, p) * inv,
        ])
    }

    #[inline]
    fn interp(&self, t: usize, l: [f64; 4]) -> f64 {
        let s = self.tets[t].map(|v| self.sizes[v as usize]);
        l[0] * s[0] + l[1] * s[1] + l[2] * s[2] + l[3] * s[3]
    }

    /// The tet containing `p`, starting the search at `*hint` (updated).
    pub fn locate(&self, p: P3, hint: &mut u32) -> Option<(usize, [f64; 4])> {
        let mut t = if (*hint as usize) < self.tets.len() {
            *hint as usize
        } else {
            0
        };
        for _ in 0..WALK_STEPS {
            let Some(l) = self.bary(t, p) else { break };
            let (f, lmin) = (0..4)
                .map(|f| (f, l[f]))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((0, 0.0));
            if lmin >= -BARY_TOL {
                *hint = t as u32;
                return Some((t, l));
            }
            let n = self.neigh[4 * t + f];
            if n == NONE {
                break;
            }
            t = n as usize;
        }
        let b = self.bin_id(self.bin_of(p));
        for &t in &self.bin_tets[self.bin_start[b] as usize..self.bin_start[b + 1] as usize] {
            if let Some(l) = self.bary(t as usize, p) {
                if l.iter().all(|&x| x >= -BARY_TOL) {
                    *hint = t;
                    return Some((t as usize, l));
                }
            }
        }
        None
    }

    /// Interpolated size, or None outside the grid.
    pub fn size_with(&self, p: P3, hint: &mut u32) -> Option<f64> {
        self.locate(p, hint).map(|(t, l)| self.interp(t, l))
    }
}

impl crate::SizeField for BackgroundGrid {
    /// +inf outside the grid (not imposed).
    fn size(&self, p: P3) -> f64 {
        HINT.with(|h| {
            let mut hint = h.get();
            let r = self.size_with(p, &mut hint);
            h.set(hint);
            r.unwrap_or(f64::INFINITY)
        })
    }
}

/// Tet across each face, matching faces by their sorted point triple.
fn adjacency(tets: &[[u32; 4]]) -> Vec<u32> {
    let mut neigh = vec![NONE; 4 * tets.len()];
    let mut open: HashMap<[u32; 3], u32> = HashMap::with_capacity(2 * tets.len());
    for (t, v) in tets.iter().enumerate() {
        for f in 0..4 {
            let mut key = [v[(f + 1) % 4], v[(f + 2) % 4], v[(f + 3) % 4]];
            key.sort_unstable();
            let me = (4 * t + f) as u32;
            match open.remove(&key) {
                Some(other) => {
                    neigh[me as usize] = other / 4;
                    neigh[other as usize] = t as u32;
                }
                None => {
                    open.insert(key, me);
                }
            }
        }
    }
    neigh
}
