//! Format readers: STL (ascii and binary), OBJ, OFF, Gmsh .msh (2.2 and
//! 4.1, ascii and binary, little-endian) and Medit .mesh (ascii).
//!
//! Every reader works on the whole file in memory, checks every count
//! against the bytes left before reserving, rejects non-finite
//! coordinates and out-of-range indices, and reports the file, the line
//! (ascii) or byte offset (binary) and what is wrong. STL corners are
//! welded by exact coordinate equality only; the other formats keep their
//! indices as given. Unreferenced points and repeated vertices in a
//! triangle are kept: validation reports them.
//!
//! [`msh`] and [`medit`] also collect tetrahedra, so the volume-mesh
//! reader reuses them: one parser per format in the project.

mod cursor;
pub mod medit;
pub mod msh;
mod obj;
mod off;
mod stl;
mod weld;

use crate::Surface;
use parafront_geom::P3;
use std::fmt;
use std::path::Path;

/// A supported surface file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// STL, ascii or binary (told apart by content).
    Stl,
    /// Wavefront OBJ (`v` and `f`; polygons fan-triangulated, `g`/`o` groups as
    /// patches).
    Obj,
    /// OFF and its variants (COFF, NOFF, ...); polygons fan-triangulated.
    Off,
    /// Gmsh .msh 2.2 or 4.1, ascii or binary (told apart by `$MeshFormat`).
    Msh,
    /// Medit .mesh (ascii).
    Medit,
}

impl Format {
    /// The format named by a file extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => Format::Stl,
            "obj" => Format::Obj,
            "off" => Format::Off,
            "msh" => Format::Msh,
            "mesh" => Format::Medit,
            _ => return None,
        })
    }
}

/// Where in a file an error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Loc {
    /// The file as a whole.
    File,
    /// 1-based line of an ascii file.
    Line(usize),
    /// Byte offset in a binary file.
    Byte(usize),
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Loc::File => Ok(()),
            Loc::Line(l) => write!(f, ":{l}"),
            Loc::Byte(b) => write!(f, ": byte {b}"),
        }
    }
}

/// A file that could not be read as a surface.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file's name, as given to the reader.
        file: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file's extension names no supported format.
    #[error("{file}: unknown file extension (expected .stl, .obj, .off, .msh or .mesh)")]
    UnknownFormat {
        /// The file's name, as given to the reader.
        file: String,
    },
    /// Malformed content: `what` says what is wrong at `at`.
    #[error("{file}{at}: {what}")]
    Bad {
        /// The file's name, as given to the reader.
        file: String,
        /// Where in the file.
        at: Loc,
        /// What is wrong there.
        what: String,
    },
}

impl ReadError {
    /// Where the error is ([`Loc::File`] for I/O and format errors).
    pub fn loc(&self) -> Loc {
        match self {
            ReadError::Bad { at, .. } => *at,
            _ => Loc::File,
        }
    }
    fn file(file: &str, what: impl Into<String>) -> ReadError {
        ReadError::Bad {
            file: file.to_string(),
            at: Loc::File,
            what: what.into(),
        }
    }
}

/// Reads a surface, choosing the reader by extension.
pub fn read_surface(path: &Path) -> Result<Surface, ReadError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    let fmt =
        Format::from_path(path).ok_or_else(|| ReadError::UnknownFormat { file: name.clone() })?;
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        file: name.clone(),
        source,
    })?;
    read_surface_bytes(&name, &bytes, fmt)
}

/// Reads a surface from bytes in memory; `name` is used in errors only.
pub fn read_surface_bytes(name: &str, bytes: &[u8], fmt: Format) -> Result<Surface, ReadError> {
    match fmt {
        Format::Stl => stl::read(name, bytes),
        Format::Obj => obj::read(name, bytes),
        Format::Off => off::read(name, bytes),
        Format::Msh => msh::parse(name, bytes).map(VolumeData::into_surface),
        Format::Medit => medit::parse(name, bytes).map(VolumeData::into_surface),
    }
}

/// What the volume-capable readers ([`msh`], [`medit`]) collect.
///
/// Indices are 0-based into `points`, checked in range. Tags are the Gmsh
/// physical tag (or the entity tag when the entity has none) or the
/// Medit reference.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeData {
    /// The nodes, in file order.
    pub points: Vec<P3>,
    /// The triangles, in file order.
    pub tris: Vec<[u32; 3]>,
    /// The tag of each triangle.
    pub tri_tags: Vec<u32>,
    /// The tetrahedra, in file order.
    pub tets: Vec<[u32; 4]>,
    /// The tag of each tet.
    pub tet_tags: Vec<u32>,
    /// Names of 2-D physical groups (surface patches).
    pub names: Vec<(u32, String)>,
    /// Names of 3-D physical groups (volumes).
    pub volume_names: Vec<(u32, String)>,
}

impl VolumeData {
    /// The triangles as a surface; all points are kept, so interior nodes
    /// of a volume mesh show up as unreferenced points.
    pub fn into_surface(self) -> Surface {
        Surface {
            points: self.points,
            tris: self.tris,
            patch: self.tri_tags,
            patch_names: self.names,
        }
    }
}

/// Checks a point count fits the u32 indices.
fn check_point_count(name: &str, n: usize) -> Result<(), ReadError> {
    if n > u32::MAX as usize {
        return Err(ReadError::file(
            name,
            format!("{n} points is more than 32-bit indices can address"),
        ));
    }
    Ok(())
}
