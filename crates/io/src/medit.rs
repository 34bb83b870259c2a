//! Medit `.mesh` ascii writer: vertices (ref 0), triangles with their patch
//! as ref, tetrahedra with their region as ref; 1-based ids.

use crate::util::{check_mesh, put_f64, put_int, write_par};
use crate::{write_atomic, IoError};
use parafront_mesh::TetMesh;
use std::io::Write;
use std::path::Path;

pub fn write_medit(path: &Path, m: &TetMesh) -> Result<(), IoError> {
    check_mesh(path, m)?;
    write_atomic(path, |w| {
        writeln!(w, "MeshVersionFormatted 2\n\nDimension 3\n")?;
        writeln!(w, "Vertices\n{}", m.points.len())?;
        write_par(w, m.points.len(), |i, buf| {
            for x in m.points[i] {
                put_f64(buf, x);
                buf.push(b' ');
            }
            buf.extend_from_slice(b"0\n");
        })?;
        if !m.bnd_tris.is_empty() {
            writeln!(w, "\nTriangles\n{}", m.bnd_tris.len())?;
            write_par(w, m.bnd_tris.len(), |i, buf| {
                for p in m.bnd_tris[i] {
                    put_int(buf, p.raw() as u64 + 1);
                    buf.push(b' ');
                }
                put_int(buf, m.bnd_patch[i]);
                buf.push(b'\n');
            })?;
        }
        if !m.tets.is_empty() {
            writeln!(w, "\nTetrahedra\n{}", m.tets.len())?;
            write_par(w, m.tets.len(), |i, buf| {
                for p in m.tets[i] {
                    put_int(buf, p.raw() as u64 + 1);
                    buf.push(b' ');
                }
                put_int(buf, m.region[i]);
                buf.push(b'\n');
            })?;
        }
        writeln!(w, "\nEnd")
    })
}
