use crate::ids::*;
use parafront_geom::P3;

/// Local faces of a tet, each listed so that its right-hand normal points
/// out of a positively oriented tet. Face `f` is opposite vertex `f`.
pub const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// A tetrahedral mesh: geometry (`points`) apart from topology (`tets`,
/// `neigh`), plus per-tet regions and the tagged boundary triangles.
#[derive(Clone, Debug, Default)]
pub struct TetMesh {
    /// Coordinates, indexed by [`PointId`].
    pub points: Vec<P3>,
    /// Four point ids per tet, positively oriented.
    pub tets: Vec<[PointId; 4]>,
    /// `neigh[4t+f]`: the face on the other side of face `f` of tet `t`, or
    /// [`NO_FACE`]. Empty until `build_adjacency` runs.
    pub neigh: Vec<FaceRef>,
    /// Region id per tet (0 when the domain has one region).
    pub region: Vec<u32>,
    /// Boundary triangles (outward, i.e. as in the input surface) with their
    /// patch tags; carried through to output.
    pub bnd_tris: Vec<[PointId; 3]>,
    /// Patch tag per boundary triangle.
    pub bnd_patch: Vec<u32>,
}

impl TetMesh {
    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }
    /// Number of tets.
    pub fn n_tets(&self) -> usize {
        self.tets.len()
    }
    /// Coordinates of the four vertices of tet `t`.
    #[inline]
    pub fn tet_points(&self, t: TetId) -> [P3; 4] {
        self.tets[t.idx()].map(|p| self.points[p.idx()])
    }
    /// Region of tet `t` (0 when `region` is empty).
    #[inline]
    pub fn region_of(&self, t: TetId) -> u32 {
        self.region.get(t.idx()).copied().unwrap_or(0)
    }
    /// Sum of the tet volumes (floating point): equals the enclosed volume
    /// of the boundary when the mesh fills it.
    pub fn volume(&self) -> f64 {
        self.tets
            .iter()
            .map(|t| {
                let p = t.map(|x| self.points[x.idx()]);
                parafront_geom::tet_volume6(p[0], p[1], p[2], p[3]) / 6.0
            })
            .sum()
    }
    /// Appends a point and returns its id.
    pub fn push_point(&mut self, p: P3) -> PointId {
        self.points.push(p);
        PointId::new(self.points.len() - 1)
    }
    /// Appends a tet with its region; invalidates `neigh` (cleared).
    pub fn push_tet(&mut self, verts: [PointId; 4], region: u32) -> TetId {
        self.neigh.clear();
        if self.region.len() < self.tets.len() {
            self.region.resize(self.tets.len(), 0);
        }
        self.tets.push(verts);
        self.region.push(region);
        TetId::new(self.tets.len() - 1)
    }
}
