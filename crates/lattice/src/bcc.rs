//! The BCC tets of the accepted cells: the cube corners and centres are
//! the points; two face-adjacent cells of a level fill the octahedron of
//! their centres and the shared square with 4 tets; a square on a block's
//! boundary closes its cell's pyramid with 2 tets, and its 2 triangles are
//! the lattice's outer faces.
use crate::octree::Cells;
use crate::CUBE_PER_SIZE;
use parafront_geom::{orient3d, tet_volume6, P3};
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
    /// Tet `i` is not positively oriented (exactly).
    NotPositive(usize),
    /// A face used more than twice, or twice from the same side.
    Face([u32; 3]),
    /// The faces used once are not the outer faces.
    Boundary,
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

    /// Every tet positive (exactly), every face shared by at most two tets
    /// from opposite sides, the faces used once exactly the outer faces
    /// (oriented away from their tet), and the tets' volume the cubes'.
    pub fn check(&self) -> Result<(), LatticeCheckError> {
        let mut vol = 0.0;
        let mut once: FxHashMap<[u32; 3], [u32; 3]> = FxHashMap::default();
        let mut twice: FxHashSet<[u32; 3]> = FxHashSet::default();
        for (i, t) in self.tets.iter().enumerate() {
            let p = t.map(|v| self.points[v as usize]);
            if !(orient3d(p[0], p[1], p[2], p[3]) > 0.0) {
                return Err(LatticeCheckError::NotPositive(i));
            }
            vol += tet_volume6(p[0], p[1], p[2], p[3]) / 6.0;
            // Each face, its normal pointing out of the tet.
            for f in [
                [t[1], t[2], t[3]],
                [t[0], t[3], t[2]],
                [t[0], t[1], t[3]],
                [t[0], t[2], t[1]],
            ] {
                let mut k = f;
                k.sort_unstable();
                if twice.contains(&k) {
                    return Err(LatticeCheckError::Face(k));
                }
                match once.remove(&k) {
                    Some(g) if same_cycle(g, [f[0], f[2], f[1]]) => {
                        twice.insert(k);
                    }
                    Some(_) => return Err(LatticeCheckError::Face(k)),
                    None => {
                        once.insert(k, f);
                    }
                }
            }
        }
        if once.len() != self.faces.len()
            || !self.faces.iter().all(|&f| {
                let mut k = f;
                k.sort_unstable();
                once.get(&k).is_some_and(|&g| same_cycle(g, f))
            })
        {
            return Err(LatticeCheckError::Boundary);
        }
        if (vol - self.volume).abs() > 1e-9 * self.volume.max(f64::MIN_POSITIVE) {
            return Err(LatticeCheckError::Volume {
                tets: vol,
                cells: self.volume,
            });
        }
        Ok(())
    }
}

fn same_cycle(a: [u32; 3], b: [u32; 3]) -> bool {
    a == b || a == [b[1], b[2], b[0]] || a == [b[2], b[0], b[1]]
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
