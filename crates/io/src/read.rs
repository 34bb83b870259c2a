//! The volume-mesh reader: `.msh` and `.mesh` through the surface crate's
//! parsers (one parser per format), `.vtu` through [`crate::vtu_read`].

use crate::{vtu_read, Format, IoError};
use parafront_mesh::{PointId, TetMesh};
use parafront_surface::read::{medit, msh, VolumeData};
use std::path::Path;

/// Reads a tet mesh from `.vtu`, `.msh` (2.2 / 4.1) or `.mesh`. Triangles
/// become `bnd_tris` / `bnd_patch`, tet tags `region`; `neigh` is left
/// empty. Ids are checked in range; orientation is not checked here.
pub fn read_mesh(path: &Path) -> Result<TetMesh, IoError> {
    let fmt = Format::from_path(path).ok_or_else(|| IoError::UnknownFormat {
        path: path.to_path_buf(),
    })?;
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let name = path.display().to_string();
    let vol = match fmt {
        Format::Vtu => return vtu_read::read_vtu(path, &bytes),
        Format::Msh => msh::parse(&name, &bytes)?,
        Format::Medit => medit::parse(&name, &bytes)?,
    };
    Ok(from_volume(vol))
}

fn from_volume(v: VolumeData) -> TetMesh {
    TetMesh {
        points: v.points,
        tets: v.tets.iter().map(|t| t.map(PointId::from_raw)).collect(),
        neigh: Vec::new(),
        region: v.tet_tags,
        bnd_tris: v.tris.iter().map(|t| t.map(PointId::from_raw)).collect(),
        bnd_patch: v.tri_tags,
    }
}
