//! The input surface (paper AG2): a watertight, consistently oriented
//! triangulation, possibly several shells, with patch tags.
//!
//! - [`read`]: the format readers (STL, OBJ, OFF, Gmsh .msh, Medit .mesh).
//! - [`validate`]: open / non-manifold / orientation / degenerate /
//!   self-intersection checks, and how the closed shells nest.
//! - [`inside`]: whether a point lies inside the surface.
//! - [`heal`]: merges the vertices a float rounding split apart, where
//!   that closes open edges (opt-in; exact welding stays the default).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod generate;
pub mod hard;
pub mod heal;
pub mod inside;
pub mod read;
pub mod validate;

use parafront_geom::P3;

/// A triangulated surface as read from a file.
///
/// Triangles are oriented with outward normals as seen from the domain:
/// an outer shell's normals point away from the material, a void's point
/// into the void.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    /// The vertices.
    pub points: Vec<P3>,
    /// The triangles, as indices into `points`, normals pointing out of the
    /// domain (see above).
    pub tris: Vec<[u32; 3]>,
    /// Patch tag per triangle (STL solid index, OBJ group, Gmsh entity or
    /// physical tag, Medit ref). 0 when the file has none.
    pub patch: Vec<u32>,
    /// Optional names of patch tags (STL solid names, OBJ groups, Gmsh
    /// physical names).
    pub patch_names: Vec<(u32, String)>,
}

impl Surface {
    /// A surface whose triangles all belong to patch 0.
    pub fn one_patch(points: Vec<parafront_geom::P3>, tris: Vec<[u32; 3]>) -> Surface {
        let n = tris.len();
        Surface {
            points,
            tris,
            patch: vec![0; n],
            patch_names: Vec::new(),
        }
    }

    /// The bounding box of every point, used or not.
    pub fn bbox(&self) -> parafront_geom::Aabb {
        parafront_geom::Aabb::from_points(&self.points)
    }
    /// Mean length of the edges at each point (AG3's default size); 0 for
    /// a point no triangle uses ([`mean_edge_lengths`]).
    pub fn mean_edge_lengths(&self) -> Vec<f64> {
        mean_edge_lengths(&self.points, &self.tris)
    }
    /// Signed enclosed volume by the divergence theorem (positive when the
    /// normals point outward).
    pub fn signed_volume(&self) -> f64 {
        // Shift to the box centre: fewer cancellation errors on far-off parts.
        let c = self.bbox().center();
        let mut v = 0.0;
        for t in &self.tris {
            let a = parafront_geom::sub(self.points[t[0] as usize], c);
            let b = parafront_geom::sub(self.points[t[1] as usize], c);
            let d = parafront_geom::sub(self.points[t[2] as usize], c);
            v += parafront_geom::dot(a, parafront_geom::cross(b, d));
        }
        v / 6.0
    }
}

/// Mean length of the edges at each point of `tris` (AG3's default size);
/// 0 for a point no triangle uses. Interior edges count once per triangle,
/// i.e. twice, which leaves the mean unchanged on a closed surface; the
/// orientation does not matter.
pub fn mean_edge_lengths(points: &[parafront_geom::P3], tris: &[[u32; 3]]) -> Vec<f64> {
    let mut sum = vec![0.0; points.len()];
    let mut n = vec![0u32; points.len()];
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let l = parafront_geom::dist(points[a], points[b]);
            sum[a] += l;
            sum[b] += l;
            n[a] += 1;
            n[b] += 1;
        }
    }
    sum.iter()
        .zip(&n)
        .map(|(s, &n)| if n > 0 { s / n as f64 } else { 0.0 })
        .collect()
}
