//! Optimal space-filling tets (the paper's §2 names them as an option of
//! the scalar front): away from the surface, where the size
//! field is nearly uniform, the volume is filled directly with a
//! body-centred cubic (BCC) lattice of near-ideal tets (dihedral angles of
//! 60° and 90°, mean ratio 0.95) instead of point by point.
//!
//! [`build`] returns the lattice's tets and its outer faces; the faces
//! join the surface in the initial front, so the front meshes only the
//! layer between the surface and the lattice (and the gaps between lattice
//! blocks of different sizes). The blocks are the accepted leaves of an
//! octree: a cell is kept when no surface triangle comes within one cell
//! of it, it lies inside the region, and the size field over it is within
//! half an octave of the cell's own size; each level is twice the size of
//! the one below. Cells next to a coarser block are dropped, so blocks of
//! different sizes never touch, and cells that would meet their level's
//! block at an edge or a corner only are dropped, so each block's boundary
//! is a manifold surface.
#![forbid(unsafe_code)]
#![warn(missing_docs)]
mod bcc;
mod octree;

pub use bcc::{Lattice, LatticeCheckError};

use parafront_geom::P3;

/// Edge of the BCC cube whose tets have the volume of a regular tet of
/// edge `h`: `s^3 / 12 = h^3 / (6 sqrt 2)`, so `s = 2^(1/6) h`. The tets'
/// edges are then `1.12 h` (two) and `0.97 h` (four).
pub const CUBE_PER_SIZE: f64 = 1.122_462_048_309_373;

/// Bounds on the lattice.
#[derive(Clone, Debug)]
pub struct LatticeOptions {
    /// Clearance between the lattice and the surface, in cells of the
    /// block's own size. Half a cell (about half a tet's height, more where
    /// the triangles' boxes are larger than they) against one: sphere_1e6
    /// at --size 0.037 goes from 57 % to 65 % lattice, 7.2 to 6.4 s, min
    /// dihedral 23.3° to 24.5°; torus_1e6 at 0.032 from 38 % to 47 %.
    pub margin: f64,
    /// Blocks are not made of fewer cells than this (a smaller block saves
    /// the front nothing).
    pub min_cells: usize,
}

impl Default for LatticeOptions {
    fn default() -> Self {
        LatticeOptions {
            margin: 0.5,
            min_cells: 8,
        }
    }
}

