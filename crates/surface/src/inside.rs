//! Whether a point lies inside a closed surface: the parity of exact
//! crossings along a ray in +x, over the triangles binned by their y-z
//! box. The lattice keeps its cells inside with it, and the pipeline
//! estimates a run's tet count.
use parafront_geom::intersect::segment_triangle_parity;
use parafront_geom::P3;

/// A point-in-surface test over a closed triangulation.
pub struct Inside<'a> {
    points: &'a [P3],
    faces: &'a [[u32; 3]],
    lo: [f64; 2],
    cell: [f64; 2],
    n: usize,
    bins: Vec<Vec<u32>>,
    xmax: f64,
}

impl<'a> Inside<'a> {
    /// The test for the closed surface `faces` over `points`.
    pub fn new(points: &'a [P3], faces: &'a [[u32; 3]]) -> Inside<'a> {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut xmax = f64::NEG_INFINITY;
        for f in faces {
            for &v in f {
                let p = points[v as usize];
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k + 1]);
                    hi[k] = hi[k].max(p[k + 1]);
                }
                xmax = xmax.max(p[0]);
            }
        }
        let n = ((faces.len() as f64 / 4.0).sqrt().ceil() as usize).clamp(1, 1024);
        let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / n as f64).max(f64::MIN_POSITIVE));
        let mut s = Inside {
            points,
            faces,
            lo,
            cell,
            n,
            bins: vec![Vec::new(); n * n],
            xmax,
        };
        for (fi, f) in faces.iter().enumerate() {
            let mut a = [f64::INFINITY; 2];
            let mut b = [f64::NEG_INFINITY; 2];
            for &v in f {
                let p = points[v as usize];
                for k in 0..2 {
                    a[k] = a[k].min(p[k + 1]);
                    b[k] = b[k].max(p[k + 1]);
                }
            }
            let (i0, j0) = (s.bin(a[0], 0), s.bin(a[1], 1));
            let (i1, j1) = (s.bin(b[0], 0), s.bin(b[1], 1));
            for i in i0..=i1 {
                for j in j0..=j1 {
                    s.bins[i * n + j].push(fi as u32);
                }
            }
        }
        s
    }

    fn bin(&self, x: f64, k: usize) -> usize {
        (((x - self.lo[k]) / self.cell[k]).floor().max(0.0) as usize).min(self.n - 1)
    }

    /// `Some(inside)`, or `None` when the ray from `p` touches an edge or
    /// a corner (ask again from another point).
    pub fn at(&self, p: P3) -> Option<bool> {
        if !(p[1] >= self.lo[0] && p[2] >= self.lo[1]) {
            return Some(false);
        }
        let (i, j) = (self.bin(p[1], 0), self.bin(p[2], 1));
        let q = [self.xmax.max(p[0]) + 1.0 + self.xmax.abs(), p[1], p[2]];
        let mut odd = false;
        for &f in &self.bins[i * self.n + j] {
            let [a, b, c] = self.faces[f as usize].map(|v| self.points[v as usize]);
            if a[0].max(b[0]).max(c[0]) < p[0] {
                continue;
            }
            if segment_triangle_parity(p, q, a, b, c)? {
                odd = !odd;
            }
        }
        Some(odd)
    }
}
