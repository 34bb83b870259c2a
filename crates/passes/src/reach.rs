//! Which parts a context face goes to (§7): besides the box around a
//! part's region, the cells of a coarse grid that its DDG tets meet. A
//! shifted region (passes 2 and 3) is a thin layer whose box spans much of
//! the domain: by the box alone, part 2 of sphere_5e6 at 32 parts got
//! 46,000 context points in pass 2 beside 18,000 owned faces.
use parafront_ddg::Ddg;
use parafront_geom::{Aabb, P3};

/// Per cell of a grid over the DDG's box, a bit for each part with a DDG
/// tet whose box meets the cell.
pub(crate) struct PartCells {
    grid: Grid,
    /// 64-bit words per cell.
    words: usize,
    bits: Vec<u64>,
}

/// A grid of `n` cells over a box from `min`.
struct Grid {
    min: P3,
    /// Cells per unit length, per axis.
    inv: [f64; 3],
    n: [usize; 3],
}

/// A box's reach is widened by this share of a cell on each side, so that
/// two boxes that touch meet in a cell whatever the rounding.
const SLACK: f64 = 1e-6;

impl Grid {
    /// The cells `b` meets (clamped to the grid), as cell indices.
    fn cells(&self, b: &Aabb) -> impl Iterator<Item = usize> + '_ {
        let at = |k: usize, x: f64, s: f64| {
            let c = ((x - self.min[k]) * self.inv[k] + s).floor();
            if c.is_nan() {
                0
            } else {
                c.clamp(0.0, (self.n[k] - 1) as f64) as usize
            }
        };
        let lo = [0, 1, 2].map(|k| at(k, b.min[k], -SLACK));
        let hi = [0, 1, 2].map(|k| at(k, b.max[k], SLACK));
        let n = self.n;
        (lo[0]..=hi[0]).flat_map(move |x| {
            (lo[1]..=hi[1])
                .flat_map(move |y| (lo[2]..=hi[2]).map(move |z| (x * n[1] + y) * n[2] + z))
        })
    }
}

impl PartCells {
    /// The cells of `part_of` (DDG tet -> part, `np` parts): about two DDG
    /// tets a cell, and at most 2^20 words.
    pub(crate) fn new(d: &Ddg, part_of: &[u32], np: usize) -> PartCells {
        let b = Aabb::from_points(d.points.iter());
        let words = np.div_ceil(64).max(1);
        let target = (d.tets.len() / 2).clamp(1, (1 << 20) / words) as f64;
        let ext = [0, 1, 2].map(|k| (b.max[k] - b.min[k]).max(0.0));
        let floor = 1e-3 * ext.iter().fold(0.0, |a: f64, &e| a.max(e));
        let vol: f64 = ext.iter().map(|&e| e.max(floor)).product();
        let h = (vol / target).cbrt();
        let n = ext.map(|e| {
            if e > 0.0 && h > 0.0 {
                ((e / h).ceil() as usize).clamp(1, 1024)
            } else {
                1
            }
        });
        let inv = [0, 1, 2].map(|k| {
            if ext[k] > 0.0 {
                n[k] as f64 / ext[k]
            } else {
                0.0
            }
        });
        let grid = Grid {
            min: if b.is_empty() { [0.0; 3] } else { b.min },
            inv,
            n,
        };
        let mut bits = vec![0; n[0] * n[1] * n[2] * words];
        for (t, &k) in part_of.iter().enumerate() {
            let (w, bit) = (k as usize / 64, 1u64 << (k % 64));
            for c in grid.cells(&Aabb::from_points(d.tet_points(t).iter())) {
                bits[c * words + w] |= bit;
            }
        }
        PartCells { grid, words, bits }
    }

    /// Whether box `b` meets a cell of part `k`.
    pub(crate) fn meets(&self, k: u32, b: &Aabb) -> bool {
        let (w, bit) = (k as usize / 64, 1u64 << (k % 64));
        (self.grid.cells(b)).any(|c| self.bits[c * self.words + w] & bit != 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_surface::generate;

    /// A torus's DDG split by the sign of x into parts 0 and 1, and by
    /// octant into parts 62 to 69 of 70 (two words a cell).
    #[test]
    fn every_tet_meets_its_parts_cells_and_far_boxes_miss() {
        let s = generate::torus([0.0; 3], 1.0, 0.35, 24, 12);
        let faces: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let h = s.mean_edge_lengths();
        let d = parafront_ddg::build(s.points.clone(), h, faces, parafront_ddg::DEFAULT_GROWTH)
            .unwrap();
        let centroid = |t: usize| {
            let q = d.tet_points(t);
            [0, 1, 2].map(|k| q.iter().map(|p| p[k]).sum::<f64>() / 4.0)
        };
        let octant =
            |c: P3| (c[0] > 0.0) as u32 + 2 * (c[1] > 0.0) as u32 + 4 * (c[2] > 0.0) as u32;
        for np in [2, 70] {
            let part_of: Vec<u32> = (0..d.tets.len())
                .map(|t| {
                    let c = centroid(t);
                    if np == 2 {
                        (c[0] > 0.0) as u32
                    } else {
                        69 - octant(c)
                    }
                })
                .collect();
            let pc = PartCells::new(&d, &part_of, np);
            for (t, &k) in part_of.iter().enumerate() {
                let b = Aabb::from_points(d.tet_points(t).iter());
                assert!(pc.meets(k, &b), "tet {t} misses its part {k}'s cells");
                // A point of the tet, as a box of no size.
                let p = Aabb::from_points([d.tet_points(t)[0]].iter());
                assert!(pc.meets(k, &p));
            }
            // Far on the side of x > 0, x < 0 parts have no cells; nor has
            // any part the torus's hole.
            let far = Aabb::from_points([[1.3, 0.0, 0.0], [1.31, 0.01, 0.01]].iter());
            let hole = Aabb::from_points([[-0.05, -0.05, -0.05], [0.05, 0.05, 0.05]].iter());
            for k in 0..np as u32 {
                let left = part_of
                    .iter()
                    .zip(0..)
                    .any(|(&q, t)| q == k && centroid(t)[0] < -0.5);
                if left {
                    assert!(!pc.meets(k, &far), "part {k} reaches x = 1.3");
                }
                assert!(!pc.meets(k, &hole), "part {k} reaches the hole");
            }
        }
    }
}
