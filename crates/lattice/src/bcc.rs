//! The BCC tets of the accepted cells: the cube corners and centres are
//! the points; two face-adjacent cells of a level fill the octahedron of
//! their centres and the shared square with 4 tets; a square on a block's
//! boundary closes its cell's pyramid with 2 tets, and its 2 triangles are
//! the lattice's outer faces.
use crate::octree::Cells;
use crate::CUBE_PER_SIZE;
use parafront_geom::{tet_volume6, P3};
use parafront_mesh::{CheckError, PointId, TetMesh, VOLUME_RTOL};
use rustc_hash::{FxHashMap, FxHashSet};

/// A lattice: points, positive tets, and the outer faces (right-hand
/// normals pointing away from the lattice, into the region the front
/// meshes: a front face's convention).
#[derive(Clone, Debug, Default)]
pub struct Lattice {
    /// The filled cubes' corners (shared by the cells that meet there) and centres.
    pub points: Vec<P3>,
    /// The tets, positively oriented (indices into `points`).
    pub tets: Vec<[u32; 4]>,
    /// The outer faces (indices into `points`), normals pointing into the region
    /// the front meshes; they join the surface in the initial front.
    pub faces: Vec<[u32; 3]>,
    /// Whether a point is on no outer face (the front never sees it).
    pub interior: Vec<bool>,
    /// Each point's size: its block's, the edge of the regular tet of the
    /// lattice tets' volume.
    pub size: Vec<f64>,
    /// Cubes filled, and their total volume.
    pub cells: usize,
    /// The filled cubes' total volume (the sum of their edges cubed), against
    /// which `check` measures the tets'.
    pub volume: f64,
}

/// Why a lattice is not valid.
#[derive(Debug, Clone, PartialEq)]
pub enum LatticeCheckError {
    /// As a mesh bounded by its outer faces it fails `TetMesh`'s check: a
    /// tet not positive (exactly), a face in more than two tets or twice
    /// from one side, the faces used once not exactly the outer faces
    /// (oriented away from their tet), or the volumes not adding up.
    Mesh(CheckError),
    /// The tets' total volume is not the cubes' (to a relative 1e-9).
    Volume {
        /// The sum of the tets' volumes.
        tets: f64,
        /// The cubes' total volume ([`Lattice::volume`]).
        cells: f64,
    },
}

impl Lattice {
    /// Whether the lattice has no tets (no cell qualified).
    pub fn is_empty(&self) -> bool {
        self.tets.is_empty()
    }

    /// `TetMesh::check_against_surface` with the outer faces as the
    /// surface, and the tets' volume the cubes'.
    pub fn check(&self) -> Result<(), LatticeCheckError> {
        let mesh = TetMesh {
            points: self.points.clone(),
            tets: self.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
            ..TetMesh::default()
        };
        let st = mesh
            .check_against_surface(&self.faces)
            .map_err(LatticeCheckError::Mesh)?;
        if (st.volume - self.volume).abs() > VOLUME_RTOL * self.volume.max(f64::MIN_POSITIVE) {
            return Err(LatticeCheckError::Volume {
                tets: st.volume,
                cells: self.volume,
            });
        }
        Ok(())
    }
}

/// The square of cell `ijk`'s face on axis `a`, side `hi` (0 or 1): its
/// corners' offsets, in cyclic order.
fn square(a: usize, hi: i64) -> [[i64; 3]; 4] {
    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
    let mut out = [[0i64; 3]; 4];
    for (i, (du, dv)) in [(0, 0), (1, 0), (1, 1), (0, 1)].into_iter().enumerate() {
        out[i][a] = hi;
        out[i][u] = du;
        out[i][v] = dv;
    }
    out
}

pub(crate) fn tetrahedralize(c: &Cells) -> Lattice {
    let mut l = Lattice::default();
    if c.cells.is_empty() {
        return l;
    }
    let set: FxHashSet<(u32, [i64; 3])> = c.cells.iter().copied().collect();
    let mut corner_id: FxHashMap<(u32, [i64; 3]), u32> = FxHashMap::default();
    let mut corner = |l: &mut Lattice, d: u32, ijk: [i64; 3]| -> u32 {
        *corner_id.entry((d, ijk)).or_insert_with(|| {
            l.points.push(c.corner(d, ijk));
            l.size.push(c.side(d) / CUBE_PER_SIZE);
            (l.points.len() - 1) as u32
        })
    };
    let mut centre_id: FxHashMap<(u32, [i64; 3]), u32> = FxHashMap::default();
    for &(d, ijk) in &c.cells {
        let s = c.side(d);
        let a = c.corner(d, ijk);
        l.points.push(a.map(|x| x + 0.5 * s));
        l.size.push(s / CUBE_PER_SIZE);
        centre_id.insert((d, ijk), (l.points.len() - 1) as u32);
        l.volume += s * s * s;
    }
    l.cells = c.cells.len();
    let mut on_face = Vec::new();
    for &(d, ijk) in &c.cells {
        let ci = centre_id[&(d, ijk)];
        for a in 0..3 {
            for hi in [0i64, 1] {
                let mut n = ijk;
                n[a] += 2 * hi - 1;
                let q = square(a, hi).map(|o| corner(&mut l, d, [0, 1, 2].map(|k| ijk[k] + o[k])));
                if set.contains(&(d, n)) {
                    // The octahedron, once, from the cell below.
                    if hi == 1 {
                        let ni = centre_id[&(d, n)];
                        for e in 0..4 {
                            push_tet(&mut l, [ci, ni, q[e], q[(e + 1) % 4]]);
                        }
                    }
                } else {
                    for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                        push_tet(&mut l, [ci, tri[0], tri[1], tri[2]]);
                        let p = tri.map(|v| l.points[v as usize]);
                        let centre = l.points[ci as usize];
                        // Pointing away from the cell.
                        let f = if tet_volume6(p[0], p[1], p[2], centre) < 0.0 {
                            tri
                        } else {
                            [tri[0], tri[2], tri[1]]
                        };
                        l.faces.push(f);
                        on_face.extend_from_slice(&f);
                    }
                }
            }
        }
    }
    l.interior = vec![true; l.points.len()];
    for v in on_face {
        l.interior[v as usize] = false;
    }
    l
}

/// Adds tet `t`, turned positive.
fn push_tet(l: &mut Lattice, mut t: [u32; 4]) {
    let p = t.map(|v| l.points[v as usize]);
    if tet_volume6(p[0], p[1], p[2], p[3]) < 0.0 {
        t.swap(2, 3);
    }
    l.tets.push(t);
}
