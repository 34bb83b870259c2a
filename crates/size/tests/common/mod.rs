//! Test surfaces generated in code.
#![allow(dead_code)]
use parafront_surface::Surface;
use std::collections::HashMap;

/// Unit icosphere (outward triangles), `level` midpoint subdivisions.
pub fn icosphere(level: u32, radius: f64) -> Surface {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pts: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(tris.len() * 4);
        for tri in &tris {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *mid.entry(key).or_insert_with(|| {
                    let (pa, pb) = (pts[a as usize], pts[b as usize]);
                    pts.push([
                        (pa[0] + pb[0]) / 2.0,
                        (pa[1] + pb[1]) / 2.0,
                        (pa[2] + pb[2]) / 2.0,
                    ]);
                    (pts.len() - 1) as u32
                });
            }
            next.push([tri[0], m[0], m[2]]);
            next.push([tri[1], m[1], m[0]]);
            next.push([tri[2], m[2], m[1]]);
            next.push([m[0], m[1], m[2]]);
        }
        tris = next;
    }
    for p in &mut pts {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = [p[0] / n * radius, p[1] / n * radius, p[2] / n * radius];
    }
    let patch = vec![0; tris.len()];
    Surface {
        points: pts,
        tris,
        patch,
        patch_names: vec![],
    }
}

/// Torus (major radius `r1`, minor `r2`) with `nu x nv` points; patch 1 on
/// the outer half (cos v > 0), 0 elsewhere.
pub fn torus(nu: usize, nv: usize, r1: f64, r2: f64) -> Surface {
    let mut points = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = i as f64 / nu as f64 * std::f64::consts::TAU;
        for j in 0..nv {
            let v = j as f64 / nv as f64 * std::f64::consts::TAU;
            let r = r1 + r2 * v.cos();
            points.push([r * u.cos(), r * u.sin(), r2 * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut tris = Vec::new();
    let mut patch = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
            let v = (j as f64 + 0.5) / nv as f64 * std::f64::consts::TAU;
            let tag = if v.cos() > 0.0 { 1 } else { 0 };
            patch.push(tag);
            patch.push(tag);
        }
    }
    Surface {
        points,
        tris,
        patch,
        patch_names: vec![],
    }
}

/// Small deterministic PRNG (xorshift*), so tests need no extra crate.
pub struct Rng(pub u64);
impl Rng {
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545F4914F6CDD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn in_box(&mut self, lo: f64, hi: f64) -> [f64; 3] {
        [0, 1, 2].map(|_| lo + (hi - lo) * self.next_f64())
    }
}
