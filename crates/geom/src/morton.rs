//! Morton (Z-order) keys: points close along the curve are close in space.
use crate::P3;

/// The Morton key of `p` in the cube of edge `ext` from corner `lo`: 20
/// bits per axis, interleaved from the highest; points outside are
/// clamped to the cube.
#[inline]
pub fn morton_key(p: P3, lo: P3, ext: f64) -> u64 {
    let q = [0, 1, 2].map(|d| (((p[d] - lo[d]) / ext * 1_048_575.0) as u64).min(1_048_575));
    let mut k = 0u64;
    for bit in (0..20).rev() {
        for &c in &q {
            k = (k << 1) | ((c >> bit) & 1);
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_the_z_curve() {
        let lo = [0.0; 3];
        // One octant after another, z fastest, x slowest.
        let k = |p| morton_key(p, lo, 1.0);
        assert!(k([0.1, 0.1, 0.1]) < k([0.1, 0.1, 0.6]));
        assert!(k([0.1, 0.1, 0.6]) < k([0.1, 0.6, 0.1]));
        assert!(k([0.1, 0.6, 0.1]) < k([0.6, 0.1, 0.1]));
        assert!(k([0.4, 0.4, 0.4]) < k([0.6, 0.1, 0.1]));
        assert_eq!(k([-1.0, -1.0, -1.0]), 0);
        assert_eq!(k([2.0, 2.0, 2.0]), (1u64 << 60) - 1);
    }
}
