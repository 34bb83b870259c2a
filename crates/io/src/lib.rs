//! Output and volume-mesh input: the pipeline's last step.
//!
//! - [`write_mesh`]: one call for every format, chosen by extension
//!   ([`Format`]): ParaView `.vtu` (raw appended binary, optional zlib),
//!   Gmsh `.msh` 4.1 / 2.2 (ascii or binary), Medit `.mesh`.
//! - [`write_vtu`] / [`write_pvtu`]: VTU with extra point / cell arrays, and
//!   one `.vtu` per part under a `.pvtu`.
//! - [`read_mesh`]: `.vtu`, `.msh`, `.mesh` back into a [`TetMesh`].
//! - [`write_surface`]: a triangle surface as STL, OBJ, OFF, `.msh`,
//!   `.mesh` or `.vtu`, patch tags kept where the format holds them.
//!
//! Every writer is atomic ([`write_atomic`]): a temp file beside the target,
//! renamed when complete. Tets and boundary triangles keep their order;
//! regions and patch tags travel as VTU `region`/`patch` cell data, Gmsh
//! named physical groups (from 1: tags shifted by 1 when one is 0) and
//! Medit refs.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod atomic;
mod medit;
mod msh;
mod read;
mod surface;
mod util;
mod vtu;
mod vtu_read;

pub use atomic::write_atomic;
pub use read::read_mesh;
pub use surface::{surface_format, write_surface, SurfaceFormat};
pub use vtu::{write_pvtu, write_pvtu_share, write_vtu, Field, FieldData, Piece};

use parafront_mesh::TetMesh;
use std::path::{Path, PathBuf};

/// Errors of reading and writing mesh files; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        #[source]
        source: std::io::Error,
    },
    /// The file's extension names no mesh format.
    #[error("{}: unknown mesh format (expected .vtu, .msh or .mesh)", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The file is malformed; `msg` says where (line, element, array).
    #[error("{}: {msg}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong, and where.
        msg: String,
    },
    /// A `.msh` or `.mesh` file the surface crate's parser rejected.
    #[error(transparent)]
    Read(#[from] parafront_surface::read::ReadError),
    /// The data handed to a writer cannot be written as asked.
    #[error("cannot write {}: {msg}", path.display())]
    BadInput {
        /// The file.
        path: PathBuf,
        /// What cannot be written.
        msg: String,
    },
}

/// Mesh file formats, chosen by [`Format::from_path`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ParaView XML UnstructuredGrid (`.vtu`).
    Vtu,
    /// Gmsh (`.msh`); version and binary flag come from [`WriteOptions`].
    Msh,
    /// Medit ascii (`.mesh`).
    Medit,
}

impl Format {
    /// The format named by the file extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "vtu" => Some(Format::Vtu),
            "msh" => Some(Format::Msh),
            "mesh" => Some(Format::Medit),
            _ => None,
        }
    }
}

/// Gmsh file format version.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MshVersion {
    /// 4.1: `$Entities`, nodes and elements grouped by entity (default).
    #[default]
    V41,
    /// 2.2: the legacy format, still the most widely read.
    V22,
}

/// Options of [`write_mesh`]; `Default` gives the documented defaults.
#[derive(Clone, Debug)]
pub struct WriteOptions {
    /// Gmsh version (default 4.1).
    pub msh_version: MshVersion,
    /// Binary Gmsh file (default false: ascii).
    pub binary: bool,
    /// zlib-compress the VTU arrays (default true).
    pub compress: bool,
    /// zlib level 0-9 (default 1: fast, most of the gain).
    pub compress_level: u32,
    /// Int64 VTU connectivity and offsets (default true); false writes Int32.
    pub vtu_int64: bool,
    /// Region names (Gmsh physical names of dimension 3).
    pub region_names: Vec<(u32, String)>,
    /// Patch names (Gmsh physical names of dimension 2).
    pub patch_names: Vec<(u32, String)>,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            msh_version: MshVersion::V41,
            binary: false,
            compress: true,
            compress_level: 1,
            vtu_int64: true,
            region_names: Vec::new(),
            patch_names: Vec::new(),
        }
    }
}

/// Writes `mesh` in the format named by the extension of `path`.
pub fn write_mesh(path: &Path, mesh: &TetMesh, opts: &WriteOptions) -> Result<(), IoError> {
    match Format::from_path(path) {
        Some(Format::Vtu) => write_vtu(path, &Piece::new(mesh), opts),
        Some(Format::Msh) => msh::write_msh(path, mesh, opts),
        Some(Format::Medit) => medit::write_medit(path, mesh),
        None => Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Writes a Gmsh `.msh` file whatever the extension.
pub fn write_msh(path: &Path, mesh: &TetMesh, opts: &WriteOptions) -> Result<(), IoError> {
    msh::write_msh(path, mesh, opts)
}

/// Writes a Medit `.mesh` file whatever the extension.
pub fn write_medit(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    medit::write_medit(path, mesh)
}
