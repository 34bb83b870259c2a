//! Test surfaces generated in code.
#![allow(dead_code)]
use parafront_surface::Surface;

/// Unit icosphere (outward triangles), `level` midpoint subdivisions.
/// The shared generator, centred at the origin.
pub fn icosphere(level: u32, radius: f64) -> Surface {
    parafront_surface::generate::icosphere([0.0; 3], radius, level)
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