/// The lattice inside the closed surface `faces` (triangles of `points`,
/// a region's boundary, voids included), sized by `size`; `point_size`
/// is the size at each point (AG3). Empty when no cell qualifies.
pub fn build(
    points: &[P3],
    point_size: &[f64],
    faces: &[[u32; 3]],
    size: &(dyn Fn(P3) -> f64 + Sync),
    opts: &LatticeOptions,
) -> Lattice {
    let t0 = std::time::Instant::now();
    let cells = octree::blocks(points, point_size, faces, size, opts);
    let t1 = t0.elapsed().as_secs_f64();
    let l = bcc::tetrahedralize(&cells);
    tracing::debug!(
        cells = cells.cells.len(),
        blocks_s = t1,
        tets_s = t0.elapsed().as_secs_f64() - t1,
        "lattice built"
    );
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed box `[0,a] x [0,b] x [0,c]`, split into `n^2` squares a
    /// side, normals pointing in.
    fn boxed(dims: [f64; 3], n: usize) -> (Vec<P3>, Vec<[u32; 3]>) {
        let mut pts = Vec::new();
        let mut faces = Vec::new();
        let mut id = rustc_hash::FxHashMap::default();
        for a in 0..3 {
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            for side in [0usize, 1] {
                let mut q = |i: usize, j: usize| -> u32 {
                    let mut g = [0usize; 3];
                    g[a] = side * n;
                    g[u] = i;
                    g[v] = j;
                    *id.entry(g).or_insert_with(|| {
                        pts.push([0, 1, 2].map(|k| dims[k] * g[k] as f64 / n as f64));
                        (pts.len() - 1) as u32
                    })
                };
                for i in 0..n {
                    for j in 0..n {
                        let (p00, p10, p11, p01) =
                            (q(i, j), q(i + 1, j), q(i + 1, j + 1), q(i, j + 1));
                        // (u, v, a) is right-handed: u x v points along +a,
                        // into the box on side 0.
                        if side == 0 {
                            faces.push([p00, p10, p11]);
                            faces.push([p00, p11, p01]);
                        } else {
                            faces.push([p00, p11, p10]);
                            faces.push([p00, p01, p11]);
                        }
                    }
                }
            }
        }
        (pts, faces)
    }

    #[test]
    fn a_uniform_box_is_mostly_lattice() {
        let (pts, faces) = boxed([1.0, 1.0, 1.0], 10);
        let l = build(
            &pts,
            &vec![0.1; pts.len()],
            &faces,
            &|_| 0.1,
            &LatticeOptions::default(),
        );
        l.check().unwrap();
        assert!(l.cells > 100, "{}", l.cells);
        // One cell of clearance on each side of a unit box: at least the
        // inner cube of side 1 - 2 * 2 * 0.1123.
        assert!(l.volume > 0.3 && l.volume < 1.0, "{}", l.volume);
        assert!(l.interior.iter().any(|&x| x) && l.interior.iter().any(|&x| !x));
        // No lattice point within the margin of the surface.
        let s = LatticeOptions::default().margin * CUBE_PER_SIZE * 0.1;
        for p in &l.points {
            assert!(
                p.iter().all(|&x| x >= s * 0.999 && x <= 1.0 - s * 0.999),
                "{p:?}"
            );
        }
        // Near-ideal tets.
        for t in &l.tets {
            let p = t.map(|v| l.points[v as usize]);
            let q = parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]);
            assert!(q > 0.0);
        }
        // The check names what is broken.
        let mut bad = l.clone();
        bad.tets[0].swap(0, 1);
        assert!(matches!(bad.check(), Err(LatticeCheckError::Mesh(_))));
        let mut bad = l.clone();
        bad.tets.pop();
        assert!(matches!(bad.check(), Err(LatticeCheckError::Mesh(_))));
        let mut bad = l.clone();
        bad.faces.pop();
        assert!(matches!(bad.check(), Err(LatticeCheckError::Mesh(_))));
        let mut bad = l.clone();
        bad.volume *= 1.001;
        assert!(matches!(bad.check(), Err(LatticeCheckError::Volume { .. })));
    }

    #[test]
    fn a_graded_field_gives_separate_levels() {
        let (pts, faces) = boxed([4.0, 2.0, 3.0], 16);
        // Grows away from the face x = 0.
        let size = |p: P3| 0.03 + 0.1 * p[0];
        let hs: Vec<f64> = pts.iter().map(|&p| size(p)).collect();
        let cells = octree::blocks(&pts, &hs, &faces, &size, &LatticeOptions::default());
        let depths: std::collections::BTreeSet<u32> = cells.cells.iter().map(|c| c.0).collect();
        assert!(depths.len() >= 2, "{depths:?}");
        // Cells of different levels stay at least the finer side apart.
        for &(d, a) in &cells.cells {
            for &(e, b) in &cells.cells {
                if e >= d {
                    continue;
                }
                let (sa, sb) = (cells.side(d), cells.side(e));
                let (pa, pb) = (cells.corner(d, a), cells.corner(e, b));
                let gap = (0..3)
                    .map(|k| (pb[k] - (pa[k] + sa)).max(pa[k] - (pb[k] + sb)))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert!(gap >= sa * 0.999, "{d} {a:?} {e} {b:?}: {gap}");
            }
        }
        let l = bcc::tetrahedralize(&cells);
        l.check().unwrap();
    }

    #[test]
    fn nothing_outside_or_in_a_void() {
        // A box with a box-shaped void: the void's faces point into the
        // material (out of the void).
        let (mut pts, mut faces) = boxed([1.0, 1.0, 1.0], 8);
        let (vp, vf) = boxed([0.4, 0.4, 0.4], 4);
        let n = pts.len() as u32;
        pts.extend(vp.iter().map(|p| p.map(|x| x + 0.3)));
        faces.extend(vf.iter().map(|f| [f[0] + n, f[2] + n, f[1] + n]));
        let l = build(
            &pts,
            &vec![0.04; pts.len()],
            &faces,
            &|_| 0.04,
            &LatticeOptions::default(),
        );
        l.check().unwrap();
        assert!(l.cells > 0);
        let s = LatticeOptions::default().margin * CUBE_PER_SIZE * 0.04;
        for p in &l.points {
            let in_void = p
                .iter()
                .all(|&x| x > 0.3 - s * 0.999 && x < 0.7 + s * 0.999);
            assert!(!in_void, "{p:?}");
        }
    }

    #[test]
    fn manifold_blocks() {
        let occ = [true, false, false, true, false, false, false, false];
        assert!(!octree_connected(&occ));
        let occ = [true, true, false, false, false, false, false, false];
        assert!(octree_connected(&occ));
    }

    fn octree_connected(occ: &[bool; 8]) -> bool {
        octree::connected_for_tests(occ)
    }
}
