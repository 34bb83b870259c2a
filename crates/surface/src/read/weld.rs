//! Exact welding of triangle-soup corners (STL).
//!
//! Corners merge only when all three coordinates are bit-identical (after
//! -0.0 -> 0.0). Never a tolerance: CAD files have real edges shorter than
//! any tolerance one could pick. Sorting rather than hashing keeps the
//! worst case O(n log n) whatever the input.

use parafront_geom::P3;
use rayon::slice::ParallelSliceMut;

fn key(p: &P3) -> [u64; 3] {
    // -0.0 == 0.0, but their bits differ.
    p.map(|x| if x == 0.0 { 0 } else { x.to_bits() })
}

/// Merges identical corners; `corners.len()` must be a multiple of 3 and
/// below 2^32. Points come out in order of first appearance.
pub(crate) fn weld(corners: &[P3]) -> (Vec<P3>, Vec<[u32; 3]>) {
    let m = corners.len();
    debug_assert!(m <= u32::MAX as usize);
    // (key, index) pairs sorted in place: contiguous, so cache-friendly.
    // Ties broken by index: each group starts with its first corner.
    let mut order: Vec<([u64; 3], u32)> = corners
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i as u32))
        .collect();
    order.par_sort_unstable();
    let mut rep = vec![0u32; m];
    for g in order.chunk_by(|a, b| a.0 == b.0) {
        for &(_, i) in g {
            rep[i as usize] = g[0].1;
        }
    }
    drop(order);
    // Number the groups in order of their first corner.
    let mut id = vec![u32::MAX; m];
    let mut points = Vec::new();
    for i in 0..m {
        let r = rep[i] as usize;
        if r == i {
            id[i] = points.len() as u32;
            points.push(corners[i].map(|x| if x == 0.0 { 0.0 } else { x }));
        } else {
            id[i] = id[r];
        }
    }
    let tris = id.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    (points, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merges_exact_duplicates_only() {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-0.0, 0.0, 0.0],               // same as corner 0
            [0.0, 1.0, 0.0],                // same as corner 2
            [1.0 + f64::EPSILON, 0.0, 0.0], // distinct from corner 1
        ];
        let (p, t) = weld(&c);
        assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(p.len(), 4);
        assert_eq!(p[3], [1.0 + f64::EPSILON, 0.0, 0.0]);
        assert!(p[0][0].is_sign_positive());
    }
}
