//! Structured box meshes for tests and demos: each grid cell split into six
//! tets around its main diagonal (Kuhn subdivision). All cells use the same
//! split, so the face diagonals agree between neighbours and the mesh is
//! conforming.
use crate::ids::*;
use crate::tetmesh::TetMesh;
use parafront_geom::P3;

/// Patch tag of the interface triangles in [`box_mesh_two_regions`].
pub const INTERFACE_PATCH: u32 = 6;

/// Kuhn tets of the unit cube, corners numbered `x + 2y + 4z`. Each is the
/// path 0 -> e_a -> e_a + e_b -> 7 for an axis permutation (a, b, c); odd
/// permutations have their middle vertices swapped to stay positive.
const KUHN: [[usize; 4]; 6] = [
    [0, 1, 3, 7], // x y z
    [0, 2, 6, 7], // y z x
    [0, 4, 5, 7], // z x y
    [0, 5, 1, 7], // x z y (odd)
    [0, 3, 2, 7], // y x z (odd)
    [0, 6, 4, 7], // z y x (odd)
];

/// An `nx` x `ny` x `nz` cell box from `min` to `max`, `6 nx ny nz` tets,
/// region 0, adjacency built, `bnd_tris` outward with `bnd_patch` the box
/// side: 0 x=min, 1 x=max, 2 y=min, 3 y=max, 4 z=min, 5 z=max.
///
/// Panics when a count is 0, the tets would overflow the `u32` ids, or
/// `min < max` fails on an axis (this is a generator for tests, not for
/// user input).
pub fn box_mesh(nx: usize, ny: usize, nz: usize, min: P3, max: P3) -> TetMesh {
    box_mesh_two_regions(nx, ny, nz, min, max, nx)
}

/// [`box_mesh`] with two regions: cells with x index below `split` are
/// region 0, the rest region 1. The interface triangles are added to
/// `bnd_tris` with patch [`INTERFACE_PATCH`], oriented out of region 0.
/// `split` = 0 or `nx` gives one region (1 or 0) and no interface.
pub fn box_mesh_two_regions(
    nx: usize,
    ny: usize,
    nz: usize,
    min: P3,
    max: P3,
    split: usize,
) -> TetMesh {
    assert!(
        nx > 0 && ny > 0 && nz > 0,
        "box_mesh needs at least one cell per axis"
    );
    assert!(
        (0..3).all(|k| min[k] < max[k]),
        "box_mesh needs min < max on every axis"
    );
    let ncell = nx
        .checked_mul(ny)
        .and_then(|n| n.checked_mul(nz))
        .filter(|&n| n.checked_mul(6).is_some_and(|t| t <= crate::MAX_TETS))
        .expect("box_mesh: too many tets for u32 ids");
    let (px, py) = (nx + 1, ny + 1);
    let pid = |i: usize, j: usize, k: usize| PointId::new(i + px * (j + py * k));
    let coord = |i: usize, n: usize, d: usize| min[d] + (max[d] - min[d]) * (i as f64 / n as f64);

    let mut m = TetMesh::default();
    m.points.reserve(px * py * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                m.points
                    .push([coord(i, nx, 0), coord(j, ny, 1), coord(k, nz, 2)]);
            }
        }
    }
    m.tets.reserve(6 * ncell);
    m.region.reserve(6 * ncell);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let c = |b: usize| pid(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
                let r = u32::from(i >= split);
                for t in KUHN {
                    m.tets.push(t.map(c));
                    m.region.push(r);
                }
            }
        }
    }
    m.build_adjacency()
        .expect("a Kuhn box is a conforming mesh");

    // Boundary: box side from the grid index shared by the three vertices.
    let grid = |p: PointId| {
        let i = p.idx();
        [i % px, (i / px) % py, i / (px * py)]
    };
    let side = |f: [PointId; 3]| -> u32 {
        let g = f.map(grid);
        let n = [nx, ny, nz];
        for d in 0..3 {
            if g.iter().all(|v| v[d] == 0) {
                return 2 * d as u32;
            }
            if g.iter().all(|v| v[d] == n[d]) {
                return 2 * d as u32 + 1;
            }
        }
        unreachable!("boundary face off the box sides")
    };
    let mut bnd: Vec<(u32, [PointId; 3])> = Vec::new();
    for (i, &n) in m.neigh.iter().enumerate() {
        let f = FaceRef::from_raw(i as u32);
        if n.is_none() {
            let v = m.face_points(f);
            bnd.push((side(v), v));
        } else if m.region[f.tet().idx()] == 0 && m.region[n.tet().idx()] == 1 {
            bnd.push((INTERFACE_PATCH, m.face_points(f)));
        }
    }
    bnd.sort_by_key(|b| b.0);
    m.bnd_patch = bnd.iter().map(|b| b.0).collect();
    m.bnd_tris = bnd.into_iter().map(|b| b.1).collect();
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_geom::orient3d;

    #[test]
    fn kuhn_cube_tets_are_positive() {
        let c = |b: usize| [(b & 1) as f64, ((b >> 1) & 1) as f64, ((b >> 2) & 1) as f64];
        for t in KUHN {
            let p = t.map(c);
            assert!(orient3d(p[0], p[1], p[2], p[3]) > 0.0, "{t:?}");
        }
    }
}
