//! Surface writers: a [`Surface`] as STL, OBJ, OFF, Gmsh `.msh`, Medit
//! `.mesh` or VTU, chosen by extension.
//!
//! Coordinates are written as the shortest text that reads back to the
//! same `f64`, so every format but binary STL (never written) keeps them
//! bit for bit. Patch tags: STL writes one `solid` per patch and OBJ one
//! `g` group per patch, in ascending tag order, named by the patch name or
//! `patch N` (readers number them 0, 1, ... in that order, so tags 0..k
//! come back as they were); OFF has no tags; `.msh`, `.mesh` and `.vtu`
//! go through the mesh writers (Gmsh groups start at 1, see [`write_mesh`]).

use crate::util::{put_f64, put_int};
use crate::{write_atomic, write_mesh, IoError, WriteOptions};
use parafront_mesh::{PointId, TetMesh};
use parafront_surface::Surface;
use std::io::Write;
use std::path::Path;

/// Surface file formats, chosen by [`surface_format`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFormat {
    /// ascii STL, one solid per patch.
    Stl,
    /// Wavefront OBJ, one group per patch.
    Obj,
    /// OFF (no tags).
    Off,
    /// A format of [`write_mesh`] (`.msh`, `.mesh`, `.vtu`), triangles only.
    Mesh(crate::Format),
}

/// The surface format named by the extension of `path` (case-insensitive).
pub fn surface_format(path: &Path) -> Option<SurfaceFormat> {
    if let Some(f) = crate::Format::from_path(path) {
        return Some(SurfaceFormat::Mesh(f));
    }
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "stl" => Some(SurfaceFormat::Stl),
        "obj" => Some(SurfaceFormat::Obj),
        "off" => Some(SurfaceFormat::Off),
        _ => None,
    }
}

/// Writes `s` in the format named by the extension of `path`; the patch
/// names come from `s` (those in `opts` are not used).
pub fn write_surface(path: &Path, s: &Surface, opts: &WriteOptions) -> Result<(), IoError> {
    let bad = |msg: String| IoError::BadInput {
        path: path.to_path_buf(),
        msg,
    };
    if s.patch.len() != s.tris.len() {
        return Err(bad(format!(
            "{} patch tags for {} triangles",
            s.patch.len(),
            s.tris.len()
        )));
    }
    let np = s.points.len();
    if let Some(t) = s
        .tris
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= np))
    {
        return Err(bad(format!("triangle {t} refers to a point >= {np}")));
    }
    let fmt = surface_format(path).ok_or_else(|| {
        bad("unknown surface format (expected .stl, .obj, .off, .msh, .mesh or .vtu)".into())
    })?;
    match fmt {
        SurfaceFormat::Stl => write_atomic(path, |w| stl(w, s)),
        SurfaceFormat::Obj => write_atomic(path, |w| obj(w, s)),
        SurfaceFormat::Off => write_atomic(path, |w| off(w, s)),
        SurfaceFormat::Mesh(_) => {
            let m = TetMesh {
                points: s.points.clone(),
                bnd_tris: s.tris.iter().map(|t| t.map(PointId::from_raw)).collect(),
                bnd_patch: s.patch.clone(),
                ..Default::default()
            };
            let o = WriteOptions {
                patch_names: s.patch_names.clone(),
                ..opts.clone()
            };
            write_mesh(path, &m, &o)
        }
    }
}

/// Triangle ids grouped by patch, ascending tags, each group in file order.
fn by_patch(s: &Surface) -> Vec<(u32, Vec<usize>)> {
    let mut ids: Vec<usize> = (0..s.tris.len()).collect();
    ids.sort_by_key(|&t| s.patch[t]);
    ids.chunk_by(|&a, &b| s.patch[a] == s.patch[b])
        .map(|g| (s.patch[g[0]], g.to_vec()))
        .collect()
}

/// The patch's name on one line, or `patch N`.
fn name(s: &Surface, tag: u32) -> String {
    s.patch_names
        .iter()
        .find(|(t, _)| *t == tag)
        .map(|(_, n)| n.chars().filter(|c| !c.is_control()).collect::<String>())
        .filter(|n| !n.trim().is_empty())
        .unwrap_or_else(|| format!("patch {tag}"))
}

fn coords(buf: &mut Vec<u8>, p: [f64; 3]) {
    for (k, x) in p.iter().enumerate() {
        if k > 0 {
            buf.push(b' ');
        }
        put_f64(buf, *x);
    }
}

fn stl(w: &mut impl Write, s: &Surface) -> std::io::Result<()> {
    let mut buf = Vec::new();
    for (tag, tris) in by_patch(s) {
        let n = name(s, tag);
        writeln!(buf, "solid {n}")?;
        for &t in &tris {
            let p = s.tris[t].map(|v| s.points[v as usize]);
            let nrm = parafront_geom::normalize(parafront_geom::cross(
                parafront_geom::sub(p[1], p[0]),
                parafront_geom::sub(p[2], p[0]),
            ));
            let nrm = if nrm.iter().all(|x| x.is_finite()) {
                nrm
            } else {
                [0.0; 3]
            };
            buf.extend_from_slice(b"facet normal ");
            coords(&mut buf, nrm);
            buf.extend_from_slice(b"\n outer loop\n");
            for q in p {
                buf.extend_from_slice(b"  vertex ");
                coords(&mut buf, q);
                buf.push(b'\n');
            }
            buf.extend_from_slice(b" endloop\nendfacet\n");
            if buf.len() > 1 << 16 {
                w.write_all(&buf)?;
                buf.clear();
            }
        }
        writeln!(buf, "endsolid {n}")?;
    }
    w.write_all(&buf)
}

fn obj(w: &mut impl Write, s: &Surface) -> std::io::Result<()> {
    let mut buf = Vec::new();
    for p in &s.points {
        buf.extend_from_slice(b"v ");
        coords(&mut buf, *p);
        buf.push(b'\n');
    }
    for (tag, tris) in by_patch(s) {
        writeln!(buf, "g {}", name(s, tag))?;
        for &t in &tris {
            buf.push(b'f');
            for v in s.tris[t] {
                buf.push(b' ');
                put_int(&mut buf, v as u64 + 1);
            }
            buf.push(b'\n');
        }
        if buf.len() > 1 << 16 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

fn off(w: &mut impl Write, s: &Surface) -> std::io::Result<()> {
    let mut buf = Vec::new();
    writeln!(buf, "OFF\n{} {} 0", s.points.len(), s.tris.len())?;
    for p in &s.points {
        coords(&mut buf, *p);
        buf.push(b'\n');
    }
    for t in &s.tris {
        buf.push(b'3');
        for v in t {
            buf.push(b' ');
            put_int(&mut buf, v);
        }
        buf.push(b'\n');
    }
    w.write_all(&buf)
}
