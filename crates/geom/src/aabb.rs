//! Axis-aligned bounding boxes.
use crate::P3;

/// An axis-aligned box, closed on every side; [`Aabb::EMPTY`] (min above max)
/// stands for the box that holds nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The lowest corner, per axis.
    pub min: P3,
    /// The highest corner, per axis.
    pub max: P3,
}

impl Aabb {
    /// The empty box: grows to the first point added.
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// The smallest box holding every point given; [`Aabb::EMPTY`] for none.
    pub fn from_points<'a>(pts: impl IntoIterator<Item = &'a P3>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in pts {
            b.grow(*p);
        }
        b
    }
    /// Widens the box to hold `p`.
    #[inline]
    pub fn grow(&mut self, p: P3) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }
    /// The smallest box holding both boxes.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        let mut b = *self;
        for k in 0..3 {
            b.min[k] = b.min[k].min(o.min[k]);
            b.max[k] = b.max[k].max(o.max[k]);
        }
        b
    }
    /// Whether the two closed boxes share a point (touching counts).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] <= o.max[k] && o.min[k] <= self.max[k])
    }
    /// `overlaps` without a branch: for scans whose answers mix.
    #[inline(always)]
    pub fn overlaps_nb(&self, o: &Aabb) -> bool {
        let mut r = true;
        for k in 0..3 {
            r &= (self.min[k] <= o.max[k]) & (o.min[k] <= self.max[k]);
        }
        r
    }
    /// Whether `p` lies in the closed box.
    #[inline]
    pub fn contains(&self, p: P3) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }
    /// Whether the box holds no point, as [`Aabb::EMPTY`] does until a point is
    /// added. Only the x extent is tested: `grow` and `union` leave a box empty
    /// on every axis or on none.
    pub fn is_empty(&self) -> bool {
        self.min[0] > self.max[0]
    }
    /// The length of the box's diagonal, 0 for the empty box.
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            crate::vec3::dist(self.min, self.max)
        }
    }
    /// The midpoint of the box (not meaningful for the empty box).
    pub fn center(&self) -> P3 {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }
    /// The axis of largest extent (the last one on a tie).
    pub fn longest_axis(&self) -> usize {
        (0..3)
            .max_by(|&a, &b| (self.max[a] - self.min[a]).total_cmp(&(self.max[b] - self.min[b])))
            .unwrap()
    }
    /// Grown by `d` on every side.
    pub fn inflated(&self, d: f64) -> Aabb {
        Aabb {
            min: [self.min[0] - d, self.min[1] - d, self.min[2] - d],
            max: [self.max[0] + d, self.max[1] + d, self.max[2] + d],
        }
    }
}
