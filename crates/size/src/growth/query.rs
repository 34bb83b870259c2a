//! Queries of the grown size field: a descent of the octree (or the
//! cursor's leaf when the point lies in it), then the near leaf's cones or
//! the far leaf's trilinear interpolant.
use super::{trilinear, GrowthCursor, GrowthStats, SurfaceGrowth};
use super::{IDX_MASK, KIND_SHIFT, K_INTERNAL, K_NEAR};
use parafront_geom::{dist, P3};

impl SurfaceGrowth {
    /// The field at `p`. Points outside the octree's cube (the seeds' box
    /// plus 5%) are clamped to it, which can only lower the value there.
    #[inline]
    pub fn size(&self, p: P3) -> f64 {
        let mut cur = GrowthCursor::default();
        self.size_with(p, &mut cur)
    }

    /// As [`size`](Self::size), starting from the cursor's leaf when `p` lies in it.
    #[inline]
    pub fn size_with(&self, p: P3, cur: &mut GrowthCursor) -> f64 {
        let s0 = self.root_s;
        let q = [
            p[0].clamp(self.root_lo[0], self.root_lo[0] + s0),
            p[1].clamp(self.root_lo[1], self.root_lo[1] + s0),
            p[2].clamp(self.root_lo[2], self.root_lo[2] + s0),
        ];
        let inside = |lo: &P3, s: f64| (0..3).all(|k| q[k] >= lo[k] && q[k] <= lo[k] + s);
        if cur.code == u32::MAX || !inside(&cur.lo, cur.s) {
            let mut lo = self.root_lo;
            let mut s = s0;
            let mut code = self.nodes[0];
            while code >> KIND_SHIFT == K_INTERNAL {
                s *= 0.5;
                let mut ch = 0;
                for k in 0..3 {
                    if q[k] >= lo[k] + s {
                        ch |= 1 << k;
                        lo[k] += s;
                    }
                }
                code = self.nodes[(code & IDX_MASK) as usize + ch];
            }
            *cur = GrowthCursor { code, lo, s };
        }
        let idx = (cur.code & IDX_MASK) as usize;
        if cur.code >> KIND_SHIFT == K_NEAR {
            self.near.min_over(idx, self.cap, |j| self.cone(j, q))
        } else {
            let t = [
                ((q[0] - cur.lo[0]) / cur.s).clamp(0.0, 1.0),
                ((q[1] - cur.lo[1]) / cur.s).clamp(0.0, 1.0),
                ((q[2] - cur.lo[2]) / cur.s).clamp(0.0, 1.0),
            ];
            let v = &self.far[idx];
            trilinear(v, t)
        }
    }

    /// The leaf containing `p`: (is a near leaf, its corner, its size).
    pub fn leaf_of(&self, p: P3) -> (bool, P3, f64) {
        let mut cur = GrowthCursor::default();
        self.size_with(p, &mut cur);
        (cur.code >> KIND_SHIFT == K_NEAR, cur.lo, cur.s)
    }

    /// The exact formula by brute force, O(N): for tests and checks.
    pub fn exact(&self, p: P3) -> f64 {
        self.seeds
            .iter()
            .map(|s| s.h + self.c * dist(p, s.p))
            .fold(self.cap, f64::min)
    }

    /// The growth per unit distance, `g - 1`.
    pub fn slope(&self) -> f64 {
        self.c
    }

    /// What the build made.
    pub fn stats(&self) -> &GrowthStats {
        &self.stats
    }
}
