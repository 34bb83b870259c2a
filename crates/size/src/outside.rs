//! Where the octree's cube lies outside the surface: a coarse voxel grid
//! whose voxels near a triangle are marked, flooded from the cube's border.
//! No front ever asks for a size out there, so the growth octree
//! (`growth.rs`) does not refine it.
use parafront_geom::P3;

/// Levels of the grid, at most: `2^7` voxels per side, the octree's cells
/// at that depth. A smaller surface gets a coarser grid, about 32 voxels
/// per triangle (at least `2^4` per side): 128^3 took 30 ms, the whole run
/// of a twisted prism 10.
const MAX_LEVELS: usize = 7;
const MIN_LEVELS: usize = 4;

/// The voxels reached from the cube's border without meeting a triangle's
/// box (grown by a voxel), and above them a pyramid: a cell of the octree
/// at depth `d` lies outside when its cell at level `min(d, levels)` does.
pub(crate) struct Outside {
    lo: P3,
    s: f64,
    levels: usize,
    /// `out[d]`: the `(2^d)^3` cells at depth `d`, each wholly outside.
    out: Vec<Vec<bool>>,
}

impl Outside {
    /// The grid over the cube `[lo, lo + s]` and the surface `tris` of
    /// `points`; `None` for a surface with no triangles.
    pub(crate) fn new(lo: P3, s: f64, points: &[P3], tris: &[[u32; 3]]) -> Option<Outside> {
        if tris.is_empty() || !(s > 0.0) {
            return None;
        }
        let want = (32.0 * tris.len() as f64).cbrt().log2().ceil() as usize;
        let levels = want.clamp(MIN_LEVELS, MAX_LEVELS);
        let n_side = 1usize << levels;
        let vs = s / n_side as f64;
        let cell = |x: f64, k: usize| -> usize {
            let c = ((x - lo[k]) / vs).floor();
            if c.is_nan() || c < 0.0 {
                0
            } else {
                (c as usize).min(n_side - 1)
            }
        };
        let idx = |i: usize, j: usize, k: usize| (i * n_side + j) * n_side + k;
        // A triangle's box, grown by one voxel on each side: float rounding
        // in `cell` can never leave a voxel it meets unmarked.
        let mut near = vec![false; n_side * n_side * n_side];
        for t in tris {
            let p = t.map(|v| points[v as usize]);
            let mut a = [0usize; 3];
            let mut b = [0usize; 3];
            for k in 0..3 {
                let mn = p[0][k].min(p[1][k]).min(p[2][k]);
                let mx = p[0][k].max(p[1][k]).max(p[2][k]);
                a[k] = cell(mn, k).saturating_sub(1);
                b[k] = (cell(mx, k) + 1).min(n_side - 1);
            }
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        near[idx(i, j, k)] = true;
                    }
                }
            }
        }
        // Flood from the border through voxels no triangle is near.
        let mut out = vec![false; n_side * n_side * n_side];
        let mut stack = Vec::new();
        for i in 0..n_side {
            for j in 0..n_side {
                for k in 0..n_side {
                    let border = [i, j, k].iter().any(|&c| c == 0 || c == n_side - 1);
                    let v = idx(i, j, k);
                    if border && !near[v] && !out[v] {
                        out[v] = true;
                        stack.push((i, j, k));
                    }
                }
            }
        }
        while let Some((i, j, k)) = stack.pop() {
            let c = [i, j, k];
            for d in 0..3 {
                for up in [false, true] {
                    let mut n = c;
                    if up {
                        if n[d] + 1 >= n_side {
                            continue;
                        }
                        n[d] += 1;
                    } else {
                        if n[d] == 0 {
                            continue;
                        }
                        n[d] -= 1;
                    }
                    let v = idx(n[0], n[1], n[2]);
                    if !near[v] && !out[v] {
                        out[v] = true;
                        stack.push((n[0], n[1], n[2]));
                    }
                }
            }
        }
        let mut pyramid = vec![out];
        for d in (0..levels).rev() {
            let n = 1usize << d;
            let up = &pyramid[pyramid.len() - 1];
            let mut cur = vec![false; n * n * n];
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let c = |a: usize, b: usize, e: usize| {
                            up[((2 * i + a) * 2 * n + 2 * j + b) * 2 * n + 2 * k + e]
                        };
                        cur[(i * n + j) * n + k] =
                            (0..8).all(|ch| c(ch & 1, (ch >> 1) & 1, ch >> 2));
                    }
                }
            }
            pyramid.push(cur);
        }
        pyramid.reverse();
        Some(Outside {
            lo,
            s,
            levels,
            out: pyramid,
        })
    }

    /// Whether the octree's cell at depth `depth` around `centre` lies
    /// wholly outside.
    pub(crate) fn holds(&self, centre: P3, depth: u32) -> bool {
        let d = (depth as usize).min(self.levels);
        let n = 1usize << d;
        let cs = self.s / n as f64;
        let mut c = [0usize; 3];
        for k in 0..3 {
            let x = ((centre[k] - self.lo[k]) / cs).floor();
            if !(x >= 0.0 && x < n as f64) {
                return false;
            }
            c[k] = x as usize;
        }
        self.out[d][(c[0] * n + c[1]) * n + c[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box surface `[1, 3]^3` (12 triangles) in the cube `[0, 4]^3`.
    fn cube() -> (Vec<P3>, Vec<[u32; 3]>) {
        let s = parafront_surface::generate::voxels([1.0; 3], 2.0, [1, 1, 1], |_, _, _| true);
        assert_eq!(s.tris.len(), 12);
        (s.points, s.tris)
    }

    #[test]
    fn cells_outside_the_surface_and_not_near_it() {
        let (pts, tris) = cube();
        let o = Outside::new([0.0; 3], 4.0, &pts, &tris).unwrap();
        // Cells in the cube's corners, away from the surface: outside.
        assert!(o.holds([0.25, 0.25, 0.25], 3));
        assert!(o.holds([3.75, 3.75, 0.25], 3));
        assert!(o.holds([0.01, 0.01, 0.01], 12));
        // The cube, a cell holding the surface, one inside it (enclosed,
        // never flooded), one on it, or past the grid: not outside.
        assert!(!o.holds([2.0, 2.0, 2.0], 0));
        assert!(!o.holds([1.0, 1.0, 1.0], 1));
        assert!(!o.holds([2.0625, 2.0625, 2.0625], 5));
        assert!(!o.holds([1.0625, 2.0625, 2.0625], 5));
        assert!(!o.holds([4.1, 2.0, 2.0], 9));
        // Just outside a face but within a voxel of it: kept (the grown
        // boxes).
        assert!(!o.holds([3.01, 2.0, 2.0], 10));
    }

    #[test]
    fn no_triangles_no_grid() {
        assert!(Outside::new([0.0; 3], 1.0, &[], &[]).is_none());
    }
}
