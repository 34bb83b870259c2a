//! Sources (paper AG1): `h0` within `r0` of a point, segment, sphere shell or
//! box, then linear growth `h0 + (growth - 1) * (d - r0)`.
use crate::{SizeField, SourceSpec};
use parafront_geom::{dist, dot, sub, P3};

#[derive(Clone, Debug)]
enum Shape {
    Point(P3),
    /// a, b - a, |b - a|^2
    Segment(P3, P3, f64),
    Sphere(P3, f64),
    Box(P3, P3),
}

/// One source, ready to evaluate (a few flops, no allocation).
#[derive(Clone, Debug)]
pub struct Source {
    shape: Shape,
    h0: f64,
    r0: f64,
    slope: f64,
}

impl Source {
    /// `gradation` is used when the spec gives no `growth`. The spec is
    /// assumed validated (`SizeOptions::validate`).
    pub fn new(spec: &SourceSpec, gradation: f64) -> Source {
        let (h0, r0, growth) = spec.params();
        let shape = match *spec {
            SourceSpec::Point { center, .. } => Shape::Point(center),
            SourceSpec::Segment { a, b, .. } => {
                let ab = sub(b, a);
                Shape::Segment(a, ab, dot(ab, ab))
            }
            SourceSpec::Sphere { center, radius, .. } => Shape::Sphere(center, radius),
            SourceSpec::Box { min, max, .. } => Shape::Box(min, max),
        };
        Source {
            shape,
            h0,
            r0,
            slope: growth.unwrap_or(gradation) - 1.0,
        }
    }

    /// Distance from `p` to the source's geometry.
    #[inline]
    pub fn distance(&self, p: P3) -> f64 {
        match self.shape {
            Shape::Point(c) => dist(p, c),
            Shape::Segment(a, ab, l2) => {
                let ap = sub(p, a);
                let t = if l2 > 0.0 {
                    (dot(ap, ab) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                dist(ap, [ab[0] * t, ab[1] * t, ab[2] * t])
            }
            Shape::Sphere(c, r) => (dist(p, c) - r).abs(),
            Shape::Box(lo, hi) => {
                let mut d2 = 0.0;
                for k in 0..3 {
                    let e = (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0);
                    d2 += e * e;
                }
                d2.sqrt()
            }
        }
    }
}

impl SizeField for Source {
    #[inline]
    fn size(&self, p: P3) -> f64 {
        self.h0 + self.slope * (self.distance(p) - self.r0).max(0.0)
    }
}
