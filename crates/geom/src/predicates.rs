//! Exact orientation predicates (Shewchuk's adaptive arithmetic via `robust`).
//!
//! Convention used throughout parafront: `orient3d(a, b, c, d) > 0` exactly
//! when tet `abcd` has positive volume, i.e. `d` lies on the side of triangle
//! `abc` that its right-hand normal `(b-a)x(c-a)` points to. This is the
//! negative of Shewchuk's sign, which is why every call goes through here.
use crate::P3;
use robust::{Coord, Coord3D};

/// The sign of a predicate's value, for callers that branch three ways.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sign {
    /// Strictly below zero.
    Negative,
    /// Exactly zero: the points are degenerate (coplanar, cospherical, ...).
    Zero,
    /// Strictly above zero.
    Positive,
}

impl Sign {
    /// The sign of `x`; NaN maps to [`Sign::Zero`].
    #[inline(always)]
    pub fn of(x: f64) -> Sign {
        if x > 0.0 {
            Sign::Positive
        } else if x < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }
}

#[inline(always)]
fn c3(p: P3) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Positive when `e` lies strictly inside the sphere through the corners of
/// the positively oriented tet `abcd` (parafront's convention), negative
/// outside, zero on it. Exact.
#[inline]
pub fn in_sphere(a: P3, b: P3, c: P3, d: P3, e: P3) -> f64 {
    // `robust` wants Shewchuk's positive orientation, parafront's negative:
    // swapping two corners turns one into the other.
    robust::insphere(c3(b), c3(a), c3(c), c3(d), c3(e))
}

/// Exact sign of six times the volume of tet `abcd` (positive = right-handed).
/// The value is not the volume; only its sign is exact.
#[inline]
pub fn orient3d(a: P3, b: P3, c: P3, d: P3) -> f64 {
    -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// The exact sign of [`orient3d`]: positive when tet `abcd` is right-handed
/// (positive volume), zero when the four points are coplanar.
#[inline]
pub fn orient3d_sign(a: P3, b: P3, c: P3, d: P3) -> Sign {
    Sign::of(orient3d(a, b, c, d))
}

/// Exact 2D orientation: positive when `abc` turns counter-clockwise.
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    robust::orient2d(
        Coord { x: a[0], y: a[1] },
        Coord { x: b[0], y: b[1] },
        Coord { x: c[0], y: c[1] },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_tet_is_positive() {
        let o = [0.0, 0.0, 0.0];
        let x = [1.0, 0.0, 0.0];
        let y = [0.0, 1.0, 0.0];
        let z = [0.0, 0.0, 1.0];
        assert_eq!(orient3d_sign(o, x, y, z), Sign::Positive);
        assert_eq!(orient3d_sign(o, y, x, z), Sign::Negative);
        assert_eq!(orient3d_sign(o, x, y, [0.3, 0.3, 0.0]), Sign::Zero);
        assert!(crate::tet_volume6(o, x, y, z) > 0.0);
    }

    #[test]
    fn exact_on_nearly_coplanar_points() {
        // A float determinant gets this wrong; the exact one sees it is coplanar.
        let a = [0.1, 0.1, 0.1];
        let b = [0.2, 0.2, 0.2];
        let c = [0.3, 0.7, 0.3];
        let d = [0.5, 1.1, 0.5];
        assert_eq!(orient3d_sign(a, b, c, d), Sign::Zero);
        assert!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]) > 0.0);
    }
}
